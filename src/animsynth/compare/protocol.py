"""The comparison's protocol: the held-out clips, their databases, starts and seeds, and the clips file.

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

File: ``compare/clips.npz`` (every clip's database, held-out clip and length: :func:`save_clips` / :func:`load_clips`)
and its table (:func:`clips_table`).
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..atomic import atomic_path
from ..config import derive_seed
from ..motion import Motion
from ..skeleton import Skeleton

__all__ = ["NativeRate", "Clip", "resample", "prepare_clips", "save_clips", "load_clips", "clips_table", "clip_seeds"]

log = logging.getLogger("animsynth.compare.protocol")


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


def clip_seeds(master: int, family_seed: int, clip: str, n: int) -> list[int]:
    """The seeds of one clip: the same for every generator."""
    return [derive_seed(master, "compare", family_seed, clip, i) for i in range(int(n))]
