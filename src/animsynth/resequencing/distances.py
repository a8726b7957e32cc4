"""Frame-to-frame distances: L2 between linearised frames and the Lee et al. (2002) metric.

Lee metric (Lee, Chai, Reitsma, Hodgins & Pollard 2002, weights optimised by
Wang & Bodenheimer 2003)::

    d(i, j) = ||p_i0 - p_j0||^2 + sum_k w_k ||log(q_jk^{-1} q_ik)||^2
              + nu * (||pdot_i0 - pdot_j0||^2 + sum_k w_k ||omega_ik - omega_jk||^2)

* ``p_0`` is the root position in metres and ``pdot_0`` its velocity (m/s);
  both root terms are used only when the global DOF are included.
* ``q_k`` are the local joint quaternions, ``log`` the half-angle quaternion
  log (radians); ``||log(q_j^{-1} q_i)|| = arccos |<q_i, q_j>|``.
* ``omega_k`` is the body-frame angular velocity in the same half-angle
  convention (rad/s, :func:`~animsynth.resequencing.features.angular_velocity`).
* ``w_k``: hips 1.0, knees 0.0901, shoulders 0.7884, elbows 0.0247, every
  other joint (including the root orientation) 0.
* The metric is a sum of *squared* terms, as published; ``sqrt=True`` returns
  its square root instead (a Euclidean-like distance). Neighbour ranks -- and
  hence every minimum k -- are the same either way.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.distance import cdist

from .features import MotionFeatures, angular_velocity

__all__ = ["PAPER_WEIGHTS", "JOINT_GROUPS", "joint_weights", "l2_distances", "lee_metric", "lee_distances",
           "check_distance_matrix"]

#: Joint-group weights of the paper (Wang & Bodenheimer 2003 optimisation of Lee's metric).
PAPER_WEIGHTS = {"hips": 1.0, "knees": 0.0901, "shoulders": 0.7884, "elbows": 0.0247}

#: Joint roles of each group (:mod:`animsynth.joints`; the rotation *of* the
#: bone: CMU lfemur / BVH LeftUpLeg = hip joint, ltibia / LeftLeg = knee, ...).
JOINT_GROUPS = {
    "hips": ("left_hip", "right_hip"),
    "knees": ("left_knee", "right_knee"),
    "shoulders": ("left_shoulder", "right_shoulder"),
    "elbows": ("left_elbow", "right_elbow"),
}


def joint_weights(joint_names, weights: dict, roles: dict | None = None) -> np.ndarray:
    """Per-joint weight vector for ``joint_names`` from group (or joint) weights.

    Keys of ``weights`` are group names of :data:`JOINT_GROUPS` (whose roles
    are resolved by :func:`animsynth.joints.resolve_role`, with the overrides
    ``roles``) or joint names. Joints not mentioned get 0.

    Raises
    ------
    ValueError
        A key that is neither a known group nor one of ``joint_names``, a group
        whose roles have no joint in the skeleton (:class:`JointRoleError`,
        naming the role and the joints), or a negative weight.
    """
    from ..joints import resolve_roles

    names = list(joint_names)
    w = np.zeros(len(names))
    for key, val in weights.items():
        val = float(val)
        if not np.isfinite(val) or val < 0:
            raise ValueError(f"Lee weight {key!r} must be finite and >= 0, got {val}")
        if key in JOINT_GROUPS:
            try:
                members = resolve_roles(names, JOINT_GROUPS[key], roles)
            except ValueError as exc:
                raise type(exc)(f"Lee weight group {key!r}: {exc}") from None
            for m in members:
                w[names.index(m)] = val
        elif key in names:
            w[names.index(key)] = val
        else:
            raise ValueError(f"Lee weight {key!r} is neither a joint group {sorted(JOINT_GROUPS)} nor a joint")
    return w


def check_distance_matrix(D, name: str = "distance matrix") -> np.ndarray:
    """Validate a square, symmetric, finite, non-negative matrix with a zero diagonal."""
    D = np.asarray(D, float)
    if D.ndim != 2 or D.shape[0] != D.shape[1]:
        raise ValueError(f"{name} must be square, got shape {D.shape}")
    if not np.all(np.isfinite(D)):
        bad = np.argwhere(~np.isfinite(D))[0]
        raise ValueError(f"{name} has a non-finite entry at {tuple(int(x) for x in bad)}")
    if np.any(D < 0):
        raise ValueError(f"{name} has negative entries")
    scale = max(float(D.max()), 1e-300)
    if not np.allclose(D, D.T, rtol=1e-9, atol=1e-12 * scale):
        raise ValueError(f"{name} is not symmetric")
    if np.any(np.abs(np.diag(D)) > 1e-12 * scale):
        raise ValueError(f"{name} has a non-zero diagonal")
    return D


def l2_distances(X) -> np.ndarray:
    """Euclidean distances between the rows of ``X`` (frames, dims)."""
    X = np.asarray(X, float)
    if not np.all(np.isfinite(X)):
        bad = int(np.argwhere(~np.isfinite(X))[0, 0])
        raise ValueError(f"frame {bad} has a non-finite feature")
    D = cdist(X, X)
    np.fill_diagonal(D, 0.0)
    return 0.5 * (D + D.T)


def _pair_angles(Q) -> np.ndarray:
    """``arccos |<q_i, q_j>|`` for all frame pairs of one joint, ``Q`` (frames, 4)."""
    dots = np.abs(Q @ Q.T)
    np.clip(dots, 0.0, 1.0, out=dots)
    return np.arccos(dots)


def lee_metric(quats, weights, fps: float, nu: float, root_pos=None, sqrt: bool = False) -> np.ndarray:
    """Lee et al. distance matrix from raw arrays (see module docstring).

    Parameters
    ----------
    quats : array (frames, joints, 4), unit quaternions (x, y, z, w)
    weights : array (joints,), >= 0
    fps : float, frame rate (velocities are per second)
    nu : float, weight of the velocity term (s^2)
    root_pos : array (frames, 3) in metres, or None to leave out the root terms
    sqrt : bool, return the square root of the metric

    Returns
    -------
    D : array (frames, frames)
    """
    q = np.asarray(quats, float)
    w = np.asarray(weights, float)
    if q.ndim != 3 or q.shape[2] != 4 or w.shape != (q.shape[1],):
        raise ValueError(f"quats {q.shape} and weights {w.shape} do not match")
    if nu < 0 or not np.isfinite(nu):
        raise ValueError(f"nu must be finite and >= 0, got {nu}")
    n = q.shape[0]
    qn = q / np.linalg.norm(q, axis=-1, keepdims=True)
    D = np.zeros((n, n))
    active = np.flatnonzero(w > 0)
    for k in active:
        D += w[k] * _pair_angles(qn[:, k, :]) ** 2
    if nu > 0 and active.size:
        om = angular_velocity(qn[:, active, :], fps) * np.sqrt(w[active])[None, :, None]
        D += nu * cdist(om.reshape(n, -1), om.reshape(n, -1), "sqeuclidean")
    if root_pos is not None:
        p = np.asarray(root_pos, float)
        D += cdist(p, p, "sqeuclidean")
        if nu > 0:
            pv = np.gradient(p, axis=0) * fps if n > 1 else np.zeros_like(p)
            D += nu * cdist(pv, pv, "sqeuclidean")
    D = 0.5 * (D + D.T)
    np.fill_diagonal(D, 0.0)
    np.maximum(D, 0.0, out=D)
    return np.sqrt(D) if sqrt else D


def lee_distances(features: MotionFeatures, weights: dict | None = None, nu: float = 0.01,
                  include_global: bool = False, sqrt: bool = False, translation_scale: float = 1.0) -> np.ndarray:
    """Lee metric between all frames of ``features`` (see :func:`lee_metric`).

    With ``include_global`` the root position enters in metres times
    ``translation_scale`` (the same scale as the L2 features, so both metrics
    weigh root travel alike). The Lee metric is sign-invariant
    (``arccos |<q_i, q_j>|``), so the linearisation's ``sign_mode`` does not
    apply to it."""
    w = joint_weights(features.joint_names, PAPER_WEIGHTS if weights is None else weights,
                      getattr(features, "roles", None))
    root = float(translation_scale) * features.root_pos if include_global else None
    return lee_metric(features.quats, w, features.fps, nu, root_pos=root, sqrt=sqrt)
