"""Is a capture fit to be held out? A check of a parsed trial before clips are cut from it.

:func:`check_capture` reads one trial's motion at its own rate and flags frames no body made:

========================  ==================================================================================
kind                      what is flagged
========================  ==================================================================================
``tpose_settling``        the file's first frames while it leaves a T-pose: from frame 0, every frame whose
                          two upper arms are both raised at least ``tpose_arm_deg`` from hanging, and every
                          step faster than ``max_joint_speed_m_s`` that follows without a break, through the
                          frame the last such step lands on (cgspeed's BVH conversions blend from their T-pose
                          frame 0 into the capture over a few frames)
``zero_part``             frames where every rotation DOF of a body part (upper body, an arm, a leg; found
                          by joint role, :mod:`animsynth.joints`) is zero within ``zero_tol_deg``: a part at
                          its exact rest pose is a gap the file filled with zeros, not a pose
``jump``                  both frames of every step in which a joint moves faster than
                          ``max_joint_speed_m_s`` (consecutive steps are one flag)
``frozen``                every DOF, root included, equal to the frame before for at least ``frozen_min_s``:
                          a held pose (a living body is never still to the file's printed precision)
========================  ==================================================================================

A joint's speed is the distance its segment's end (:func:`animsynth.kinematics.forward_kinematics`,
``ends=True``, metres) moves between two consecutive frames times the frame rate. The thresholds are the
``capture_check`` config keys (config/README.md says why each value); nothing is tuned to a subject.

:func:`checks_table` gives one row per flag (one row for a trial without flags) for ``capture_checks.csv``.
Frames are 0-based frames of the motion as given (after the trial record's ``first_frame``); a note names the
trial, the frames, the file's frames when ``first_frame`` is given, and what was seen.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .config import ConfigError
from .joints import JointRoleError, resolve_role
from .kinematics import forward_kinematics, joint_starts
from .motion import Motion

log = logging.getLogger("animsynth.capture_check")

__all__ = ["CaptureFlag", "CaptureCheck", "check_capture", "checks_table", "KINDS", "BODY_PARTS", "CONFIG_KEYS"]

#: The kinds of flag, in the order they are looked for.
KINDS = ("tpose_settling", "zero_part", "jump", "frozen")
#: Body parts of the ``zero_part`` check, largest first (a part inside a flagged larger one is not flagged again).
BODY_PARTS = {
    "upper_body": ("spine", "chest", "neck", "head", "left_shoulder", "left_elbow", "left_wrist", "right_shoulder",
                   "right_elbow", "right_wrist"),
    "left_arm": ("left_shoulder", "left_elbow", "left_wrist"),
    "right_arm": ("right_shoulder", "right_elbow", "right_wrist"),
    "left_leg": ("left_hip", "left_knee", "left_ankle", "left_toe"),
    "right_leg": ("right_hip", "right_knee", "right_ankle", "right_toe"),
}
#: The keys of the ``capture_check`` config block that :func:`check_capture` reads.
CONFIG_KEYS = ("max_joint_speed_m_s", "tpose_arm_deg", "zero_tol_deg", "frozen_min_s")
#: Columns of :func:`checks_table`.
TABLE_COLUMNS = ["trial", "fps", "frames", "usable_frames", "kind", "first_frame", "last_frame", "flagged_frames",
                 "file_first_frame", "note"]


@dataclass(frozen=True)
class CaptureFlag:
    """One flagged stretch of a trial.

    Attributes
    ----------
    kind : str, one of :data:`KINDS`
    first, last : int, the first and last flagged frame (0-based, inclusive, at the motion's own rate)
    note : str, one line naming the trial, the frames and what was seen
    """

    kind: str
    first: int
    last: int
    note: str

    @property
    def n_frames(self) -> int:
        return self.last - self.first + 1


@dataclass
class CaptureCheck:
    """What :func:`check_capture` found on one trial.

    Attributes
    ----------
    trial : str
    fps : float, the motion's rate (the frames of ``usable`` and ``flags``)
    usable : ndarray of bool, shape (frames,), False on every flagged frame
    flags : list of CaptureFlag, by first frame
    first_frame : int, frames the trial record dropped before frame 0 (file frame = frame + first_frame)
    """

    trial: str
    fps: float
    usable: np.ndarray
    flags: list[CaptureFlag] = field(default_factory=list)
    first_frame: int = 0

    @property
    def n_frames(self) -> int:
        return int(self.usable.shape[0])

    def usable_every(self, step: int) -> np.ndarray:
        """``usable`` for the motion resampled by keeping every ``step``-th frame from frame 0.

        Frame ``j`` of the resampled motion (frame ``j * step`` here) is usable when every frame within
        ``step - 1`` of it is: then two consecutive usable resampled frames span only usable frames, so no
        flagged step hides between them.

        Returns
        -------
        ndarray of bool, shape (ceil(frames / step),)
        """
        step = int(step)
        if step < 1:
            raise ValueError(f"step must be a positive integer, got {step}")
        bad = np.convolve(~self.usable, np.ones(2 * step - 1, dtype=int), mode="same") > 0
        return ~bad[::step]

    def usable_stretches(self, min_frames: int = 1) -> list[tuple[int, int]]:
        """``[(start, stop), ...]`` (half-open) of the runs of usable frames at least ``min_frames`` long."""
        return [(a, b) for a, b in _runs(self.usable) if b - a >= int(min_frames)]


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open ``(start, stop)`` of every run of True in a 1-d boolean array."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    edges = np.flatnonzero(m[1:] != m[:-1])
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]


def _settings(cfg: dict) -> dict:
    """The ``capture_check`` keys as floats; a missing or bad one is a :class:`ConfigError` naming it."""
    out = {}
    for key in CONFIG_KEYS:
        if key not in (cfg or {}):
            raise ConfigError(f"config key 'capture_check.{key}' is missing (config/schema.yaml gives its default)")
        value = float(cfg[key])
        if not math.isfinite(value) or value < 0:
            raise ConfigError(f"config key 'capture_check.{key}': expected a finite number >= 0, got {cfg[key]!r}")
        out[key] = value
    return out


def _where(trial: str, first: int, last: int, fps: float, first_frame: int) -> str:
    n = last - first + 1
    file = f"; file frames {first + first_frame}-{last + first_frame}" if first_frame else ""
    return f"{trial}: frames {first}-{last} ({n} frame{'s' if n != 1 else ''} at {fps:g} fps{file})"


def _arms_raised_deg(motion: Motion, ends: np.ndarray) -> np.ndarray | None:
    """(frames,) the smaller of the two upper arms' angles from hanging straight down (degrees), or None when
    the skeleton has no joint for a shoulder role. An upper arm runs from the start to the end of the shoulder
    role's segment (for CMU ASF ``lhumerus``, for BVH ``LeftArm``)."""
    sk = motion.skeleton
    try:
        idx = [sk.index(resolve_role(sk, r)) for r in ("left_shoulder", "right_shoulder")]
    except JointRoleError:
        return None
    starts = joint_starts(sk, motion.values, idx) * float(sk.length_to_m)
    arm = ends[:, idx] - starts
    length = np.linalg.norm(arm, axis=2)
    down = -arm[..., 1] / np.where(length > 0, length, 1.0)
    return np.degrees(np.arccos(np.clip(down, -1.0, 1.0))).min(axis=1)


def _settling(trial, motion, speed, arms, s, first_frame) -> CaptureFlag | None:
    """The ``tpose_settling`` flag: the leading frames with both arms raised or a too-fast step, through the
    frame the last too-fast step lands on (None when frame 0 is neither)."""
    n = motion.n_frames
    peak = speed.max(axis=1) if speed.size else np.zeros(0)
    fast = peak > s["max_joint_speed_m_s"]
    up = arms >= s["tpose_arm_deg"] if arms is not None else np.zeros(n, bool)
    i = 0
    while i < n and (up[i] or (i < n - 1 and fast[i])):
        i += 1
    if i == 0:
        return None
    last = i if i < n and fast[i - 1] else i - 1  # the frame the last too-fast step lands on
    seen = []
    if up[0]:
        seen.append(f"both upper arms raised at least {float(arms[0]):.0f} degrees from hanging at frame 0, limit "
                    f"{s['tpose_arm_deg']:g}")
    if fast[:i].any():
        seen.append(f"joints up to {float(peak[:i].max()):.3g} m/s, limit {s['max_joint_speed_m_s']:g} m/s")
    what = "leaving a T-pose" if up[0] else "moving faster than a body can (a blend out of a converter's rest pose)"
    note = f"{_where(trial, 0, last, motion.fps, first_frame)}: the file starts {what} (" + "; ".join(seen) + ")"
    return CaptureFlag("tpose_settling", 0, int(last), note)


def _jumps(trial, motion, speed, start, s, first_frame) -> list[CaptureFlag]:
    """``jump`` flags: runs of steps from frame ``start`` on in which a joint moves faster than the limit."""
    if not speed.size:
        return []
    peak = speed.max(axis=1)
    fast = peak > s["max_joint_speed_m_s"]
    fast[:start] = False
    names = motion.skeleton.names
    out = []
    for a, b in _runs(fast):  # steps a..b-1: frames a..b
        k = a + int(np.argmax(peak[a:b]))
        j = names[int(np.argmax(speed[k]))]
        out.append(CaptureFlag("jump", a, b, f"{_where(trial, a, b, motion.fps, first_frame)}: joint {j!r} moves "
                                             f"{float(peak[k]):.3g} m/s between frames {k} and {k + 1}, faster than "
                                             f"a body can (limit {s['max_joint_speed_m_s']:g} m/s)"))
    return out


def _part_columns(skeleton, roles) -> list[int]:
    """Column indices of the rotation DOF of the joints playing ``roles`` ([] when fewer than two of those
    joints resolve with rotation DOF)."""
    sl = skeleton.dof_slices()
    cols, joints = [], 0
    for role in roles:
        try:
            j = skeleton[resolve_role(skeleton, role)]
        except JointRoleError:
            continue
        rot = [sl[j.name].start + k for k, d in enumerate(j.dofs) if d in ("rx", "ry", "rz")]
        joints += bool(rot)
        cols += rot
    return sorted(set(cols)) if joints >= 2 else []


def _zero_parts(trial, motion, s, first_frame, start: CaptureFlag | None) -> list[CaptureFlag]:
    """``zero_part`` flags: runs of frames where every rotation DOF of a body part is zero within the tolerance
    (a run inside the T-pose settling is that rest pose, not flagged again)."""
    v = np.asarray(motion.values, float)
    covered = np.zeros(motion.n_frames, bool)
    if start is not None:
        covered[start.first:start.last + 1] = True
    out = []
    for part, roles in BODY_PARTS.items():
        cols = _part_columns(motion.skeleton, roles)
        if not cols:
            continue
        zero = np.all(np.abs(v[:, cols]) <= s["zero_tol_deg"], axis=1)
        for a, b in _runs(zero):
            if covered[a:b].all():
                continue
            out.append(CaptureFlag("zero_part", a, b - 1, f"{_where(trial, a, b - 1, motion.fps, first_frame)}: "
                                                           f"{part.replace('_', ' ')} at exactly zero on all its "
                                                           f"{len(cols)} rotation DOF (within "
                                                           f"{s['zero_tol_deg']:g} degrees): a gap, not a pose"))
        covered |= zero
    return out


def _frozen(trial, motion, s, first_frame) -> list[CaptureFlag]:
    """``frozen`` flags: runs of frames equal to the frame before on every DOF, at least ``frozen_min_s`` long."""
    v = np.asarray(motion.values, float)
    same = np.concatenate([[False], np.all(v[1:] == v[:-1], axis=1)]) if len(v) else np.zeros(0, bool)
    need = max(1, math.ceil(s["frozen_min_s"] * float(motion.fps) - 1e-9))
    return [CaptureFlag("frozen", a, b - 1, f"{_where(trial, a, b - 1, motion.fps, first_frame)}: every DOF repeats "
                                            f"frame {a - 1} exactly (a held pose; limit {s['frozen_min_s']:g} s)")
            for a, b in _runs(same) if b - a >= need]


def check_capture(motion: Motion, trial: str, cfg: dict, first_frame: int = 0) -> CaptureCheck:
    """Flag the frames of one trial that no body made (module docstring).

    Parameters
    ----------
    motion : Motion
        The parsed trial at its own rate (after the record's ``first_frame``), in the canonical frame (+y up);
        its skeleton's roles (config ``joint_roles``) name the shoulders and the body parts.
    trial : str
        The trial id, named in every note.
    cfg : dict
        The ``capture_check`` config block: :data:`CONFIG_KEYS`.
    first_frame : int
        The record's ``first_frame`` (frames the file has before ``motion``'s frame 0); notes then also give
        the file's frame numbers.

    Returns
    -------
    CaptureCheck
        ``usable`` (frames,) False on every flagged frame; ``flags`` by first frame.

    Raises
    ------
    ConfigError
        A key of ``cfg`` missing or not a finite number >= 0.
    """
    s = _settings(cfg)
    first_frame = int(first_frame)
    ends = forward_kinematics(motion.skeleton, motion.values, ends=True) * float(motion.skeleton.length_to_m)
    speed = np.linalg.norm(np.diff(ends, axis=0), axis=2) * float(motion.fps)  # (frames - 1, joints) m/s
    start = _settling(trial, motion, speed, _arms_raised_deg(motion, ends), s, first_frame)
    flags = [start] if start else []
    flags += _zero_parts(trial, motion, s, first_frame, start)
    flags += _jumps(trial, motion, speed, start.last if start else 0, s, first_frame)
    flags += _frozen(trial, motion, s, first_frame)
    flags.sort(key=lambda f: (f.first, KINDS.index(f.kind)))
    usable = np.ones(motion.n_frames, bool)
    for f in flags:
        usable[f.first:f.last + 1] = False
        log.info("%s", f.note)
    return CaptureCheck(str(trial), float(motion.fps), usable, flags, first_frame)


def checks_table(checks: list[CaptureCheck]) -> pd.DataFrame:
    """One row per flag of every check, and one row (``kind`` ``none``) for a trial without flags.

    Columns: ``trial``, ``fps``, ``frames`` (the motion's), ``usable_frames``, ``kind``, ``first_frame`` and
    ``last_frame`` (0-based, inclusive, at ``fps``; empty for ``none``), ``flagged_frames``, ``file_first_frame``
    (``first_frame`` plus the frames the record dropped), ``note``. Rows in the order of ``checks``, then by
    first frame.
    """
    rows = []
    for c in checks:
        base = {"trial": c.trial, "fps": c.fps, "frames": c.n_frames, "usable_frames": int(c.usable.sum())}
        if not c.flags:
            rows.append(dict(base, kind="none", first_frame=None, last_frame=None, flagged_frames=0,
                             file_first_frame=None, note=f"{c.trial}: all {c.n_frames} frames usable"))
        for f in c.flags:
            rows.append(dict(base, kind=f.kind, first_frame=f.first, last_frame=f.last, flagged_frames=f.n_frames,
                             file_first_frame=f.first + c.first_frame, note=f.note))
    table = pd.DataFrame(rows, columns=TABLE_COLUMNS)
    for col in ("first_frame", "last_frame", "file_first_frame"):
        table[col] = table[col].astype("Int64")
    return table
