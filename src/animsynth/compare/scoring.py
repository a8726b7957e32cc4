"""Score motions made anywhere with the compare family's metrics (``animsynth score``).

A generated motion (a BVH file from any tool) is scored against the held-out capture it should continue, as a
generator's motion is scored in the comparison (:func:`animsynth.compare.jobs.score`): its first ``context``
frames are the start (the frames the generator was given, as in the protocol: the same frames as the
reference's first ``context``), the frames after them are the generated ones, compared with the reference's
frames after its start.

What a BVH file cannot give is left empty (:data:`UNSCORED`): the generator's seams (and so every metric at
seams), its transition count and the spread over seeds. The metrics that read the database (:data:`DATABASE_METRICS`:
the floor of foot skating, L2P's normalisation, coverage, novelty, the capture's jump percentiles) are left
empty without one; foot skating is scored without a database when the floor height is given
(``compare.metrics.floor_m``). With the database and the settings of a compare run, a motion of that run's BVH
folder scores as in its ``metrics.csv`` (L2P: when the run's database is this clip's, as in a run of one clip;
the comparison normalises L2P by the whole run's database).
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from ..motion import Motion
from .jobs import KEY_COLUMNS, Clip, reference, run_stats, score
from .metrics import METRIC_NAMES, SENSITIVITY_SPEEDS

log = logging.getLogger("animsynth.compare.scoring")

__all__ = ["SKATING_METRICS", "DATABASE_METRICS", "UNSCORED", "score_motions", "on_skeleton"]

#: foot skating: needs the floor (the database's foot heights, or compare.metrics.floor_m)
SKATING_METRICS = ("contact_share", "skate_share", "skate_m_per_contact_frame", "skating_ratio_gmd",
                   *(f"skate_share_at_{v:g}" for v in SENSITIVITY_SPEEDS),
                   *(f"skating_ratio_gmd_at_{v:g}" for v in SENSITIVITY_SPEEDS))
#: the other metrics that read the database
DATABASE_METRICS = ("l2p", "coverage", "local_diversity_m", "novelty_median_m", "copy_share")
#: never scored from a file: the generator's seams, its transitions, the spread over seeds of one start
UNSCORED = ("transition_skate_share", "n_seams", "seams_per_s", "transitions_kept", "velocity_jump",
            "velocity_jump_ratio", "velocity_jump_pct", "accel_jump", "accel_jump_ratio", "accel_jump_pct",
            "seed_diversity_m")


def on_skeleton(motion: Motion, skeleton, what: str, reference_name: str = "the reference") -> Motion:
    """``motion`` on ``skeleton`` (the reference's), by joint name.

    Every joint of ``skeleton`` must be in ``motion`` with the same parent joint (by name); joints of
    ``motion`` that the reference does not have (an extra end joint, a prop, a finger) are left out, logged.
    Otherwise (a joint missing, or one whose parent differs: an extra joint inside a chain would move its
    children) a ``ValueError`` names the joints. The rest is :func:`animsynth.retarget.retarget`: its values
    as they are when it is the same skeleton (rest offsets within
    :data:`animsynth.skeleton.SAME_SKELETON_TOL_M`) with the same DOF columns; its rotations read onto the
    reference's DOF when only the channels or the rest frame differ (a Z-up re-export: every joint's position
    unchanged); retargeted by joint name with a logged warning when the rest offsets differ; refused (naming
    both and the largest offset difference) when the rest pose differs.
    """
    from ..retarget import retarget

    msk = motion.skeleton
    missing = [n for n in skeleton.names if n not in msk.names]
    if missing:
        raise ValueError(f"{what}: its joints differ from the reference's: {len(missing)} of the reference's "
                         f"{len(skeleton.names)} joints are not in it ({', '.join(missing[:5])}"
                         f"{', ...' if len(missing) > 5 else ''}); score motions on the reference's skeleton")

    def parent(sk, name):
        p = sk[name].parent
        return sk.joints[p].name if p >= 0 else None

    moved = [n for n in skeleton.names if parent(msk, n) != parent(skeleton, n)]
    if moved:
        raise ValueError(f"{what}: joint(s) {', '.join(moved[:5])} hang from another parent than in the "
                         "reference (an extra joint inside a chain would move them); score motions on the "
                         "reference's skeleton")
    extra = [n for n in msk.names if n not in skeleton.names]
    if extra:
        log.info("%s: joints the reference does not have are left out: %s", what, ", ".join(extra))
        motion = _without_joints(motion, set(extra))
    return retarget(motion, skeleton, what, reference_name)


def _without_joints(motion: Motion, drop: set) -> Motion:
    """``motion`` with the joints ``drop`` (and their DOF columns) removed: the kept joints' parents re-indexed.
    Only joints that no kept joint hangs from may be dropped (:func:`on_skeleton` checks the parents), so the
    kept joints move as before."""
    import copy

    from ..skeleton import Skeleton

    sk = motion.skeleton
    keep = [i for i, j in enumerate(sk.joints) if j.name not in drop]
    new_index = {old: new for new, old in enumerate(keep)}
    joints = []
    for i in keep:
        j = copy.deepcopy(sk.joints[i])
        j.parent = new_index[j.parent] if j.parent >= 0 else -1
        joints.append(j)
    out_sk = Skeleton(joints, length_to_m=sk.length_to_m, angle_unit=sk.angle_unit, name=sk.name,
                      file_angle_unit=sk.file_angle_unit, roles=dict(sk.roles))
    cols = sk.columns()
    pos = {c: k for k, c in enumerate(cols)}
    take = [pos[c] for c in out_sk.columns()]
    return Motion(np.asarray(motion.values, float)[:, take], out_sk, motion.fps, motion.name, dict(motion.meta))


def score_motions(generated: dict, reference_motion: Motion, database: dict | None, context: int, mcfg: dict,
                  reference_name: str = "reference") -> pd.DataFrame:
    """Every metric of :mod:`animsynth.compare.jobs` that a motion file gives, one row per generated motion.

    Parameters
    ----------
    generated : {name: Motion}, each with ``context`` start frames then its generated frames, at the
        reference's frame rate
    reference_motion : Motion, the held-out capture: the start, then at least as many frames as any generated
        motion
    database : {name: Motion} or None, the clips the generator learned from (``None``: :data:`SKATING_METRICS`
        unless ``mcfg["floor_m"]`` is set, and :data:`DATABASE_METRICS`, are left empty)
    context : int >= 1, start frames
    mcfg : the ``compare.metrics`` block
    reference_name : the ``clip`` column

    Returns
    -------
    DataFrame with the columns of ``compare/metrics.csv`` (:data:`~animsynth.compare.jobs.KEY_COLUMNS`,
    :data:`~animsynth.compare.jobs.METRIC_NAMES`, ``note``): ``generator`` the name, ``protocol`` "scored file",
    ``seed`` empty, ``note`` what was left empty for want of a database.
    """
    ref = reference_motion
    sk, fps, context = ref.skeleton, float(ref.fps), int(context)
    if context < 1:
        raise ValueError(f"context {context}: at least 1 start frame is needed (the foot speed and the facing of "
                         "L2P read the frame before the first scored one)")
    if ref.n_frames <= context:
        raise ValueError(f"{reference_name}: {ref.n_frames} frames, none after the {context} start frames")
    db = []
    for name, d in (database or {}).items():
        if not np.isclose(float(d.fps), fps):
            raise ValueError(f"database {name}: {float(d.fps):g} fps, the reference runs at {fps:g} fps")
        db.append(Motion(on_skeleton(d, sk, f"database {name}", reference_name).values, sk, fps, name))
    blank = set(UNSCORED)
    note = ""
    if not db:
        blank |= set(DATABASE_METRICS)
        if mcfg.get("floor_m") is None:
            blank |= set(SKATING_METRICS)
            note = "no database: foot skating (no floor height), L2P, coverage and novelty empty"
        else:
            note = "no database: L2P, coverage and novelty empty"
    roles = None
    if SKATING_METRICS[0] in blank:  # no foot metric: the feet need no joint (the columns are left empty)
        from ..joints import FOOT_ROLES, JointRoleError, resolve_roles

        try:
            resolve_roles(sk, FOOT_ROLES)
        except JointRoleError:
            roles = {r: sk.names[0] for r in FOOT_ROLES}
            log.info("%s: no joints for the foot roles; foot skating is not scored (no database, no floor height)",
                     reference_name)
    rows = []
    for name, g in generated.items():
        if not np.isclose(float(g.fps), fps):
            raise ValueError(f"{name}: {float(g.fps):g} fps, the reference {reference_name} runs at {fps:g} fps "
                             "(score motions at the reference's rate)")
        m = on_skeleton(g, sk, name, reference_name)
        length = m.n_frames - context
        if length < 1:
            raise ValueError(f"{name}: {m.n_frames} frames, none after the {context} start frames")
        if context + length > ref.n_frames:
            raise ValueError(f"{name}: {context} start + {length} generated frames, but the reference "
                             f"{reference_name} has {ref.n_frames} frames to compare them with")
        _check_start(m, ref, context, name, reference_name)
        clip = Clip(reference_name, "", "scored file", reference_name, ref, db or [ref], context, length)
        std = run_stats([clip], mcfg) if db else np.ones((len(sk.joints), 3))
        row, _f = score(clip, reference(clip, mcfg, roles, std),
                        Motion(np.asarray(m.values[context:], float), sk, fps, name), name, mcfg, roles)
        row["transitions_kept"] = np.nan
        row.update({k: np.nan for k in blank})
        rows.append({"clip": reference_name, "group": "", "protocol": "scored file", "generator": name, "seed": "",
                     **row, "note": note})
    return pd.DataFrame(rows, columns=KEY_COLUMNS + METRIC_NAMES + ["note"])


def _check_start(m: Motion, ref: Motion, context: int, name: str, reference_name: str) -> None:
    """Warn when the first ``context`` frames of ``m`` are not the reference's start (the reference's are used)."""
    from .metrics import positions

    a = positions(Motion(np.asarray(m.values[:context], float), m.skeleton, m.fps))
    b = positions(Motion(np.asarray(ref.values[:context], float), ref.skeleton, ref.fps))
    gap = float(np.max(np.linalg.norm(a - b, axis=-1)))
    if gap > 0.01:
        log.warning("%s: its first %d frames are not the start of %s (joints up to %.3g m apart); scored from the "
                    "reference's start, as the comparison scores every generator", name, context, reference_name,
                    gap)
