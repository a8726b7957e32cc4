"""Per-frame pose representation shared by the motion-matching and GenMM generators.

A motion's frames are split into what a generator edits and what it integrates:

* the local rotation of every joint with rotational DOF (the root excluded), as unit quaternions;
* a heading-invariant root: the root rotation with its facing yaw removed (``tilt``), the root height,
  the ground step from the previous frame expressed in the previous frame's facing frame (``step``)
  and the change of facing yaw (``turn``).

The facing yaw is that of the rest-pose forward from the hip joints turned by the root rotation (as
:func:`animsynth.compare.metrics.facing`), so it does not depend on a file's forward-axis convention.
:func:`decode` integrates steps and turns from an anchor pose and converts rotations back to the
skeleton's Euler DOF, continuous with the anchor (same Euler branch, angles unwrapped from it), so a
motion encoded and decoded from its own previous frame comes back to its own values.

Written by hand: no maintained library splits a skeleton's DOF this way (scipy's ``Rotation`` does
the rotation algebra).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ..joints import resolve_roles
from ..kinematics import (forward_kinematics, local_rotations, root_rotation, root_translation, wrap_degrees,
                          wrap_radians)
from ..motion import Motion
from ..skeleton import ROT_DOFS, TRANS_DOFS

__all__ = ["Track", "encode", "decode", "facing_yaw", "rotation_yaw", "rest_forward", "rotating_joints", "yaw_rotation",
           "rot6d", "from_rot6d", "qmul", "qinv", "qlog", "qexp",
           "dof_values"]


def yaw_rotation(yaw) -> Rotation:
    """Rotations about +Y by ``yaw`` (radians); ``yaw_rotation(a)`` turns +Z to ``(sin a, 0, cos a)``."""
    return Rotation.from_euler("y", np.atleast_1d(np.asarray(yaw, float))[:, None])


def rest_forward(skeleton) -> np.ndarray:
    """The skeleton's forward direction in the zero pose, (3,) unit: ``cross(left_hip - right_hip, up)`` from the
    hip-role joints, as :func:`animsynth.compare.metrics.facing` (independent of a file's forward axis)."""
    lh, rh = resolve_roles(skeleton, ("left_hip", "right_hip"))
    rest = forward_kinematics(skeleton, np.zeros((1, skeleton.n_dof)), ends=False)[0]
    f = np.cross(rest[skeleton.index(lh)] - rest[skeleton.index(rh)], [0.0, 1.0, 0.0])
    f[1] = 0.0
    n = float(np.linalg.norm(f))
    if n < 1e-9:
        raise ValueError(f"skeleton {skeleton.name!r}: the hips ({lh}, {rh}) are vertically aligned in the zero pose; "
                         "no facing direction")
    return f / n


def rotation_yaw(skeleton, R: Rotation, forward: np.ndarray | None = None) -> np.ndarray:
    """Facing yaw (radians about +Y, 0 = +Z) of root rotations ``R``: the yaw of :func:`rest_forward` turned by
    ``R`` (a pelvis pointing straight up or down keeps the yaw of the frame before); ``forward``: the
    skeleton's :func:`rest_forward` when known."""
    f = R.apply(rest_forward(skeleton) if forward is None else forward)
    yaw = np.arctan2(f[:, 0], f[:, 2])
    bad = np.hypot(f[:, 0], f[:, 2]) < 1e-6
    for t in np.flatnonzero(bad):
        yaw[t] = yaw[t - 1] if t else 0.0
    return yaw


def facing_yaw(motion: Motion, forward: np.ndarray | None = None) -> np.ndarray:
    """Facing yaw (radians about +Y, 0 = +Z) per frame: shape ``(frames,)``."""
    return rotation_yaw(motion.skeleton, root_rotation(motion.skeleton, motion.values), forward)


def rot6d(q: np.ndarray) -> np.ndarray:
    """Quaternions ``(..., 4)`` (x, y, z, w) to the 6D representation of Zhou et al. 2019: the first two
    columns of the rotation matrix, ``(..., 6)``."""
    q = np.asarray(q, float)
    m = Rotation.from_quat(q.reshape(-1, 4)).as_matrix()
    return m[:, :, :2].transpose(0, 2, 1).reshape(q.shape[:-1] + (6,))


def from_rot6d(x: np.ndarray) -> np.ndarray:
    """The 6D representation ``(..., 6)`` back to quaternions ``(..., 4)`` by Gram-Schmidt."""
    x = np.asarray(x, float)
    a, b = x[..., :3], x[..., 3:]
    c1 = a / np.maximum(np.linalg.norm(a, axis=-1, keepdims=True), 1e-12)
    b = b - np.sum(c1 * b, axis=-1, keepdims=True) * c1
    c2 = b / np.maximum(np.linalg.norm(b, axis=-1, keepdims=True), 1e-12)
    c3 = np.cross(c1, c2)
    m = np.stack([c1, c2, c3], axis=-1)
    return Rotation.from_matrix(m.reshape(-1, 3, 3)).as_quat().reshape(x.shape[:-1] + (4,))


def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Quaternion products ``a b`` (x, y, z, w; ``b`` applied first, as ``Rotation`` products), broadcasting."""
    ax, ay, az, aw = np.moveaxis(np.asarray(a, float), -1, 0)
    bx, by, bz, bw = np.moveaxis(np.asarray(b, float), -1, 0)
    return np.stack([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz], axis=-1)


def qinv(q: np.ndarray) -> np.ndarray:
    """Inverse of unit quaternions (x, y, z, w)."""
    q = np.array(q, float, copy=True)
    q[..., :3] *= -1.0
    return q


def qlog(q: np.ndarray) -> np.ndarray:
    """Rotation vectors (radians) of unit quaternions, the shorter way round: ``(..., 3)``."""
    q = np.asarray(q, float)
    q = np.where(q[..., 3:] < 0, -q, q)
    v = q[..., :3]
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(n, q[..., 3:])
    small = n < 1e-12
    return v * np.where(small, 2.0 / np.maximum(q[..., 3:], 1e-12), angle / np.where(small, 1.0, n))


def qexp(r: np.ndarray) -> np.ndarray:
    """Unit quaternions of rotation vectors ``(..., 3)`` (radians)."""
    r = np.asarray(r, float)
    a = np.linalg.norm(r, axis=-1, keepdims=True)
    small = a < 1e-12
    k = np.where(small, 0.5, np.sin(0.5 * a) / np.where(small, 1.0, a))
    return np.concatenate([r * k, np.cos(0.5 * a)], axis=-1)


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


def _continuous_sign(q: np.ndarray) -> np.ndarray:
    """Quaternions ``(T, ..., 4)`` with signs flipped so that consecutive frames have a non-negative dot product
    (the running product of the raw consecutive signs)."""
    q = np.array(q, float, copy=True)
    if q.shape[0] > 1:
        s = np.where(np.sum(q[1:] * q[:-1], axis=-1) < 0, -1.0, 1.0)
        q[1:] *= np.cumprod(s, axis=0)[..., None]
    return q


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
    yaw = facing_yaw(motion, forward)
    tilt = (yaw_rotation(-yaw) * L[0]).as_quat()
    p = root_translation(sk, values)
    ground = p[:, [0, 2]]
    d = np.diff(p, axis=0)
    local = yaw_rotation(-yaw[:-1]).apply(d)[:, [0, 2]]
    step = np.vstack([local[:1], local])
    turn = wrap_radians(np.diff(yaw))
    turn = np.concatenate([turn[:1], turn])
    return Track(joints, _continuous_sign(rot), _continuous_sign(tilt[:, None, :])[:, 0], p[:, 1].copy(), step,
                 turn, yaw, ground)


def _euler_from(anchor, ang: np.ndarray) -> np.ndarray:
    """Euler triples ``ang (T, 3)`` (degrees, scipy's branch) made continuous from ``anchor (3,)``: each frame
    takes the branch (``(a, b, c)`` or ``(a + 180, 180 - b, c + 180)``) nearer the frame before, then the
    360-degree turn nearest it. A loop over plain floats: a few hundred frames per joint."""
    out = np.empty_like(ang)
    pa, pb, pc = (float(v) for v in anchor)
    for t, (a, b, c) in enumerate(ang.tolist()):
        best = None
        for x, y, z in ((a, b, c), (a + 180.0, 180.0 - b, c + 180.0)):
            x = pa + wrap_degrees(x - pa)
            y = pb + wrap_degrees(y - pb)
            z = pc + wrap_degrees(z - pc)
            d = abs(x - pa) + abs(y - pb) + abs(z - pc)
            if best is None or d < best[0]:
                best = (d, x, y, z)
        _, pa, pb, pc = best
        out[t] = (pa, pb, pc)
    return out


def dof_values(skeleton, rotations: list, root_t: np.ndarray, anchor) -> np.ndarray:
    """DOF values ``(T, n_dof)`` from local rotations (one ``Rotation`` of T per joint) and root translations,
    every angle continuous from the pose ``anchor (n_dof,)`` (same Euler branch, unwrapped from it).

    :func:`animsynth.kinematics.dof_values_from_local` with the continuity anchored to the frame before the
    first (the generated frames continue a start) and the branch loop on plain floats (it runs per sample).
    Joints with fewer than three rotational DOF keep their own axes (the others, applied last, are dropped).
    """
    anchor = np.asarray(anchor, float)
    n = root_t.shape[0]
    values = np.zeros((n, skeleton.n_dof))
    sl = skeleton.dof_slices()
    for i, j in enumerate(skeleton.joints):
        start = sl[j.name].start
        rd = [(k, d) for k, d in enumerate(j.dofs) if d in ROT_DOFS]
        if rd:
            C = j.axis_rotation()
            M = C.inv() * rotations[i] * C
            axes = [d[1] for _, d in rd]
            full = axes + [a for a in "xyz" if a not in axes]
            ang = M.as_euler("".join(full), degrees=True)
            cols = [start + k for k, _ in rd]
            if len(axes) == 3:
                ang = _euler_from(anchor[cols], ang)
            else:
                ang = ang[:, :len(axes)]
                ang = anchor[cols] + wrap_degrees(ang - anchor[cols])
                ang = np.rad2deg(np.unwrap(np.deg2rad(np.vstack([anchor[cols][None, :], ang])), axis=0))[1:]
            values[:, cols] = ang
        for k, d in enumerate(j.dofs):
            if d in TRANS_DOFS:
                a = TRANS_DOFS.index(d)
                values[:, start + k] = root_t[:, a] - j.offset[a]
    return values


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
    am = Motion(anchor[None, :], skeleton, 1.0, "anchor")
    yaw0 = float(facing_yaw(am, forward)[0])
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
    return dof_values(skeleton, rots, pos, anchor)
