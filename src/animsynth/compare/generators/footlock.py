"""Foot locking and two-bone leg IK: the post-process motion matching's reference applies by default.

A reimplementation written from the documented behaviour and constants of Holden's MIT-licensed reference
(github.com/orangeduck/Motion-Matching, ``ik_enabled = true``); no code copied. Three steps:

1. **Contact labels** of the database (:func:`contact_labels`): a foot is in contact where its contact point
   moves slower than 0.15 m/s, then a median filter of 0.1 s (the reference: 6 frames at 60 fps) removes
   short runs ("a majority vote").
2. **Locking** (:func:`lock_contacts`), per foot and frame, from the animation's contact point and the played
   database frame's label: when a contact starts, the point is locked where the (blended) foot is, at the
   contact height; while locked the output is the locked point; the lock is released when the contact ends or
   when the animation's point is more than the unlock radius (0.2 m) away from it; every lock and release is
   inertialized (the offset decays by the critically damped spring, half-life 0.1 s).
3. **Two-bone IK** (:func:`place_feet`, :func:`two_bone_ik`): as the reference, the heel (the ankle joint) is sent
   to the contact target less the animation's heel-to-contact vector, hip and knee turn to put it there (its
   distance from the hip kept 0.015 m short of the leg's reach, the reference's ``ik_max_length_buffer``), then
   the foot is turned back to the animation's world orientation.

Where this departs from the reference (the skeleton here is a file's, not the reference's BVH character):

* the contact point is the end of the ``left_ankle`` / ``right_ankle`` role's segment (for an ASF ``lfoot``
  bone its tip: the ball of the foot; for a BVH skeleton the toe joint), the point the reference calls its
  toe bone, and the IK chain is the ``*_hip``, ``*_knee`` and ``*_ankle`` roles;
* the foot is turned back to the animation's world orientation instead of the reference's heel "look-at" onto
  the contact point, and its toe alignment with the floor (``ik_toe_length``) is not done; an ankle with fewer
  than three rotational DOF (CMU's ``lfoot``: two) drops the rotation about its missing axis, so the contact
  point lands near the target (a millimetre or so) rather than on it;
* the knee turns about its own hinge (its last rotational DOF's axis when it has fewer than three; the
  plane of the leg otherwise) and its and the hip's new rotations are written back to the skeleton's Euler
  DOF, so the leg stays a pose of the file's skeleton;
* heights come from the database, not from a floor at 0: a locked point is placed at its foot's median
  height over the database's contact frames (the reference: ``ik_foot_height`` = 0.02 m above its floor),
  and targets are kept above the lowest height the foot reaches in the database (the reference's clamp);
* contact speeds by central differences at the database's rate (the reference: its 60 fps velocities).

Written by hand: no maintained library does a skeleton's foot locking and analytic two-bone IK.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import median_filter
from scipy.spatial.transform import Rotation

from ...joints import resolve_roles
from ...kinematics import UP, forward_kinematics, joint_euler, nearest_euler, wrap_degrees
from ...skeleton import ROT_DOFS
from ...springs import decay_spring

__all__ = ["hip_knee_ankle", "contact_points", "contact_labels", "lock_contacts", "two_bone_ik", "place_feet"]


def hip_knee_ankle(skeleton) -> np.ndarray:
    """``(2, 3)`` joint indices (hip, knee, ankle) of the left and right legs, from the joint roles.

    Raises ``ValueError`` when a knee's parent is not its hip, an ankle's parent not its knee, or a hip has
    fewer than three rotational DOF (the IK turns it freely)."""
    out = []
    for side in ("left", "right"):
        names = resolve_roles(skeleton, (f"{side}_hip", f"{side}_knee", f"{side}_ankle"))
        h, k, a = (skeleton.index(n) for n in names)
        if skeleton.joints[k].parent != h or skeleton.joints[a].parent != k:
            raise ValueError(f"skeleton {skeleton.name!r}: the {side} leg {names} is not a chain hip -> knee -> ankle "
                             "(foot locking needs one; set foot_lock to false)")
        if sum(d in ROT_DOFS for d in skeleton.joints[h].dofs) != 3:
            raise ValueError(f"skeleton {skeleton.name!r}: the {side} hip {names[0]!r} needs three rotational DOF for "
                             "the leg IK (set foot_lock to false)")
        if not any(d in ROT_DOFS for d in skeleton.joints[k].dofs):
            raise ValueError(f"skeleton {skeleton.name!r}: the {side} knee {names[1]!r} has no rotational DOF "
                             "(set foot_lock to false)")
        out.append((h, k, a))
    return np.array(out, np.int64)


def contact_points(skeleton, values, chains: np.ndarray) -> np.ndarray:
    """World contact points ``(T, 2, 3)`` in metres: the end of each ankle joint's segment."""
    pos = forward_kinematics(skeleton, values, ends=True)
    return pos[:, chains[:, 2]] * float(skeleton.length_to_m)


def contact_labels(points: np.ndarray, fps: float, speed_m_s: float = 0.15, filter_s: float = 0.1) -> np.ndarray:
    """Contact states ``(T, F)`` of one clip's contact points ``(T, F, 3)`` (m): speed (central differences)
    below ``speed_m_s``, then a median filter of ``filter_s`` seconds (at least one frame) per foot."""
    T = points.shape[0]
    if T < 2:
        return np.zeros(points.shape[:2], bool)
    speed = np.linalg.norm(np.gradient(points, axis=0), axis=-1) * float(fps)
    c = speed < float(speed_m_s)
    size = max(1, int(round(float(filter_s) * float(fps))))
    if size > 1:
        c = median_filter(c.astype(np.uint8), size=(size, 1), mode="nearest").astype(bool)
    return c


def lock_contacts(points: np.ndarray, states: np.ndarray, fps: float, reset_point: np.ndarray,
                  contact_height: np.ndarray, unlock_radius_m: float = 0.2,
                  halflife_s: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """The reference's contact state machine: targets of the contact points, frame by frame.

    Parameters
    ----------
    points : ndarray (T, F, 3), the animation's contact points (m)
    states : bool ndarray (T, F), the contact labels of the frames played
    fps : float
    reset_point : ndarray (F, 3), the points of the frame before the first (the state starts there unlocked,
        out of contact, with no offset)
    contact_height : ndarray (F,), the height (m) a locked point is placed at
    unlock_radius_m : float, a lock is released when the animation's point is farther than this from it
    halflife_s : float, half-life of the lock and release blends

    Returns
    -------
    targets : ndarray (T, F, 3), where each contact point should be (m)
    locked : bool ndarray (T, F), frames whose target is (blending to) a locked point
    """
    points = np.asarray(points, float)
    T, F, _ = points.shape
    dt = 1.0 / float(fps)
    targets = np.empty_like(points)
    locked = np.zeros((T, F), bool)
    for f in range(F):
        prev_in = np.asarray(reset_point[f], float)
        off_x, off_v = np.zeros(3), np.zeros(3)
        state, lock, point = False, False, np.zeros(3)
        for t in range(T):
            x_in = points[t, f]
            v_in = (x_in - prev_in) / dt
            prev_in = x_in
            # the inertialized output follows the locked point (at rest) or the animation
            off_x, off_v = decay_spring(off_x, off_v, halflife_s, dt)
            pos = (point if lock else x_in) + off_x
            targets[t, f] = pos
            locked[t, f] = lock
            s = bool(states[t, f])
            release = lock and float(np.linalg.norm(point - x_in)) > float(unlock_radius_m)
            if s and not state:
                lock = True
                point = pos.copy()
                point[UP] = float(contact_height[f])
                off_x = off_x + x_in - point
                off_v = off_v + v_in
            elif (lock and state and not s) or release:
                lock = False
                off_x = off_x + point - x_in
                off_v = off_v - v_in
            state = s
    return targets, locked


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 1e-12, n, 1.0)


def _write_rotation(skeleton, j: int, L: Rotation, values: np.ndarray) -> None:
    """Write local rotations ``L`` of joint ``j`` into its Euler DOF columns of ``values`` (in place), each
    frame nearest its old values; a joint with fewer than three rotational DOF keeps its own axes (the
    rotation about the others is dropped)."""
    joint = skeleton.joints[j]
    start = skeleton.dof_slices()[joint.name].start
    rd = [(i, d[1]) for i, d in enumerate(joint.dofs) if d in ROT_DOFS]
    cols = np.array([start + i for i, _ in rd])
    ang = joint_euler(joint, L)
    old = values[:, cols]
    values[:, cols] = nearest_euler(ang, old) if len(rd) == 3 else old + wrap_degrees(ang - old)


def place_feet(skeleton, values, chain, targets, max_length_buffer_m: float = 0.015, fk=None) -> np.ndarray:
    """The reference's order: the heel (the ankle joint) is sent to the contact target less the animation's
    heel-to-contact vector, hip and knee turned by :func:`two_bone_ik` on the heel, then the ankle turned back
    to the animation's world orientation, so the foot lands on ``targets (T, 3)`` (m) as the animation held it.

    With a three-DOF ankle the contact point reaches a reachable target exactly; with fewer (CMU's ``lfoot``:
    two) the rotation about the missing axis is dropped and the point lands near it.

    ``fk``: the ``(starts, world rotations)`` of ``values`` (:func:`animsynth.kinematics.forward_kinematics`
    with ``ends=False, world_rotations=True``) when already computed."""
    values = np.array(values, float)
    if values.ndim == 1:
        values = values[None, :]
    a = int(chain[2])
    m = float(skeleton.length_to_m)
    starts, W = forward_kinematics(skeleton, values, ends=False, world_rotations=True) if fk is None else fk
    foot = W[a].apply(skeleton.joints[a].tail) * m  # heel to contact point, world, metres
    out, Wk = _two_bone(skeleton, values, chain, np.asarray(targets, float) - foot, max_length_buffer_m, "heel",
                        starts, W)
    _write_rotation(skeleton, a, Wk.inv() * W[a], out)
    return out


def two_bone_ik(skeleton, values, chain, targets, max_length_buffer_m: float = 0.015,
                effector: str = "ball") -> np.ndarray:
    """DOF values whose leg ``chain`` (hip, knee, ankle indices) puts the ankle segment's end (``effector``
    "ball"; "heel": the ankle joint itself) on ``targets``.

    The knee turns about its hinge until the end's distance from the hip is the target's (clamped to the
    leg's reach minus ``max_length_buffer_m`` and to its shortest fold), then the hip turns by the smallest
    rotation that points the end at the target. Every other DOF is unchanged, bones keep their lengths (only
    rotations change); an unreachable target gets the leg stretched as far as the buffer allows, pointing at it.

    Parameters
    ----------
    skeleton : Skeleton
    values : ndarray (T, n_dof)
    chain : 3 ints, hip, knee, ankle (:func:`hip_knee_ankle`)
    targets : ndarray (T, 3), world targets in metres
    max_length_buffer_m : float, metres kept short of full extension (the reference: 0.015)
    effector : "ball" (the ankle segment's end) or "heel" (the ankle joint)

    Returns
    -------
    ndarray (T, n_dof)
    """
    values = np.array(values, float)
    if values.ndim == 1:
        values = values[None, :]
    if effector not in ("ball", "heel"):
        raise ValueError(f"two_bone_ik: effector must be 'ball' or 'heel', got {effector!r}")
    starts, W = forward_kinematics(skeleton, values, ends=False, world_rotations=True)
    return _two_bone(skeleton, values, chain, targets, max_length_buffer_m, effector, starts, W)[0]


def _two_bone(skeleton, values, chain, targets, max_length_buffer_m, effector, starts, W):
    """:func:`two_bone_ik` on ``values`` (edited in place) with their forward kinematics ``starts`` and ``W``;
    also returns the knee's new world rotations."""
    T = values.shape[0]
    h, k, a = (int(i) for i in chain)
    m = float(skeleton.length_to_m)
    tgt = np.asarray(targets, float).reshape(T, 3) / m
    sh, sk_ = starts[:, h], starts[:, k]
    end = starts[:, a] + (W[a].apply(skeleton.joints[a].tail) if effector == "ball" else 0.0)
    knee = skeleton.joints[k]
    krot = [(i, d) for i, d in enumerate(knee.dofs) if d in ROT_DOFS]
    C = knee.axis_rotation()
    if len(krot) < 3:  # the hinge: the knee's last rotational DOF axis
        axis = np.eye(3)["xyz".index(krot[-1][1][1])]
        kw = W[k].apply(C.apply(axis))
    else:  # the plane of the leg (the last DOF axis when straight)
        axis = np.eye(3)["xyz".index(krot[-1][1][1])]
        fallback = W[k].apply(C.apply(axis))
        n = np.cross(sk_ - sh, end - sk_)
        ok = np.linalg.norm(n, axis=1) > 1e-9 * np.linalg.norm(sk_ - sh, axis=1) * np.linalg.norm(end - sk_, axis=1)
        kw = np.where(ok[:, None], n, fallback)
    kw = _unit(kw)
    av, bv = sk_ - sh, end - sk_
    b_par = np.sum(bv * kw, axis=1, keepdims=True) * kw
    b_perp = bv - b_par
    b_side = np.cross(kw, b_perp)
    c0 = np.sum(av * b_par, axis=1)
    A = np.sum(av * b_perp, axis=1)
    B = np.sum(av * b_side, axis=1)
    r = np.hypot(A, B)
    phi = np.arctan2(B, A)
    base = np.sum(av * av, axis=1) + np.sum(bv * bv, axis=1)
    dmax = np.sqrt(np.maximum(base + 2.0 * (c0 + r), 0.0))
    dmin = np.sqrt(np.maximum(base + 2.0 * (c0 - r), 0.0))
    to = tgt - sh
    dist = np.linalg.norm(to, axis=1)
    want = np.clip(dist, dmin, np.maximum(dmax - float(max_length_buffer_m) / m, dmin))
    cosv = np.clip(np.where(r > 1e-12, ((want ** 2 - base) / 2.0 - c0) / np.where(r > 1e-12, r, 1.0), 1.0), -1.0, 1.0)
    side = np.where(np.sin(-phi) < 0.0, -1.0, 1.0)  # stay on the side of the fold the knee is on
    delta = np.angle(np.exp(1j * (phi + side * np.arccos(cosv))))
    delta = np.where(r > 1e-12, delta, 0.0)
    turn = Rotation.from_rotvec(kw * delta[:, None])
    new_end = sk_ + turn.apply(bv)
    # the hip: the smallest rotation taking the end's direction to the target's
    u, w = _unit(new_end - sh), _unit(to)
    cr = np.cross(u, w)
    sn, cs = np.linalg.norm(cr, axis=1), np.sum(u * w, axis=1)
    ang = np.arctan2(sn, cs)
    perp = _unit(np.cross(u, np.where(np.abs(u[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])))
    ax = np.where((sn > 1e-12)[:, None], cr / np.where(sn > 1e-12, sn, 1.0)[:, None], perp)
    R2 = Rotation.from_rotvec(ax * np.where(dist > 1e-12, ang, 0.0)[:, None])
    sl = skeleton.dof_slices()
    # knee DOF
    kcols = np.array([sl[knee.name].start + i for i, _ in krot])
    if len(krot) < 3:
        values[:, kcols[-1]] += np.rad2deg(delta)
    else:
        Wp = W[knee.parent]
        Lk = Wp.inv() * turn * W[k]
        values[:, kcols] = nearest_euler(joint_euler(knee, Lk), values[:, kcols])
    # hip DOF: new world rotation R2 * W_h
    hip = skeleton.joints[h]
    hcols = np.array([sl[hip.name].start + i for i, d in enumerate(hip.dofs) if d in ROT_DOFS])
    Wp = W[hip.parent] if hip.parent >= 0 else Rotation.identity(T)
    Lh = Wp.inv() * R2 * W[h]
    values[:, hcols] = nearest_euler(joint_euler(hip, Lh), values[:, hcols])
    return values, R2 * turn * W[k]
