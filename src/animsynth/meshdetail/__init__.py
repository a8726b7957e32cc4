"""Hybrid mesh animation: skinned 18-joint skeleton plus learned time-varying detail.

Modules
-------
rig          18-joint skeleton, forward kinematics, linear blend skinning, automatic weights, CMU mapping
fit          per-frame pose fitting (Kabsch + Levenberg-Marquardt) and motion-based joint refinement
gp           shared GPLVM with GPDM dynamics (:class:`SharedGPDM`), GP regression, analytic gradients
detail       decimation, biharmonic up-sampling, detail frames, Laplacian coordinates
models       :class:`HybridModel` (hybrid / linear / LBS-only / full-deformation) and :class:`MeshContext`
experiments  the paper's experiments as functions returning tables
pipeline     workflow steps (character generation, loading, skeleton fit)
plots        Fig. 5 panels and rendered frames
"""

from .gp import GPRegression, SharedGPDM
from .models import HybridModel, MeshContext
from ..skinning import JOINTS, PARENTS, Rig, default_rig

__all__ = ["GPRegression", "HybridModel", "JOINTS", "MeshContext", "PARENTS", "Rig", "SharedGPDM", "default_rig"]
