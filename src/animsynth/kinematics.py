"""Forward kinematics and joint rotations for :class:`~animsynth.skeleton.Skeleton`.

All functions are vectorised over frames. See :mod:`animsynth.skeleton` for the
conventions (``L = C M C^-1``, extrinsic DOF order, offsets in world axes).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .skeleton import ROT_DOFS, TRANS_DOFS, Skeleton


def _check_values(skeleton: Skeleton, values: np.ndarray) -> np.ndarray:
    values = np.atleast_2d(np.asarray(values, float))
    if values.shape[1] != skeleton.n_dof:
        raise ValueError(f"motion has {values.shape[1]} DOF columns, skeleton {skeleton.name!r} has {skeleton.n_dof}")
    if not np.all(np.isfinite(values)):
        bad = int(np.argwhere(~np.isfinite(values))[0, 0])
        raise ValueError(f"motion frame {bad} (0-based) has a non-finite value")
    return values


def local_rotations(skeleton: Skeleton, values) -> list[Rotation]:
    """Local rotation ``L_j = C_j M_j C_j^-1`` of every joint, per frame.

    Returns a list (one entry per joint) of ``Rotation`` objects of length
    ``frames``.
    """
    values = _check_values(skeleton, values)
    n = values.shape[0]
    out = []
    sl = skeleton.dof_slices()
    for j in skeleton.joints:
        cols = values[:, sl[j.name]]
        rdofs = [(k, d) for k, d in enumerate(j.dofs) if d in ROT_DOFS]
        if rdofs:
            seq = "".join(d[1] for _, d in rdofs)
            M = Rotation.from_euler(seq, cols[:, [k for k, _ in rdofs]], degrees=True)
        else:
            M = Rotation.identity(n)
        C = j.axis_rotation()
        out.append(C * M * C.inv())
    return out


def root_rotation(skeleton: Skeleton, values) -> Rotation:
    """The root joint's local rotation per frame: ``local_rotations(skeleton, values)[0]`` without the others
    (placing and turning a motion on the floor needs only the root)."""
    values = _check_values(skeleton, values)
    root = skeleton.joints[0]
    cols = values[:, skeleton.dof_slices()[root.name]]
    rdofs = [(k, d) for k, d in enumerate(root.dofs) if d in ROT_DOFS]
    if rdofs:
        M = Rotation.from_euler("".join(d[1] for _, d in rdofs), cols[:, [k for k, _ in rdofs]], degrees=True)
    else:
        M = Rotation.identity(values.shape[0])
    C = root.axis_rotation()
    return C * M * C.inv()


def root_translation(skeleton: Skeleton, values) -> np.ndarray:
    """Root translation per frame (frames, 3), skeleton length units."""
    values = _check_values(skeleton, values)
    root = skeleton.joints[0]
    t = np.tile(np.asarray(root.offset, float), (values.shape[0], 1))
    sl = skeleton.dof_slices()[root.name]
    for k, d in enumerate(root.dofs):
        if d in TRANS_DOFS:
            t[:, TRANS_DOFS.index(d)] = values[:, sl][:, k] + root.offset[TRANS_DOFS.index(d)]
    return t


def forward_kinematics(skeleton: Skeleton, values, ends: bool = True, world_rotations: bool = False):
    """World positions of every joint, per frame.

    Parameters
    ----------
    skeleton : Skeleton
    values : array (frames, n_dof)
    ends : bool
        ``True``: the *end* of each joint's segment (for ASF bones, the bone
        tip, so the root gives the pelvis and ``ltoes`` the toe tip).
        ``False``: the start of each joint (BVH joint positions).
    world_rotations : bool
        Also return the world rotation of every joint (list of Rotation).

    Returns
    -------
    positions : ndarray (frames, joints, 3) in skeleton length units
    """
    L = local_rotations(skeleton, values)
    root_t = root_translation(skeleton, values)
    n = root_t.shape[0]
    nj = len(skeleton.joints)
    starts = np.empty((n, nj, 3))
    endpos = np.empty((n, nj, 3))
    W: list[Rotation] = [None] * nj  # type: ignore[list-item]
    for i, j in enumerate(skeleton.joints):
        if j.parent < 0:
            starts[:, i] = root_t
            W[i] = L[i]
        else:
            p = j.parent
            starts[:, i] = starts[:, p] + W[p].apply(j.offset)
            W[i] = W[p] * L[i]
        endpos[:, i] = starts[:, i] + W[i].apply(j.tail)
    pos = endpos if ends else starts
    return (pos, W) if world_rotations else pos


def quaternions(skeleton: Skeleton, values) -> np.ndarray:
    """Local joint rotations as unit quaternions, shape (frames, joints, 4), scalar-last (x, y, z, w).

    The sign is made continuous over time (q and -q are the same rotation).
    """
    L = local_rotations(skeleton, values)
    q = np.stack([r.as_quat() for r in L], axis=1)
    # temporal sign continuity
    for t in range(1, q.shape[0]):
        flip = np.sum(q[t] * q[t - 1], axis=-1) < 0
        q[t, flip] *= -1
    return q


def exponential_maps(skeleton: Skeleton, values) -> np.ndarray:
    """Local joint rotations as exponential maps (rotation vectors, radians), (frames, joints, 3)."""
    L = local_rotations(skeleton, values)
    return np.stack([r.as_rotvec() for r in L], axis=1)


def bone_lengths(skeleton: Skeleton, values) -> np.ndarray:
    """Length of every non-root segment per frame (frames, joints-1), from FK positions."""
    starts = forward_kinematics(skeleton, values, ends=False)
    ends = forward_kinematics(skeleton, values, ends=True)
    return np.linalg.norm(ends - starts, axis=-1)[:, 1:]


def _wrap(a):
    return (a + 180.0) % 360.0 - 180.0


def _continuous_euler(ang: np.ndarray) -> np.ndarray:
    """Pick, frame by frame, the Tait-Bryan solution closest to the previous frame.

    Every rotation has two Euler triples ``(a, b, c)`` and
    ``(a + 180, 180 - b, c + 180)``; scipy returns the one with ``|b| <= 90``.
    A motion whose middle angle crosses 90 degrees (e.g. a CMU root yaw) is
    continuous only if we switch to the other branch, as the original data did.
    """
    alt = _wrap(np.stack([ang[:, 0] + 180.0, 180.0 - ang[:, 1], ang[:, 2] + 180.0], axis=1))
    out = ang.copy()
    for t in range(1, len(ang)):
        d0 = np.abs(_wrap(ang[t] - out[t - 1])).sum()
        d1 = np.abs(_wrap(alt[t] - out[t - 1])).sum()
        if d1 < d0:
            out[t] = alt[t]
    return out


def dof_values_from_local(skeleton: Skeleton, rotations: list[Rotation], root_t: np.ndarray) -> np.ndarray:
    """Inverse of :func:`local_rotations`: DOF values (degrees) from local rotations.

    For a joint with fewer than three rotational DOF the missing axes are
    appended (applied last) and must come out ~0 if the rotation is
    representable; their values are dropped.
    """
    n = root_t.shape[0]
    values = np.zeros((n, skeleton.n_dof))
    sl = skeleton.dof_slices()
    for i, j in enumerate(skeleton.joints):
        C = j.axis_rotation()
        M = C.inv() * rotations[i] * C
        rd = [d for d in j.dofs if d in ROT_DOFS]
        block = np.zeros((n, len(j.dofs)))
        if rd:
            axes = [d[1] for d in rd]
            full = axes + [a for a in "xyz" if a not in axes]
            ang = M.as_euler("".join(full), degrees=True)
            if len(axes) == 3:
                ang = _continuous_euler(ang)
            for k, d in enumerate(j.dofs):
                if d in ROT_DOFS:
                    block[:, k] = ang[:, axes.index(d[1])]
        for k, d in enumerate(j.dofs):
            if d in TRANS_DOFS:
                a = TRANS_DOFS.index(d)
                block[:, k] = root_t[:, a] - j.offset[a]
        values[:, sl[j.name]] = block
    return values
