"""The comparison's protocol: the held-out clips (windows), their databases, starts and seeds, and the clips file.

Protocol (docs/compare/protocol.md):

* Every trial is resampled to the working rate ``compare.fps`` by keeping every n-th frame
  (n = trial fps / working fps, an integer); frames a capture check flags (``usable``) stay out of held-out
  windows and databases (a database piece is a usable stretch of at least ``context + min_length`` frames).
* **Leave one out** (each Gauch & Peters subset of ``compare.subsets`` and each set of two or more trials of
  ``compare.subjects``): every trial is held out in turn; its database is the set's other trials.
* **Temporal split** (each re-sequencing clip of ``compare.resequencing`` and each one-trial set of
  ``compare.subjects``): the trial is cut into ``compare.split_blocks`` blocks of equal length (fewer when the
  trial is too short for that many blocks of ``context + min_length`` frames); each block is held out in turn, its
  database the rest of the trial (the frames before and after the block).
* **Windows**: each held-out part (a trial, or a block) is cut into non-overlapping windows of ``context + length``
  frames along its usable frames; the last shorter window is kept when it has at least ``context + min_length``
  frames. Every window of one held-out part shares that part's database (:attr:`Clip.database_id`): a generator is
  fitted once per database. A window is a clip, ``<group>/<trial>@<frame>`` (its first frame in the trial at the
  working rate).
* **At most ``compare.max_clips_per_subject`` clips per subject**, chosen evenly and deterministically: the cap is
  shared as equally as the windows allow among the subject's groups, then among each group's held-out parts,
  and a part's share is spread evenly along it (:func:`choose_windows`). A part none of whose windows is chosen
  is not built. **At most ``compare.max_database_s`` seconds of database** per held-out part: a longer database
  keeps the first frames of each of its pieces, shares as equal as their lengths allow.
* For the generators that run at a native rate (fairmotion's 60 fps, ``compare.fairmotion.native_fps``), every
  clip also carries its database and start at that rate, taken by frame step from the trials too
  (:class:`NativeRate`): the same instants as the working-rate frames and the real frames between them. A trial
  whose rate is not a whole multiple of the native rate has none (a log line and the clips table's ``note`` say
  so), and the generator upsamples the working-rate clips instead.
* The start is a window's first ``compare.context`` frames; every generator makes ``length = window frames -
  context`` frames from it (at most ``compare.length``); the ground truth is the window's frames after the start
  (the ``replay`` row).
* Every clip runs ``compare.seeds`` seeds, seed ``i`` of clip ``c`` derived from the master seed, ``compare.seed``,
  ``c`` and ``i`` (the same for every generator and whatever else the run holds).

File: ``compare/clips/<subject>.npz`` (one subject's held-out parts, their databases and windows:
:func:`save_clips` / :func:`load_clips`) and its table (:func:`clips_table`).
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

__all__ = ["NativeRate", "Clip", "resample", "prepare_clips", "save_clips", "load_clips", "clips_table", "clip_seeds",
           "split_blocks", "window_offsets", "share", "choose_windows", "working_usable", "group_subject",
           "load_skeletons"]

log = logging.getLogger("animsynth.compare.protocol")


@dataclass
class NativeRate:
    """One clip's database and start at a generator's native rate (by frame step from the trials).

    Attributes
    ----------
    fps : float, the native rate (a whole multiple ``k`` of the working rate)
    database : list of Motion at ``fps``, the clip's database pieces in the same order (native frame ``i * k`` is
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
    """One held-out window with its database (all at the working rate).

    Attributes
    ----------
    clip : str, ``<group>/<trial>@<frame>`` (e.g. ``w1/35_16@68``, ``walk/35_01@30``): the window's first frame in
        the trial at the working rate
    group : str, the subset, re-sequencing dataset or subject set
    protocol : str, ``leave one out`` or ``temporal split``
    trial : str, the held-out trial
    held_out : Motion, the held-out frames from the window's first frame to the end of its usable stretch of the
        held-out part (the start, the ground truth, then the held-out frames after it)
    database : list of Motion, shared by every clip of one ``database_id``
    context, length : int, start frames and generated frames
    database_names : list of str
    native : list of NativeRate, the database and start at each native rate of ``compare``'s generators
    subject : str, the subject (the trial record's ``subject``)
    database_id : str, the held-out part whose database this is (``<group>/<trial>``, or ``<group>/<trial>#<block>``
        for a temporal split): clips of one id share one build of every generator
    frame : int, the window's first frame in the trial (working rate)
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
    subject: str = ""
    database_id: str = ""
    frame: int = 0

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


def working_usable(usable, step: int, n: int) -> np.ndarray:
    """Which of ``n`` frames kept by a frame step ``step`` are usable (``usable``: bool per source frame, or
    ``None``: all): frame ``j`` (source frame ``j * step``) when every source frame within ``step - 1`` of it is, so
    two consecutive usable frames span only usable source frames
    (:meth:`animsynth.capture_check.CaptureCheck.usable_every`)."""
    from ..capture_check import CaptureCheck

    if usable is None:
        return np.ones(n, bool)
    return CaptureCheck("", 0.0, np.asarray(usable, bool)).usable_every(int(step))[:n]


# ----------------------------------------------------------------------------- windows and shares


def split_blocks(n: int, blocks: int, min_frames: int) -> list[tuple[int, int]]:
    """The held-out blocks ``[(first, end)]`` of a temporal split of ``n`` frames: ``blocks`` of equal length (as
    equal as whole frames allow), fewer when a block would be shorter than ``min_frames``; empty when not even two
    blocks fit (no database would be left)."""
    k = min(int(blocks), n // max(1, int(min_frames)))
    if k < 2:
        return []
    edges = [int(round(i * n / k)) for i in range(k + 1)]
    return list(zip(edges[:-1], edges[1:]))


def window_offsets(usable: np.ndarray, size: int, min_size: int) -> list[tuple[int, int, int]]:
    """Non-overlapping windows ``[(first, frames, end)]`` along each stretch of usable frames: ``size`` frames each,
    the last shorter one kept when it has at least ``min_size``; ``end`` is where the window's stretch ends."""
    u = np.asarray(usable, bool)
    out, i, n = [], 0, u.size
    while i < n:
        if not u[i]:
            i += 1
            continue
        j = i
        while j < n and u[j]:
            j += 1
        a = i
        while j - a >= min_size:
            w = min(size, j - a)
            out.append((a, w, j))
            a += w
        i = j
    return out


def _spread(m: int, n: int) -> list[int]:
    """``m`` of ``n`` positions spread evenly: ``ceil((j + 1/2) n / m) - 1`` for ``j < m`` (the middle one for
    ``m = 1``, the earlier of two middles)."""
    return [int(np.ceil((j + 0.5) * n / m)) - 1 for j in range(m)]


def share(total: int, sizes) -> list[int]:
    """``total`` split over items of ``sizes`` as equally as their sizes allow (each at most its size; what an
    item cannot take goes to the others; a remainder that cannot be split equally to items spread evenly among
    them, :func:`_spread`). Deterministic."""
    sizes = [int(s) for s in sizes]
    out = [0] * len(sizes)
    left = min(int(total), sum(sizes))
    open_ = [i for i, s in enumerate(sizes) if s > 0]
    while left > 0 and open_:
        each, extra = divmod(left, len(open_))
        more = set(_spread(extra, len(open_))) if extra else set()
        for rank, i in enumerate(open_):
            give = min(sizes[i] - out[i], each + (1 if rank in more else 0))
            out[i] += give
            left -= give
        open_ = [i for i in open_ if out[i] < sizes[i]]
    return out


def choose_windows(groups: list[list[int]], cap: int | None) -> list[list[list[int]]]:
    """Which windows to keep: ``groups`` holds, per group, the window count of each of its held-out parts; the
    result, per group and part, the chosen window indices. ``cap`` (None: every window) is shared among the groups
    (:func:`share`), each group's share among its parts, and a part's ``m`` of ``n`` windows spread evenly along
    it: window ``ceil((j + 1/2) n / m) - 1`` for ``j < m`` (the middle one when it keeps one, the earlier of two
    middles: a full-length window before the last, shorter one)."""
    if cap is None:
        return [[list(range(n)) for n in parts] for parts in groups]
    per_group = share(cap, [sum(parts) for parts in groups])
    return [[_spread(m, n) for n, m in zip(parts, share(k, parts))] for parts, k in zip(groups, per_group)]


def _stretches(usable: np.ndarray, min_len: int, lo: int = 0, hi: int | None = None) -> list[tuple[int, int]]:
    """The stretches ``[(first, end)]`` of usable frames within ``[lo, hi)`` that are at least ``min_len`` long."""
    hi = usable.size if hi is None else hi
    u = np.concatenate([[False], np.asarray(usable[lo:hi], bool), [False]])
    d = np.flatnonzero(np.diff(u.astype(np.int8)))
    return [(lo + int(a), lo + int(b)) for a, b in zip(d[::2], d[1::2]) if b - a >= min_len]


def _capped(pieces: list, cap: int | None, min_len: int) -> list:
    """``pieces`` ``[(trial, first, end)]`` cut to at most ``cap`` frames in all: each keeps its first frames, shares
    as equal as their lengths allow (:func:`share`); a piece left shorter than ``min_len`` is dropped."""
    if cap is None or sum(b - a for _t, a, b in pieces) <= cap:
        return pieces
    keep = share(cap, [b - a for _t, a, b in pieces])
    return [(t, a, a + k) for (t, a, _b), k in zip(pieces, keep) if k >= min_len]


@dataclass
class _Part:
    """One held-out part (a trial, or a block of one) and its database: every window of it shares the database.
    ``native``: per native rate ``(fps, database, held part at that rate or None, k, note)``."""

    key: str
    group: str
    protocol: str
    trial: str
    subject: str
    held: Motion
    first: int
    usable: np.ndarray
    database: list
    database_names: list
    native: list
    windows: list = field(default_factory=list)


class _Trials:
    """The trials of one :func:`prepare_clips` call, unwrapped at their own rate (a fast joint may move more than 180
    degrees between working frames), at the working rate and at each native rate, with their usable frames."""

    def __init__(self, trials: dict, cfg: dict, usable: dict | None):
        from ..retarget import unwrap_angles

        self.fps = float(cfg["fps"])
        self.full = {t: unwrap_angles(m, f"trial {t}") for t, m in trials.items()}
        self.work = {t: resample(m, self.fps) for t, m in self.full.items()}
        usable = usable or {}
        self.usable = {t: working_usable(usable.get(t), int(round(float(m.fps) / self.fps)), self.work[t].n_frames)
                       for t, m in self.full.items()}
        self.rates = sorted({float(r) for r in cfg.get("native_fps") or []} - {self.fps})
        self.native = {}  # {(rate, trial): (Motion at the rate, k) or the reason there is none}
        for r in self.rates:
            k = r / self.fps
            for t, m in self.full.items():
                step = float(m.fps) / r
                if abs(k - round(k)) > 1e-6 or round(k) < 1:
                    why = f"{r:g} fps is not a whole multiple of the working rate {self.fps:g} fps"
                elif abs(step - round(step)) > 1e-6 or round(step) < 1:
                    why = f"trial {t!r} at {float(m.fps):g} fps is not a whole multiple of {r:g} fps"
                else:
                    self.native[r, t] = (resample(m, r, key="compare.fairmotion.native_fps"), int(round(k)))
                    continue
                self.native[r, t] = f"{why}: its generators upsample the {self.fps:g} fps clips to {r:g} fps"
                log.info("clips: no %g fps database from trial %s (%s)", r, t, self.native[r, t])

    def pieces(self, motions: dict, pieces: list, fps: float, k: int = 1) -> list:
        """The database pieces ``[(trial, first, end)]`` (working frames) cut from ``motions`` ({trial: Motion at
        ``fps``}, ``k`` frames per working frame): a whole trial keeps its name, a piece is ``trial[first:end]``."""
        out = []
        for t, a, b in pieces:
            m = motions[t]
            whole = a == 0 and b == self.work[t].n_frames
            vals = np.asarray(m.values[a * k:min(b * k, m.n_frames)], float)
            out.append(Motion(vals, m.skeleton, fps, t if whole else f"{t}[{a}:{b}]"))
        return out


def _names(T: _Trials, pieces: list) -> list[str]:
    """The clips table's names of database pieces: the trial, or ``trial frames a-b``."""
    return [t if (a == 0 and b == T.work[t].n_frames) else f"{t} frames {a}-{b - 1}" for t, a, b in pieces]


def _loo_part(T: _Trials, group: str, t: str, others: list, subject: str, cfg: dict) -> _Part:
    """Trial ``t`` held out, its database the usable stretches of ``others`` (on ``t``'s skeleton, on the angle
    branch of the first database trial, capped at ``compare.max_database_s``)."""
    from ..retarget import align_angle_branches, retarget

    fps, floor = T.fps, _piece_floor(cfg)
    db = {o: resample(retarget(T.full[o], T.full[t].skeleton, f"trial {o}", f"trial {t}"), fps) for o in others}
    ref = db[others[0]]
    db = {o: align_angle_branches(d, ref) for o, d in db.items()}
    held = align_angle_branches(T.work[t], ref)
    pieces = [(o, a, b) for o in others for a, b in _stretches(T.usable[o], floor)]
    pieces = _capped(pieces, _cap_frames(cfg, fps), floor)
    native = []
    for r in T.rates:
        got = [T.native[r, x] for x in [t] + others]
        why = next((g for g in got if isinstance(g, str)), "")
        if why:
            native.append((r, [], None, 0, why))
            continue
        (held_n, k), dbs = got[0], got[1:]
        nat = {o: Motion(np.asarray(retarget(m, held_n.skeleton, f"trial {o}", f"trial {t}").values, float),
                         held_n.skeleton, r, o) for (m, _k), o in zip(dbs, others)}
        nref = nat[others[0]]
        nat = {o: align_angle_branches(d, nref) for o, d in nat.items()}
        native.append((r, T.pieces(nat, pieces, r, k), align_angle_branches(held_n, nref), k, ""))
    return _Part(f"{group}/{t}", group, "leave one out", t, subject, held, 0, T.usable[t],
                 T.pieces(db, pieces, fps), _names(T, pieces), native)


def _split_parts(T: _Trials, group: str, t: str, subject: str, cfg: dict) -> list[_Part]:
    """Trial ``t`` cut into blocks (:func:`split_blocks`), each held out in turn with the rest of the trial (its
    usable stretches before and after the block) as its database."""
    fps, context, floor = T.fps, int(cfg["context"]), _piece_floor(cfg)
    m, u = T.work[t], T.usable[t]
    n, win_min = m.n_frames, context + int(cfg["min_length"])
    blocks = split_blocks(n, int(cfg["split_blocks"]), win_min)
    if not blocks:
        raise ValueError(f"clip {group}/{t}: {n} frames at {fps:g} fps hold no two blocks of {win_min} frames "
                         "(context + min_length) for a temporal split (config keys 'compare.split_blocks', "
                         "'compare.context', 'compare.min_length', 'compare.fps')")
    parts = []
    for i, (s, e) in enumerate(blocks):
        pieces = [(t, a, b) for lo, hi in ((0, s), (e, n)) for a, b in _stretches(u, floor, lo, hi)]
        pieces = _capped(pieces, _cap_frames(cfg, fps), floor)
        if not pieces:
            raise ValueError(f"clip {group}/{t}: block {i} (frames {s}-{e - 1}) leaves no database stretch of "
                             f"{floor} usable frames (config keys 'compare.split_blocks', 'compare.fps')")
        native = []
        for r in T.rates:
            got = T.native[r, t]
            if isinstance(got, str):
                native.append((r, [], None, 0, got))
                continue
            full, k = got
            held_n = Motion(np.asarray(full.values[s * k:min(e * k, full.n_frames)], float), full.skeleton, r,
                            f"{t}[{s}:{e}]@{r:g}")
            native.append((r, T.pieces({t: full}, pieces, r, k), held_n, k, ""))
        held = Motion(np.asarray(m.values[s:e], float), m.skeleton, fps, f"{t}[{s}:{e}]")
        parts.append(_Part(f"{group}/{t}#{i}", group, "temporal split", t, subject, held, s, u[s:e],
                           T.pieces({t: m}, pieces, fps), _names(T, pieces), native))
    return parts


def _piece_floor(cfg: dict) -> int:
    """The fewest frames of a database piece: a usable stretch shorter than a held-out window's minimum, ``context +
    min_length``, is dropped (a capture check's flag inside a trial can leave a few frames, too short for a graph's
    window or a patch)."""
    return max(4, int(cfg["context"]) + int(cfg["min_length"]))


def _cap_frames(cfg: dict, fps: float) -> int | None:
    cap = cfg.get("max_database_s")
    return None if cap is None else max(1, int(round(float(cap) * fps)))


def group_subject(ids, subjects: dict, group: str) -> str:
    """The subject of a group of trials: their ``subject`` (``subjects``: {trial id: subject}; a trial without one
    counts as the group's own), the subjects joined by ``+`` when they differ."""
    return "+".join(sorted({str(subjects.get(t, group)) for t in ids}))


def _clip(part: _Part, a: int, w: int, e: int, context: int) -> Clip:
    """The clip of window ``[a, a + w)`` of ``part`` (its stretch ends at ``e``; offsets in the part)."""
    held = part.held
    frame = part.first + a
    held_out = Motion(np.asarray(held.values[a:e], float), held.skeleton, held.fps, f"{part.trial}@{frame}")
    native = []
    for r, db, held_n, k, note in part.native:
        start = None
        if held_n is not None:
            start = Motion(np.asarray(held_n.values[a * k:(a + context - 1) * k + 1], float), held_n.skeleton, r,
                           f"{part.trial}@{frame}:start@{r:g}")
        native.append(NativeRate(r, db, start, note))
    return Clip(f"{part.group}/{part.trial}@{frame}", part.group, part.protocol, part.trial, held_out,
                part.database, context, w - context, list(part.database_names), native, part.subject, part.key, frame)


def prepare_clips(trials: dict, subsets: dict, resequencing: dict, cfg: dict, subjects: dict | None = None,
                  usable: dict | None = None) -> list[Clip]:
    """Every held-out clip of the protocol (module docstring), subject by subject.

    Parameters
    ----------
    trials : {trial id: Motion} (parsed trials at their own rate)
    subsets : {group: [trial ids]}, leave one out within each group: the subsets of ``compare.subsets`` and the
        sets of ``compare.subjects`` with two or more trials (:func:`animsynth.compare.settings.groups`)
    resequencing : {group: trial id}, a temporal split of each: the clips of ``compare.resequencing`` and the
        sets of ``compare.subjects`` with one trial
    cfg : the ``compare`` config block (``fps``, ``context``, ``length``, ``min_length``, ``split_blocks``,
        ``max_clips_per_subject``, ``min_clips_per_subject``, ``max_database_s``) and ``native_fps`` (optional:
        the native rates to prepare, :func:`animsynth.compare.settings.native_rates`)
    subjects : {trial id: subject} (default: each group its own subject); the cap on clips is per subject
    usable : {trial id: bool per frame at the trial's own rate} (a capture check's; default: every frame)

    Every trial's angles are made continuous at its own rate, before resampling
    (:func:`animsynth.retarget.unwrap_angles`). A leave-one-out part's database trials are put on the held-out
    trial's skeleton (:func:`animsynth.retarget.retarget`: the same skeleton is kept as it is; other rest offsets
    are retargeted with a logged warning, or refused naming both trials) and every one of them, the held-out
    trial too, on the angle branch of the database's first trial (:func:`animsynth.retarget.align_angle_branches`).
    A temporal split is one continuous trial and stays as it is. The clips at a native rate are made the same way
    from the unwrapped trials. Returns the clips in the order of the subjects' first groups, then of the groups
    (``subsets``, then ``resequencing``), parts and windows.
    """
    T = _Trials(trials, cfg, usable)
    context, length = int(cfg["context"]), int(cfg["length"])
    size, min_size = context + length, context + int(cfg["min_length"])
    subjects = subjects or {}
    by_subject: dict[str, list[list[_Part]]] = {}
    for group, ids in subsets.items():
        if len(ids) < 2:
            raise ValueError(f"config key 'compare.subsets': subset {group!r} needs >= 2 trials for leave one out")
        subject = group_subject(ids, subjects, group)
        parts = [_loo_part(T, group, t, [o for o in ids if o != t], subject, cfg) for t in ids]
        by_subject.setdefault(subject, []).append(parts)
    for group, t in resequencing.items():
        subject = group_subject([t], subjects, group)
        by_subject.setdefault(subject, []).append(_split_parts(T, group, t, subject, cfg))
    clips = []
    for subject, groups in by_subject.items():
        for parts in groups:
            for p in parts:
                p.windows = window_offsets(p.usable, size, min_size)
        chosen = choose_windows([[len(p.windows) for p in parts] for parts in groups],
                                cfg.get("max_clips_per_subject"))
        own = [_clip(p, *p.windows[i], context) for parts, pick in zip(groups, chosen) for p, idx in zip(parts, pick)
               for i in idx]
        if not own:
            raise ValueError(f"subject {subject}: no held-out window of at least {min_size} usable frames at {T.fps:g} "
                             "fps (context + min_length; config keys 'compare.context', 'compare.min_length', "
                             "'compare.fps')")
        floor = int(cfg.get("min_clips_per_subject") or 0)
        if len(own) < floor:
            log.warning("compare: subject %s gives %d clips of at least %d frames, fewer than "
                        "compare.min_clips_per_subject (%d): left out of the declared tests", subject, len(own),
                        min_size, floor)
        log.info("clips: subject %s: %d clips over %d databases", subject, len(own),
                 len({c.database_id for c in own}))
        clips += own
    return clips


# ----------------------------------------------------------------------------- the clips file


def _held_ranges(cs: list[Clip]) -> list[tuple[int, int, np.ndarray]]:
    """The held-out frames of clips sharing a database, each frame once: ``[(first, end, values)]`` (trial frames;
    overlapping clips merged, checked to hold the same values where they overlap)."""
    out: list[list] = []
    for c in sorted(cs, key=lambda c: c.frame):
        a, v = c.frame, np.asarray(c.held_out.values, float)
        b = a + v.shape[0]
        if out and a <= out[-1][1]:
            f0, e0, v0 = out[-1]
            lo, hi = a - f0, min(b, e0) - f0
            if not np.array_equal(v0[lo:hi], v[:hi - lo]):
                raise ValueError(f"clip {c.clip}: its held-out frames differ from another clip's of database "
                                 f"{c.database_id!r} where they overlap")
            if b > e0:
                out[-1] = [f0, b, np.vstack([v0, v[e0 - a:]])]
        else:
            out.append([a, b, v])
    return [tuple(r) for r in out]


def save_clips(path, clips: list[Clip]) -> None:
    """Store clips in one ``.npz``: a JSON manifest, each database once per ``database_id`` (and at each native
    rate), the held-out frames of its clips once, each clip's native start, one JSON per skeleton."""
    arrays, skeletons, manifest = {}, {}, []
    by_db: dict[str, list[int]] = {}
    for i, c in enumerate(clips):
        by_db.setdefault(c.database_id or f"#{c.clip}", []).append(i)
    for d, (key, idx) in enumerate(by_db.items()):
        cs = [clips[i] for i in idx]
        c0 = cs[0]
        sk = c0.held_out.skeleton.to_json()
        for j, m in enumerate(c0.database):
            arrays[f"d{d}_db{j}"] = np.asarray(m.values, float)
        nat = []
        for r, n in enumerate(c0.native):
            for j, m in enumerate(n.database):
                arrays[f"d{d}_n{r}_db{j}"] = np.asarray(m.values, float)
            nat.append({"fps": float(n.fps), "database": [m.name for m in n.database], "note": n.note})
        ranges = _held_ranges(cs)
        for h, (_a, _b, v) in enumerate(ranges):
            arrays[f"d{d}_h{h}"] = v
        entry = {"database_id": c0.database_id, "group": c0.group, "protocol": c0.protocol, "trial": c0.trial,
                 "subject": c0.subject, "fps": c0.held_out.fps,
                 "skeleton": skeletons.setdefault(sk, f"skeleton{len(skeletons)}"),
                 "database": [m.name for m in c0.database], "database_names": list(c0.database_names),
                 "native": nat, "ranges": [[int(a), int(b)] for a, b, _v in ranges], "clips": []}
        for i, c in zip(idx, cs):
            for r, n in enumerate(c.native):
                if n.start is not None:
                    arrays[f"c{i}_n{r}_start"] = np.asarray(n.start.values, float)
            entry["clips"].append({"index": i, "clip": c.clip, "frame": int(c.frame), "frames": c.held_out.n_frames,
                                   "context": c.context, "length": c.length, "held_name": c.held_out.name,
                                   "starts": [None if n.start is None else n.start.name for n in c.native]})
        manifest.append(entry)
    for sk, key in skeletons.items():
        arrays[key] = np.array(sk)
    arrays["manifest"] = np.array(json.dumps(manifest))
    with atomic_path(path, suffix=".npz") as tmp:
        np.savez_compressed(tmp, **arrays)


def load_clips(path) -> list[Clip]:
    """The clips stored by :func:`save_clips`, in the order they were stored (clips of one ``database_id`` share
    one list of database motions)."""
    with np.load(path, allow_pickle=False) as z:
        manifest = json.loads(str(z["manifest"]))
        sks = {k: Skeleton.from_json(str(z[k])) for k in z.files if k.startswith("skeleton")}
        out = {}
        for d, e in enumerate(manifest):
            sk, fps = sks[e["skeleton"]], float(e["fps"])
            db = [Motion(np.array(z[f"d{d}_db{j}"]), sk, fps, name) for j, name in enumerate(e["database"])]
            ndb = [[Motion(np.array(z[f"d{d}_n{r}_db{j}"]), sk, float(n["fps"]), name)
                    for j, name in enumerate(n["database"])] for r, n in enumerate(e["native"])]
            ranges = [(a, b, np.array(z[f"d{d}_h{h}"])) for h, (a, b) in enumerate(e["ranges"])]
            for c in e["clips"]:
                a0, _b, v = next(r for r in ranges if r[0] <= c["frame"] < r[1])
                lo = c["frame"] - a0
                held = Motion(v[lo:lo + c["frames"]], sk, fps, c["held_name"])
                nat = [NativeRate(float(n["fps"]), ndb[r], None if s is None else
                                  Motion(np.array(z[f"c{c['index']}_n{r}_start"]), sk, float(n["fps"]), s), n["note"])
                       for r, (n, s) in enumerate(zip(e["native"], c["starts"]))]
                out[c["index"]] = Clip(c["clip"], e["group"], e["protocol"], e["trial"], held, db, int(c["context"]),
                                       int(c["length"]), list(e["database_names"]), nat, e["subject"],
                                       e["database_id"], int(c["frame"]))
    return [out[i] for i in sorted(out)]


def load_skeletons(path) -> dict:
    """``{held-out trial: Skeleton}`` of a clips file (:func:`save_clips`), without reading its motions."""
    with np.load(path, allow_pickle=False) as z:
        manifest = json.loads(str(z["manifest"]))
        return {e["trial"]: Skeleton.from_json(str(z[e["skeleton"]])) for e in manifest}


def clips_table(clips: list[Clip], min_clips: int = 0) -> pd.DataFrame:
    """The protocol as a table: one row per held-out clip (window): its subject, group, held-out frames (the
    window), database (``database_id``: the clips sharing it; ``database_longest``: its longest piece's frames),
    lengths, native rates and notes; ``subject_clips``:
    the clips of its subject, and ``enough_clips``: whether they reach ``min_clips``
    (``compare.min_clips_per_subject``; a subject below it is left out of the declared tests)."""
    count: dict[str, int] = {}
    for c in clips:
        count[c.subject] = count.get(c.subject, 0) + 1
    return pd.DataFrame([{
        "clip": c.clip, "subject": c.subject, "group": c.group, "protocol": c.protocol,
        "held_out": f"{c.trial} frames {c.frame}-{c.frame + c.context + c.length - 1}",
        "database": " ".join(c.database_names), "database_id": c.database_id,
        "database_frames": int(sum(d.n_frames for d in c.database)),
        "database_longest": int(max(d.n_frames for d in c.database)), "held_out_frames": c.context + c.length,
        "fps": c.held_out.fps, "context": c.context, "length": c.length,
        "native_fps": " ".join(f"{n.fps:g}" for n in c.native if n.database),
        "subject_clips": count[c.subject], "enough_clips": count[c.subject] >= int(min_clips),
        "note": "; ".join(n.note for n in c.native if n.note),
    } for c in clips], columns=["clip", "subject", "group", "protocol", "held_out", "database", "database_id",
                                "database_frames", "database_longest", "held_out_frames", "fps", "context", "length",
                                "native_fps", "subject_clips", "enough_clips", "note"])


def clip_seeds(master: int, family_seed: int, clip: str, n: int) -> list[int]:
    """The seeds of one clip: the same for every generator."""
    return [derive_seed(master, "compare", family_seed, clip, i) for i in range(int(n))]
