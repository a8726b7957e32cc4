"""2-D Procrustes fits (closed form, reflection-free, batched).

``scipy.spatial.procrustes`` standardises both shapes (it always scales) and
``scipy.linalg.orthogonal_procrustes`` may return a reflection; the 2-D rigid
and similarity fits have a two-line closed form, written here once for the
three alignment uses (stage 1, stage 2, node merging).
"""

from __future__ import annotations

import numpy as np


def fit_transform_2d(src: np.ndarray, dst: np.ndarray, scale: bool = False):
    """Best rotation R (+ uniform scale s if ``scale``) and translation t with
    ``s * src @ R.T + t ~ dst`` in the least-squares sense.

    Parameters
    ----------
    src, dst : ndarray, shape (..., n, 2)

    Returns
    -------
    R : (..., 2, 2), s : (...,), t : (..., 2)
    """
    src = np.asarray(src, float)
    dst = np.asarray(dst, float)
    ms, md = src.mean(-2, keepdims=True), dst.mean(-2, keepdims=True)
    a, b = src - ms, dst - md
    dot = (a * b).sum((-1, -2))
    cross = (a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]).sum(-1)
    theta = np.arctan2(cross, dot)
    c, s_ = np.cos(theta), np.sin(theta)
    R = np.stack([np.stack([c, -s_], -1), np.stack([s_, c], -1)], -2)
    if scale:
        na = (a * a).sum((-1, -2))
        if np.any(na <= 1e-12):
            raise ValueError("degenerate shape: all source points coincide")
        sc = np.hypot(dot, cross) / na
    else:
        sc = np.ones_like(theta)
    t = md[..., 0, :] - sc[..., None] * np.einsum("...ij,...j->...i", R, ms[..., 0, :])
    return R, sc, t


def apply_transform_2d(points: np.ndarray, R, s, t) -> np.ndarray:
    """``s * points @ R.T + t`` with broadcasting over leading dims of R, s, t."""
    R = np.asarray(R)
    s = np.asarray(s)
    t = np.asarray(t)
    return s[..., None, None] * np.einsum("...ij,...nj->...ni", R, points) + t[..., None, :]
