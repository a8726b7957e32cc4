"""Facial animation with region motion graphs (Serra et al., CGF 2018) and the
face-graph baseline (Zhang et al. 2004).

Pipeline: :class:`FacePreprocessor` (sigmoid fit, two-stage Procrustes,
neutral-peak-neutral samples) -> :class:`FaceGraphModel` (Algorithm 1 sample
graphs, merging, compression-driven thresholds, one graph per region) ->
:class:`FaceSynthesizer` (labels -> peak nodes -> Dijkstra -> motion
recovery, coherent noise). The family's rooms: :mod:`.settings` (config checks,
configurations, the published Table 1), :mod:`.jobs` (the workflow steps: Table 1,
the baseline comparison, the uniqueness study), :mod:`.verdicts` (the paper's
claims decided), :mod:`.plots` (figures), :mod:`.kernels` and :mod:`.merge_kernels` (the
compiled loops of graph creation).
"""

from .._lazy import lazy_exports

# name -> module; imported on first use (the family's heavy libraries load only when needed)
_EXPORTS = {
    "Animation": ".synthesis",
    "DEFAULT_REDUCED": ".regions",
    "DEFAULT_REGIONS": ".regions",
    "DEFAULT_RIGID": ".regions",
    "FaceDatabase": ".preprocess",
    "FaceGraphBaseline": ".baseline",
    "FaceGraphModel": ".model",
    "FacePreprocessor": ".preprocess",
    "FaceSynthesizer": ".synthesis",
    "REGION_NAMES": ".regions",
    "RegionGraph": ".regiongraph",
    "SynthesisError": ".synthesis",
    "load_graphs": ".regiongraph",
    "node_similarity": ".similarity",
    "pose_similarity": ".similarity",
    "save_graphs": ".regiongraph",
    "vinfl": ".similarity",
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
