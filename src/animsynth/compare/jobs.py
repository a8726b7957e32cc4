"""Workflow steps of the compare family (the scripts in workflow/scripts only call these).

Protocol (docs/compare.md, "Protocol"):

* Every trial is resampled to the working rate ``compare.fps`` by keeping every n-th frame
  (n = trial fps / working fps, an integer).
* **Leave one out** (each Gauch & Peters subset of ``compare.subsets``): every trial is held out
  once; the database is the subset's other trials.
* **Temporal split** (each re-sequencing clip of ``compare.resequencing``): the last part of the
  clip is held out (``compare.holdout_fraction`` of it, at least ``context + min_length``
  frames); the database is the frames before it.
* For the generators that run at a native rate (fairmotion's 60 fps, ``compare.fairmotion.native_fps``),
  every clip also carries its database and start at that rate, taken by frame step from the trials too
  (:class:`NativeRate`): the same instants as the working-rate frames and the real frames between them. A
  trial whose rate is not a whole multiple of the native rate has none (a log line and the clips table's
  ``note`` say so), and the generator upsamples the working-rate clips instead.
* The start is the held-out clip's first ``compare.context`` frames; every generator makes
  ``length = min(compare.length, held-out frames - context)`` frames from it; the ground truth
  is the held-out frames that follow the start (the ``replay`` row).
* Every clip runs ``compare.seeds`` seeds, seed ``i`` of clip ``c`` derived from the master seed,
  ``compare.seed``, ``c`` and ``i`` (the same for every generator, so generators are compared
  seed by seed).

Every workflow step is a function here: :func:`run_job` (one generator over every clip), :func:`tables_job`
(the family's tables, built by :mod:`animsynth.compare.tables` and :mod:`animsynth.compare.verdicts`) and
:func:`sweep_job` (the transition budget sweep).

Files between steps: ``compare/clips.npz`` (every clip's database, held-out clip and length:
:func:`save_clips` / :func:`load_clips`), per generator ``compare/runs/<generator>.csv`` (metrics,
one row per clip x seed), ``<generator>_timing.csv`` (build and generation cost, one row per clip)
and ``<generator>_showcase.npz`` (the showcase clip's start and generated frames).
"""

from __future__ import annotations

import json
import logging
import os
import sys
import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..atomic import atomic_path
from ..config import derive_seed
from ..motion import Motion
from ..skeleton import Skeleton
from .generators import make_generator
from .metrics import METRIC_NAMES, SENSITIVITY_SPEEDS

log = logging.getLogger("animsynth.compare.jobs")

KEY_COLUMNS = ["clip", "group", "protocol", "generator", "seed"]
TIMING_COLUMNS = ["generator", "clip", "database_frames", "build_cpu_s", "build_wall_s", "generate_cpu_s",
                  "generate_wall_s", "frames_generated", "peak_rss_mb"]


# ----------------------------------------------------------------------------- clips


@dataclass
class NativeRate:
    """One clip's database and start at a generator's native rate (by frame step from the trials).

    Attributes
    ----------
    fps : float, the native rate (a whole multiple ``k`` of the working rate)
    database : list of Motion at ``fps``, the clip's database clips in the same order (native frame ``i * k`` is
        working frame ``i``; the ``k - 1`` real frames after each are kept); empty when the trials' rate is not a
        whole multiple of ``fps`` (``note`` says so)
    start : Motion or None, the start at ``fps``: ``(context - 1) * k + 1`` frames, its last frame the working
        start's last
    note : str, why there is no native database ("" when there is one)
    """

    fps: float
    database: list
    start: Motion | None
    note: str = ""


@dataclass
class Clip:
    """One held-out clip with its database (all at the working rate).

    Attributes
    ----------
    clip : str, ``<group>/<trial>`` (e.g. ``w1/35_16``, ``walk/35_01``)
    group : str, the subset or re-sequencing dataset
    protocol : str, ``leave one out`` or ``temporal split``
    trial : str, the held-out trial
    held_out : Motion, the held-out frames (the start, then the ground truth)
    database : list of Motion
    context, length : int, start frames and generated frames
    database_names : list of str
    native : list of NativeRate, the database and start at each native rate of ``compare``'s generators
    """

    clip: str
    group: str
    protocol: str
    trial: str
    held_out: Motion
    database: list
    context: int
    length: int
    database_names: list = field(default_factory=list)
    native: list = field(default_factory=list)

    def at_rate(self, fps: float) -> NativeRate | None:
        """The clip at the native rate ``fps`` (``None``: not prepared for that rate)."""
        for n in self.native:
            if np.isclose(n.fps, float(fps)):
                return n
        return None

    @property
    def start(self) -> Motion:
        h = self.held_out
        return Motion(np.asarray(h.values[:self.context], float), h.skeleton, h.fps, f"{self.clip}:start")

    @property
    def future(self) -> Motion:
        """Every held-out frame after the start (the truth and what follows it): the query trajectory of a
        generator whose ``query`` is ``"future_trajectory"``."""
        h = self.held_out
        return Motion(np.asarray(h.values[self.context:], float), h.skeleton, h.fps, f"{self.clip}:future")

    @property
    def truth(self) -> Motion:
        h = self.held_out
        return Motion(np.asarray(h.values[self.context:self.context + self.length], float), h.skeleton, h.fps,
                      f"{self.clip}:truth")


def resample(motion: Motion, fps: float, key: str = "compare.fps") -> Motion:
    """Every n-th frame of ``motion`` for the working rate ``fps`` (n = motion.fps / fps, an integer)."""
    ratio = float(motion.fps) / float(fps)
    step = int(round(ratio))
    if step < 1 or abs(ratio - step) > 1e-6:
        raise ValueError(f"config key '{key}': {fps} fps is not the rate of trial {motion.name!r} "
                         f"({motion.fps} fps) divided by a whole number")
    return Motion(np.asarray(motion.values[::step], float), motion.skeleton, float(motion.fps) / step, motion.name)


def prepare_clips(trials: dict, subsets: dict, resequencing: dict, cfg: dict) -> list[Clip]:
    """Every held-out clip of the protocol.

    Parameters
    ----------
    trials : {trial id: Motion} (parsed trials at their own rate)
    subsets : {group: [trial ids]}, leave one out within each group: the subsets of ``compare.subsets`` and the
        sets of ``compare.subjects`` with two or more trials (:func:`animsynth.compare.settings.groups`)
    resequencing : {group: trial id}, a temporal split of each: the clips of ``compare.resequencing`` and the
        sets of ``compare.subjects`` with one trial
    cfg : the ``compare`` config block (``fps``, ``context``, ``length``, ``min_length``,
        ``holdout_fraction``) and ``native_fps`` (optional: the native rates to prepare,
        :func:`animsynth.compare.settings.native_rates`)

    Every trial's angles are made continuous at its own rate, before resampling
    (:func:`animsynth.retarget.unwrap_angles`: a fast joint may turn by more than 180 degrees between two
    working frames without wrapping, so the working frames are not unwrapped again). A leave-one-out clip's
    database trials are put on the held-out trial's skeleton (:func:`animsynth.retarget.retarget`: the same
    skeleton is kept as it is; other rest offsets are retargeted with a logged warning, or refused naming
    both trials) and every one of them, the held-out trial too, on the angle branch of the database's first
    trial (:func:`animsynth.retarget.align_angle_branches`). A temporal split's database and held-out part
    are one continuous trial and stay as they are. The clips at a native rate are made the same way from
    the unwrapped trials.
    """
    from ..retarget import align_angle_branches, unwrap_angles
    from ..retarget import retarget

    fps, context = float(cfg["fps"]), int(cfg["context"])
    length, min_length = int(cfg["length"]), int(cfg["min_length"])
    # unwrapped at the capture's own rate: a fast joint may move more than 180 degrees between working frames
    full = {t: unwrap_angles(m, f"trial {t}") for t, m in trials.items()}
    work = {t: resample(m, fps) for t, m in full.items()}
    rates = sorted({float(r) for r in cfg.get("native_fps") or []} - {fps})
    native = {}  # {(rate, trial): (Motion at the rate, k) or the reason there is none}
    for r in rates:
        k = r / fps
        for t, m in full.items():
            step = float(m.fps) / r
            if abs(k - round(k)) > 1e-6 or round(k) < 1:
                why = f"{r:g} fps is not a whole multiple of the working rate {fps:g} fps"
            elif abs(step - round(step)) > 1e-6 or round(step) < 1:
                why = f"trial {t!r} at {float(m.fps):g} fps is not a whole multiple of {r:g} fps"
            else:
                native[r, t] = (resample(m, r, key="compare.fairmotion.native_fps"), int(round(k)))
                continue
            native[r, t] = (f"{why}: its generators upsample the {fps:g} fps clips to {r:g} fps")
            log.info("clips: no %g fps database from trial %s (%s)", r, t, native[r, t])
    clips = []

    def at_rates(trial: str, db_trials: list, db_names: list, first: int, n_db: int | None) -> list:
        """The clip at every native rate: the held-out trial's start from working frame ``first``, the database
        trials (the whole trials; ``n_db``: the held-out trial's first ``n_db`` working frames)."""
        out = []
        for r in rates:
            got = [native[r, t] for t in [trial] + db_trials]
            why = next((g for g in got if isinstance(g, str)), "")
            if why:
                out.append(NativeRate(r, [], None, why))
                continue
            (held, k), dbs = got[0], got[1:]
            if n_db is None:  # as the working-rate clip: on the held-out trial's skeleton and the database's branch
                db = [Motion(np.asarray(retarget(m, held.skeleton, f"trial {o}", f"trial {trial}").values, float),
                             held.skeleton, r, name) for (m, _k), o, name in zip(dbs, db_trials, db_names)]
                db = [align_angle_branches(d, db[0]) for d in db]
                # the whole held-out trial shifted, as at the working rate, then its start cut: the same branch
                held = align_angle_branches(held, db[0])
            vals = np.asarray(held.values, float)
            start = Motion(vals[first * k:first * k + (context - 1) * k + 1], held.skeleton, r,
                           f"{trial}:start@{r:g}")
            if n_db is not None:
                db = [Motion(vals[:n_db * k], held.skeleton, r, db_names[0])]
            out.append(NativeRate(r, db, start))
        return out

    def add(clip_id, group, protocol, trial, held, db, db_names, nat):
        n_after = held.n_frames - context
        L = min(length, n_after)
        if L < min_length:
            raise ValueError(f"clip {clip_id}: the held-out part has {held.n_frames} frames at {fps:g} fps, "
                             f"{context} of them the start, leaving {n_after} < {min_length} to generate "
                             "(config keys 'compare.context', 'compare.min_length', 'compare.fps')")
        for d in db:
            if d.n_frames < max(4, context):
                raise ValueError(f"clip {clip_id}: database clip {d.name!r} has {d.n_frames} frames at {fps:g} fps "
                                 f"(need >= {max(4, context)}; config keys 'compare.fps', 'compare.holdout_fraction')")
        clips.append(Clip(clip_id, group, protocol, trial, held, db, context, L, db_names, nat))

    for group, ids in subsets.items():
        if len(ids) < 2:
            raise ValueError(f"config key 'compare.subsets': subset {group!r} needs >= 2 trials for leave one out")
        for t in ids:
            others = [o for o in ids if o != t]
            db = [resample(retarget(full[o], full[t].skeleton, f"trial {o}", f"trial {t}"), fps) for o in others]
            db = [align_angle_branches(d, db[0]) for d in db]
            add(f"{group}/{t}", group, "leave one out", t, align_angle_branches(work[t], db[0]), db, others,
                at_rates(t, others, [work[o].name for o in others], 0, None))
    for group, t in resequencing.items():
        m = work[t]
        n = m.n_frames
        hold = max(int(round(float(cfg["holdout_fraction"]) * n)), context + min_length)
        if n - hold < max(4, context):
            raise ValueError(f"clip {group}/{t}: {n} frames at {fps:g} fps leave {n - hold} for the database "
                             "after the held-out part (config keys 'compare.holdout_fraction', 'compare.length')")
        db = Motion(m.values[:n - hold], m.skeleton, m.fps, f"{t}[0:{n - hold}]")
        held = Motion(m.values[n - hold:], m.skeleton, m.fps, f"{t}[{n - hold}:{n}]")
        add(f"{group}/{t}", group, "temporal split", t, held, [db], [f"{t} frames 0-{n - hold - 1}"],
            at_rates(t, [], [db.name], n - hold, n - hold))
    return clips


def save_clips(path, clips: list[Clip]) -> None:
    """Store clips in one ``.npz``: a JSON manifest, one array per motion, one JSON per skeleton."""
    arrays, skeletons, manifest = {}, {}, []
    for i, c in enumerate(clips):
        sk = c.held_out.skeleton.to_json()
        key = skeletons.setdefault(sk, f"skeleton{len(skeletons)}")
        arrays[f"c{i}_held"] = np.asarray(c.held_out.values, float)
        for j, d in enumerate(c.database):
            arrays[f"c{i}_db{j}"] = np.asarray(d.values, float)
        nat = []
        for r, n in enumerate(c.native):
            for j, d in enumerate(n.database):
                arrays[f"c{i}_n{r}_db{j}"] = np.asarray(d.values, float)
            if n.start is not None:
                arrays[f"c{i}_n{r}_start"] = np.asarray(n.start.values, float)
            nat.append({"fps": float(n.fps), "database": [d.name for d in n.database], "note": n.note,
                        "start": None if n.start is None else n.start.name})
        manifest.append({"clip": c.clip, "group": c.group, "protocol": c.protocol, "trial": c.trial,
                         "context": c.context, "length": c.length, "fps": c.held_out.fps, "skeleton": key,
                         "held_name": c.held_out.name, "database": [d.name for d in c.database],
                         "database_names": list(c.database_names), "native": nat})
    for sk, key in skeletons.items():
        arrays[key] = np.array(sk)
    arrays["manifest"] = np.array(json.dumps(manifest))
    with atomic_path(path, suffix=".npz") as tmp:
        np.savez_compressed(tmp, **arrays)


def load_clips(path) -> list[Clip]:
    """The clips stored by :func:`save_clips` (a file without native-rate clips, written before they existed, loads
    with ``native`` empty)."""
    with np.load(path, allow_pickle=False) as z:
        manifest = json.loads(str(z["manifest"]))
        sks = {k: Skeleton.from_json(str(z[k])) for k in z.files if k.startswith("skeleton")}
        clips = []
        for i, m in enumerate(manifest):
            sk, fps = sks[m["skeleton"]], float(m["fps"])
            held = Motion(np.array(z[f"c{i}_held"]), sk, fps, m["held_name"])
            db = [Motion(np.array(z[f"c{i}_db{j}"]), sk, fps, name) for j, name in enumerate(m["database"])]
            nat = []
            for r, n in enumerate(m.get("native", [])):
                nfps = float(n["fps"])
                ndb = [Motion(np.array(z[f"c{i}_n{r}_db{j}"]), sk, nfps, name) for j, name in enumerate(n["database"])]
                start = None if n["start"] is None else Motion(np.array(z[f"c{i}_n{r}_start"]), sk, nfps, n["start"])
                nat.append(NativeRate(nfps, ndb, start, n["note"]))
            clips.append(Clip(m["clip"], m["group"], m["protocol"], m["trial"], held, db, int(m["context"]),
                              int(m["length"]), list(m["database_names"]), nat))
    return clips


def clips_table(clips: list[Clip]) -> pd.DataFrame:
    """The protocol as a table: one row per held-out clip."""
    return pd.DataFrame([{
        "clip": c.clip, "group": c.group, "protocol": c.protocol, "held_out": c.held_out.name,
        "database": " ".join(c.database_names), "database_frames": int(sum(d.n_frames for d in c.database)),
        "held_out_frames": c.held_out.n_frames, "fps": c.held_out.fps, "context": c.context, "length": c.length,
        "native_fps": " ".join(f"{n.fps:g}" for n in c.native if n.database),
        "note": "; ".join(n.note for n in c.native if n.note),
    } for c in clips])


# ----------------------------------------------------------------------------- scoring


@dataclass
class Reference:
    """What scoring needs from one clip's database (computed once per clip).

    Attributes
    ----------
    foot_idx : int array, the foot joints
    floor : float, the floor height (m)
    jumps : metrics.JumpReference, the database's own frame-to-frame jumps
    std : ndarray (J, 3), LAFAN1 position statistics of the whole run's database windows (:func:`run_stats`)
    capture_max : (float, float), the held-out capture's largest velocity and acceleration jump
    features : list of ndarray, the database clips' pose features
    truth_pos, truth_q : the ground truth's positions (m) and global quaternions
    truth_forward : ndarray (2,), the ground truth's facing at the last start frame
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


class DatabaseKinematics:
    """Positions (m, :func:`animsynth.compare.metrics.positions`) and facing (:func:`~animsynth.compare.metrics.facing`)
    of each database motion, computed once per job for every clip and metric that reads them.

    A database clip is shared by several held-out clips (leave one out) and read by the run's L2P statistics and
    by each clip's reference: calling an instance with a motion returns its ``(positions, facing)``, computed on
    the first call (keyed by the motion's name, checked by its values: two motions of one name and other values
    are computed apart). The arrays are read-only (a metric that wrote into them would change the others').
    """

    def __init__(self, roles: dict | None = None):
        self.roles = roles
        self._memo: dict[str, tuple] = {}

    def __call__(self, motion: Motion) -> tuple[np.ndarray, np.ndarray]:
        from . import metrics as M

        hit = self._memo.get(motion.name)
        if hit is not None and (hit[0] is motion.values or np.array_equal(hit[0], motion.values)):
            return hit[1], hit[2]
        pos, fwd = M.positions(motion), M.facing(motion, self.roles)
        pos.setflags(write=False)
        fwd.setflags(write=False)
        if hit is None:
            self._memo[motion.name] = (motion.values, pos, fwd)
        return pos, fwd


def run_stats(clips: list[Clip], mcfg: dict, roles: dict | None = None,
              kin: DatabaseKinematics | None = None) -> np.ndarray:
    """LAFAN1's position statistics (std, (J, 3)) over the whole run's database: every distinct database clip
    of every held-out clip (by name), as LAFAN1 normalises by its whole training set. Windows of
    ``context + length`` frames (the longest of the run's clips; shorter if a database clip is shorter),
    every ``compare.metrics.l2p_stride`` frames, aligned at the last context frame (``kin``: the job's
    :class:`DatabaseKinematics`, made here if not given)."""
    from . import metrics as M

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


def _joint_count(clip: Clip) -> int:
    return len(clip.held_out.skeleton.joints)


def run_stats_by_skeleton(clips: list[Clip], mcfg: dict, roles: dict | None = None,
                          kin: DatabaseKinematics | None = None) -> dict:
    """:func:`run_stats` per skeleton: {joint count: std (J, 3)}. A run of one skeleton (CMU, the demo) has one
    entry, the whole run's database; a run mixing skeletons (a user's BVH files of several sources) normalises
    each clip's L2P by the database clips of its own skeleton, logged (positions of different joint sets have no
    common statistics)."""
    groups: dict[int, list[Clip]] = {}
    for c in clips:
        groups.setdefault(_joint_count(c), []).append(c)
    if len(groups) > 1:
        log.warning("the run mixes skeletons of %s joints: each clip's L2P is normalised by the database clips of "
                    "its own skeleton", sorted(groups))
    kin = kin or DatabaseKinematics(roles)
    return {n: run_stats(cs, mcfg, roles, kin) for n, cs in groups.items()}


def reference(clip: Clip, mcfg: dict, roles: dict | None = None, std: np.ndarray | None = None,
              kin: DatabaseKinematics | None = None) -> Reference:
    """The database side of every metric of ``clip`` (``mcfg``: the ``compare.metrics`` block; ``std``: the
    run's L2P statistics, :func:`run_stats`; ``None``: this clip's database only; ``kin``: the job's
    :class:`DatabaseKinematics`, made here if not given).

    Forward kinematics runs once per database motion of the job (``kin``) and once for the held-out clip
    (positions and the ground truth's world rotations from one pass)."""
    from . import metrics as M

    from ..kinematics import forward_kinematics

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
    # one pass over the held-out clip: its positions (M.positions) and the ground truth's world rotations
    # (M.global_quaternions of the frames after the start)
    held_pos, W = forward_kinematics(sk, clip.held_out.values, ends=True, world_rotations=True)
    held_pos = held_pos * float(sk.length_to_m)
    truth = slice(clip.context, clip.context + clip.length)
    truth_q = M.align_quaternions(np.stack([r.as_quat() for r in W], axis=1)[truth])
    held_fwd = M.facing(clip.held_out, roles)
    return Reference(foot, floor, M.jump_reference(db_pos, fps), std,
                     [M.pose_features(p, f) for p, f in zip(db_pos, db_fwd)],
                     held_pos[truth], truth_q, held_fwd[clip.context - 1], M.capture_max_jumps(held_pos, fps))


def score(clip: Clip, ref: Reference, motion: Motion, generator: str, mcfg: dict,
          roles: dict | None = None) -> tuple[dict, np.ndarray]:
    """Every per-seed metric of one generated motion; returns the row and its pose features.

    The start and the generated frames are scored together where a measure needs frames before the
    first generated one (foot speed at the first frame, the jump at the entry seam); the entry
    (generated frame 0) is a seam for every generator but ``replay``.
    """
    from . import metrics as M

    from ..kinematics import forward_kinematics

    fps = float(motion.fps)
    start = clip.start
    joined = Motion(np.vstack([start.values, motion.values]), motion.skeleton, fps, motion.name)
    c = clip.context
    # one forward kinematics pass for positions (M.positions) and world rotations (M.global_quaternions)
    pos, W = forward_kinematics(joined.skeleton, joined.values, ends=True, world_rotations=True)
    pos = pos * float(joined.skeleton.length_to_m)
    q = M.align_quaternions(np.stack([r.as_quat() for r in W], axis=1)[c:])
    gen_pos = pos[c:]
    seams = np.asarray(motion.meta.get("seams", []), np.int64)
    if generator != "replay":
        seams = np.union1d(seams, [0])
    row = {}
    height, speed = float(mcfg["contact_height_m"]), float(mcfg["skate_speed_m_s"])
    row.update(M.foot_skating(pos[c - 1:], fps, ref.foot_idx, height, speed, ref.floor))
    gmd_feet = ref.foot_idx[[0, 2]]  # left_ankle, right_ankle: the balls of the feet
    row["skating_ratio_gmd"] = M.skating_ratio(pos[c - 1:], fps, gmd_feet, height, speed, ref.floor)
    for v in SENSITIVITY_SPEEDS:
        row[f"skate_share_at_{v:g}"] = M.foot_skating(pos[c - 1:], fps, ref.foot_idx, height, v,
                                                      ref.floor)["skate_share"]
        row[f"skating_ratio_gmd_at_{v:g}"] = M.skating_ratio(pos[c - 1:], fps, gmd_feet, height, v, ref.floor)
    # skating near seams: frames within transition_window of a seam, pooled over seams
    w = int(mcfg["transition_window"])
    n_contact = n_skate = 0.0
    for s in seams:
        lo, hi = c + max(int(s) - w, 0), c + min(int(s) + w, motion.n_frames - 1)
        part = M.foot_skating(pos[lo - 1:hi + 1], fps, ref.foot_idx, height, speed, ref.floor)
        nc = part["contact_share"] * (hi - lo + 1) * len(ref.foot_idx)
        n_contact += nc
        n_skate += (part["skate_share"] * nc) if nc else 0.0
    row["transition_skate_share"] = n_skate / n_contact if n_contact else np.nan
    jumps = M.seam_jumps(pos, fps, seams + c, ref.jumps)
    row.update(M.frame_jumps(pos, fps, c, ref.capture_max))
    row["n_seams"] = int(seams.size)
    row["seams_per_s"] = seams.size / (motion.n_frames / fps)
    for k in ("velocity_jump", "velocity_jump_ratio", "velocity_jump_pct", "accel_jump", "accel_jump_ratio",
              "accel_jump_pct"):
        row[k] = jumps[k]
    row["ldlj"] = M.ldlj(gen_pos, fps)
    row["sparc"] = M.sparc(gen_pos, fps)
    row["l2p"] = M.l2p(gen_pos, ref.truth_pos, ref.std, forward=ref.truth_forward)
    row["l2p_m"] = M.l2p(gen_pos, ref.truth_pos, None)
    row["l2q"] = M.l2q(q, ref.truth_q)
    row["npss"] = M.npss(q, ref.truth_q, spectrum=mcfg["npss_spectrum"], quaternions=True)
    feats = M.pose_features(gen_pos, M.facing(joined, roles)[c:])
    win = M.window_scores(feats, ref.features, min(int(mcfg["window"]), motion.n_frames),
                          float(mcfg["coverage_threshold_m"]))
    row["coverage"] = win["coverage"]
    row["local_diversity_m"] = win["local_diversity"]
    row.update(M.novelty(feats, ref.features, float(mcfg["copy_tolerance_m"])))
    return row, feats


# ----------------------------------------------------------------------------- one generator over every clip


def cpu_seconds() -> float:
    """CPU seconds (user + system) of this process and of its finished child processes (fairmotion builds
    its graph in a multiprocessing pool)."""
    import resource

    c = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + c.ru_utime + c.ru_stime


def peak_rss_mb() -> float:
    """The largest resident memory (MB) so far of this process and of its largest finished child process
    (``getrusage``): a generator job's peak, a pool it starts included."""
    import resource

    return max(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
               resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss) / 1024.0


def clip_seeds(master: int, family_seed: int, clip: str, n: int) -> list[int]:
    """The seeds of one clip: the same for every generator."""
    return [derive_seed(master, "compare", family_seed, clip, i) for i in range(int(n))]


def run_generator(clips: list[Clip], generator: str, cfg: dict, master_seed: int, roles: dict | None = None,
                  showcase: tuple[str, int] | None = None):
    """Fit ``generator`` on every clip's database, generate every seed from the clip's start, score.

    Parameters
    ----------
    clips : list of Clip
    generator : a name of :data:`animsynth.compare.generators.GENERATORS`
    cfg : the ``compare`` block (with the re-sequencing study's ``stisomap`` block added)
    master_seed : the config's ``seed``
    roles : joint-role overrides (config ``joint_roles``)
    showcase : (clip id, seed index) whose motion is returned

    Returns
    -------
    metrics : DataFrame, one row per clip x seed (:data:`KEY_COLUMNS` + :data:`METRIC_NAMES` + ``note``):
        a clip whose database the generator cannot be built on (its ``fit`` raises ValueError, e.g. a
        motion graph without transitions) keeps its rows with no values and ``note`` = "not built: <why>"
    timing : DataFrame, one row per clip (:data:`TIMING_COLUMNS`): CPU (:func:`cpu_seconds`, child
        processes included) and wall seconds of the build and of the generation, the job's peak resident
        memory so far (:func:`peak_rss_mb`)
    shown : Motion or None, the showcase clip's start and generated frames joined
        (``meta["context"]``: start frames)

    A user generator (``compare.user_generators``) that fails in any way (:class:`UserGeneratorError`) stops at
    its first failure: one error line, and every row of it empty (:func:`failed_run`).
    """
    from .user import UserGeneratorError, close_processes

    try:
        return _run_generator(clips, generator, cfg, master_seed, roles, showcase)
    except UserGeneratorError as exc:
        return failed_run(clips, generator, cfg, str(exc), showcase)
    finally:
        close_processes()  # a user generator's child process ends with its job


def failed_run(clips: list[Clip], generator: str, cfg: dict, why: str, showcase: tuple[str, int] | None = None):
    """The files of a generator that could not run at all: ``why`` logged as one error line (and printed to
    stderr, the run's console), every clip x seed row with no values and ``note`` = "failed: <why>", every timing
    row empty, and as the showcase the showcase clip's start alone (no generated frame; ``meta["note"]``)."""
    line = " ".join(why.split())
    log.error("%s", line)
    print(f"animsynth: ERROR: {line}", file=sys.stderr)
    rows, trows, shown = [], [], None
    for clip in clips:
        r, t = _empty_rows(clip, generator, int(cfg["seeds"]), f"failed: {line}")
        rows += r
        trows.append(t)
        if showcase is not None and clip.clip == showcase[0]:
            shown = _start_only(clip, generator, f"failed: {line}")
    return (pd.DataFrame(rows, columns=KEY_COLUMNS + METRIC_NAMES + ["note"]), pd.DataFrame(trows, columns=TIMING_COLUMNS),
            shown)


def _start_only(clip: Clip, generator: str, note: str) -> Motion:
    """The showcase of a generator with no motion for the clip: the start alone, ``meta["note"]`` saying why."""
    start = clip.start
    return Motion(np.asarray(start.values, float), start.skeleton, start.fps, f"{generator} {clip.clip}",
                  {"context": clip.context, "seams": np.zeros(0, np.int64), "note": note})


def _empty_rows(clip: Clip, generator: str, n_seeds: int, note: str) -> tuple[list, dict]:
    """The metric rows (one per seed, no values, ``note``) and the timing row (no times) of a clip a generator
    has no motion for."""
    key = {"clip": clip.clip, "group": clip.group, "protocol": clip.protocol, "generator": generator}
    rows = [{**key, "seed": i, **{m: np.nan for m in METRIC_NAMES}, "note": note} for i in range(n_seeds)]
    timing = {"generator": generator, "clip": clip.clip, "database_frames": int(sum(d.n_frames for d in clip.database)),
              "build_cpu_s": np.nan, "build_wall_s": np.nan, "generate_cpu_s": np.nan, "generate_wall_s": np.nan,
              "frames_generated": 0, "peak_rss_mb": peak_rss_mb()}
    return rows, timing


def generation_query(gen, clip: Clip) -> dict:
    """What ``gen.generate`` is given besides the start, length and seed, by its ``query``
    (:class:`animsynth.generator.Generator`): nothing for ``"start"``; ``trajectory`` = the clip's held-out frames
    after the start (:attr:`Clip.future`) for ``"future_trajectory"``."""
    from ..generator import QUERY_FUTURE_TRAJECTORY, QUERY_START

    query = getattr(gen, "query", QUERY_START)
    if query == QUERY_START:
        return {}
    if query == QUERY_FUTURE_TRAJECTORY:
        return {"trajectory": clip.future}
    raise ValueError(f"generator {getattr(gen, 'name', gen)!r}: unknown query {query!r} (one of "
                     f"{[QUERY_START, QUERY_FUTURE_TRAJECTORY]})")


def native_inputs(gen, clip: Clip) -> tuple[dict, dict]:
    """What ``gen.fit`` and ``gen.generate`` are given at the generator's native rate: for a generator with
    ``input_rate = "native"`` (fairmotion's peer) whose ``native_fps`` the clip carries from the source
    (:class:`NativeRate`), ``({"native_clips": database}, {"native_start": start})``; else ``({}, {})`` (the generator
    upsamples the working-rate clips itself)."""
    if getattr(gen, "input_rate", "working") != "native" or getattr(gen, "native_fps", None) is None:
        return {}, {}
    nat = clip.at_rate(float(gen.native_fps))
    if nat is None or not nat.database:
        return {}, {}
    return {"native_clips": nat.database}, {"native_start": nat.start}


def _run_generator(clips, generator, cfg, master_seed, roles, showcase):
    from .cost import guard as cost_guard

    mcfg = cfg["metrics"]
    rows, trows, shown = [], [], None
    kin = DatabaseKinematics(roles)  # each database motion's forward kinematics, once for the whole job
    std = run_stats_by_skeleton(clips, mcfg, roles, kin)
    for clip in clips:
        seeds = clip_seeds(master_seed, cfg["seed"], clip.clip, cfg["seeds"])
        key = {"clip": clip.clip, "group": clip.group, "protocol": clip.protocol, "generator": generator}
        db_frames = int(sum(d.n_frames for d in clip.database))
        # the cost guard (compare.cost_guard; animsynth.compare.cost): an estimate before the build
        level, line = cost_guard(generator, clip.clip, db_frames, cfg, clip.length, len(seeds))
        if level == "refuse":
            log.error("%s", line)
            print(f"animsynth: compare: {line}", file=sys.stderr)
            r, t = _empty_rows(clip, generator, len(seeds), f"not run: {line}")
            rows += r
            trows.append(t)
            if showcase is not None and clip.clip == showcase[0]:
                shown = _start_only(clip, generator, f"not run: {line}")
            continue
        if level == "warn":
            log.warning("%s", line)
        gen = make_generator(generator, cfg, held_out=clip.held_out)
        fit_native, generate_native = native_inputs(gen, clip)
        if hasattr(gen, "child_cpu_s_"):  # a user generator: its log lines name the clip
            gen.clip = clip.clip
        c0, w0 = cpu_seconds(), time.perf_counter()
        try:
            gen.fit(clip.database, **fit_native)
        except ValueError as exc:  # e.g. a motion graph without transitions on a short database
            if showcase is not None and clip.clip == showcase[0]:
                raise ValueError(f"{generator} cannot be built on the showcase clip {clip.clip} ({exc}); choose "
                                 "another with config key 'compare.showcase.clip'") from exc
            log.warning("%s cannot be built on %s: %s", generator, clip.clip, exc)
            r, t = _empty_rows(clip, generator, len(seeds), f"not built: {exc}")
            rows += r
            trows.append(t)
            continue
        build_cpu, build_wall = cpu_seconds() - c0, time.perf_counter() - w0
        # a user generator's child process: its CPU is not among the job's finished children until it ends
        build_cpu += float(getattr(gen, "child_cpu_s_", 0.0))
        start = clip.start
        ref = reference(clip, mcfg, roles, std[_joint_count(clip)], kin)
        gen_cpu = gen_wall = 0.0
        feats = []
        query = {**generation_query(gen, clip), **generate_native}
        for i, s in enumerate(seeds):
            c0, w0 = cpu_seconds(), time.perf_counter()
            m = gen.generate(start, clip.length, s, **query)
            gen_cpu += cpu_seconds() - c0 + float(getattr(gen, "child_cpu_s_", 0.0))
            gen_wall += time.perf_counter() - w0
            row, f = score(clip, ref, m, generator, mcfg, roles)
            row["transitions_kept"] = float(getattr(gen, "n_below_threshold_", np.nan))
            feats.append(f)
            rows.append({**key, "seed": i, **row, "note": ""})
            if showcase is not None and (clip.clip, i) == tuple(showcase):
                seams = np.asarray(m.meta["seams"], np.int64)
                if generator != "replay":  # the entry is a seam, as scored
                    seams = np.union1d(seams, [0])
                shown = Motion(np.vstack([start.values, m.values]), m.skeleton, m.fps, f"{generator} {clip.clip}",
                               {"context": clip.context, "seams": seams + clip.context})
        from .metrics import seed_diversity

        div = seed_diversity(feats)
        for r in rows[-len(seeds):]:
            r["seed_diversity_m"] = div
        trows.append({"generator": generator, "clip": clip.clip, "database_frames": db_frames,
                      "build_cpu_s": build_cpu, "build_wall_s": build_wall, "generate_cpu_s": gen_cpu,
                      "generate_wall_s": gen_wall, "frames_generated": clip.length * len(seeds),
                      "peak_rss_mb": max(peak_rss_mb(), float(getattr(gen, "child_rss_mb_", 0.0)))})
        log.info("%s on %s: build %.3f s CPU, %d seeds x %d frames in %.3f s CPU", generator, clip.clip, build_cpu,
                 len(seeds), clip.length, gen_cpu)
    metrics = pd.DataFrame(rows, columns=KEY_COLUMNS + METRIC_NAMES + ["note"])
    return metrics, pd.DataFrame(trows, columns=TIMING_COLUMNS), shown


# ----------------------------------------------------------------------------- files of one generator job


def save_shown(path, motion: Motion) -> None:
    """Store the showcase motion (start + generated frames) with its start length and seams (and ``meta["note"]``
    when the generator failed: then the start alone)."""
    note = {"note": np.array(motion.meta["note"])} if motion.meta.get("note") else {}  # a run that failed
    with atomic_path(path, suffix=".npz") as tmp:
        np.savez_compressed(tmp, values=np.asarray(motion.values, float), fps=np.float64(motion.fps),
                            name=np.array(motion.name), skeleton=np.array(motion.skeleton.to_json()),
                            context=np.int64(motion.meta["context"]),
                            seams=np.asarray(motion.meta.get("seams", []), np.int64), **note)


def load_shown(path) -> Motion:
    """The motion stored by :func:`save_shown` (``meta``: ``context``, ``seams``, ``note`` when stored)."""
    with np.load(path, allow_pickle=False) as z:
        meta = {"context": int(z["context"]), "seams": np.array(z["seams"])}
        if "note" in z.files:
            meta["note"] = str(z["note"])
        return Motion(np.array(z["values"]), Skeleton.from_json(str(z["skeleton"])), float(z["fps"]), str(z["name"]),
                      meta)


def run_job(clips_path, generator: str, cfg: dict, master_seed: int, roles: dict | None, showcase, out: dict) -> None:
    """One generator over every clip and seed (one workflow job): ``out`` names ``metrics``, ``timing``,
    ``shown`` and ``bvh`` (the showcase as BVH, start frames included; both optional, together)."""
    from threadpoolctl import threadpool_limits

    from ..io.bvh import write_bvh
    from ..tables import write_table

    clips = load_clips(clips_path)
    if generator in (cfg.get("user_generators") or {}):
        # a user generator may not change files in the project (the working directory) or beside this job's outputs
        outs = [os.path.dirname(os.path.abspath(p)) for p in out.values()]
        cfg = dict(cfg, user_guard=list(dict.fromkeys([os.getcwd(), os.path.commonpath(outs)])))
    # one BLAS thread, as the job's threads: 1 (the simplex searches make many small LAPACK calls)
    with threadpool_limits(1, user_api="blas"):
        metrics, timing, shown = run_generator(clips, generator, cfg, master_seed, roles, showcase)
    if "shown" in out and shown is None:
        raise ValueError(f"config key 'compare.showcase': clip {showcase[0]!r} seed {showcase[1]} was not run")
    write_table(metrics, out["metrics"], md=False)
    write_table(timing, out["timing"], md=False)
    if "shown" in out:  # the budget sweep's jobs write metrics and timing only
        save_shown(out["shown"], shown)
        write_bvh(out["bvh"], shown)


# ----------------------------------------------------------------------------- the family's tables


def read_metrics(paths) -> pd.DataFrame:
    """The generator jobs' metrics files as one table (``note``: '' where a row has none)."""
    m = pd.concat([pd.read_csv(p, dtype={"note": str}, keep_default_na=False, na_values=[""]) for p in paths],
                  ignore_index=True)
    m["note"] = m["note"].fillna("")
    return m


def sweep_runs(default: pd.DataFrame, paths, default_budget: float, budgets, generators) -> dict:
    """``{budget: metrics of the graph generators}``: the default run's rows of ``generators`` at
    ``default_budget`` and one metrics file per further budget and generator (``paths``, in the order of
    ``budgets`` x ``generators``)."""
    runs = {float(default_budget): default[default["generator"].isin(generators)]}
    paths = list(paths)
    if len(paths) != len(list(budgets)) * len(list(generators)):
        raise ValueError(f"budget sweep: {len(paths)} metrics files for {len(list(budgets))} budgets x "
                         f"{len(list(generators))} generators")
    k = 0
    for b in budgets:
        runs[float(b)] = read_metrics(paths[k:k + len(generators)])
        k += len(generators)
    return runs


def sweep_job(inp: dict, out: dict, default_budget: float, budgets, generators, order) -> None:
    """The sweep table and figure from the default run's graph-generator metrics (``inp["default"]``) and one
    metrics file per budget and generator (``inp["sweep"]``, in the order of ``budgets`` x ``generators``)."""
    from ..tables import write_table
    from .plots import sweep_figure
    from .tables import sweep_table

    table = sweep_table(sweep_runs(read_metrics(inp["default"]), inp["sweep"], default_budget, budgets, generators),
                        order)
    write_table(table, out["table"], md=out["table_md"])
    sweep_figure(table, out["figure"], float(default_budget))


def tables_job(inp: dict, out: dict, generators, left_out: dict, cfg: dict, source: str, sweep: dict | None = None) -> None:
    """Assemble the family's tables from the generator jobs' files (``inp``: ``clips``, ``metrics``,
    ``timing`` lists; optional ``sweep``: the budget sweep's metrics files) into ``out``: ``metrics``,
    ``metrics_timing``, ``summary``, ``winners`` (+ ``winners_md``), ``cost`` (+ ``cost_md``), ``verdicts``
    (+ ``verdicts_md``; the declared claims, ``cfg["claims"]``), ``claims_stats`` (their numbers), ``exploratory``
    (+ ``exploratory_md``; every other pair, no verdict), ``sanity`` (+ ``sanity_md``), ``sensitivity``
    (+ ``sensitivity_md``), ``summary_md`` (the family's page).

    ``sweep``: ``{"default": transitions_per_s, "budgets": [...], "generators": [...]}`` describing
    ``inp["sweep"]`` (:func:`sweep_runs`); the claims against the peer quote the sweep as evidence."""
    from ..atomic import atomic_write_text
    from ..tables import write_table
    from .generators import GENERATORS
    from .tables import (cost_table, data_label, sensitivity_table, summary_markdown, summary_table, sweep_table,
                         winners_table)
    from .verdicts import decide_claims, exploratory_table, independent_groups, sanity_checks

    order = list(cfg["generators"])
    metrics = read_metrics(inp["metrics"])
    metrics["_g"] = metrics["generator"].map({g: i for i, g in enumerate(order)})
    clips = pd.read_csv(inp["clips"], dtype={"held_out": str})
    metrics["_c"] = metrics["clip"].map({c: i for i, c in enumerate(clips["clip"])})
    metrics = metrics.sort_values(["_c", "_g", "seed"], kind="stable").drop(columns=["_g", "_c"])
    timing = pd.concat([pd.read_csv(p) for p in inp["timing"]], ignore_index=True)
    summary = summary_table(metrics, order)
    winners = winners_table(metrics, summary, order)
    clips_full = pd.read_csv(inp["clips"], dtype=str)
    n_groups = len(set(independent_groups(clips_full, cfg["verdicts"].get("grouping", "subject")).values()))
    data = data_label(source, clips, cfg["seeds"]) + f" in {n_groups} independent groups"
    # the claims are the family's own: a user generator (compare.user_generators) is in every table, not in them
    own = metrics[metrics["generator"].isin(GENERATORS)]
    sweep_tab = None
    if sweep and sweep.get("budgets") and inp.get("sweep"):
        sweep_tab = sweep_table(sweep_runs(metrics, inp["sweep"], sweep["default"], sweep["budgets"],
                                           sweep["generators"]), order)
    seed = int(cfg.get("seed", 0))
    declared = cfg.get("claims")
    verdicts, claims_stats = decide_claims(own, cfg["verdicts"], data, left_out, clips_full, sweep=sweep_tab,
                                           claims=declared, seed=seed)
    exploratory = exploratory_table(own, cfg["verdicts"], clips_full, claims=declared, order=order, seed=seed)
    sanity = sanity_checks(own, cfg["verdicts"], data, left_out, clips_full, seed=seed)
    write_table(metrics, out["metrics"], md=False)
    write_table(timing, out["metrics_timing"], md=False)
    write_table(summary, out["summary"], md=False)  # compare/summary.md is the family's page below
    write_table(winners, out["winners"], md=out["winners_md"])
    write_table(cost_table(timing, order), out["cost"], md=out["cost_md"])
    write_table(verdicts, out["verdicts"], md=out["verdicts_md"])
    write_table(claims_stats, out["claims_stats"], md=False)
    write_table(exploratory, out["exploratory"], md=out["exploratory_md"])
    write_table(sanity, out["sanity"], md=out["sanity_md"])
    write_table(sensitivity_table(metrics, order), out["sensitivity"], md=out["sensitivity_md"])
    not_built = metrics.loc[metrics["note"] != "", ["generator", "clip", "note"]].drop_duplicates()
    log.info("%d rows (%d clips x %d generators x %d seeds), %d not built, %d verdicts: %s", len(metrics),
             metrics["clip"].nunique(), metrics["generator"].nunique(), int(cfg["seeds"]), len(not_built),
             len(verdicts), ", ".join(verdicts["verdict"]))
    atomic_write_text(out["summary_md"], summary_markdown(clips, winners, verdicts, generators, left_out, data, cfg,
                                                          not_built, sanity))
