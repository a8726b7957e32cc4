"""Lazy package exports (PEP 562): a package names what it exports and from which module, and a module is
imported on first use of one of its names. Importing one submodule of a family (as every workflow job does)
then no longer imports the whole family and every heavy library behind it (scikit-learn, scipy.stats, numba)."""

from __future__ import annotations

import importlib


def lazy_exports(package: str, exports: dict[str, str]):
    """``__all__``, ``__getattr__`` and ``__dir__`` for ``package`` from {name: relative module}."""

    def __getattr__(name: str):
        try:
            module = exports[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        return getattr(importlib.import_module(module, package), name)

    def __dir__():
        return sorted(exports)

    return sorted(exports), __getattr__, __dir__
