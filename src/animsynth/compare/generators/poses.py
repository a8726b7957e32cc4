"""Per-frame pose representation shared by the motion-matching and GenMM generators.

A motion's frames are split into what a generator edits and what it integrates:

* the local rotation of every joint with rotational DOF (the root excluded), as unit quaternions;
* a heading-invariant root: the root rotation with its facing yaw removed (``tilt``), the root height,
  the ground step from the previous frame expressed in the previous frame's facing frame (``step``)
  and the change of facing yaw (``turn``).

The facing yaw is that of the rest-pose forward from the hip joints turned by the root rotation
(:func:`animsynth.kinematics.rotation_heading` of :func:`animsynth.kinematics.rest_forward`), so it does not
depend on a file's forward-axis convention.
:func:`decode` integrates steps and turns from an anchor pose and converts rotations back to the
skeleton's Euler DOF, continuous with the anchor (same Euler branch, angles unwrapped from it), so a
motion encoded and decoded from its own previous frame comes back to its own values.

Written by hand: no maintained library splits a skeleton's DOF this way (scipy's ``Rotation`` does
the rotation algebra; the pose math is :mod:`animsynth.kinematics`'s).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ...kinematics import (continuous_sign, dof_values_from_local, joint_translations, local_rotations, rest_forward,
                          root_rotation, root_translation, rotation_heading, wrap_radians, yaw_rotation)
from ...motion import Motion
from ...skeleton import ROT_DOFS

__all__ = ["Track", "encode", "decode", "rotating_joints"]


@dataclass
class Track:
    """A motion split into edited and integrated parts (skeleton length units, radians).

    Attributes
    ----------
    joints : int array (J,), skeleton joint indices with rotational DOF, root excluded
    rotations : ndarray (T, J, 4), their local rotations (x, y, z, w), sign continuous over time
    tilt : ndarray (T, 4), the root rotation with the facing yaw removed
    height : ndarray (T,), root height
    step : ndarray (T, 2), ground step (x, z) from frame t-1 in frame t-1's facing frame (frame 0: frame 1's)
    turn : ndarray (T,), facing yaw change from frame t-1 (frame 0: frame 1's)
    yaw : ndarray (T,), facing yaw
    ground : ndarray (T, 2), root ground position (x, z)
    """

    joints: np.ndarray
    rotations: np.ndarray
    tilt: np.ndarray
    height: np.ndarray
    step: np.ndarray
    turn: np.ndarray
    yaw: np.ndarray
    ground: np.ndarray


def rotating_joints(skeleton) -> np.ndarray:
    """Indices of the joints with rotational DOF, the root excluded."""
    return np.array([i for i, j in enumerate(skeleton.joints) if i > 0 and any(d in ROT_DOFS for d in j.dofs)],
                    np.int64)


def encode(motion: Motion, forward: np.ndarray | None = None) -> Track:
    """The :class:`Track` of a motion (>= 2 frames); ``forward``: the skeleton's :func:`rest_forward` when known."""
    sk = motion.skeleton
    values = np.asarray(motion.values, float)
    if values.shape[0] < 2:
        raise ValueError(f"motion {motion.name!r}: needs >= 2 frames to encode, has {values.shape[0]}")
    L = local_rotations(sk, values)
    joints = rotating_joints(sk)
    rot = np.stack([L[i].as_quat() for i in joints], axis=1) if joints.size else np.zeros((values.shape[0], 0, 4))
    yaw = rotation_heading(root_rotation(sk, values), rest_forward(sk) if forward is None else forward,
                           hold_vertical=True)
    tilt = (yaw_rotation(-yaw) * L[0]).as_quat()
    p = root_translation(sk, values)
    ground = p[:, [0, 2]]
    d = np.diff(p, axis=0)
    local = yaw_rotation(-yaw[:-1]).apply(d)[:, [0, 2]]
    step = np.vstack([local[:1], local])
    turn = wrap_radians(np.diff(yaw))
    turn = np.concatenate([turn[:1], turn])
    return Track(joints, continuous_sign(rot), continuous_sign(tilt[:, None, :])[:, 0], p[:, 1].copy(), step,
                 turn, yaw, ground)


def decode(skeleton, rotations: np.ndarray, tilt: np.ndarray, height: np.ndarray, step: np.ndarray,
           turn: np.ndarray, anchor, forward: np.ndarray | None = None) -> np.ndarray:
    """DOF values ``(T, n_dof)`` of frames that follow the pose ``anchor`` (n_dof,).

    Parameters
    ----------
    skeleton : Skeleton
    rotations : (T, J, 4) local rotations of :func:`rotating_joints` (need not be unit: normalised here)
    tilt : (T, 4) root rotation without its facing yaw
    height : (T,) root height
    step, turn : (T, 2), (T,) ground step and yaw change of each frame from the frame before it (the first
        from the anchor), in the previous frame's facing frame
    anchor : (n_dof,) the pose before the first frame (its root ground position and facing start the
        integration; its Euler branches and angle turns are kept)
    forward : (3,) the skeleton's :func:`rest_forward` when known
    """
    anchor = np.asarray(anchor, float)
    yaw0 = float(rotation_heading(root_rotation(skeleton, anchor[None, :]),
                                  rest_forward(skeleton) if forward is None else forward, hold_vertical=True)[0])
    p0 = root_translation(skeleton, anchor[None, :])[0]
    T = len(height)
    yaw = yaw0 + np.cumsum(turn)
    prev = np.concatenate([[yaw0], yaw[:-1]])
    world = yaw_rotation(prev).apply(np.column_stack([step[:, 0], np.zeros(T), step[:, 1]]))
    pos = np.empty((T, 3))
    pos[:, 0] = p0[0] + np.cumsum(world[:, 0])
    pos[:, 2] = p0[2] + np.cumsum(world[:, 2])
    pos[:, 1] = height
    rots = [yaw_rotation(yaw) * Rotation.from_quat(tilt)]
    ident = Rotation.identity(T)
    joints = rotating_joints(skeleton)
    where = {int(i): k for k, i in enumerate(joints)}
    for i in range(1, len(skeleton.joints)):
        rots.append(Rotation.from_quat(rotations[:, where[i]]) if i in where else ident)
    # the encoding keeps no translation of a non-root joint (BVH position channels on any joint): each holds the
    # anchor's translation, the pose the frames continue
    translations = np.broadcast_to(joint_translations(skeleton, anchor[None, :]), (T, len(skeleton.joints), 3))
    return dof_values_from_local(skeleton, rots, pos, translations, anchor)
