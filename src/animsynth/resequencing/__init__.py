"""Re-sequencing motion with Isomap and ST-Isomap.

Modules
-------
features    quaternion linearisation (Lee & Shin), sign modes (continuous; matrix_naive, the
            reproduction of a probable artefact of the paper), sign flips, global DOF
distances   L2 between linearised frames, Lee et al. metric with the paper's weights
embedding   k-NN graphs (optionally with always-present edges), exact minimum connected k,
            Isomap (no silent graph joining), ST-Isomap (Jenkins & Mataric 2004), residual variance
paths       Dijkstra re-sequencing, padding, playing a path as a motion
metrics     transitions, path classes, per-transition and whole-path smoothness
study       the workflow steps (analyse, explain, resequence, tables)
verdicts    the paper's claims in the common verdict format
plots       Fig. 2 (embeddings with edges) and Fig. 3 (residual variance)
"""

from .distances import PAPER_WEIGHTS, l2_distances, lee_distances, lee_metric
from .embedding import (DisconnectedGraphError, PrecomputedIsomap, STIsomap, knn_graph, min_connected_k,
                        residual_variance, spatio_temporal_distances, temporal_adjacency)
from .features import (SIGN_MODES, linearize_quaternions, matrix_naive_quaternions, motion_features, quat_log,
                       sign_flips)
from .metrics import classify_path, pass_jumps, transitions
from .paths import pad_path, play_path, shortest_path_frames

__all__ = [
    "PAPER_WEIGHTS", "l2_distances", "lee_distances", "lee_metric",
    "DisconnectedGraphError", "PrecomputedIsomap", "STIsomap", "knn_graph", "min_connected_k",
    "residual_variance", "spatio_temporal_distances", "temporal_adjacency",
    "SIGN_MODES", "linearize_quaternions", "matrix_naive_quaternions", "motion_features", "quat_log", "sign_flips",
    "classify_path", "pass_jumps", "transitions",
    "pad_path", "play_path", "shortest_path_frames",
]
