"""Re-sequencing motion with Isomap and ST-Isomap (issue 4).

Modules
-------
features    quaternion linearisation (Lee & Shin) and global DOF
distances   L2 between linearised frames, Lee et al. metric with the paper's weights
embedding   k-NN graphs, exact minimum connected k, Isomap (scikit-learn, no silent
            graph joining), ST-Isomap (Jenkins & Mataric 2004), residual variance
paths       Dijkstra re-sequencing, padding, playing a path as a motion
metrics     measured smoothness (pose jumps, jerk, root sliding, foot skate)
study       the workflow steps (analyse, resequence, tables, verdicts)
plots       Fig. 2 (embeddings with edges) and Fig. 3 (residual variance)
"""

from .distances import PAPER_WEIGHTS, l2_distances, lee_distances, lee_metric
from .embedding import (DisconnectedGraphError, PrecomputedIsomap, STIsomap, knn_graph, min_connected_k,
                        residual_variance, spatio_temporal_distances)
from .features import linearize_quaternions, motion_features, quat_log
from .paths import pad_path, play_path, shortest_path_frames

__all__ = [
    "PAPER_WEIGHTS", "l2_distances", "lee_distances", "lee_metric",
    "DisconnectedGraphError", "PrecomputedIsomap", "STIsomap", "knn_graph", "min_connected_k",
    "residual_variance", "spatio_temporal_distances",
    "linearize_quaternions", "motion_features", "quat_log",
    "pad_path", "play_path", "shortest_path_frames",
]
