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

from .experiment import FOLD_COLUMNS, MEMBER_COLUMNS, Variant, run_fold, run_fold_ensemble, run_subset
from .generate import generate_from_trials
from .field import FieldStack, VectorField, training_vectors
from .geometry import SafeDelaunay
from .graph import MotionGraph
from .metrics import error_a, error_f, point_polyline_distance
from .path import TargetPlanner, follow_batch, follow_field

__all__ = [
    "FOLD_COLUMNS", "FieldStack", "MEMBER_COLUMNS", "MotionGraph", "SafeDelaunay", "TargetPlanner", "Variant",
    "VectorField", "error_a", "error_f", "follow_batch", "follow_field", "generate_from_trials",
    "point_polyline_distance", "run_fold", "run_fold_ensemble", "run_subset", "training_vectors",
]
