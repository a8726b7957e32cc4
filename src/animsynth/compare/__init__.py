"""Beyond the papers: every motion generator of the project and the classic motion graph, side by side.

The same held-out clips (CMU's Gauch & Peters subsets by leave one out, the re-sequencing clips by a
temporal split), the same starts and seeds, one set of metrics (foot skating, seam jumps, smoothness,
LAFAN1's L2P / L2Q / NPSS, coverage, diversity, novelty) and the cost of each generator. This package
sits above the four families: it fits and runs their estimators (the registry, :mod:`.generators`)
to score them; no family imports it. Every generator, the graphs included, is a
:class:`animsynth.generator.Generator`: the interface (Generator, Database, root placement) has the one import
path :mod:`animsynth.generator`.

Layout
------
generators/     the rows it runs (registry, names, motion graph, fairmotion peer and its fixes, motion matching and
                foot locking, GenMM, the references, user generators)
measures/       the metric table and each measure (pose, skating, jumps, transitions, smoothness, ground truth, windows;
                the long track's repetition, root, over time)
protocol        the protocol: held-out clips, their databases, starts and seeds; the clips file
scoring         one generated motion's metrics against its clip (``score``), also for motion files from any tool
                (``animsynth score``)
runner, cost    one generator over every clip and seed, scored, with its cost; the cost guard
jobs            one function per workflow step (clips, one generator's run, the tables, the budget sweep, figures)
tables, plots   the family's tables and figures
verdicts        the declared claims (claims: read from config, margins, checks), decided over independent
                groups (groups, claim_stats)
settings        config checks and what the workflow reads of the ``compare`` block
"""

from .._lazy import lazy_exports

# name -> module; imported on first use (the families' estimators, FieldFollower and Resequencer, are exported by
# their families: animsynth.simplicial, animsynth.resequencing)
_EXPORTS = {
    "Concat": ".generators.references",
    "GENERATORS": ".generators.names",
    "METRICS": ".measures.metric_table",
    "MotionGraph": ".generators.motiongraph",
    "Replay": ".generators.references",
    "make_generator": ".generators.registry",
    "prepare_clips": ".protocol",
    "run_generator": ".runner",
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
