"""Simplicial-complex motion generation (Gauch & Peters) and its extensions.

Modules
-------
geometry    robust Delaunay triangulation (duplicates, rank deficiency, Qhull failures)
graph       the motion graph G', edge orientation, connectivity (SCC, H)
field       training vectors (half / forward / central) and the interpolated vector field
path        field following (one path, or many together) and target-directed shortest paths in G'
metrics     Error A / Error F and point-to-polyline distances
experiment  leave-one-sequence-out folds, ensembles of starts, Table II, paired tests, variant grids
settings    the published values (paper Table II) and the paper's conclusion
verdicts    the claims checked, decided from the tables
plots       the paper's figures and the beyond-the-paper figure
jobs        one function per workflow job (the Snakemake scripts stay thin)
"""

from .._lazy import lazy_exports

# name -> module; imported on first use (the family's heavy libraries load only when needed)
_EXPORTS = {
    "FOLD_COLUMNS": ".experiment",
    "FieldStack": ".field",
    "MEMBER_COLUMNS": ".experiment",
    "MotionGraph": ".graph",
    "SafeDelaunay": ".geometry",
    "TargetPlanner": ".path",
    "Variant": ".experiment",
    "VectorField": ".field",
    "error_a": ".metrics",
    "error_f": ".metrics",
    "follow_batch": ".path",
    "follow_field": ".path",
    "generate_from_trials": ".generate",
    "point_polyline_distance": ".metrics",
    "run_fold": ".experiment",
    "run_fold_ensemble": ".experiment",
    "run_subset": ".experiment",
    "training_vectors": ".field",
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
