"""One-call motion generation for users (CLI, notebooks): train on clips, follow the field
(:class:`~.generator.FieldFollower`, the estimator the paper folds and the comparison call too)."""

from __future__ import annotations

import numpy as np

from .generator import FieldFollower


def generate_from_trials(clips, method: str = "delaunay", k: int = 16, latent_dim: int = 2, steps: int = 300,
                         start=None, derivative: str = "half", weights: str = "idw", seed: int = 0):
    """Generate joint angles with the Gauch & Peters vector field.

    Parameters
    ----------
    clips : list of arrays (frames_i, D)
        Training joint angles (root DOF already removed, e.g. ``Motion.without_root()``).
    method : {"delaunay", "knn", "kdelaunay"}
    k, latent_dim, weights : see :class:`~.generator.FieldFollower` and :class:`~.field.VectorField`
    steps : int
        Number of field steps (frames generated = steps + 1).
    start : array (D,), optional
        Start pose (joint angles); default the first frame of the first clip.
    derivative : {"half", "forward", "central"}
        Training vectors. Default ``half``, the paper's printed ``(x[i+1]-x[i])/2``
        and the default of every entry point (config, CLI): it is what the paper
        states, and on CMU it is the only variant whose Delaunay-vs-k-NN ordering
        survives a 1e-6 nudge of the start (see docs/config_simplicial.md). It
        moves half a frame per step, so ``steps`` steps cover about ``steps / 2``
        frames of motion.
    seed : int
        Unused by the deterministic field; kept so every generator takes a seed.

    Returns
    -------
    angles : ndarray (steps + 1, D)
    info : str  (fallback steps, latent start)
    """
    clips = [np.asarray(c, float) for c in clips]
    if not clips:
        raise ValueError("generate_from_trials: no training clips")
    est = FieldFollower(method, latent_dim, k, derivative, weights=weights).fit_angles(clips)
    x0 = est.encode(np.asarray(clips[0][0] if start is None else start, float).reshape(1, -1))[0]
    path = est.follow(x0, steps)
    angles = est.decode(path.points)
    return angles, f"{method}, {path.fallback_steps} fallback steps of {path.steps}"
