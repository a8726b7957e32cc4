"""The generator's seams and transitions: how many seams it reports, the velocity and acceleration jump at each
(relative to the capture's own frame-to-frame jumps, :func:`~.jumps.seam_jumps`), and the transitions a graph
generator keeps (its :meth:`~animsynth.generator.Generator.run_notes`).

A seam is a generated frame that does not follow the frame before in the source (``Motion.meta["seams"]``); the
entry (generated frame 0) is one for every generator but ``replay`` (:attr:`~.scored.ScoredMotion.seams`). These
records trust what the generator reports: the per-frame jumps (:func:`~.jumps.frame_jumps`) measure every frame.
"""

from __future__ import annotations

from .jumps import seam_jumps
from .metric_record import Metric

__all__ = ["score_seam_count", "score_seam_jumps", "run_transitions_kept", "RECORDS"]

_SEAM_JUMPS = ("velocity_jump", "velocity_jump_ratio", "velocity_jump_pct", "accel_jump", "accel_jump_ratio",
               "accel_jump_pct")


def score_seam_count(s) -> dict:
    """``n_seams`` and ``seams_per_s`` of ``s`` (a :class:`~.scored.ScoredMotion`)."""
    return {"n_seams": int(s.seams.size), "seams_per_s": s.seams.size / (s.n_frames / s.fps)}


def score_seam_jumps(s) -> dict:
    """The velocity and acceleration jump at the seams of ``s``, absolute and against the database's own
    (``s.ref.jumps``)."""
    jumps = seam_jumps(s.pos, s.fps, s.seams + s.context, s.ref.jumps)
    return {k: jumps[k] for k in _SEAM_JUMPS}


def run_transitions_kept(run) -> dict:
    """``transitions_kept``: the candidate transitions the generator of ``run`` (a :class:`~.scored.RunOutputs`)
    keeps before pruning, from its ``run_notes()``; NaN where it gives none (a generator without transitions)."""
    return {"transitions_kept": float(run.generator.run_notes().get("transitions_kept", float("nan")))}


#: this module's columns, in their order in ``metrics.csv``; the jumps at the seams a generator reports are
#: secondary: they trust the generator's own seams
RECORDS = (
    Metric("n_seams", "seams", "", "seams", compute="transitions:score_seam_count"),
    Metric("seams_per_s", "1/s", "", "seams", compute="transitions:score_seam_count"),
    Metric("transitions_kept", "transitions before pruning", "", "generator", title="transitions kept (before pruning)",
           compute="transitions:run_transitions_kept"),
    Metric("velocity_jump", "m/s", "", "seams", "seam velocity jump (m/s)", "velocity jump at reported seams (m/s)",
           compute="transitions:score_seam_jumps"),
    Metric("velocity_jump_ratio", "x capture median", "", "seams", compute="transitions:score_seam_jumps"),
    Metric("velocity_jump_pct", "percentile in capture", "", "seams", compute="transitions:score_seam_jumps"),
    Metric("accel_jump", "m/s^2", "", "seams", compute="transitions:score_seam_jumps"),
    Metric("accel_jump_ratio", "x capture median", "", "seams", compute="transitions:score_seam_jumps"),
    Metric("accel_jump_pct", "percentile in capture", "", "seams", compute="transitions:score_seam_jumps"),
)
