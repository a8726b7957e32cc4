"""Hybrid mesh animation: skinned 18-joint skeleton plus learned time-varying detail.

Modules
-------
fit          per-frame pose fitting (Kabsch + Levenberg-Marquardt), joint centres from motion, inside-mesh placement
gp           shared GPLVM with GPDM dynamics (:class:`SharedGPDM`), GP regression, analytic gradients
detail       control meshes (replayed edge collapses / vertex subset), RBF reconstruction, Laplacian coordinates
models       :class:`HybridModel` (hybrid / plain GP / CV ridge / LBS-only / full-deformation), :class:`MeshContext`
rigfit       skeleton fitting of a sequence: 18-joint embedding, skinning weights, per-frame poses, fit tables
evaluation   the paper's experiments as functions returning tables (blocked cross-validation)
dembones     the Dem Bones (SSDR) LBS floor under the same blocked cross-validation
settings     config checks beyond the schema, the mesh sequences of a run
verdicts     the paper's claims checked against the tables (common verdict format)
jobs         workflow steps (character generation, loading, skeleton fit, Dem Bones floor, scale steps)
plots        Fig. 5 panels and rendered frames

The skeleton, forward kinematics, linear blend skinning and skinning weights
(bone heat, refit, distance) live in :mod:`animsynth.skinning`.
"""

from .._lazy import lazy_exports

# name -> module; imported on first use (the family's heavy libraries load only when needed)
_EXPORTS = {
    "GPRegression": ".gp",
    "HybridModel": ".models",
    "JOINTS": "..skinning",
    "MeshContext": ".models",
    "PARENTS": "..skinning",
    "Rig": "..skinning",
    "SharedGPDM": ".gp",
    "default_rig": "..skinning",
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
