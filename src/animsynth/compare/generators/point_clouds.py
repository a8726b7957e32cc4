"""Point clouds of joint positions and their alignment on the floor (Kovar, Gleicher & Pighin 2002).

The distance between two poses or windows of poses is the weighted mean squared distance of their joint
positions after the best rotation about the vertical y axis and translation on the floor
(:func:`floor_alignment`, the paper's closed form), for one pair of clouds or for every pair of two sets at once
as matrix products (:func:`pair_terms`, :func:`transform_from_terms`). Both graph generators of the comparison
(:mod:`.motiongraph`, :mod:`.fairmotion_peer`) compare and place motion with it.
"""

from __future__ import annotations

import numpy as np

from ...kinematics import forward_kinematics
from ...motion import Motion

__all__ = ["apply_floor_transform", "compose_floor_transforms", "floor_alignment", "normalised_weights", "pair_terms",
           "positions_m", "transform_from_terms", "window_clouds"]


def normalised_weights(weights, n: int) -> np.ndarray:
    w = np.ones(n) if weights is None else np.asarray(weights, float).reshape(-1)
    if w.shape != (n,):
        raise ValueError(f"weights must have one value per point ({n}), got {w.shape[0]}")
    if not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
        raise ValueError("weights must be finite, >= 0 and not all 0")
    return w / w.sum()


def apply_floor_transform(points, theta, x0, z0) -> np.ndarray:
    """Rotate ``points`` by ``theta`` about the vertical y axis, then translate by ``(x0, 0, z0)``.

    Parameters
    ----------
    points : array (..., n, 3)
    theta, x0, z0 : float or array (...)
        Radians and the points' length unit. ``theta`` turns +z towards +x (the right-handed rotation
        about +y, ``Rotation.from_euler("y", theta)``).

    Returns
    -------
    array (..., n, 3)
    """
    p = np.asarray(points, float)
    th = np.asarray(theta, float)[..., None]
    c, s = np.cos(th), np.sin(th)
    out = p.copy()
    out[..., 0] = c * p[..., 0] + s * p[..., 2] + np.asarray(x0, float)[..., None]
    out[..., 2] = -s * p[..., 0] + c * p[..., 2] + np.asarray(z0, float)[..., None]
    return out


def floor_alignment(p, q, weights=None):
    """The rotation about y and floor translation that best map point cloud ``q`` onto ``p`` (closed form).

    Minimises ``sum_n w_n |p_n - T q_n|^2`` over ``T`` = rotation by ``theta`` about the vertical y axis
    followed by ``(x0, 0, z0)`` (the closed form of Kovar, Gleicher & Pighin 2002). With ``xb = sum w x`` etc.
    (weights normalised to sum 1)::

        theta = atan2(sum w (x z' - x' z) - (xb zb' - xb' zb), sum w (x x' + z z') - (xb xb' + zb zb'))
        x0 = xb - xb' cos(theta) - zb' sin(theta)
        z0 = zb + xb' sin(theta) - zb' cos(theta)

    (``atan2`` rather than the paper's ``arctan`` of the quotient, which is ambiguous by pi: atan2 picks the
    minimum, not the maximum.)

    Parameters
    ----------
    p, q : array (..., n, 3)
        Corresponding points; y is up.
    weights : array (n,), optional
        Non-negative point weights (uniform if omitted), normalised to sum 1.

    Returns
    -------
    theta, x0, z0, d2 : arrays (...)
        The transform and the weighted mean squared distance ``sum w |p - T q|^2`` after it.
    """
    p = np.asarray(p, float)
    q = np.asarray(q, float)
    if p.shape != q.shape or p.ndim < 2 or p.shape[-1] != 3:
        raise ValueError(f"p and q must both have shape (..., n, 3), got {p.shape} and {q.shape}")
    w = normalised_weights(weights, p.shape[-2])
    x, z, xq, zq = p[..., 0], p[..., 2], q[..., 0], q[..., 2]
    xb, zb, xqb, zqb = x @ w, z @ w, xq @ w, zq @ w
    a = (x * xq + z * zq) @ w - (xb * xqb + zb * zqb)
    b = (x * zq - xq * z) @ w - (xb * zqb - xqb * zb)
    theta = np.arctan2(b, a)
    c, s = np.cos(theta), np.sin(theta)
    x0 = xb - xqb * c - zqb * s
    z0 = zb + xqb * s - zqb * c
    d2 = (((p - apply_floor_transform(q, theta, x0, z0)) ** 2).sum(-1)) @ w
    return theta, x0, z0, d2


def compose_floor_transforms(outer, inner):
    """``outer o inner`` of two floor transforms ``(theta, x0, z0)`` (apply ``inner`` first)."""
    th_o, xo, zo = outer
    th_i, xi, zi = inner
    c, s = np.cos(th_o), np.sin(th_o)
    return th_o + th_i, c * xi + s * zi + xo, -s * xi + c * zi + zo


def window_clouds(pos: np.ndarray, k: int) -> np.ndarray:
    """The point cloud of every window of ``k`` frames, frame-major (the points of the window's first frame,
    then its second's, ...).

    Parameters
    ----------
    pos : array (T, J, 3), joint positions of ``T`` frames
    k : int, frames per window (``1 <= k <= T``)

    Returns
    -------
    array (T-k+1, k*J, 3); row ``t`` is the window ``pos[t:t+k]``
    """
    v = np.lib.stride_tricks.sliding_window_view(pos, k, axis=0)  # (T-k+1, J, 3, k)
    return np.ascontiguousarray(np.moveaxis(v, -1, 1)).reshape(v.shape[0], k * pos.shape[1], 3)


def pair_terms(P: np.ndarray, Q: np.ndarray, w: np.ndarray):
    """Closed-form terms of the floor alignment (:func:`floor_alignment`) for every pair (row of P, row of Q) of
    point clouds, as matrix products.

    Centring x and z per cloud first (the optimal translation removes them anyway) keeps the differences of
    large numbers out of the products.

    Parameters
    ----------
    P : array (m, n, 3), Q : array (l, n, 3), point clouds of ``n`` corresponding points (y up)
    w : array (n,), point weights summing to 1

    Returns
    -------
    d2 : array (m, l), the aligned weighted mean squared distance (Q moved onto P)
    a, b : arrays (m, l), ``theta = atan2(b, a)`` is the aligning rotation about y (:func:`transform_from_terms`)
    cp, cq : ``(x, z)`` weighted centroids of P (two arrays (m,)) and of Q (two arrays (l,))
    """
    xp, yp, zp = P[..., 0], P[..., 1], P[..., 2]
    xq, yq, zq = Q[..., 0], Q[..., 1], Q[..., 2]
    xpb, zpb, xqb, zqb = xp @ w, zp @ w, xq @ w, zq @ w
    xp, zp = xp - xpb[:, None], zp - zpb[:, None]
    xq, zq = xq - xqb[:, None], zq - zqb[:, None]
    left = np.hstack([xp * w, zp * w])
    a = left @ np.hstack([xq, zq]).T  # sum w (x x' + z z')
    b = left @ np.hstack([zq, -xq]).T  # sum w (x z' - z x')
    cyy = (yp * w) @ yq.T
    sp = (yp**2 + xp**2 + zp**2) @ w
    sq = (yq**2 + xq**2 + zq**2) @ w
    d2 = sp[:, None] + sq[None, :] - 2.0 * cyy - 2.0 * np.hypot(a, b)
    return np.maximum(d2, 0.0), a, b, (xpb, zpb), (xqb, zqb)


def transform_from_terms(a, b, cp, cq):
    """The floor transform ``(theta, x0, z0)`` moving Q onto P (:func:`apply_floor_transform`), from the terms of
    :func:`pair_terms`: ``a``, ``b`` and the centroids ``cp = (x, z)``, ``cq = (x, z)`` of the pairs wanted
    (arrays of one shape, or scalars); returns three arrays of that shape."""
    theta = np.arctan2(b, a)
    c, s = np.cos(theta), np.sin(theta)
    (xpb, zpb), (xqb, zqb) = cp, cq
    return theta, xpb - xqb * c - zqb * s, zpb + xqb * s - zqb * c


def positions_m(motion: Motion) -> np.ndarray:
    """World joint positions (segment ends, forward kinematics) of ``motion`` in metres: array (T, J, 3)."""
    return forward_kinematics(motion.skeleton, motion.values, ends=True) * motion.skeleton.length_to_m
