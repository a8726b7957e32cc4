"""Pose features for re-sequencing: joint quaternions, their Lee & Shin
linearisation, and the global degrees of freedom.

Conventions
-----------
* Quaternions are scipy's scalar-last ``(x, y, z, w)`` unit quaternions of the
  *local* joint rotations (:func:`animsynth.kinematics.quaternions`).
* ``log`` is the quaternion logarithm of a unit quaternion,
  ``log(q) = (theta / 2) * axis`` -- *half* the rotation angle, in radians
  (Lee & Shin 2002; Lee et al. 2002 use the same convention in their metric).
  The shortest rotation is taken (``q`` and ``-q`` give the same log).
* Lengths (root translation) are converted to metres with
  ``skeleton.length_to_m``.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from ..kinematics import qinv, qlog, qmul, quaternions, root_translation, translated_joints

log = logging.getLogger("animsynth.resequencing")

__all__ = ["relative_log", "linearize_quaternions", "MotionFeatures", "motion_features",
           "angular_velocity", "SIGN_MODES", "matrix_naive_quaternions", "naive_quat_log",
           "sign_flips"]

#: Quaternion sign handling of the linearisation (config key ``resequencing.linearisation.sign_mode``).
SIGN_MODES = ("continuous", "matrix_naive")


def relative_log(qa, qb) -> np.ndarray:
    """``log(qa^{-1} qb)`` for quaternion arrays of equal shape ``(..., 4)`` -> ``(..., 3)``: half the rotation
    vector of the relative rotation, the shorter way round (:func:`animsynth.kinematics.qlog`, the package's one
    quaternion logarithm, halved)."""
    return 0.5 * qlog(qmul(qinv(np.asarray(qa, float)), np.asarray(qb, float)))


def matrix_naive_quaternions(q) -> np.ndarray:
    """Quaternions as a rotation-matrix conversion gives them: largest component positive.

    Each rotation ``(..., 4)`` is turned into its rotation matrix and back with
    the classic largest-component (Shepperd) conversion, whose result has its
    largest-magnitude component positive. Nothing keeps the sign continuous
    over time, so ``q`` and ``-q`` alternate between neighbouring frames
    whenever the largest component changes (large rotations, e.g. the humeri).

    This reproduces a *probable artefact* of the re-sequencing paper's
    pipeline (``sign_mode: matrix_naive``); it is not a method.
    """
    q = np.asarray(q, float)
    flat = q.reshape(-1, 4)
    qn = Rotation.from_matrix(Rotation.from_quat(flat).as_matrix()).as_quat()
    big = np.argmax(np.abs(qn), axis=1)
    qn *= np.sign(qn[np.arange(len(qn)), big])[:, None]
    return qn.reshape(q.shape)


def naive_quat_log(q) -> np.ndarray:
    """``acos(w) * v / |v|`` of quaternions ``(..., 4)`` *without* taking ``|w|``.

    For ``w < 0`` this is the log of the *long* way round (up to ``pi``
    instead of ``pi / 2``): ``-q`` and ``q`` give logs about ``pi`` apart.
    Part of the ``matrix_naive`` reproduction only.
    """
    q = np.asarray(q, float)
    w = np.clip(q[..., 3], -1.0, 1.0)
    v = q[..., :3]
    nv = np.linalg.norm(v, axis=-1, keepdims=True)
    axis = np.where(nv > 1e-12, v / np.maximum(nv, 1e-300), 0.0)
    return np.arccos(w)[..., None] * axis


def sign_flips(q) -> np.ndarray:
    """Frames whose quaternion has the opposite sign to the previous frame's
    (``<q_t, q_{t+1}> < 0``), counted per joint: ``(frames, joints, 4)`` -> ``(joints,)``."""
    q = np.asarray(q, float)
    if q.shape[0] < 2:
        return np.zeros(q.shape[1:-1], dtype=np.int64)
    return np.count_nonzero(np.sum(q[1:] * q[:-1], axis=-1) < 0, axis=0)


def linearize_quaternions(q, sign_mode: str = "continuous") -> np.ndarray:
    """Lee & Shin linearisation of quaternion sequences.

    For every joint (last-but-one axis) ``v_0 = 0`` and
    ``v_i = sum_{j < i} log(q_j^{-1} q_{j+1})``: the running sum of the
    body-frame rotation increments. A rotation with constant angular velocity
    therefore becomes a straight line traversed at constant speed.

    Parameters
    ----------
    q : array (frames, joints, 4) or (frames, 4)
    sign_mode : {"continuous", "matrix_naive"}
        ``continuous`` (the method): each increment is the shortest rotation,
        so ``q`` and ``-q`` agree. ``matrix_naive`` (a reproduction of a
        probable artefact): quaternions from :func:`matrix_naive_quaternions`,
        raw products, log via ``acos(w)`` (:func:`naive_quat_log`) -- each sign
        change between two frames adds a jump of about ``pi`` to the running
        sum, offsetting every later frame.

    Returns
    -------
    v : array (frames, joints, 3) or (frames, 3), radians (half-angle convention)

    Notes
    -----
    ``v_0 = 0`` follows the Lee & Shin running sum (it starts at zero); any constant ``v_0`` (e.g.
    ``log(q_0)``) shifts every frame of a joint by the same vector and leaves
    all inter-frame distances unchanged.
    """
    q = np.asarray(q, float)
    squeeze = q.ndim == 2
    if squeeze:
        q = q[:, None, :]
    if q.ndim != 3 or q.shape[-1] != 4:
        raise ValueError(f"expected quaternions of shape (frames, joints, 4), got {q.shape}")
    if sign_mode not in SIGN_MODES:
        raise ValueError(f"config key 'resequencing.linearisation.sign_mode': {sign_mode!r} is not one of {SIGN_MODES}")
    n, j, _ = q.shape
    v = np.zeros((n, j, 3))
    if n > 1:
        if sign_mode == "continuous":
            inc = relative_log(q[:-1], q[1:])
        else:
            qn = matrix_naive_quaternions(q)
            inc = naive_quat_log(qmul(qinv(qn[:-1]), qn[1:]))
        v[1:] = np.cumsum(inc, axis=0)
    return v[:, 0, :] if squeeze else v


def angular_velocity(q, fps: float) -> np.ndarray:
    """Body-frame angular velocity ``log(q_{t-1}^{-1} q_{t+1}) * fps / 2`` per frame.

    Central differences inside, one-sided at the ends; half-angle convention
    (radians / s, i.e. half the physical angular speed), the same as
    :func:`relative_log`. Shape ``(frames, joints, 3)`` for ``q`` ``(frames, joints, 4)``.
    """
    q = np.asarray(q, float)
    n = q.shape[0]
    w = np.zeros(q.shape[:-1] + (3,))
    if n < 2:
        return w
    if n > 2:
        w[1:-1] = relative_log(q[:-2], q[2:]) * (fps / 2.0)
    w[0] = relative_log(q[0], q[1]) * fps
    w[-1] = relative_log(q[-2], q[-1]) * fps
    return w


@dataclass
class MotionFeatures:
    """Per-frame pose data of one motion, ready for the distance functions.

    Attributes
    ----------
    joint_names : list of str
        Non-root joints that have rotational DOF (CMU: 28), in skeleton order.
    quats : ndarray (frames, joints, 4)
        Their local rotations (sign-continuous over time).
    root_quat : ndarray (frames, 4)
        Root (global) orientation.
    root_pos : ndarray (frames, 3)
        Root position in metres (Y up).
    fps : float
    roles : dict
        The skeleton's joint-role overrides (:mod:`animsynth.joints`).
    """

    joint_names: list
    quats: np.ndarray
    root_quat: np.ndarray
    root_pos: np.ndarray
    fps: float
    roles: dict = field(default_factory=dict)

    @property
    def n_frames(self) -> int:
        return int(self.quats.shape[0])

    def linearised(self, include_global: bool, sign_mode: str = "continuous",
                   translation_scale: float = 1.0) -> np.ndarray:
        """Frames as vectors: the linearised joint rotations (3 per joint) and,
        if ``include_global``, the linearised root orientation and the root
        position in metres times ``translation_scale`` (radians per metre; 6
        more columns). Shape ``(frames, 3m [+ 6])``. ``sign_mode``: see
        :func:`linearize_quaternions` (applies to the root orientation too)."""
        v = linearize_quaternions(self.quats, sign_mode).reshape(self.n_frames, -1)
        if include_global:
            v = np.hstack([v, linearize_quaternions(self.root_quat, sign_mode),
                           float(translation_scale) * self.root_pos])
        return v


def motion_features(motion) -> MotionFeatures:
    """Extract :class:`MotionFeatures` from an :class:`animsynth.motion.Motion`.

    The pose is the joints' rotations (and, as global DOF, the root's rotation
    and translation). A translation of a joint other than the root (BVH
    position channels that move, :mod:`animsynth.io.bvh`) is left out of the
    features, with one logged note naming the joints: the paper's features are
    rotations. The re-sequenced motion still plays every frame's full pose,
    translations included.
    """
    sk = motion.skeleton
    values = np.asarray(motion.values, float)
    if values.ndim != 2 or values.shape[0] < 2:
        raise ValueError(f"motion {motion.name!r} needs at least 2 frames, got shape {values.shape}")
    moved = translated_joints(sk)
    if moved:
        log.info("motion %r: the translation of joint(s) %s (not the root) is left out of the re-sequencing "
                 "features (rotations only); the played frames keep it", motion.name, ", ".join(moved))
    q = quaternions(sk, values)
    keep = [i for i, j in enumerate(sk.joints) if i > 0 and j.rot_dofs]
    return MotionFeatures(
        joint_names=[sk.joints[i].name for i in keep],
        quats=q[:, keep, :],
        root_quat=q[:, 0, :],
        root_pos=root_translation(sk, values) * sk.length_to_m,
        fps=float(motion.fps),
        roles=dict(getattr(sk, "roles", None) or {}),
    )
