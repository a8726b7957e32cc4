"""Continuous Euler angles across a database of clips, and retargeting a motion onto a skeleton by joint name.

:func:`unwrap_angles` makes every rotation DOF of a motion continuous along time, :func:`align_angle_branches`
puts the clips of a database on one branch, :func:`continuous_clips` does both, and :func:`retarget` carries
a motion over to another file's skeleton (the same joints, within a tolerance of its rest pose).
"""

from __future__ import annotations

import logging

import numpy as np

from .kinematics import dof_values_from_local, joint_translations, local_rotations, root_translation
from .skeleton import RETARGET_MAX_ANGLE_DEG, ROT_DOFS, SAME_SKELETON_TOL_M, Skeleton, compare_skeletons

log = logging.getLogger("animsynth.retarget")

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
    (:func:`unwrap_angles`).

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
