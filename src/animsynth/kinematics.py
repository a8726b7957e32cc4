"""Forward kinematics, joint rotations and the world axes for :class:`~animsynth.skeleton.Skeleton`.

All functions are vectorised over frames. See :mod:`animsynth.skeleton` for the
conventions (``L = C M C^-1``, extrinsic DOF order, offsets in world axes,
translation DOF on any joint).

World axes: the one place
-------------------------
Every study works in the *canonical* world frame: ``+y`` up
(:data:`UP`, :data:`HORIZONTAL`), ``+z`` forward. The height check, the
floor, foot contacts, facing, heading, root alignment and the figures all read
the up axis from here. A file in another frame (Z up, as Blender and 3ds Max
write it) is turned into the canonical one when it is loaded
(:func:`to_canonical_frame`, called by :func:`animsynth.data.load_trial`),
with the up axis detected from the motion (:func:`detect_up_axis`: for a
biped by its joint roles, the head above the feet; for another body, a
quadruped or a crab, by its legs standing on the floor; when that is
ambiguous for a body that is not a biped, the file's own +y is kept) or given
(config ``up_axis`` / ``forward_axis``; :func:`lying_down` checks a given one). A rest pose lying along X
(LAFAN1) is not a different frame: the up axis comes from the frames, not the
rest pose, and facing from the hips (:func:`facing`), so such a file needs no
change.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

import copy
import logging

from .skeleton import RETARGET_MAX_ANGLE_DEG, ROT_DOFS, SAME_SKELETON_TOL_M, TRANS_DOFS, Skeleton, compare_skeletons

log = logging.getLogger("animsynth.kinematics")

#: Index of the canonical up axis (+y).
UP = 1
#: Indices of the canonical horizontal axes (x, z).
HORIZONTAL = (0, 2)
#: Signed axis names accepted by ``up_axis`` / ``forward_axis``.
AXES = ("+x", "-x", "+y", "-y", "+z", "-z")
#: The canonical frame's up and forward axes.
CANONICAL_UP, CANONICAL_FORWARD = "+y", "+z"


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


def joint_translations(skeleton: Skeleton, values) -> np.ndarray:
    """Every joint's translation from its parent's start, in the parent's frame, per frame.

    The joint's ``offset`` plus its translation DOF (``tx ty tz``; any joint may
    have them, as BVH position channels on any joint). For the root this is
    :func:`root_translation` (world).

    Returns
    -------
    ndarray (frames, joints, 3), skeleton length units
    """
    values = _check_values(skeleton, values)
    n = values.shape[0]
    out = np.empty((n, len(skeleton.joints), 3))
    sl = skeleton.dof_slices()
    for i, j in enumerate(skeleton.joints):
        out[:, i] = np.asarray(j.offset, float)
        cols = values[:, sl[j.name]]
        for k, d in enumerate(j.dofs):
            if d in TRANS_DOFS:
                a = TRANS_DOFS.index(d)
                out[:, i, a] = cols[:, k] + j.offset[a]
    return out


def translated_joints(skeleton: Skeleton) -> list[str]:
    """Names of the non-root joints that have translation DOF."""
    return [j.name for j in skeleton.joints[1:] if any(d in TRANS_DOFS for d in j.dofs)]


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
    n = T.shape[0]
    nj = len(skeleton.joints)
    starts = np.empty((n, nj, 3))
    endpos = np.empty((n, nj, 3))
    W: list[Rotation] = [None] * nj  # type: ignore[list-item]
    for i, j in enumerate(skeleton.joints):
        if j.parent < 0:
            starts[:, i] = T[:, i]
            W[i] = L[i]
        else:
            p = j.parent
            starts[:, i] = starts[:, p] + W[p].apply(T[:, i])
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


def wrap_degrees(a):
    """Angles in degrees wrapped to [-180, 180): ``(a + 180) % 360 - 180``, elementwise (any shape)."""
    return (a + 180.0) % 360.0 - 180.0


def wrap_radians(a):
    """Angles in radians wrapped to [-pi, pi): ``(a + pi) % 2 pi - pi``, elementwise (any shape)."""
    return (np.asarray(a, float) + np.pi) % (2.0 * np.pi) - np.pi


def _continuous_euler(ang: np.ndarray) -> np.ndarray:
    """Pick, frame by frame, the Tait-Bryan solution closest to the previous frame.

    Every rotation has two Euler triples ``(a, b, c)`` and
    ``(a + 180, 180 - b, c + 180)``; scipy returns the one with ``|b| <= 90``.
    A motion whose middle angle crosses 90 degrees (e.g. a CMU root yaw) is
    continuous only if we switch to the other branch, as the original data did.
    """
    alt = wrap_degrees(np.stack([ang[:, 0] + 180.0, 180.0 - ang[:, 1], ang[:, 2] + 180.0], axis=1))
    out = ang.copy()
    for t in range(1, len(ang)):
        d0 = np.abs(wrap_degrees(ang[t] - out[t - 1])).sum()
        d1 = np.abs(wrap_degrees(alt[t] - out[t - 1])).sum()
        if d1 < d0:
            out[t] = alt[t]
    return out


def dof_values_from_local(skeleton: Skeleton, rotations: list[Rotation], root_t: np.ndarray,
                          translations: np.ndarray | None = None) -> np.ndarray:
    """Inverse of :func:`local_rotations`: DOF values (degrees) from local rotations.

    For a joint with fewer than three rotational DOF the missing axes are
    appended (applied last) and must come out ~0 if the rotation is
    representable; their values are dropped. ``translations`` (frames,
    joints, 3; :func:`joint_translations`) gives the translation DOF of
    non-root joints; without it they are 0 (the joint at its ``offset``).
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
        C = root.axis_rotation()
        ang = (C.inv() * R * C).as_euler("".join(d[1] for d in rd), degrees=True)
        for k, d in enumerate(root.dofs):
            if d in ROT_DOFS:
                out[:, sl.start + k] = ang[:, rd.index(d)]
    for k, d in enumerate(root.dofs):
        if d in TRANS_DOFS:
            a = TRANS_DOFS.index(d)
            out[:, sl.start + k] = pos[:, a] - root.offset[a]
    return out


# ---------------------------------------------------------------------------------------------------------------
# world axes (see the module docstring: the one place the up and forward axes are defined)
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


def _role_index(skeleton: Skeleton, roles, overrides=None):
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


def joint_starts(skeleton: Skeleton, values, joints) -> np.ndarray:
    """World start positions (frames, len(joints), 3) of a few joints: forward kinematics along their chains
    to the root only (the hips need the root and the hip joints, not the whole body)."""
    values = _check_values(skeleton, values)
    need: set[int] = set()
    for i in joints:
        while i >= 0 and i not in need:
            need.add(i)
            i = skeleton.joints[i].parent
    sl = skeleton.dof_slices()
    n = values.shape[0]
    starts, W = {}, {}
    for i in sorted(need):
        j = skeleton.joints[i]
        cols = values[:, sl[j.name]]
        T = np.tile(np.asarray(j.offset, float), (n, 1))
        for k, d in enumerate(j.dofs):
            if d in TRANS_DOFS:
                T[:, TRANS_DOFS.index(d)] += cols[:, k]
        rdofs = [(k, d) for k, d in enumerate(j.dofs) if d in ROT_DOFS]
        M = (Rotation.from_euler("".join(d[1] for _, d in rdofs), cols[:, [k for k, _ in rdofs]], degrees=True)
             if rdofs else Rotation.identity(n))
        C = j.axis_rotation()
        L = C * M * C.inv()
        if j.parent < 0:
            starts[i], W[i] = T, L
        else:
            starts[i], W[i] = starts[j.parent] + W[j.parent].apply(T), W[j.parent] * L
    return np.stack([starts[i] for i in joints], axis=1)


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
    if _role_index(skeleton, ("left_hip", "right_hip"), overrides) is not None:
        f = facing(skeleton, values, overrides)
        return np.arctan2(f[:, 0], f[:, 1])
    return rotation_heading(root_rotation(skeleton, values))


def rotation_heading(R: Rotation) -> np.ndarray:
    """Heading (radians about +y, 0 = +z) of the local +z axis turned by ``R``, shape ``(len(R),)``.

    The root's own forward axis, not the body's (:func:`heading` reads the hips where it can): the right
    measure of how much a root *turns* between two frames, whatever its rest pose.
    """
    f = R.apply(np.array([0.0, 0.0, 1.0]))
    return np.arctan2(f[:, 0], f[:, 2])


def standing_height(skeleton: Skeleton, values, up="+y", positions: np.ndarray | None = None) -> float:
    """Median over frames of the body's extent along ``up`` (skeleton units): segment starts and ends."""
    if positions is None:
        positions = np.concatenate([forward_kinematics(skeleton, values, ends=False),
                                    forward_kinematics(skeleton, values, ends=True)], axis=1)
    h = positions @ axis_vector(up)
    return float(np.median(h.max(axis=1) - h.min(axis=1)))


#: A body is read as a biped when it has a head and two feet by joint role and at most this many leg-like chains
#: (three would be a person with a hand on the floor, or a contorted pose: still a biped; four, an animal).
MAX_BIPED_LEGS = 3
#: A leaf chain is leg-like when its end is this share of the body's largest extent from the floor or closer
#: in a quarter of the frames at least (a foot stands in part of a gait) ...
LEG_FLOOR_SHARE = 0.05
#: ... and it points down: the cosine between its start-to-end vector and the down direction is at least this.
LEG_DOWN_COS = 0.3
#: Second best over best above this (by leg count for a non-biped, by the head-to-feet vector's components for
#: a biped, by extent between the tallest axes) makes the up axis ambiguous.
AMBIGUOUS_RATIO = 0.7


def _leaf_chains(skeleton: Skeleton) -> list[tuple[int, int]]:
    """``(first joint, leaf joint)`` of every chain that runs without branching from just below a branching
    joint (or the root) to a leaf of at least two segments: the limbs, tails, necks of a skeleton."""
    kids: dict[int, list[int]] = {i: [] for i in range(len(skeleton.joints))}
    for i, j in enumerate(skeleton.joints):
        if j.parent >= 0:
            kids[j.parent].append(i)
    out = []
    for leaf in (i for i, k in kids.items() if not k and i > 0):
        first, n = leaf, 1
        while True:
            p = skeleton.joints[first].parent
            if p <= 0 or len(kids[p]) > 1:
                break
            first, n = p, n + 1
        if n >= 2:
            out.append((first, leaf))
    return out


def count_legs(skeleton: Skeleton, starts: np.ndarray, ends: np.ndarray, up) -> int:
    """How many leg-like chains :func:`leg_chains` finds."""
    return len(leg_chains(skeleton, starts, ends, up))


def leg_chains(skeleton: Skeleton, starts: np.ndarray, ends: np.ndarray, up) -> list[set[int]]:
    """Leg-like chains of a body for the signed axis ``up``: leaf chains (:func:`_leaf_chains`) that point
    down (:data:`LEG_DOWN_COS`, median over frames) and end on the floor (within :data:`LEG_FLOOR_SHARE` of
    the body's largest extent above its lowest point, in a quarter of the frames at least).

    Parameters
    ----------
    skeleton : Skeleton
    starts, ends : ndarray (frames, joints, 3)
        Joint starts and segment ends (:func:`forward_kinematics`).
    up : str
        A signed axis (:data:`AXES`).

    Returns
    -------
    list of set of int
        The joint indices of each leg-like chain.
    """
    u = axis_vector(up)
    pos = np.concatenate([starts, ends], axis=1)
    size = float(np.max(np.median(pos.max(axis=1) - pos.min(axis=1), axis=0)))
    h = pos @ u
    floor = h.min(axis=1)
    legs = []
    for first, leaf in _leaf_chains(skeleton):
        v = np.median(ends[:, leaf] - starts[:, first], axis=0)
        nv = float(np.linalg.norm(v))
        if nv <= 0 or float(-(v @ u)) / nv < LEG_DOWN_COS:
            continue
        if float(np.quantile(ends[:, leaf] @ u - floor, 0.25)) <= LEG_FLOOR_SHARE * size:
            chain, i = {leaf}, leaf
            while i != first:
                i = skeleton.joints[i].parent
                chain.add(i)
            legs.append(chain)
    return legs


def detect_up_axis(skeleton: Skeleton, values, overrides: dict | None = None) -> tuple[str, dict]:
    """The up axis of a motion, from the joint roles for a biped, from the legs otherwise.

    *A biped* (a ``head`` and two feet, ``left_ankle``/``right_ankle`` or
    ``left_toe``/``right_toe``, by joint role; at most :data:`MAX_BIPED_LEGS`
    leg-like chains, :func:`leg_chains`, along any axis along which a foot's
    chain is one of them): the signed axis nearest to the head minus the
    mid-point of the feet (median over frames). It is ambiguous when
    that vector's second largest component is more than
    :data:`AMBIGUOUS_RATIO` of its largest (the body lies diagonally), when the
    hips are not between head and feet along it, or when the body is clearly
    tallest along another axis (a lying body).

    *Not a biped* (no head or feet by role, or four or more leg-like chains:
    a quadruped, a crab): a four-legged body is longer than it is tall, so the
    extents do not tell up. The up axis is the signed axis with the most
    leg-like chains (pointing down and ending on the floor). It is ambiguous
    with fewer than three such chains or when another axis has more than
    :data:`AMBIGUOUS_RATIO` of them; then the file's own axes are kept
    (``+y``, BVH's convention), never a turn.

    Parameters
    ----------
    skeleton : Skeleton
    values : array (frames, n_dof)
    overrides : dict, optional
        ``{role: joint name}`` over the skeleton's own.

    Returns
    -------
    axis : str
        One of :data:`AXES`.
    info : dict
        ``extent`` (3,) median extents; ``ratio`` (second largest / largest
        extent); ``biped`` (bool); ``legs`` (leg-like chains along ``axis``);
        ``sign_from`` (``"roles"``: head above feet; ``"legs"``; ``"file"``:
        kept, as nothing told); ``ambiguous`` (bool); ``why`` (str: what was
        found, for the log).
    """
    starts = forward_kinematics(skeleton, values, ends=False)
    ends = forward_kinematics(skeleton, values, ends=True)
    pos = np.concatenate([starts, ends], axis=1)
    ext = np.median(pos.max(axis=1) - pos.min(axis=1), axis=0)
    tall = int(np.argmax(ext))
    ratio = float(np.sort(ext)[-2] / max(ext[tall], 1e-300))
    info = {"extent": ext, "ratio": ratio, "biped": False, "legs": 0, "ambiguous": False, "why": ""}
    head = _role_index(skeleton, ("head",), overrides)
    feet = (_role_index(skeleton, ("left_ankle", "right_ankle"), overrides)
            or _role_index(skeleton, ("left_toe", "right_toe"), overrides))
    chains = {ax: leg_chains(skeleton, starts, ends, ax) for ax in AXES}
    counts = {ax: len(c) for ax, c in chains.items()}
    # four or more legs where the feet (by role) stand: a four-legged animal on a biped template's names
    most = max((n for ax, n in counts.items()
                if feet is None or any(f in c for c in chains[ax] for f in feet)), default=0)
    if head is not None and feet is not None and most <= MAX_BIPED_LEGS:
        d = np.median(starts[:, head[0]] - 0.5 * (starts[:, feet[0]] + starts[:, feet[1]]), axis=0)
        a = int(np.argmax(np.abs(d)))
        axis = ("+" if d[a] >= 0 else "-") + "xyz"[a]
        info.update(biped=True, legs=counts[axis], sign_from="roles")
        why = []
        second = float(np.sort(np.abs(d))[-2] / max(abs(d[a]), 1e-300))
        if second > AMBIGUOUS_RATIO:
            why.append(f"the head-to-feet vector {_fmt_vec(d)} lies between two axes")
        hips = _role_index(skeleton, ("left_hip", "right_hip"), overrides)
        if hips is not None:
            u = axis_vector(axis)
            hh = float(np.median(0.5 * (starts[:, hips[0]] + starts[:, hips[1]]) @ u))
            hd = float(np.median(starts[:, head[0]] @ u))
            hf = float(np.median(0.5 * (starts[:, feet[0]] + starts[:, feet[1]]) @ u))
            if not hf <= hh <= hd:
                why.append("the hips are not between the head and the feet")
        if tall != a and ratio < AMBIGUOUS_RATIO:
            why.append(f"the body is tallest along {'xyz'[tall]} (lying down?)")
        info.update(ambiguous=bool(why), why="; ".join(why) or "head above feet")
        return axis, info
    if head is not None and feet is not None:
        info["why"] = f"head and feet found by role, but {most} leg-like chains"
    else:
        info["why"] = "no head or feet by joint role"
    best = max(AXES, key=lambda ax: (counts[ax], ax == CANONICAL_UP))
    second = max(c for ax, c in counts.items() if ax != best)
    info["legs"] = counts[best]
    if counts[best] >= 3 and second <= AMBIGUOUS_RATIO * counts[best]:
        info.update(sign_from="legs", why=info["why"] + f"; {counts[best]} legs stand on the floor along {best}")
        return best, info
    info.update(sign_from="file", ambiguous=True, legs=counts[CANONICAL_UP],
                why=info["why"] + "; leg-like chains per up axis: "
                + " ".join(f"{ax} {counts[ax]}" for ax in AXES))
    return CANONICAL_UP, info


def lying_down(skeleton: Skeleton, values, up, overrides: dict | None = None) -> str:
    """Why the body would lie down or stand on its head with ``up`` as the up axis, or ``""``.

    For a biped by joint role (head, ankles or toes): its head not above its
    feet (median over frames), or its extent along ``up`` less than half its
    largest extent across. For any body: :func:`detect_up_axis` finding
    another axis without ambiguity.
    """
    u = axis_vector(up)
    detected, info = detect_up_axis(skeleton, values, overrides)
    why = []
    head = _role_index(skeleton, ("head",), overrides)
    feet = (_role_index(skeleton, ("left_ankle", "right_ankle"), overrides)
            or _role_index(skeleton, ("left_toe", "right_toe"), overrides))
    if info["biped"] and head is not None and feet is not None:
        s = joint_starts(skeleton, values, [head[0], feet[0], feet[1]])
        if float(np.median((s[:, 0] - 0.5 * (s[:, 1] + s[:, 2])) @ u)) <= 0:
            why.append("its head is not above its feet")
        ext = info["extent"]
        k = int(np.argmax(np.abs(u)))
        across = max(ext[i] for i in range(3) if i != k)
        if ext[k] < 0.5 * across:
            why.append(f"it is {ext[k]:.3g} units tall along {up} but {across:.3g} across")
    if detected != parse_axis(up) and not info["ambiguous"] and not why:
        why.append(f"its {'head is above its feet' if info['biped'] else 'legs stand'} along {detected}")
    return "; ".join(why)


def _fmt_vec(v) -> str:
    return "(" + " ".join(f"{float(x):.3g}" for x in v) + ")"


def detect_forward_axis(skeleton: Skeleton, values, up, overrides: dict | None = None) -> tuple[str, str]:
    """The signed world axis, perpendicular to ``up``, the body faces most: from the hips, else the travel.

    Returns ``(axis, source)`` with source ``"hips"`` (mean of the per-frame
    unit :func:`hip_forward`) or ``"travel"`` (root displacement, first to last
    frame) or ``"default"`` (neither gives a direction: the axis after ``up``
    in ``x y z`` order).
    """
    u = axis_vector(up)
    v, src = None, "default"
    if _role_index(skeleton, ("left_hip", "right_hip"), overrides) is not None:
        f = hip_forward(skeleton, values, up, overrides)
        f = f - np.outer(f @ u, u)
        n = np.linalg.norm(f, axis=1)
        if np.any(n > 0):
            v, src = (f[n > 0] / n[n > 0, None]).mean(axis=0), "hips"
    if v is None or np.linalg.norm(v) < 1e-6:
        t = root_translation(skeleton, values)
        d = t[-1] - t[0]
        d = d - (d @ u) * u
        v, src = (d, "travel") if np.linalg.norm(d) > 0 else (None, "default")
    ua = int(np.argmax(np.abs(u)))
    cands = [s + "xyz"[k] for k in range(3) if k != ua for s in "+-"]
    if v is None:
        return cands[0], src
    return max(cands, key=lambda c: float(axis_vector(c) @ v)), src


def frame_rotation(up, forward) -> Rotation:
    """The rotation taking the file's ``up`` to +y and ``forward`` to +z.

    Raises
    ------
    ValueError
        ``up`` and ``forward`` are not perpendicular.
    """
    u, f = axis_vector(up), axis_vector(forward)
    if abs(u @ f) > 0:
        raise ValueError(f"up axis {up!r} and forward axis {forward!r} must be perpendicular")
    return Rotation.from_matrix(np.stack([np.cross(u, f), u, f]))


def default_forward(up) -> str:
    """The forward axis that the smallest turn taking ``up`` to +y takes to +z (``+z`` up -> ``-y`` forward,
    Blender's and 3ds Max's convention)."""
    u = axis_vector(up)
    e_y = np.array([0.0, 1.0, 0.0])
    c = np.cross(u, e_y)
    if np.linalg.norm(c) < 1e-12:
        R = Rotation.identity() if u[1] > 0 else Rotation.from_euler("x", 180, degrees=True)
    else:
        R = Rotation.from_rotvec(c / np.linalg.norm(c) * np.arccos(np.clip(u @ e_y, -1.0, 1.0)))
    back = R.inv().apply(np.array([0.0, 0.0, 1.0]))
    k = int(np.argmax(np.abs(back)))
    return ("+" if back[k] > 0 else "-") + "xyz"[k]


def to_canonical_frame(skeleton: Skeleton, values, up, forward) -> tuple[Skeleton, np.ndarray]:
    """Express a motion in the canonical frame (+y up, +z forward): turn the whole body by
    :func:`frame_rotation`.

    Only the root changes: its world rotation becomes ``R @ W_root`` and its
    translation ``R @ t`` (the children's offsets are in the root's frame and
    follow). A root without three rotation or three translation DOF gets the
    missing ones (zero in the rest pose), so the turn is exact; every joint's
    world position becomes ``R @ p``. Returns ``(skeleton, values)``, the
    skeleton a copy when it changed.
    """
    values = _check_values(skeleton, values)
    R = frame_rotation(up, forward)
    if np.allclose(R.as_matrix(), np.eye(3)):
        return skeleton, values
    sk = copy.deepcopy(skeleton)
    root = sk.joints[0]
    old = skeleton.joints[0]
    t = root_translation(skeleton, values)
    W = root_rotation(skeleton, values)
    trans = [d for d in old.dofs if d in TRANS_DOFS]
    rots = [d for d in old.dofs if d in ROT_DOFS]
    trans += [d for d in TRANS_DOFS if d not in trans]
    rots += [d for d in ROT_DOFS if d not in rots]
    root.dofs = trans + rots
    root.limits = []
    root.offset = R.apply(np.asarray(old.offset, float))
    n = values.shape[0]
    tn = R.apply(t)
    C = root.axis_rotation()
    ang = _continuous_euler((C.inv() * R * W * C).as_euler("".join(d[1] for d in rots), degrees=True))
    block = np.concatenate([tn[:, [TRANS_DOFS.index(d) for d in trans]] - root.offset[[TRANS_DOFS.index(d)
                                                                                       for d in trans]], ang], axis=1)
    sl = skeleton.dof_slices()[old.name]
    out = np.concatenate([block, values[:, sl.stop:]], axis=1).reshape(n, sk.n_dof)
    sk.__post_init__()
    return sk, out


# ---------------------------------------------------------------------------------------------------------------
# continuous angles (the one place Euler angles are unwrapped along time and put on one branch across clips)
# ---------------------------------------------------------------------------------------------------------------
#: A rotation DOF that changes by more than this many degrees between consecutive frames has wrapped (a file
#: writes every angle in (-180, 180], so a joint turning past 180 jumps by about 360): :func:`unwrap_angles`
#: adds the multiple of 360 degrees that removes the jump (``numpy.unwrap`` with period 360).
WRAP_JUMP_DEG = 180.0


def rotation_columns(skeleton: Skeleton, root: bool = True) -> np.ndarray:
    """Indices of the rotational DOF columns of a motion on ``skeleton``, shape ``(k,)`` int.

    ``root=False`` leaves out the root joint's.
    """
    cols, k = [], 0
    for i, j in enumerate(skeleton.joints):
        for d in j.dofs:
            if d in ROT_DOFS and (root or i > 0):
                cols.append(k)
            k += 1
    return np.array(cols, dtype=int)


def wrap_count(skeleton: Skeleton, values) -> int:
    """How many frame-to-frame changes above :data:`WRAP_JUMP_DEG` the rotational DOF of ``values``
    (frames, n_dof) hold (all columns together)."""
    v = np.asarray(values, float)
    cols = rotation_columns(skeleton)
    if v.shape[0] < 2 or not cols.size:
        return 0
    return int(np.count_nonzero(np.abs(np.diff(v[:, cols], axis=0)) > WRAP_JUMP_DEG))


def unwrap_angles(motion, what: str | None = None):
    """``motion`` with every rotational DOF made continuous along time.

    Each rotation column (the root's too) is unwrapped on its own with ``numpy.unwrap(period=360)``: a change
    between consecutive frames above :data:`WRAP_JUMP_DEG` degrees gets the multiple of 360 degrees that makes
    it at most 180. Every frame keeps the same rotation (an Euler angle plus 360 degrees is the same turn), so
    forward kinematics is unchanged up to rounding; translations (the root's, and those of other joints) are
    untouched. A column without such a change keeps its values bit for bit (no arithmetic touches it), and a
    motion without any is returned as it is.

    Parameters
    ----------
    motion : Motion, ``values`` (frames, n_dof)
    what : str, optional
        Names the motion in the log line (default its name).

    Returns
    -------
    Motion
        The same object when nothing wrapped, else a new one (same skeleton, frame rate, name; ``meta`` copied
        with ``"unwrapped"``: the number of changes removed). One info line gives the count and the columns.
    """
    from .motion import Motion

    v = np.asarray(motion.values, float)
    if v.shape[0] < 2:
        return motion
    cols = rotation_columns(motion.skeleton)
    if not cols.size:
        return motion
    jumps = np.abs(np.diff(v[:, cols], axis=0)) > WRAP_JUMP_DEG
    hit = np.flatnonzero(jumps.any(axis=0))
    if not hit.size:
        return motion
    out = v.copy()
    for c in cols[hit]:
        out[:, c] = np.unwrap(v[:, c], period=360.0)
    names = motion.skeleton.columns()
    n = int(jumps.sum())
    log.info("%s: %d frame-to-frame change(s) above %g degrees in %d rotation column(s) (%s) read as wraps of "
             "the Euler angle and unwrapped (the same rotations, continuous along time)", what or motion.name, n,
             WRAP_JUMP_DEG, hit.size, ", ".join(names[c] for c in cols[hit][:8]) + (" ..." if hit.size > 8 else ""))
    return Motion(out, motion.skeleton, motion.fps, motion.name, dict(motion.meta, unwrapped=n))


def align_angle_branches(motion, reference):
    """``motion`` with each non-root rotation column shifted by the multiple of 360 degrees that brings its
    median nearest the ``reference``'s median of that column.

    The branch rule of a database of clips: after :func:`unwrap_angles` each clip is continuous on its own,
    but a joint that sits near 180 degrees may sit near +180 in one clip and near -180 in another. Shifting
    the clip by ``360 * round((median_ref - median_clip) / 360)`` per column gives the same pose the same
    value across clips (the same rotation). The root's rotation is left as it is: it is the clip's heading,
    not part of the pose, and differs between clips anyway.

    Parameters
    ----------
    motion : Motion, ``(frames, n_dof)``
    reference : Motion or ndarray ``(frames_r, n_dof)`` on a skeleton with the same columns

    Returns
    -------
    Motion, the same object when no column moves, else a new one (``meta["branch_shift"]``: the columns moved).
    """
    from .motion import Motion

    ref = np.asarray(getattr(reference, "values", reference), float)
    v = np.asarray(motion.values, float)
    if ref.shape[1] != v.shape[1]:
        raise ValueError(f"{motion.name!r}: {v.shape[1]} DOF columns, the reference has {ref.shape[1]}")
    cols = rotation_columns(motion.skeleton, root=False)
    if not cols.size or not len(ref) or not len(v):
        return motion
    k = np.round((np.median(ref[:, cols], axis=0) - np.median(v[:, cols], axis=0)) / 360.0)
    moved = np.flatnonzero(k != 0)
    if not moved.size:
        return motion
    out = v.copy()
    out[:, cols[moved]] += 360.0 * k[moved]
    names = motion.skeleton.columns()
    log.info("%s: %d rotation column(s) (%s) shifted by a multiple of 360 degrees to the branch of the "
             "database's first clip", motion.name, moved.size, ", ".join(names[c] for c in cols[moved][:8]))
    return Motion(out, motion.skeleton, motion.fps, motion.name,
                  dict(motion.meta, branch_shift=[names[c] for c in cols[moved]]))


def continuous_clips(motions, reference=None) -> list:
    """Clips made ready to share one database: each :func:`unwrap_angles` on its own, then
    :func:`align_angle_branches` to ``reference`` (default: the first clip, itself unwrapped).

    Parameters
    ----------
    motions : list of Motion on skeletons with the same DOF columns
    reference : Motion, optional

    Returns
    -------
    list of Motion (an input that needs no change is returned as it is)
    """
    out = [unwrap_angles(m) for m in motions]
    if not out:
        return out
    ref = out[0] if reference is None else unwrap_angles(reference)
    return [align_angle_branches(m, ref) for m in out]


def retarget(motion, reference: Skeleton, what: str = "", reference_name: str = "", tol_m: float = SAME_SKELETON_TOL_M):
    """``motion`` on the ``reference`` skeleton, by joint name.

    * The same skeleton (:func:`compare_skeletons` within ``tol_m``, no rest-frame turn) with the same DOF
      columns: the values as they are, on ``reference`` (bit for bit).
    * The same skeleton otherwise (other channels or channel orders, or its rest pose turned, as in a Z-up
      re-export): the local rotations read onto ``reference``'s DOF (``L' = Q L Q^-1``, the root's world
      rotation ``W Q^-1``): every joint's world position is unchanged. One info line.
    * Other rest offsets (bone lengths, or directions within :data:`RETARGET_MAX_ANGLE_DEG`): retargeted, the
      local rotations kept (after the rest-frame turn) and the root's world translation kept, on
      ``reference``'s offsets. One warning names both and the largest offset difference.
    * Refused (ValueError naming both and the largest difference): other joint names or parents, or a bone
      whose rest direction differs by more than :data:`RETARGET_MAX_ANGLE_DEG` (another rest pose: keeping the
      local rotations would not carry the motion over).

    Translation DOF of non-root joints the reference lacks are dropped; rotation DOF the reference lacks must be
    zero (:func:`animsynth.kinematics.dof_values_from_local`). The result's angles are made continuous
    (:func:`animsynth.kinematics.unwrap_angles`).

    Parameters
    ----------
    motion : Motion, ``(frames, n_dof)``
    reference : Skeleton
    what, reference_name : str, name the motion and the reference in messages
    tol_m : float, metres

    Returns
    -------
    Motion, ``(frames, reference.n_dof)`` on ``reference``
    """
    from .motion import Motion

    what = what or motion.name or "motion"
    ref_name = reference_name or reference.name
    sk = motion.skeleton
    diff = compare_skeletons(sk, reference, tol_m)
    if not diff.joints_match:
        raise ValueError(f"{what}: its joints differ from the reference's ({ref_name}): {diff.why}; "
                         "give motions on the same skeleton")
    values = np.asarray(motion.values, float)
    same_cols = sk.columns() == reference.columns()
    turned = diff.turn_deg > 0
    if diff.same and same_cols and not turned:
        return Motion(values, reference, motion.fps, motion.name, dict(motion.meta))
    if diff.largest_angle_deg > RETARGET_MAX_ANGLE_DEG:
        raise ValueError(f"{what} and {ref_name}: another rest pose (rest offsets differ by up to "
                         f"{diff.largest_m * 1000:.1f} mm at joint {diff.joint!r}, a bone's rest direction by "
                         f"{diff.largest_angle_deg:.0f} degrees > {RETARGET_MAX_ANGLE_DEG:g}); retargeting by joint "
                         "name would not carry the motion over: give motions on one skeleton")
    Q = diff.turn
    L = local_rotations(sk, values)
    T = joint_translations(sk, values)
    n = values.shape[0]
    rots, trans = [], np.empty((n, len(reference.joints), 3))
    for i, j in enumerate(reference.joints):
        k = sk.index(j.name)
        rots.append(L[k] * Q.inv() if j.parent < 0 else Q * L[k] * Q.inv())
        if j.parent >= 0:
            moved = (T[:, k] - np.asarray(sk.joints[k].offset, float)) * (sk.length_to_m / reference.length_to_m)
            trans[:, i] = np.asarray(j.offset, float) + Q.apply(moved)
    root_t = root_translation(sk, values) * (sk.length_to_m / reference.length_to_m)
    trans[:, 0] = root_t
    out = Motion(dof_values_from_local(reference, rots, root_t, trans), reference, motion.fps, motion.name,
                 dict(motion.meta))
    if diff.same:
        log.info("%s: the skeleton of %s%s (rest offsets within %g mm); its rotations are read onto %s's DOF "
                 "(every joint's position unchanged)", what, ref_name,
                 f" with its rest pose turned by {diff.turn_deg:.0f} degrees" if turned else "", tol_m * 1000,
                 ref_name)
    else:
        log.warning("%s and %s: rest offsets differ by up to %.1f mm (joint %r; tolerance %g mm)%s; %s is "
                    "retargeted onto %s's skeleton by joint name (local rotations kept, %s's offsets)", what,
                    ref_name, diff.largest_m * 1000, diff.joint, tol_m * 1000,
                    f" after turning the rest pose by {diff.turn_deg:.0f} degrees" if turned else "", what, ref_name,
                    ref_name)
    return unwrap_angles(out, what)
