"""Scoring: every metric of one generated motion against the held-out clip it continues.

The comparison scores each generator's motion with :func:`score` (its clip's database side computed once,
:func:`reference`; L2P normalised by the clip's own database, so a clip's scores do not depend on what else the
run holds). ``animsynth score`` scores motions
made anywhere (a BVH file from any tool) the same way (:func:`score_motions`): a generated motion is scored against
the held-out capture it should continue, as a generator's motion is scored in the comparison: its first ``context``
frames are the start (the frames the generator was given, as in the protocol: the same frames as the
reference's first ``context``), the frames after them are the generated ones, compared with the reference's
frames after its start.

:func:`score` loops over the records of the metric table (:mod:`.measures.metric_table`) computed on a track, grouped
by what they need, and calls the computation each record names once per motion (one computation may fill several
records); the intermediates they share (positions, world rotations, seams, pose features, the floor) are computed
once per motion (:class:`~.measures.scored.ScoredMotion`). The records a run gives, not one motion (the generator's
transitions, the spread over seeds), are computed once per clip and generator by :func:`run_values`.

What a scored file cannot give is left empty, by what each metric needs (:attr:`~.metric_table.Metric.needs`):
:data:`UNSCORED`, the generator's seams (and so every metric at seams), its transition count and the spread over
seeds. The metrics that read the database (:data:`DATABASE_METRICS`: L2P's normalisation, coverage, novelty) and
foot skating (:data:`SKATING_METRICS`: the floor from the database's feet) are left empty without one; foot skating
is scored without a database when the floor height is given (``compare.metrics.floor_m``). With the database and
the settings of a compare run, a motion of that run's BVH folder scores as in its ``metrics.csv`` (given the clip's
whole database: the comparison normalises L2P by the clip's own database).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..motion import Motion
from .measures.metric_table import (KEY_COLUMNS, METRIC_NAMES, MOTION_NEEDS, PER_RUN, RUN_NEEDS, by_computation,
                                    computation, names_needing, on_track)
from .protocol import Clip

log = logging.getLogger("animsynth.compare.scoring")

__all__ = ["Reference", "DatabaseKinematics", "References", "run_stats", "reference",
           "score", "run_values", "SKATING_METRICS", "DATABASE_METRICS", "UNSCORED", "score_motions", "on_skeleton"]

#: foot skating: needs the floor (the database's foot heights, or compare.metrics.floor_m)
SKATING_METRICS = names_needing("floor")
#: the other metrics that read the database
DATABASE_METRICS = names_needing("database")
#: never scored from a file: the generator's seams, its transitions, the spread over seeds of one start
UNSCORED = names_needing(*PER_RUN)


# ----------------------------------------------------------------------------- one motion against its clip


@dataclass
class Reference:
    """What scoring needs from one clip's database (computed once per clip).

    Attributes
    ----------
    foot_idx : int array, the foot joints
    floor : float, the floor height (m)
    jumps : metrics.JumpReference, the database's own frame-to-frame jumps
    std : ndarray (J, 3), LAFAN1 position statistics of the clip's database windows (the comparison's; or given)
    capture_max : (float, float), the held-out capture's largest velocity and acceleration jump
    features : list of ndarray, the database clips' pose features
    truth_pos, truth_q : the ground truth's positions (m) and global quaternions
    truth_forward : ndarray (2,), the ground truth's facing at the last start frame
    db_pos : list of ndarray (T_i, J, 3), the database clips' positions (read-only: shared by the job's clips)
    held_pos, held_facing : ndarray (T, J, 3) and (T, 2), the whole held-out clip's positions and facing
    """

    foot_idx: np.ndarray
    floor: float
    jumps: object
    std: np.ndarray
    features: list
    truth_pos: np.ndarray
    truth_q: np.ndarray
    truth_forward: np.ndarray
    capture_max: tuple = (np.nan, np.nan)
    db_pos: list = field(default_factory=list)
    held_pos: np.ndarray | None = None
    held_facing: np.ndarray | None = None
    _shared: dict = field(default_factory=dict, repr=False, compare=False)

    def shared(self, key: str, compute):
        """``compute(self)``, computed once per clip for every motion scored against it (a measure's own reading
        of the database or the held-out capture, such as the capture's still share)."""
        if key not in self._shared:
            self._shared[key] = compute(self)
        return self._shared[key]


class DatabaseKinematics:
    """Positions (m, :func:`animsynth.compare.measures.pose.positions`) and facing
    (:func:`~animsynth.compare.measures.pose.facing`) of each database motion, computed once per job for every clip and
    metric that reads them.

    A database clip is shared by several held-out clips (leave one out) and read by the run's L2P statistics and
    by each clip's reference: calling an instance with a motion returns its ``(positions, facing)``, computed on
    the first call (keyed by the motion's name, checked by its values and its skeleton: two motions of one name and
    other values or bones are computed apart). The arrays are read-only (a metric that wrote into them would change the others').
    """

    def __init__(self, roles: dict | None = None):
        self.roles = roles
        self._memo: dict[str, tuple] = {}

    def __call__(self, motion: Motion) -> tuple[np.ndarray, np.ndarray]:
        from . import measures as M

        hit = self._memo.get(motion.name)
        if (hit is not None and (hit[0] is motion.values or np.array_equal(hit[0], motion.values))
                and _same_skeleton(hit[3], motion.skeleton)):
            return hit[1], hit[2]
        pos, fwd = M.positions(motion), M.facing(motion, self.roles)
        pos.setflags(write=False)
        fwd.setflags(write=False)
        if hit is None:
            self._memo[motion.name] = (motion.values, pos, fwd, motion.skeleton)
        return pos, fwd


class References:
    """The database side of every clip one job scores, for all its rows: one :class:`DatabaseKinematics` per
    joint-role mapping, and one :class:`Reference` per clip, ``compare.metrics`` block and joint roles
    (:func:`reference`, made on the first request).

    A reference depends on its clip, the metrics block and the roles, never on the generator: the rows of one
    method that run in one workflow job (Delaunay and k-NN, the three motion-matching rows, ...) and a row's two
    tracks read the first request's. A clip is known by its identity, so the rows must be given the same clip
    objects (one :func:`animsynth.compare.protocol.load_clips` per job).

    Calling an instance, ``refs(clip, mcfg, roles)``, gives the reference of that clip (:func:`reference` with the
    job's kinematics, made on the first call).

    Parameters of a call
    --------------------
    clip : Clip, one of the job's clips (the same object for every row)
    mcfg : dict, the ``compare.metrics`` block
    roles : dict or None, joint-role overrides (config ``joint_roles``)
    """

    def __init__(self):
        self._kin: dict[str, DatabaseKinematics] = {}
        self._refs: dict[tuple, tuple] = {}

    @staticmethod
    def _key(value) -> str:
        import json

        return json.dumps(value, sort_keys=True, default=repr)

    def kinematics(self, roles: dict | None) -> DatabaseKinematics:
        """The job's :class:`DatabaseKinematics` for the joint roles ``roles``."""
        key = self._key(roles)
        if key not in self._kin:
            self._kin[key] = DatabaseKinematics(roles)
        return self._kin[key]

    def __call__(self, clip: Clip, mcfg: dict, roles: dict | None = None) -> Reference:
        """The reference of ``clip`` under ``mcfg`` and ``roles``, made on the first call."""
        key = (id(clip), self._key(mcfg), self._key(roles))
        hit = self._refs.get(key)
        if hit is None or hit[0] is not clip:  # the clip object is kept, so its id names it while it is here
            hit = self._refs[key] = (clip, reference(clip, mcfg, roles, None, self.kinematics(roles)))
        return hit[1]


def _same_skeleton(a, b) -> bool:
    """Whether two skeletons pose alike: the same object, or the same serialised skeleton (every joint's offset,
    tail, axis and DOFs and the unit: :meth:`animsynth.skeleton.Skeleton.to_json`). A database trial read onto
    another held-out trial's rest pose keeps its values but not its bones."""
    return a is b or a.to_json() == b.to_json()


def run_stats(clips: list[Clip], mcfg: dict, roles: dict | None = None,
              kin: DatabaseKinematics | None = None) -> np.ndarray:
    """LAFAN1's position statistics (std, (J, 3)) over the databases of ``clips``: every distinct database clip
    (by name), as LAFAN1 normalises by its whole training set (the comparison passes one clip: its own database). Windows of
    ``context + length`` frames (the longest of the run's clips; shorter if a database clip is shorter),
    every ``compare.metrics.l2p_stride`` frames, aligned at the last context frame (``kin``: the job's
    :class:`DatabaseKinematics`, made here if not given)."""
    from . import measures as M

    kin = kin or DatabaseKinematics(roles)

    seen = {}
    for c in clips:
        for d in c.database:
            seen.setdefault(d.name, d)
    db = list(seen.values())
    joints = {len(d.skeleton.joints) for d in db}
    if len(joints) != 1:
        raise ValueError(f"the run's database clips have different joint counts ({sorted(joints)}): no common L2P "
                         "statistics")
    window = min(max(c.context + c.length for c in clips), min(d.n_frames for d in db))
    context = min(min(c.context for c in clips), window)
    pos, fwd = zip(*(kin(d) for d in db))
    return M.position_stats(pos, fwd, window, int(mcfg["l2p_stride"]), context)[1]


def reference(clip: Clip, mcfg: dict, roles: dict | None = None, std: np.ndarray | None = None,
              kin: DatabaseKinematics | None = None) -> Reference:
    """The database side of every metric of ``clip`` (``mcfg``: the ``compare.metrics`` block; ``std``: the
    run's L2P statistics, :func:`run_stats`; ``None``: this clip's database only; ``kin``: the job's
    :class:`DatabaseKinematics`, made here if not given).

    Forward kinematics runs once per database motion of the job (``kin``) and once for the held-out clip
    (positions and the ground truth's world rotations from one pass)."""
    from . import measures as M

    kin = kin or DatabaseKinematics(roles)
    sk = clip.held_out.skeleton
    fps = clip.held_out.fps
    foot = M.foot_indices(sk, roles)
    db_pos, db_fwd = (list(x) for x in zip(*(kin(d) for d in clip.database)))
    floor = (M.floor_height(db_pos, foot, float(mcfg["floor_percentile"])) if mcfg["floor_m"] is None
             else float(mcfg["floor_m"]))
    if std is None:
        window = min(clip.context + clip.length, max(p.shape[0] for p in db_pos))
        std = M.position_stats(db_pos, db_fwd, window, int(mcfg["l2p_stride"]), min(clip.context, window))[1]
    # the held-out clip's positions and the world rotations of the frames after the start (the ground truth's)
    held_pos, truth_q = M.positions_and_quaternions(sk, clip.held_out.values, start=clip.context)
    truth = slice(clip.context, clip.context + clip.length)
    truth_q = truth_q[:clip.length]
    held_fwd = M.facing(clip.held_out, roles)
    return Reference(foot, floor, M.jump_reference(db_pos, fps), std,
                     [M.pose_features(p, f) for p, f in zip(db_pos, db_fwd)],
                     held_pos[truth], truth_q, held_fwd[clip.context - 1], M.capture_max_jumps(held_pos, fps),
                     db_pos=db_pos, held_pos=held_pos, held_facing=held_fwd)


def score(clip: Clip, ref: Reference, motion: Motion, generator: str, mcfg: dict, roles: dict | None = None,
          track: str = "short", needs=None, entry_seam: bool = True) -> tuple[dict, np.ndarray]:
    """Every metric of ``track`` that one generated motion gives; returns the row and its pose features.

    Parameters
    ----------
    clip : Clip, the held-out clip the motion continues
    ref : Reference, the clip's database side (:func:`reference`)
    motion : Motion, the generated frames (without the start)
    generator : str, its name
    mcfg : the ``compare.metrics`` block
    roles : joint-role overrides
    track : ``"short"`` (the columns of ``metrics.csv``) or ``"long"``: the records computed on it
        (:func:`~animsynth.compare.measures.metric_table.on_track`)
    needs : the needs available (keys of :data:`~animsynth.compare.measures.metric_table.NEEDS`; ``None``: every
        need of one motion, :data:`~animsynth.compare.measures.metric_table.MOTION_NEEDS`): a record whose need is
        not among them is NaN, its computation not called
    entry_seam : whether the entry (generated frame 0) is a seam: the generator's declared
        :attr:`animsynth.generator.Generator.entry_seam` (every generator but the replay of the capture)

    Returns
    -------
    row : dict, one value per record of the track but those a run gives (``needs`` ``"generator"``, ``"seeds"``:
        :func:`run_values`)
    features : ndarray (T, 3 J), the generated frames' pose features (the runner's spread over seeds reads them)

    The records are computed grouped by what they need; a computation that fills several records is called once,
    and the intermediates are computed once per motion (:class:`~.measures.scored.ScoredMotion`). The start and
    the generated frames are scored together where a measure needs frames before the first generated one (foot
    speed at the first frame, the jump at the entry seam).
    """
    from .measures.scored import ScoredMotion

    s = ScoredMotion(clip, ref, motion, generator, mcfg, roles, entry_seam)
    have = MOTION_NEEDS if needs is None else tuple(needs)
    row: dict = {}
    for need in MOTION_NEEDS:
        records = [m for m in on_track(track) if m.needs == need]
        row.update(_values(records, s) if need in have else dict.fromkeys((m.name for m in records), np.nan))
    return row, s.features


def run_values(generator, features, track: str = "short") -> dict:
    """The values of the records a run gives, not one motion (``needs`` ``"generator"`` and ``"seeds"``): the same
    for every seed's row of one clip and generator.

    Parameters
    ----------
    generator : the fitted generator (its :meth:`~animsynth.generator.Generator.run_notes`)
    features : list of ndarray, each seed's pose features (the second value :func:`score` returns), in seed order
    track : the track whose records are computed

    Returns
    -------
    dict, one value per record of ``track`` whose need is in
    :data:`~animsynth.compare.measures.metric_table.RUN_NEEDS` (``transitions_kept``, ``seed_diversity_m``)
    """
    from .measures.scored import RunOutputs

    return _values([m for m in on_track(track) if m.needs in RUN_NEEDS], RunOutputs(generator, list(features)))


def _values(records, subject) -> dict:
    """The values of ``records``: each computation they name called once with ``subject`` (a ScoredMotion or
    RunOutputs), its value for every record that names it taken."""
    out = {}
    for path, names in by_computation(records).items():
        got = computation(path)(subject)
        missing = [n for n in names if n not in got]
        if missing:
            raise KeyError(f"the computation {path} gives no value for the metric(s) {missing} that name it")
        out.update((n, got[n]) for n in names)
    return out


# ----------------------------------------------------------------------------- motion files


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
    """Every metric of :func:`score` that a motion file gives, one row per generated motion.

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
    DataFrame with the columns of ``compare/metrics.csv`` (:data:`~animsynth.compare.measures.metric_table.KEY_COLUMNS`,
    :data:`~animsynth.compare.measures.metric_table.METRIC_NAMES`, ``note``): ``generator`` the name, ``protocol`` "scored file",
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
    have = [n for n in MOTION_NEEDS if n not in PER_RUN]  # a file reports no seams
    note = ""
    if not db:
        have.remove("database")
        if mcfg.get("floor_m") is None:
            have.remove("floor")
            note = "no database: foot skating (no floor height), L2P, coverage and novelty empty"
        else:
            note = "no database: L2P, coverage and novelty empty"
    roles = None
    if "floor" not in have:  # no foot metric: the feet need no joint (the columns are left empty)
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
                        Motion(np.asarray(m.values[context:], float), sk, fps, name), name, mcfg, roles, needs=have)
        row.update(dict.fromkeys(names_needing(*RUN_NEEDS), np.nan))
        rows.append({"clip": reference_name, "group": "", "protocol": "scored file", "generator": name, "seed": "",
                     **row, "note": note})
    return pd.DataFrame(rows, columns=KEY_COLUMNS + METRIC_NAMES + ["note"])


def _check_start(m: Motion, ref: Motion, context: int, name: str, reference_name: str) -> None:
    """Warn when the first ``context`` frames of ``m`` are not the reference's start (the reference's are used)."""
    from .measures import positions

    a = positions(Motion(np.asarray(m.values[:context], float), m.skeleton, m.fps))
    b = positions(Motion(np.asarray(ref.values[:context], float), ref.skeleton, ref.fps))
    gap = float(np.max(np.linalg.norm(a - b, axis=-1)))
    if gap > 0.01:
        log.warning("%s: its first %d frames are not the start of %s (joints up to %.3g m apart); scored from the "
                    "reference's start, as the comparison scores every generator", name, context, reference_name,
                    gap)
