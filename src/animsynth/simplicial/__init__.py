"""Simplicial-complex motion generation (Gauch & Peters) and its extensions.

Modules
-------
geometry    robust Delaunay triangulation (duplicates, rank deficiency, Qhull failures)
graph       the motion graph G', edge orientation, connectivity (SCC, H)
field       training vectors (half / forward / central) and the interpolated vector field
path        field following (one path, or many together) and target-directed shortest paths in G'
generator   the method as one estimator (FieldFollower: PCA, training vectors, field, following, decoding),
            called by the folds, the one-call route and the comparison
generate    the one-call route for users and the CLI (generate_from_trials)
metrics     Error A / Error F and point-to-polyline distances
folds       leave-one-sequence-out folds, ensembles of starts, variant grids (the fold and member rows)
tables      Table II in the paper's layout, in every unit, over the ensemble of starts, per fold
stats       stability over the ensemble, paired tests, bootstrap CIs, derivative and variant summaries
table1      Gauch & Peters Table I of the run's data (results/data/datasets.csv)
settings    config checks, the published values (paper Tables I and II) and the paper's conclusion
verdicts    the claims checked, decided from the tables
plots       the paper's figures and the beyond-the-paper figure
jobs        one function per workflow job (the Snakemake scripts stay thin)
"""

from .._lazy import lazy_exports

# name -> module; imported on first use (the family's heavy libraries load only when needed)
_EXPORTS = {
    "FOLD_COLUMNS": ".folds",
    "FieldFollower": ".generator",
    "FieldStack": ".field",
    "MEMBER_COLUMNS": ".folds",
    "MotionGraph": ".graph",
    "SafeDelaunay": ".geometry",
    "TargetPlanner": ".path",
    "Variant": ".folds",
    "VectorField": ".field",
    "datasets_table": ".table1",
    "error_a": ".metrics",
    "error_f": ".metrics",
    "follow_batch": ".path",
    "follow_field": ".path",
    "generate_from_trials": ".generate",
    "point_polyline_distance": ".metrics",
    "run_fold": ".folds",
    "run_fold_ensemble": ".folds",
    "run_subset": ".folds",
    "table2": ".tables",
    "training_vectors": ".field",
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
