"""File formats: ASF/AMC, BVH, OBJ sequences, CK+ landmarks.

The package's names load their module on first use (:mod:`animsynth._lazy`), so importing one format's module
(``animsynth.io.obj``, as the data sources do when the Snakefile is parsed) does not load the motion formats and
scipy behind them."""

from .._lazy import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "MotionFormatError": "..errors",
    "read_amc": ".amc",
    "write_amc": ".amc",
    "read_asf": ".asf",
    "write_asf": ".asf",
})
