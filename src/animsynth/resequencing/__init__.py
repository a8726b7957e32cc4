"""Re-sequencing motion with Isomap and ST-Isomap.

Modules
-------
features    quaternion linearisation (Lee & Shin), sign modes (continuous; matrix_naive, the
            reproduction of a probable artefact of the paper), sign flips, global DOF
distances   L2 between linearised frames, Lee et al. metric with the paper's weights
embedding   k-NN graphs (optionally with always-present edges), exact minimum connected k,
            Isomap (no silent graph joining), ST-Isomap (Jenkins & Mataric 2004), residual variance
paths       Dijkstra re-sequencing, padding (a path plays as a motion by animsynth.generator.play_path)
generator   the method as one estimator (Resequencer: the neighbourhood graph, sparse or dense, its Dijkstra
            paths, generate), called by the study's paths, the one-call route and the comparison
metrics     transitions, path classes, per-transition and whole-path smoothness
landmark    Landmark Isomap (geodesics from a few frames) for large databases
sparse      the sparse (k-NN candidate) pipeline of large databases
jobs        the workflow steps (analyse, explain, resequence, summarise the paths)
settings    config checks beyond the schema and the config adapters (names, wildcards, ST-Isomap parameters)
tables      the paper's Table 2 and Lee weights in our names, beside ours
quick       the one-call :func:`~.quick.resequence_motion` (CLI, notebooks)
cost        the scale study's measured steps and Landmark vs exact Isomap
verdicts    the paper's claims in the common verdict format
plots       Fig. 2 (embeddings with edges) and Fig. 3 (residual variance)
"""

from .._lazy import lazy_exports

# name -> module; imported on first use (the family's heavy libraries load only when needed)
_EXPORTS = {
    "DisconnectedGraphError": ".embedding",
    "PAPER_WEIGHTS": ".distances",
    "PrecomputedIsomap": ".embedding",
    "Resequencer": ".generator",
    "SIGN_MODES": ".features",
    "STIsomap": ".embedding",
    "classify_path": ".metrics",
    "knn_graph": ".embedding",
    "l2_distances": ".distances",
    "lee_distances": ".distances",
    "lee_metric": ".distances",
    "linearize_quaternions": ".features",
    "matrix_naive_quaternions": ".features",
    "min_connected_k": ".embedding",
    "motion_features": ".features",
    "pad_path": ".paths",
    "pass_jumps": ".metrics",
    "residual_variance": ".embedding",
    "shortest_path_frames": ".paths",
    "sign_flips": ".features",
    "spatio_temporal_distances": ".embedding",
    "temporal_adjacency": ".embedding",
    "transitions": ".metrics",
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
