"""Measures along a long run: how much of the database a generator has reached after 5, 10 and 20 s, and its
foot skating and per-frame jumps in the first and in the last 2 s.

Coverage against time
    ``coverage_after_<t>s``: :func:`~.windows.coverage` of the generated frames up to ``t`` seconds (the first
    ``round(t * fps)`` frames), with the windows and threshold of ``coverage``. A generator that walks on through
    the database keeps rising; one that loops over a few transitions levels off. NaN when the motion is shorter
    than ``t``.
First against last seconds
    ``skate_share_first_2s`` / ``_last_2s``: :func:`~.skating.foot_skating`'s skate share over the first and the
    last 2 s of the generated frames (each frame with the step into it); ``velocity_jump_p95_first_2s`` /
    ``_last_2s``: the 95th percentile of :func:`~.jumps.frame_jumps`'s per-frame velocity jump over the same
    frames (the stencils reach into the frames before). ``*_change``: the last minus the first, so that a claim can
    compare how generators degrade as well as how they end. NaN when the motion is shorter than twice the span (the
    first and last spans would overlap).
"""

from __future__ import annotations

import numpy as np

from .jumps import VELOCITY_JUMP_P95, frame_jumps
from .metric_record import COVERAGE_TIMES_S, EDGE_S, Metric, after_time, at_edge
from .skating import SKATE_SHARE, foot_skating
from .windows import COVERAGE, coverage

__all__ = ["coverage_after", "score_coverage_over_time", "score_skating_first_last", "score_jumps_first_last",
           "RECORDS"]

_NAN = float("nan")


def coverage_after(features, db_features, fps: float, window: int, threshold_m: float, times_s) -> dict:
    """Coverage of the database's windows by the frames up to each time.

    Parameters
    ----------
    features : ndarray, shape (T, F)
        The generated frames' pose features.
    db_features : sequence of ndarray (T_i, F)
        The database clips' pose features.
    fps : float
    window : int
        Window length (frames; shortened to a cut's frames when longer, as ``coverage`` is for a short motion).
    threshold_m : float
    times_s : sequence of float

    Returns
    -------
    dict
        ``{t: coverage}`` per time (NaN where the motion is shorter than ``t``).
    """
    F = np.asarray(features, float)
    out = {}
    for t in times_s:
        n = int(round(float(t) * float(fps)))
        out[t] = coverage(F[:n], db_features, min(int(window), n), threshold_m) if 0 < n <= F.shape[0] else _NAN
    return out


def score_coverage_over_time(s) -> dict:
    """``coverage_after_<t>s`` for every :data:`~.metric_record.COVERAGE_TIMES_S` of ``s``
    (:class:`~.scored.ScoredMotion`)."""
    cov = coverage_after(s.features, s.ref.features, s.fps, int(s.mcfg["window"]), s.setting("coverage_threshold_m"),
                         COVERAGE_TIMES_S)
    return {after_time("coverage", t): v for t, v in cov.items()}


def _edges(s) -> tuple[int, int] | None:
    """The frames of one span and the index of the last span's first generated frame (None when they overlap)."""
    n = int(round(EDGE_S * s.fps))
    return None if s.n_frames < 2 * n or n < 1 else (n, s.n_frames - n)


def _with_change(name: str, first: float, last: float) -> dict:
    return {at_edge(name, "first"): first, at_edge(name, "last"): last, at_edge(name, "change"): last - first}


def score_skating_first_last(s) -> dict:
    """``skate_share`` over the first and the last :data:`~.metric_record.EDGE_S` seconds, and their change."""
    edges = _edges(s)
    if edges is None:
        return _with_change("skate_share", _NAN, _NAN)
    n, last = edges
    c, pos = s.context, s.pos
    args = (s.fps, s.ref.foot_idx, s.setting("contact_height_m"), s.setting("skate_speed_m_s"), s.ref.floor)
    first_share = foot_skating(pos[c - 1:c + n], *args)["skate_share"]
    last_share = foot_skating(pos[c + last - 1:], *args)["skate_share"]
    return _with_change("skate_share", first_share, last_share)


def score_jumps_first_last(s) -> dict:
    """``velocity_jump_p95`` over the first and the last :data:`~.metric_record.EDGE_S` seconds, and their change."""
    edges = _edges(s)
    if edges is None:
        return _with_change("velocity_jump_p95", _NAN, _NAN)
    n, last = edges
    c, pos, none = s.context, s.pos, (_NAN, _NAN)  # the percentile reads no capture
    first_p95 = frame_jumps(pos[:c + n], s.fps, c, none)["velocity_jump_p95"]
    last_p95 = frame_jumps(pos, s.fps, c + last, none)["velocity_jump_p95"]
    return _with_change("velocity_jump_p95", first_p95, last_p95)


# ----------------------------------------------------------------------------- the records
def _edge_records(of: Metric, compute: str, why: str) -> tuple[Metric, ...]:
    """The records of ``of`` over the first and the last :data:`~.metric_record.EDGE_S` seconds and their change,
    with its unit, direction, needs and margin."""
    return tuple(Metric(at_edge(of.name, w), of.unit + (", last minus first" if w == "change" else ""), of.better,
                        of.needs, skating_claim=of.skating_claim, margin=of.margin, margin_why=why, compute=compute,
                        tracks=("long",), min_seconds=2 * EDGE_S)
                 for w in ("first", "last", "change"))


#: this module's columns of the long track's table, in their order: coverage after each time (the unit, direction
#: and margin of ``coverage``), then the skate share and the velocity jump's 95th percentile over the first and the
#: last seconds (those of the whole run's)
RECORDS = (
    *(Metric(after_time(COVERAGE.name, t), COVERAGE.unit, COVERAGE.better, COVERAGE.needs, margin=COVERAGE.margin,
             margin_why=COVERAGE.margin_why, compute="over_time:score_coverage_over_time", tracks=("long",),
             min_seconds=float(t))
      for t in COVERAGE_TIMES_S),
    *_edge_records(SKATE_SHARE, "over_time:score_skating_first_last",
                   "5 percentage points of contact joint-frames, as for the skate share over the whole run"),
    *_edge_records(VELOCITY_JUMP_P95, "over_time:score_jumps_first_last",
                   "0.2 m/s within one frame, as for the per-frame velocity jump over the whole run"),
)
