"""Jumps between frames: the velocity and acceleration jump at each seam a generator reports, relative to the
capture's own frame-to-frame jumps, and at every generated frame against the held-out capture's largest."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .metric_record import Metric

__all__ = ["JumpReference", "jump_reference", "seam_jumps", "frame_jumps", "capture_max_jumps", "score_frame_jumps",
           "score_jumps_over_capture", "VELOCITY_JUMP_P95", "RECORDS"]

_NAN = float("nan")


def _jumps(pos: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame velocity jump (T-2,) for t = 2..T-1 and acceleration jump (T-3,) for t = 3..T-1."""
    pos = np.asarray(pos, float)
    if pos.ndim != 3:
        raise ValueError(f"pos must have shape (T, J, 3), got {pos.shape}")
    v = np.diff(pos, axis=0) * fps  # v[t-1] = velocity into frame t
    dv = np.diff(v, axis=0)  # dv[t-2] = v_t - v_{t-1} (m/s)
    da = np.diff(dv * fps, axis=0)  # da[t-3] = a_t - a_{t-1} (m/s^2)
    return np.linalg.norm(dv, axis=-1).mean(axis=1), np.linalg.norm(da, axis=-1).mean(axis=1)


@dataclass(frozen=True)
class JumpReference:
    """The capture's own distribution of frame-to-frame jumps (:func:`jump_reference`).

    Attributes
    ----------
    velocity : ndarray, shape (N_v,)
        Sorted velocity jumps (m/s) of every frame of every reference clip.
    accel : ndarray, shape (N_a,)
        Sorted acceleration jumps (m/s^2).
    """

    velocity: np.ndarray
    accel: np.ndarray


def jump_reference(pos_list, fps: float) -> JumpReference:
    """The velocity and acceleration jump of every frame of the reference clips (no jump across clips).

    Parameters
    ----------
    pos_list : sequence of ndarray, each shape (T_i, J, 3)
        Metres, at ``fps``.
    fps : float

    Returns
    -------
    JumpReference
    """
    vs, acs = zip(*(_jumps(p, fps) for p in pos_list)) if len(pos_list) else ((), ())
    v = np.sort(np.concatenate([np.zeros(0), *vs]))
    a = np.sort(np.concatenate([np.zeros(0), *acs]))
    if v.size == 0 or a.size == 0:
        raise ValueError("the jump reference needs at least one clip of >= 4 frames")
    return JumpReference(v, a)


def _pct(sorted_ref: np.ndarray, x: np.ndarray) -> np.ndarray:
    return 100.0 * np.searchsorted(sorted_ref, x, side="right") / sorted_ref.size


def seam_jumps(pos, fps: float, seams, reference) -> dict:
    """Velocity and acceleration jump at each seam, absolute and relative to the capture's distribution.

    With ``v_t = (p_t - p_{t-1}) fps`` and ``a_t = (v_t - v_{t-1}) fps`` per joint (world positions), the
    velocity jump at frame ``t`` is the mean over joints of ``|v_t - v_{t-1}|`` (m/s, frames ``t-2..t``) and
    the acceleration jump the mean over joints of ``|a_t - a_{t-1}|`` (m/s^2, frames ``t-3..t``). A seam ``t``
    (frame ``t`` does not follow frame ``t-1`` in the source) is measured at ``t``; a seam too close to the
    start for a stencil (t < 2, resp. t < 3) is left out of that measure.

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
        Metres.
    fps : float
    seams : array of int
        Frame indices in ``1 .. T-1`` (``Motion.meta["seams"]``).
    reference : JumpReference or sequence of ndarray (T_i, J, 3)
        The database clips (or their :func:`jump_reference`), at ``fps``.

    Returns
    -------
    dict
        ``n_seams``; ``velocity_jump`` (mean over seams, m/s), ``velocity_jump_ratio`` (over the median of
        the reference), ``velocity_jump_pct`` (mean over seams of the percentile rank, 0-100, in the
        reference); the same for ``accel_jump`` (m/s^2). NaN when no seam can be measured.
    """
    pos = np.asarray(pos, float)
    ref = reference if isinstance(reference, JumpReference) else jump_reference(reference, fps)
    T = pos.shape[0]
    s = np.unique(np.asarray(seams, dtype=np.int64).ravel())
    if s.size and (s.min() < 1 or s.max() > T - 1):
        raise ValueError(f"seams must lie in 1..{T - 1} for a motion of {T} frames, got {s.min()}..{s.max()}")
    jv, ja = _jumps(pos, fps)
    out: dict = {"n_seams": int(s.size)}
    for key, vals, first, dist in (("velocity", jv, 2, ref.velocity), ("accel", ja, 3, ref.accel)):
        x = vals[s[s >= first] - first]
        if x.size == 0:
            out[f"{key}_jump"] = out[f"{key}_jump_ratio"] = out[f"{key}_jump_pct"] = _NAN
            continue
        med = float(np.median(dist))
        m = float(x.mean())
        out[f"{key}_jump"] = m
        out[f"{key}_jump_ratio"] = m / med if med > 0 else _NAN
        out[f"{key}_jump_pct"] = float(_pct(dist, x).mean())
    return out


def frame_jumps(pos, fps: float, first: int, capture_max: tuple[float, float]) -> dict:
    """The velocity and acceleration jump of **every** frame from ``first`` on, whatever a generator reports
    as its seams (:func:`seam_jumps` measures only there).

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
        Metres: the start and the generated frames joined (the stencils of the first generated frames reach
        into the start).
    fps : float
    first : int
        The first frame measured (the first generated frame).
    capture_max : (float, float)
        The held-out capture's own largest velocity jump (m/s) and acceleration jump (m/s^2) at the same rate
        (:func:`_jumps` over its frames).

    Returns
    -------
    dict
        ``velocity_jump_p95``, ``velocity_jump_max`` (m/s), ``velocity_jump_over_capture`` (share of the
        measured frames whose jump exceeds the capture's largest); the same for ``accel_jump`` (m/s^2).
    """
    jv, ja = _jumps(pos, fps)
    out = {}
    for key, vals, lag, cmax in (("velocity", jv, 2, capture_max[0]), ("accel", ja, 3, capture_max[1])):
        x = vals[max(int(first), lag) - lag:]
        if x.size == 0:
            out[f"{key}_jump_p95"] = out[f"{key}_jump_max"] = out[f"{key}_jump_over_capture"] = _NAN
            continue
        out[f"{key}_jump_p95"] = float(np.percentile(x, 95))
        out[f"{key}_jump_max"] = float(x.max())
        out[f"{key}_jump_over_capture"] = float(np.mean(x > float(cmax)))
    return out


def capture_max_jumps(pos, fps: float) -> tuple[float, float]:
    """The largest velocity jump (m/s) and acceleration jump (m/s^2) of one capture (:func:`frame_jumps`)."""
    jv, ja = _jumps(pos, fps)
    if jv.size == 0 or ja.size == 0:
        raise ValueError("the capture needs at least 4 frames for its largest jumps")
    return float(jv.max()), float(ja.max())


# ----------------------------------------------------------------------------- the records' computations


def _frame_jumps(s) -> dict:
    """:func:`frame_jumps` of every generated frame of ``s`` (a :class:`~.scored.ScoredMotion`), once per motion."""
    return s.shared("frame_jumps", lambda s: frame_jumps(s.pos, s.fps, s.context, s.ref.capture_max))


def score_frame_jumps(s) -> dict:
    """The 95th percentile and the largest velocity and acceleration jump of the generated frames of ``s``."""
    return _frame_jumps(s)


def score_jumps_over_capture(s) -> dict:
    """The share of the generated frames of ``s`` jumping more than the held-out capture's largest jump."""
    return _frame_jumps(s)


# ----------------------------------------------------------------------------- the records
VELOCITY_JUMP_P95 = Metric(
    "velocity_jump_p95", "m/s", "lower", "", "per-frame velocity jump p95 (m/s)",
    "per-frame velocity jump: 95th percentile (m/s)", exploratory=True, margin=0.2,
    margin_why="a change of joint velocity of 0.2 m/s within one frame (7 mm of position at 30 fps), about half of a "
               "capture's own 95th percentile: smaller pops hide in the capture's own noise",
    compute="jumps:score_frame_jumps")
#: this module's columns, in their order in ``metrics.csv``
RECORDS = (
    VELOCITY_JUMP_P95,
    Metric("velocity_jump_max", "m/s", "lower", "", compute="jumps:score_frame_jumps"),
    Metric("velocity_jump_over_capture", "share of frames", "lower", "reference",
           "frames above the capture's largest jump", "share of frames jumping more than the capture's largest",
           compute="jumps:score_jumps_over_capture"),
    Metric("accel_jump_p95", "m/s^2", "lower", "", compute="jumps:score_frame_jumps"),
    Metric("accel_jump_max", "m/s^2", "lower", "", compute="jumps:score_frame_jumps"),
    Metric("accel_jump_over_capture", "share of frames", "lower", "reference", compute="jumps:score_jumps_over_capture"),
)
