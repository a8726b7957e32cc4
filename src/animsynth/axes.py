"""The up and forward axes of a motion file: detection, checks and the turn to the canonical frame.

Every study works in the canonical world frame of :mod:`animsynth.kinematics` (``+y`` up, ``+z``
forward). A file in another frame (Z up, as Blender and 3ds Max write it) is turned into the canonical one
when it is loaded (:func:`to_canonical_frame`, called by :func:`animsynth.data.load_trial`), with the up
axis detected from the motion (:func:`detect_up_axis`: for a biped by its joint roles, the head above the
feet; for another body, a quadruped or a crab, by its legs standing on the floor; when that is ambiguous
for a body that is not a biped, the file's own +y is kept) or given (config ``up_axis`` / ``forward_axis``;
:func:`lying_down` checks a given one). A rest pose lying along X (LAFAN1) is not a different frame: the up
axis comes from the frames, not the rest pose, and facing from the hips
(:func:`animsynth.kinematics.facing`), so such a file needs no change.
"""

from __future__ import annotations

import copy

import numpy as np
from scipy.spatial.transform import Rotation

from .kinematics import (AXES, CANONICAL_UP, axis_vector, check_values, continuous_euler, forward_kinematics,
                         hip_forward, joint_starts, parse_axis, role_indices, root_rotation, root_translation)
from .skeleton import ROT_DOFS, TRANS_DOFS, Skeleton


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


#: The roles decide a biped's up axis, whatever its lean or extents, when its head is above its feet along that
#: axis (the largest component of the head-to-feet vector) in at least this share of the frames ...
ROLES_DECIDE_SHARE = 0.9


def _roles_decide(head_to_feet: np.ndarray, axis: str, counts: dict) -> bool:
    """Whether a biped's head-to-feet vectors ``(frames, 3)`` point along ``axis`` in :data:`ROLES_DECIDE_SHARE`
    of the frames, and its legs do not say otherwise (two leg-like chains stand along ``axis``, or none stands
    along any axis): a person leaning 40 degrees forward (a crouched walk), or taller across than along up in part
    of a take, is still upright; a file turned 45 degrees is not decided."""
    k = np.argmax(np.abs(head_to_feet), axis=1)
    signs = np.sign(head_to_feet[np.arange(len(k)), k])
    want = "xyz".index(axis[1]), (1.0 if axis[0] == "+" else -1.0)
    share = float(np.mean((k == want[0]) & (signs == want[1]))) if len(k) else 0.0
    legs_agree = counts.get(axis, 0) >= 2 or max(counts.values(), default=0) < 2
    return share >= ROLES_DECIDE_SHARE and legs_agree


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
    tallest along another axis (a lying body); the first and the last do not
    count when the roles decide (:func:`_roles_decide`: the head above the feet
    along that axis in nearly every frame, the legs agreeing).

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
        ``leg_counts`` (``{signed axis: leg-like chains along it}``);
        ``sign_from`` (``"roles"``: head above feet; ``"legs"``; ``"file"``:
        kept, as nothing told); ``ambiguous`` (bool); ``why`` (str: what was
        found, for the log).
    """
    starts = forward_kinematics(skeleton, values, ends=False)
    ends = forward_kinematics(skeleton, values, ends=True)
    pos = np.concatenate([starts, ends], axis=1)
    ext = np.median(pos.max(axis=1) - pos.min(axis=1), axis=0)
    ratio = float(np.sort(ext)[-2] / max(ext[int(np.argmax(ext))], 1e-300))
    info = {"extent": ext, "ratio": ratio, "biped": False, "legs": 0, "ambiguous": False, "why": "",
            "leg_counts": {}}
    head = role_indices(skeleton, ("head",), overrides)
    feet = (role_indices(skeleton, ("left_ankle", "right_ankle"), overrides)
            or role_indices(skeleton, ("left_toe", "right_toe"), overrides))
    chains = {ax: leg_chains(skeleton, starts, ends, ax) for ax in AXES}
    counts = {ax: len(c) for ax, c in chains.items()}
    info["leg_counts"] = counts
    # four or more legs where the feet (by role) stand: a four-legged animal on a biped template's names
    most = max((n for ax, n in counts.items()
                if feet is None or any(f in c for c in chains[ax] for f in feet)), default=0)
    if head is not None and feet is not None and most <= MAX_BIPED_LEGS:
        return _biped_up(skeleton, starts, head[0], feet, info, overrides)
    if head is not None and feet is not None:
        info["why"] = f"head and feet found by role, but {most} leg-like chains"
    else:
        info["why"] = "no head or feet by joint role"
    return _up_from_legs(info)


def _biped_up(skeleton: Skeleton, starts: np.ndarray, head: int, feet: list[int], info: dict,
              overrides: dict | None) -> tuple[str, dict]:
    """A biped's up axis (:func:`detect_up_axis`): the signed axis nearest to its head minus the mid-point of its
    feet, and ``info`` updated with whether (and why) that is ambiguous.

    ``starts`` (frames, joints, 3) are the joint starts; ``head`` and ``feet`` joint indices by role; ``info``
    holds the extents and leg counts already found."""
    counts = info["leg_counts"]
    per_frame = starts[:, head] - 0.5 * (starts[:, feet[0]] + starts[:, feet[1]])
    d = np.median(per_frame, axis=0)
    a = int(np.argmax(np.abs(d)))
    axis = ("+" if d[a] >= 0 else "-") + "xyz"[a]
    info.update(biped=True, legs=counts[axis], sign_from="roles")
    why = []
    second = float(np.sort(np.abs(d))[-2] / max(abs(d[a]), 1e-300))
    decided = _roles_decide(per_frame, axis, counts)
    if second > AMBIGUOUS_RATIO and not decided:
        why.append(f"the head-to-feet vector {_fmt_vec(d)} lies between two axes")
    hips = role_indices(skeleton, ("left_hip", "right_hip"), overrides)
    if hips is not None:
        u = axis_vector(axis)
        hh = float(np.median(0.5 * (starts[:, hips[0]] + starts[:, hips[1]]) @ u))
        hd = float(np.median(starts[:, head] @ u))
        hf = float(np.median(0.5 * (starts[:, feet[0]] + starts[:, feet[1]]) @ u))
        if not hf <= hh <= hd:
            why.append("the hips are not between the head and the feet")
    tall = int(np.argmax(info["extent"]))
    if tall != a and info["ratio"] < AMBIGUOUS_RATIO and not decided:
        why.append(f"the body is tallest along {'xyz'[tall]} (lying down?)")
    info.update(ambiguous=bool(why), why="; ".join(why) or "head above feet")
    return axis, info


def _up_from_legs(info: dict) -> tuple[str, dict]:
    """The up axis of a body that is not a biped (:func:`detect_up_axis`): the signed axis along which the most
    leg-like chains (``info["leg_counts"]``) stand, or the file's own +y when that is ambiguous; ``info``
    updated (its ``why`` extended)."""
    counts = info["leg_counts"]
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
    another axis without ambiguity. For a body that is not a biped, also when
    that detection is ambiguous: more leg-like chains (two at least) ending on
    the floor along another axis than along ``up`` (a bird, an animal whose
    legs do not all touch the floor).
    """
    u = axis_vector(up)
    detected, info = detect_up_axis(skeleton, values, overrides)
    why = []
    head = role_indices(skeleton, ("head",), overrides)
    feet = (role_indices(skeleton, ("left_ankle", "right_ankle"), overrides)
            or role_indices(skeleton, ("left_toe", "right_toe"), overrides))
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
    counts = info["leg_counts"]
    best = max(AXES, key=lambda ax: (counts.get(ax, 0), ax == parse_axis(up)))
    if not info["biped"] and not why and counts.get(best, 0) >= 2 and counts[best] > counts.get(parse_axis(up), 0):
        # not a biped, its up axis not told by the legs (ambiguous): still, more legs stand on another axis
        why.append(f"{counts.get(parse_axis(up), 0)} leg-like chains end on the floor along {up}, {counts[best]} "
                   f"along {best}")
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
    if role_indices(skeleton, ("left_hip", "right_hip"), overrides) is not None:
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
    values = check_values(skeleton, values)
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
    ang = continuous_euler((C.inv() * R * W * C).as_euler("".join(d[1] for d in rots), degrees=True))
    block = np.concatenate([tn[:, [TRANS_DOFS.index(d) for d in trans]] - root.offset[[TRANS_DOFS.index(d)
                                                                                       for d in trans]], ang], axis=1)
    sl = skeleton.dof_slices()[old.name]
    out = np.concatenate([block, values[:, sl.stop:]], axis=1).reshape(n, sk.n_dof)
    sk.__post_init__()
    return sk, out
