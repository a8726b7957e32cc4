"""Metrics that score a generated motion against the capture it was built from.

Pure numpy functions (scipy where it helps). Every length is in metres, every speed in m/s, every acceleration
in m/s^2; the vertical axis is y (:data:`UP`), as in CMU ASF/AMC and BVH. ``docs/compare/metrics.md`` defines each
metric, names its source and says where ours differs from it. This package gathers them; each concern is a module of
its own, imported on first use of one of its names. Each measure module declares the records of its columns (unit,
direction, what each needs, the computation that gives it, its tracks: :class:`~.metric_record.Metric`) beside
their computations, in a tuple ``RECORDS``; the metric table (:mod:`.metric_table`) collects them into the columns
of ``metrics.csv``, and a new module that declares ``RECORDS`` joins it without an edit elsewhere.

Positions and features (:mod:`.pose`)
    :func:`positions` (forward kinematics in metres), :func:`positions_and_quaternions` (and the world rotations,
    one pass), :func:`foot_indices`, :func:`facing`, :func:`body_frame`,
    :func:`pose_features`, :func:`global_quaternions`, :func:`align_quaternions`
What a measure is given (:mod:`.scored`)
    :class:`ScoredMotion` (one generated motion and the intermediates its measures share), :class:`RunOutputs`
    (one generator's run on a clip, every seed)
Foot skating (:mod:`.skating`)
    :func:`floor_height`, :func:`foot_skating`, :func:`skating_ratio` (GMD's)
Per-frame jumps (:mod:`.jumps`) and the generator's seams and transitions (:mod:`.transitions`)
    :func:`jump_reference`, :func:`seam_jumps`, :func:`frame_jumps`, :func:`capture_max_jumps`
Smoothness (:mod:`.smoothness`)
    :func:`speed_profile`, :func:`ldlj` (log dimensionless jerk), :func:`sparc` (spectral arc length)
Against a ground truth, the LAFAN1 benchmark (:mod:`.ground_truth`)
    :func:`position_stats`, :func:`l2p`, :func:`l2q`, :func:`npss`
Against the database (:mod:`.windows`)
    :func:`window_nearest`, :func:`window_scores`, :func:`coverage`, :func:`local_diversity`,
    :func:`seed_diversity`, :func:`novelty`
Long runs (:mod:`.repetition`, :mod:`.root`, :mod:`.over_time`)
    :func:`repetition_share`, :func:`still_frames`, :func:`root_tilt_deg`, :func:`drift_share`,
    :func:`coverage_after`

Frame distance: the windows, novelty, repetition and diversity metrics compare :func:`pose_features` rows, scaled
so that the Euclidean distance of two rows is the root-mean-square distance of corresponding joints (metres) in the
body frame (horizontal centroid removed, facing aligned).
"""

from __future__ import annotations

from ..._lazy import lazy_exports

_MODULES = {
    ".ground_truth": ("l2p", "l2q", "npss", "position_stats"),
    ".jumps": ("JumpReference", "capture_max_jumps", "frame_jumps", "jump_reference", "seam_jumps"),
    ".pose": ("HORIZONTAL", "UP", "align_quaternions", "body_frame", "facing", "foot_indices",
                   "global_quaternions", "pose_features", "positions", "positions_and_quaternions"),
    ".scored": ("ScoredMotion", "RunOutputs"),
    ".skating": ("floor_height", "foot_skating", "skating_ratio"),
    ".smoothness": ("ldlj", "sparc", "speed_profile"),
    ".windows": ("coverage", "local_diversity", "novelty", "seed_diversity", "window_nearest", "window_scores"),
    ".repetition": ("repetition_share",),
    ".root": ("still_frames", "root_tilt_deg", "drift_share"),
    ".over_time": ("coverage_after",),
}
# name -> module; imported on first use
__all__, __getattr__, __dir__ = lazy_exports(__name__, {n: m for m, names in _MODULES.items() for n in names})
