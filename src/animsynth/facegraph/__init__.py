"""Facial animation with region motion graphs (Serra et al., CGF 2018) and the
face-graph baseline (Zhang et al. 2004).

Pipeline: :class:`FacePreprocessor` (sigmoid fit, two-stage Procrustes,
neutral-peak-neutral samples) -> :class:`FaceGraphModel` (Algorithm 1 sample
graphs, merging, compression-driven thresholds, one graph per region) ->
:class:`FaceSynthesizer` (labels -> peak nodes -> Dijkstra -> motion
recovery, coherent noise). :mod:`.experiments` holds Table 1, the baseline
comparison and the uniqueness study.
"""

from .baseline import FaceGraphBaseline
from .model import FaceGraphModel
from .regiongraph import RegionGraph, load_graphs, save_graphs
from .preprocess import FaceDatabase, FacePreprocessor
from .regions import DEFAULT_REDUCED, DEFAULT_REGIONS, DEFAULT_RIGID, REGION_NAMES
from .similarity import node_similarity, pose_similarity, vinfl
from .synthesis import Animation, FaceSynthesizer, SynthesisError

__all__ = [
    "Animation", "DEFAULT_REDUCED", "DEFAULT_REGIONS", "DEFAULT_RIGID", "FaceDatabase", "FaceGraphBaseline",
    "FaceGraphModel", "FacePreprocessor", "FaceSynthesizer", "REGION_NAMES", "RegionGraph", "SynthesisError",
    "load_graphs", "node_similarity", "pose_similarity", "save_graphs", "vinfl",
]
