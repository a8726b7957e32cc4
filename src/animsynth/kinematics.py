"""Pose math for :class:`~animsynth.skeleton.Skeleton`: forward kinematics, joint rotations, Euler angles,
quaternions, heading (the critically damped springs that move poses in time: :mod:`animsynth.springs`).

All functions are vectorised over frames. See :mod:`animsynth.skeleton` for the
conventions (``L = C M C^-1``, extrinsic DOF order, offsets in world axes,
translation DOF on any joint).

World axes
----------
Every study works in the *canonical* world frame: ``+y`` up
(:data:`UP`, :data:`HORIZONTAL`), ``+z`` forward. The height check, the
floor, foot contacts, facing, heading, root alignment and the figures all read
the up axis from here. A file in another frame is turned into the canonical
one when it is loaded (:mod:`animsynth.axes` detects its up and forward axes
and turns it). Facing comes from the hips (:func:`facing`), so a rest pose lying
along X (LAFAN1) needs no change.

Heading (radians about +y, 0 = +z) has two sources: the body's, from the hips
of every frame (:func:`facing`, :func:`heading`), and a root rotation's, the
yaw of a forward vector turned by it (:func:`rotation_heading`: the root's own
+z, or the hips' forward in the zero pose, :func:`rest_forward`).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .skeleton import ROT_DOFS, TRANS_DOFS, Skeleton

#: Index of the canonical up axis (+y).
UP = 1
#: Indices of the canonical horizontal axes (x, z).
HORIZONTAL = (0, 2)
#: Signed axis names accepted by ``up_axis`` / ``forward_axis``.
AXES = ("+x", "-x", "+y", "-y", "+z", "-z")
#: The canonical frame's up and forward axes.
CANONICAL_UP, CANONICAL_FORWARD = "+y", "+z"


def check_values(skeleton: Skeleton, values) -> np.ndarray:
    """``values`` as a float array (frames, n_dof) of finite numbers for ``skeleton``; ValueError otherwise."""
    values = np.atleast_2d(np.asarray(values, float))
    if values.shape[1] != skeleton.n_dof:
        raise ValueError(f"motion has {values.shape[1]} DOF columns, skeleton {skeleton.name!r} has {skeleton.n_dof}")
    if not np.all(np.isfinite(values)):
        bad = int(np.argwhere(~np.isfinite(values))[0, 0])
        raise ValueError(f"motion frame {bad} (0-based) has a non-finite value")
    return values


def _joint_local(joint, cols: np.ndarray, n: int) -> Rotation:
    """``C M C^-1`` of one joint from its DOF columns ``cols (n, len(joint.dofs))``."""
    rdofs = [(k, d) for k, d in enumerate(joint.dofs) if d in ROT_DOFS]
    if rdofs:
        M = Rotation.from_euler("".join(d[1] for _, d in rdofs), cols[:, [k for k, _ in rdofs]], degrees=True)
    else:
        M = Rotation.identity(n)
    C = joint.axis_rotation()
    return C * M * C.inv()


def _joint_translation(joint, cols: np.ndarray, n: int) -> np.ndarray:
    """The joint's ``offset`` plus its translation DOF, ``(n, 3)``."""
    t = np.tile(np.asarray(joint.offset, float), (n, 1))
    for k, d in enumerate(joint.dofs):
        if d in TRANS_DOFS:
            a = TRANS_DOFS.index(d)
            t[:, a] = cols[:, k] + joint.offset[a]
    return t


def local_rotations(skeleton: Skeleton, values) -> list[Rotation]:
    """Local rotation ``L_j = C_j M_j C_j^-1`` of every joint, per frame.

    Returns a list (one entry per joint) of ``Rotation`` objects of length
    ``frames``.
    """
    values = check_values(skeleton, values)
    sl = skeleton.dof_slices()
    return [_joint_local(j, values[:, sl[j.name]], values.shape[0]) for j in skeleton.joints]


def root_rotation(skeleton: Skeleton, values) -> Rotation:
    """The root joint's local rotation per frame: ``local_rotations(skeleton, values)[0]`` without the others
    (placing and turning a motion on the floor needs only the root)."""
    values = check_values(skeleton, values)
    root = skeleton.joints[0]
    return _joint_local(root, values[:, skeleton.dof_slices()[root.name]], values.shape[0])


def root_translation(skeleton: Skeleton, values) -> np.ndarray:
    """Root translation per frame (frames, 3), skeleton length units."""
    values = check_values(skeleton, values)
    root = skeleton.joints[0]
    return _joint_translation(root, values[:, skeleton.dof_slices()[root.name]], values.shape[0])


def joint_translations(skeleton: Skeleton, values) -> np.ndarray:
    """Every joint's translation from its parent's start, in the parent's frame, per frame.

    The joint's ``offset`` plus its translation DOF (``tx ty tz``; any joint may
    have them, as BVH position channels on any joint). For the root this is
    :func:`root_translation` (world).

    Returns
    -------
    ndarray (frames, joints, 3), skeleton length units
    """
    values = check_values(skeleton, values)
    sl = skeleton.dof_slices()
    return np.stack([_joint_translation(j, values[:, sl[j.name]], values.shape[0]) for j in skeleton.joints], axis=1)


def translated_joints(skeleton: Skeleton) -> list[str]:
    """Names of the non-root joints that have translation DOF."""
    return [j.name for j in skeleton.joints[1:] if any(d in TRANS_DOFS for d in j.dofs)]


def tree_forward(parents, local, translations, joints=None) -> tuple[list, list]:
    """World rotations and joint starts of a kinematic tree: ``W_j = W_parent L_j``,
    ``s_j = s_parent + W_parent t_j``; the root's ``W = L`` and ``s = t`` (world).

    The one forward kinematics of the package: :func:`forward_kinematics` (``Rotation`` objects) and the
    skinning rig (:func:`animsynth.skinning.forward`, rotation matrices) run it.

    Parameters
    ----------
    parents : sequence of int (J,), every parent before its children, -1 for the root
    local : list of J local rotations, each a ``Rotation`` of F frames or an ndarray (F, 3, 3) of matrices
    translations : list of J ndarrays (F, 3) or (3,), each joint's start from its parent's start in the
        parent's frame (the root's: its world position)
    joints : sorted sequence of int, optional
        Only these joints (every parent of one included); the others stay ``None``.

    Returns
    -------
    W : list of J world rotations (the type of ``local``)
    S : list of J ndarrays (F, 3) (or (3,) where a root translation is), world joint starts
    """
    J = len(parents)
    W: list = [None] * J
    S: list = [None] * J
    for i in range(J) if joints is None else joints:
        p = parents[i]
        if p < 0:
            W[i], S[i] = local[i], translations[i]
        elif isinstance(local[i], Rotation):
            W[i], S[i] = W[p] * local[i], S[p] + W[p].apply(translations[i])
        else:
            t = translations[i]
            W[i], S[i] = W[p] @ local[i], S[p] + (W[p] @ t if t.ndim == 1 else (W[p] @ t[..., None])[..., 0])
    return W, S


def tree_local(parents, W: np.ndarray) -> np.ndarray:
    """Local rotation matrices ``(F, J, 3, 3)`` of world rotation matrices ``W (F, J, 3, 3)`` on a tree: the inverse
    of :func:`tree_forward`'s rotations, ``L_j = W_parent^T W_j`` (the root's ``W``)."""
    L = np.empty_like(W)
    for j, p in enumerate(parents):
        L[:, j] = W[:, j] if p < 0 else np.swapaxes(W[:, p], -1, -2) @ W[:, j]
    return L


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
    T = joint_translations(skeleton, values)
    W, S = tree_forward([j.parent for j in skeleton.joints], L, [T[:, i] for i in range(T.shape[1])])
    if ends:
        pos = np.stack([S[i] + W[i].apply(j.tail) for i, j in enumerate(skeleton.joints)], axis=1)
    else:
        pos = np.stack(S, axis=1)
    return (pos, W) if world_rotations else pos


def joint_starts(skeleton: Skeleton, values, joints) -> np.ndarray:
    """World start positions (frames, len(joints), 3) of a few joints: forward kinematics along their chains
    to the root only (the hips need the root and the hip joints, not the whole body)."""
    values = check_values(skeleton, values)
    need: set[int] = set()
    for i in joints:
        while i >= 0 and i not in need:
            need.add(i)
            i = skeleton.joints[i].parent
    sl = skeleton.dof_slices()
    n = values.shape[0]
    L: list = [None] * len(skeleton.joints)
    T: list = [None] * len(skeleton.joints)
    for i in need:
        j = skeleton.joints[i]
        L[i], T[i] = _joint_local(j, values[:, sl[j.name]], n), _joint_translation(j, values[:, sl[j.name]], n)
    _, S = tree_forward([j.parent for j in skeleton.joints], L, T, sorted(need))
    return np.stack([S[i] for i in joints], axis=1)


def quaternions(skeleton: Skeleton, values) -> np.ndarray:
    """Local joint rotations as unit quaternions, shape (frames, joints, 4), scalar-last (x, y, z, w).

    The sign is made continuous over time (q and -q are the same rotation): each frame is flipped when its
    dot product with the frame before (as already flipped) is negative.
    """
    L = local_rotations(skeleton, values)
    q = np.stack([r.as_quat() for r in L], axis=1)
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


# ---------------------------------------------------------------------------------------------------------------
# quaternions (x, y, z, w, scalar last, as scipy's Rotation) and the 6D representation
# ---------------------------------------------------------------------------------------------------------------
def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products ``a b`` of quaternions ``(..., 4)`` (x, y, z, w; ``b`` applied first, as ``Rotation``
    products), broadcasting, *without* any sign normalisation (scipy's composition may return either sign)."""
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


def continuous_sign(q: np.ndarray) -> np.ndarray:
    """Quaternions ``(T, ..., 4)`` with signs flipped so that consecutive frames have a non-negative dot product
    (the running product of the raw consecutive signs); a new array."""
    q = np.array(q, float, copy=True)
    if q.shape[0] > 1:
        s = np.where(np.sum(q[1:] * q[:-1], axis=-1) < 0, -1.0, 1.0)
        q[1:] *= np.cumprod(s, axis=0)[..., None]
    return q


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


# ---------------------------------------------------------------------------------------------------------------
# Euler angles (degrees) and DOF values
# ---------------------------------------------------------------------------------------------------------------
def wrap_degrees(a):
    """Angles in degrees wrapped to [-180, 180): ``(a + 180) % 360 - 180``, elementwise (any shape)."""
    return (a + 180.0) % 360.0 - 180.0


def wrap_radians(a):
    """Angles in radians wrapped to [-pi, pi): ``(a + pi) % 2 pi - pi``, elementwise (any shape)."""
    return (np.asarray(a, float) + np.pi) % (2.0 * np.pi) - np.pi


def other_euler_branch(ang: np.ndarray) -> np.ndarray:
    """The other Tait-Bryan triple of the same rotations, ``(a + 180, 180 - b, c + 180)`` for ``ang (T, 3)``
    (degrees, not wrapped): every rotation has these two, scipy returns the one with ``|b| <= 90``."""
    return np.stack([ang[:, 0] + 180.0, 180.0 - ang[:, 1], ang[:, 2] + 180.0], axis=1)


def nearest_euler(ang: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Euler triples ``ang (T, 3)`` (degrees) each put on the branch and 360-degree turn nearest ``ref (T, 3)``:
    of ``ang`` and :func:`other_euler_branch`, each turned to ``ref + wrap_degrees(. - ref)``, the one with the
    smaller sum of absolute differences to ``ref`` (a tie keeps ``ang``'s)."""
    best = None
    for cand in (ang, other_euler_branch(ang)):
        c = ref + wrap_degrees(cand - ref)
        d = np.abs(c - ref).sum(axis=1)
        best = (c, d) if best is None else (np.where((d < best[1])[:, None], c, best[0]), np.minimum(d, best[1]))
    return best[0]


def continuous_euler(ang: np.ndarray, anchor=None) -> np.ndarray:
    """Euler triples ``ang (T, 3)`` (degrees, scipy's branch) made continuous along time.

    ``anchor=None``: frame 0 is kept; every later frame takes the branch (``ang`` or
    :func:`other_euler_branch`, wrapped) whose wrapped differences to the frame before sum smaller; angles
    stay in [-180, 180) (a motion whose middle angle crosses 90 degrees, e.g. a CMU root yaw, is continuous
    only on the other branch, as the original data was).

    ``anchor (3,)``: the triples continue the pose ``anchor``: frame after frame, :func:`nearest_euler` to the
    frame before (the first: to ``anchor``), so the branch and the 360-degree turns of the anchor carry on.
    A loop over plain floats (it runs per generated sample).
    """
    if anchor is None:
        alt = wrap_degrees(other_euler_branch(ang))
        out = ang.copy()
        for t in range(1, len(ang)):
            d0 = np.abs(wrap_degrees(ang[t] - out[t - 1])).sum()
            d1 = np.abs(wrap_degrees(alt[t] - out[t - 1])).sum()
            if d1 < d0:
                out[t] = alt[t]
        return out
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


def joint_euler(joint, rotations: Rotation) -> np.ndarray:
    """Euler angles (degrees, scipy's branch) of a joint's local rotations, ``(T, k)`` for its ``k`` rotational
    DOF in their order: ``C^-1 L C`` in the DOF's axis order, the missing axes appended (applied last) and
    dropped (they come out ~0 when the rotation is representable)."""
    C = joint.axis_rotation()
    axes = [d[1] for d in joint.dofs if d in ROT_DOFS]
    full = axes + [a for a in "xyz" if a not in axes]
    return (C.inv() * rotations * C).as_euler("".join(full), degrees=True)[:, :len(axes)]


def xyz_euler_rotation(angles) -> Rotation:
    """Rotations of extrinsic-xyz Euler angles in radians (``Rz Ry Rx``, the Acclaim ``rx ry rz`` order; the
    pose convention of :mod:`animsynth.skinning`): ``angles (..., 3)`` to one Rotation of ``prod(...)``."""
    return Rotation.from_euler("xyz", np.asarray(angles, float).reshape(-1, 3))


def xyz_euler_to_matrix(angles) -> np.ndarray:
    """Extrinsic-xyz Euler angles ``(..., 3)`` radians to rotation matrices ``(..., 3, 3)`` ``Rz Ry Rx``."""
    a = np.asarray(angles, float)
    return xyz_euler_rotation(a).as_matrix().reshape(a.shape[:-1] + (3, 3))


def matrix_to_xyz_euler(R) -> np.ndarray:
    """Inverse of :func:`xyz_euler_to_matrix` (scipy's branch): ``(..., 3, 3)`` to ``(..., 3)`` radians."""
    R = np.asarray(R, float)
    return Rotation.from_matrix(R.reshape(-1, 3, 3)).as_euler("xyz").reshape(R.shape[:-2] + (3,))


def dof_values_from_local(skeleton: Skeleton, rotations: list[Rotation], root_t: np.ndarray,
                          translations: np.ndarray | None = None, anchor=None) -> np.ndarray:
    """Inverse of :func:`local_rotations`: DOF values (degrees) from local rotations.

    For a joint with fewer than three rotational DOF the missing axes are
    appended (applied last) and must come out ~0 if the rotation is
    representable; their values are dropped (:func:`joint_euler`). ``translations`` (frames,
    joints, 3; :func:`joint_translations`) gives the translation DOF of
    non-root joints; without it they are 0 (the joint at its ``offset``).

    ``anchor (n_dof,)``: the pose before the first frame (generated frames continue it): three-DOF joints by
    :func:`continuous_euler` from it, the others' angles turned to the 360-degree turn nearest it and
    unwrapped from it. Without: three-DOF joints by :func:`continuous_euler` from their own first frame.
    """
    n = root_t.shape[0]
    values = np.zeros((n, skeleton.n_dof))
    sl = skeleton.dof_slices()
    if anchor is not None:
        anchor = np.asarray(anchor, float)
    for i, j in enumerate(skeleton.joints):
        block = np.zeros((n, len(j.dofs)))
        rk = [k for k, d in enumerate(j.dofs) if d in ROT_DOFS]
        if rk:
            ang = joint_euler(j, rotations[i])
            a0 = None if anchor is None else anchor[sl[j.name]][rk]
            if len(rk) == 3:
                ang = continuous_euler(ang, a0)
            elif a0 is not None:
                ang = a0 + wrap_degrees(ang - a0)
                ang = np.rad2deg(np.unwrap(np.deg2rad(np.vstack([a0[None, :], ang])), axis=0))[1:]
            block[:, rk] = ang
        for k, d in enumerate(j.dofs):
            if d in TRANS_DOFS:
                a = TRANS_DOFS.index(d)
                if i == 0:
                    block[:, k] = root_t[:, a] - j.offset[a]
                elif translations is not None:
                    block[:, k] = translations[:, i, a] - j.offset[a]
        values[:, sl[j.name]] = block
    return values


def set_root(skeleton: Skeleton, values, R: Rotation, pos: np.ndarray) -> np.ndarray:
    """``values`` with the root's DOF set from world rotations and positions (the other joints unchanged).

    Parameters
    ----------
    skeleton : Skeleton
    values : array (frames, n_dof)
    R : Rotation of length ``frames``, the root's world rotation per frame
    pos : array (frames, 3), the root's world position per frame (skeleton units)

    Returns
    -------
    array (frames, n_dof), a new array. The root's rotational DOF come from ``C^-1 R C`` in the root's own
    Euler order (degrees), its translation DOF from ``pos`` minus the root offset.

    Raises
    ------
    ValueError
        ``R`` is to be written to a root with one or two rotational DOF (no Euler triple fits).
    """
    out = np.array(values, float, copy=True)
    root = skeleton.joints[0]
    sl = skeleton.dof_slices()[root.name]
    rd = [d for d in root.dofs if d in ROT_DOFS]
    if rd:
        if len(rd) < 3:
            raise ValueError(f"skeleton {skeleton.name!r}: setting the root rotation needs a root with three "
                             f"rotational DOF, {root.name!r} has {len(rd)}")
        ang = joint_euler(root, R)
        for k, d in enumerate(root.dofs):
            if d in ROT_DOFS:
                out[:, sl.start + k] = ang[:, rd.index(d)]
    for k, d in enumerate(root.dofs):
        if d in TRANS_DOFS:
            a = TRANS_DOFS.index(d)
            out[:, sl.start + k] = pos[:, a] - root.offset[a]
    return out



# ---------------------------------------------------------------------------------------------------------------
# axes, facing and heading
# ---------------------------------------------------------------------------------------------------------------
def parse_axis(axis) -> str:
    """A signed axis name (``"+y"``, ``"-z"``, ``"y"``; any case) as one of :data:`AXES`.

    Raises
    ------
    ValueError
        Anything else.
    """
    s = str(axis).strip().lower()
    if len(s) == 1:
        s = "+" + s
    if s not in AXES:
        raise ValueError(f"axis {axis!r} is not one of {', '.join(AXES)}")
    return s


def axis_vector(axis) -> np.ndarray:
    """The unit vector (3,) of a signed axis name."""
    s = parse_axis(axis)
    v = np.zeros(3)
    v["xyz".index(s[1])] = 1.0 if s[0] == "+" else -1.0
    return v


def role_indices(skeleton: Skeleton, roles, overrides=None):
    """Joint indices of ``roles``, or None when one does not resolve."""
    from .joints import JointRoleError, resolve_roles

    try:
        return [skeleton.index(n) for n in resolve_roles(skeleton, roles, overrides)]
    except JointRoleError:
        return None


def hip_forward(skeleton: Skeleton, values, up="+y", overrides: dict | None = None,
                starts: np.ndarray | None = None) -> np.ndarray:
    """The body's forward direction from the hips, per frame: ``cross(left_hip - right_hip, up)``.

    Not normalised, not projected (its length is the hip width times the sine of
    the hip axis' angle to ``up``). ``starts``: joint starts (frames, joints, 3)
    if already computed.

    Raises
    ------
    animsynth.joints.JointRoleError
        No joint plays ``left_hip`` or ``right_hip``.
    """
    from .joints import resolve_roles

    lh, rh = resolve_roles(skeleton, ("left_hip", "right_hip"), overrides)
    a, b = skeleton.index(lh), skeleton.index(rh)
    if starts is None:
        s = joint_starts(skeleton, values, [a, b])
        across = s[:, 0] - s[:, 1]
    else:
        across = starts[:, a] - starts[:, b]
    return np.cross(across, axis_vector(up))



def facing(skeleton: Skeleton, values, overrides: dict | None = None, starts: np.ndarray | None = None,
           name: str = "") -> np.ndarray:
    """Horizontal facing direction per frame, from the hips and the up axis (canonical frame).

    ``cross(left_hip - right_hip, +y)`` (the starts of the hip-role joints in
    world positions) projected onto the floor: it does not depend on the
    root's rotation convention or on the rest pose (a LAFAN1 rest pose lying
    along X faces the same way as its hips). A frame whose hips are vertically
    aligned (projection shorter than 1e-6 of the hip width) takes the facing of
    the nearest frame that has one.

    Returns
    -------
    ndarray (frames, 2)
        Unit vectors ``(x, z)``.
    """
    f3 = hip_forward(skeleton, values, CANONICAL_UP, overrides, starts)
    f = f3[:, list(HORIZONTAL)]
    n = np.linalg.norm(f, axis=1)
    scale = max(float(np.median(np.linalg.norm(f3, axis=1))), 1e-300)
    ok = n > 1e-6 * scale
    if not ok.any():
        raise ValueError(f"motion {name or skeleton.name!r}: the hips never span a horizontal direction; "
                         "no facing")
    if not ok.all():
        good = np.flatnonzero(ok)
        t = np.arange(len(n))
        after = good[np.clip(np.searchsorted(good, t), 0, len(good) - 1)]
        before = good[np.clip(np.searchsorted(good, t) - 1, 0, len(good) - 1)]
        pick = np.where(np.abs(t - before) <= np.abs(after - t), before, after)
        f, n = f[pick], n[pick]
    return f / n[:, None]



def heading(skeleton: Skeleton, values, overrides: dict | None = None) -> np.ndarray:
    """Heading (radians about +y, 0 = +z) per frame: :func:`facing` as an angle.

    Falls back to the root's local +z axis projected on the floor when the
    skeleton has no hip roles.
    """
    if role_indices(skeleton, ("left_hip", "right_hip"), overrides) is not None:
        return ground_heading(facing(skeleton, values, overrides))
    return rotation_heading(root_rotation(skeleton, values))


def ground_heading(v) -> np.ndarray:
    """Heading (radians about +y, 0 = +z) of ground vectors ``v (..., 2)`` given as (x, z):
    ``arctan2(x, z)``, shape ``(...)`` (``(1, 0)``, along +x, is ``pi / 2``)."""
    v = np.asarray(v)
    return np.arctan2(v[..., 0], v[..., 1])


def rotation_heading(R: Rotation, forward: np.ndarray | None = None, hold_vertical: bool = False) -> np.ndarray:
    """Heading (radians about +y, 0 = +z) of ``forward`` turned by ``R``, shape ``(len(R),)``.

    ``forward`` (3,): by default the local +z axis, the root's own forward axis, not the body's
    (:func:`heading` reads the hips where it can): the right measure of how much a root *turns* between two
    frames, whatever its rest pose. :func:`rest_forward` gives the body's forward in the zero pose, so the
    heading does not depend on a file's forward-axis convention. ``hold_vertical``: a frame whose turned
    vector is within 1e-6 of vertical (no horizontal direction) takes the heading of the frame before (the
    first frame: 0).
    """
    f = R.apply(np.array([0.0, 0.0, 1.0]) if forward is None else forward)
    yaw = np.arctan2(f[:, 0], f[:, 2])
    if hold_vertical:
        for t in np.flatnonzero(np.hypot(f[:, 0], f[:, 2]) < 1e-6):
            yaw[t] = yaw[t - 1] if t else 0.0
    return yaw


def rest_forward(skeleton: Skeleton, overrides: dict | None = None) -> np.ndarray:
    """The skeleton's forward direction in the zero pose, (3,) unit: :func:`hip_forward` of the zero pose
    projected on the floor (independent of a file's forward axis).

    Raises
    ------
    ValueError
        The hips are vertically aligned in the zero pose.
    """
    rest = forward_kinematics(skeleton, np.zeros((1, skeleton.n_dof)), ends=False)
    f = hip_forward(skeleton, None, CANONICAL_UP, overrides, starts=rest)[0]
    f[UP] = 0.0
    n = float(np.linalg.norm(f))
    if n < 1e-9:
        from .joints import resolve_roles

        lh, rh = resolve_roles(skeleton, ("left_hip", "right_hip"), overrides)
        raise ValueError(f"skeleton {skeleton.name!r}: the hips ({lh}, {rh}) are vertically aligned in the zero pose; "
                         "no facing direction")
    return f / n


def yaw_rotation(yaw) -> Rotation:
    """Rotations about +y by ``yaw`` (radians, one per frame); ``yaw_rotation(a)`` turns +z to
    ``(sin a, 0, cos a)``."""
    return Rotation.from_euler("y", np.atleast_1d(np.asarray(yaw, float))[:, None])
