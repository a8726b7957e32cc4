"""Joint positions and pose features of the compare family's metrics: forward kinematics in metres, the foot
joints, the facing, the body frame, the pose features the window, novelty and diversity metrics compare, and global
quaternions.

Every length is in metres; the vertical axis is y (:data:`UP`), as in CMU ASF/AMC and BVH.
"""

from __future__ import annotations

import numpy as np

from ...joints import FOOT_ROLES, resolve_roles
from ...kinematics import HORIZONTAL as _KINHORIZONTAL
from ...kinematics import UP as _KIN_UP
from ...kinematics import facing as _hip_facing
from ...kinematics import continuous_sign, forward_kinematics

__all__ = ["UP", "HORIZONTAL", "positions", "positions_and_quaternions", "foot_indices", "facing", "body_frame", "pose_features",
           "align_quaternions", "global_quaternions", "rotate_to"]

#: Index of the vertical axis (y up: the canonical frame of :mod:`animsynth.kinematics`).
UP = _KIN_UP
#: Indices of the horizontal axes (x, z).
HORIZONTAL = list(_KINHORIZONTAL)


def positions(motion) -> np.ndarray:
    """World joint positions in metres.

    Parameters
    ----------
    motion : Motion

    Returns
    -------
    ndarray, shape (T, J, 3)
        The *end* of every joint's segment (:func:`animsynth.kinematics.forward_kinematics` with
        ``ends=True``: for an ASF bone its tip, so the foot roles give the ball and the toe tip), times
        ``skeleton.length_to_m``.
    """
    sk = motion.skeleton
    return forward_kinematics(sk, motion.values, ends=True) * float(sk.length_to_m)


def positions_and_quaternions(skeleton, values, start: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """World joint positions in metres and world joint rotations, from one forward kinematics pass.

    Parameters
    ----------
    skeleton : Skeleton
    values : ndarray, shape (T, n_dof)
    start : int
        The first frame of the rotations: their signs are made continuous from it on
        (:func:`align_quaternions`).

    Returns
    -------
    positions : ndarray, shape (T, J, 3)
        As :func:`positions`: the end of every joint's segment, in metres.
    quaternions : ndarray, shape (T - start, J, 4)
        The world rotation of every joint of frames ``start:``, unit quaternions, scalar last, continuous over
        time (:func:`global_quaternions`).
    """
    pos, W = forward_kinematics(skeleton, values, ends=True, world_rotations=True)
    q = align_quaternions(np.stack([r.as_quat() for r in W], axis=1)[start:])
    return pos * float(skeleton.length_to_m), q


def foot_indices(skeleton, overrides: dict | None = None) -> np.ndarray:
    """Indices of the :data:`animsynth.joints.FOOT_ROLES` joints (left ankle, left toe, right ankle, right toe).

    Parameters
    ----------
    skeleton : Skeleton
    overrides : dict, optional
        ``{role: joint name}`` (config ``joint_roles``), over the skeleton's own :attr:`roles`.

    Returns
    -------
    ndarray of int, shape (4,)

    Raises
    ------
    animsynth.joints.JointRoleError
        A role has no joint (the message names the role and the joints available).
    """
    return np.array([skeleton.index(n) for n in resolve_roles(skeleton, FOOT_ROLES, overrides)], dtype=np.int64)


def facing(motion, overrides: dict | None = None) -> np.ndarray:
    """Horizontal facing direction of the body per frame, from the hips and the up axis.

    ``cross(left_hip - right_hip, up)`` from the world positions of the hip-role joints, projected onto the
    floor (:func:`animsynth.kinematics.facing`, the one definition the workflow uses): it does not depend on
    the root's rotation convention or the rest pose. A frame whose hips are vertically aligned takes the
    facing of the nearest frame that has one.

    Parameters
    ----------
    motion : Motion
    overrides : dict, optional
        Joint-role overrides (``left_hip``, ``right_hip``).

    Returns
    -------
    ndarray, shape (T, 2)
        Unit vectors ``(x, z)``.
    """
    return _hip_facing(motion.skeleton, motion.values, overrides, name=motion.name)


def rotate_to(v: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """Rotate vectors ``v (..., 3)`` about the vertical so that ``forward (..., 2)`` (x, z) becomes +z."""
    fx, fz = forward[..., 0], forward[..., 1]
    out = np.empty_like(v)
    out[..., 0] = (fz * v[..., 0] - fx * v[..., 2])
    out[..., 1] = v[..., 1]
    out[..., 2] = (fx * v[..., 0] + fz * v[..., 2])
    return out


def body_frame(pos: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """Joint positions in the body frame: horizontal centroid removed, facing turned to +z.

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
        Metres.
    forward : ndarray, shape (T, 2)
        Unit facing vectors (:func:`facing`).

    Returns
    -------
    ndarray, shape (T, J, 3)
        Height (y) unchanged: a floating or sunken body stays distinguishable.
    """
    pos = np.asarray(pos, float)
    forward = np.asarray(forward, float)
    if forward.shape != (pos.shape[0], 2):
        raise ValueError(f"forward has shape {forward.shape}, expected ({pos.shape[0]}, 2)")
    p = pos.copy()
    p[:, :, HORIZONTAL] -= p[:, :, HORIZONTAL].mean(axis=1, keepdims=True)
    return rotate_to(p, forward[:, None, :])


def pose_features(pos: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """Per-frame pose features: :func:`body_frame` flattened and divided by ``sqrt(J)``.

    The Euclidean distance between two rows is the root-mean-square distance of corresponding joints (m).

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
    forward : ndarray, shape (T, 2)

    Returns
    -------
    ndarray, shape (T, 3 J)
    """
    b = body_frame(pos, forward)
    return b.reshape(b.shape[0], -1) / np.sqrt(b.shape[1])


def align_quaternions(q: np.ndarray, ref: np.ndarray | None = None) -> np.ndarray:
    """Choose the sign of unit quaternions (``q`` and ``-q`` are one rotation).

    Parameters
    ----------
    q : ndarray, shape (T, J, 4)
    ref : ndarray, shape (T, J, 4), optional
        ``None``: continuous over time (each frame in the hemisphere of the previous one, as LAFAN1 prepares
        its data). Given: each quaternion in the hemisphere of ``ref`` at the same frame and joint (the
        nearest of the two signs).

    Returns
    -------
    ndarray, shape (T, J, 4)
    """
    q = np.asarray(q, float)
    if ref is not None:
        ref = np.asarray(ref, float)
        if ref.shape != q.shape:
            raise ValueError(f"quaternion arrays differ in shape: {q.shape} vs {ref.shape}")
        return np.where((np.sum(q * ref, axis=-1) < 0)[..., None], -q, q)
    return continuous_sign(q)


def global_quaternions(motion) -> np.ndarray:
    """World rotation of every joint as unit quaternions, scalar last, continuous over time.

    Parameters
    ----------
    motion : Motion

    Returns
    -------
    ndarray, shape (T, J, 4)
    """
    return positions_and_quaternions(motion.skeleton, motion.values)[1]
