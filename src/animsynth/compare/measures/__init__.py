"""Metrics that score a generated motion against the capture it was built from.

Pure numpy functions (scipy where it helps). Every length is in metres, every speed in m/s, every acceleration
in m/s^2; the vertical axis is y (:data:`UP`), as in CMU ASF/AMC and BVH. ``docs/compare.md`` (section
"Metrics") defines each metric, names its source and says where ours differs from it. This module gathers them;
each concern is a module of its own. The columns of ``metrics.csv`` (unit, direction, what each needs) are the
metric table, :mod:`.metric_table`.

Positions and features (:mod:`.positions`)
    :func:`positions` (forward kinematics in metres), :func:`positions_and_quaternions` (and the world rotations,
    one pass), :func:`foot_indices`, :func:`facing`, :func:`body_frame`,
    :func:`pose_features`, :func:`global_quaternions`, :func:`align_quaternions`
Foot skating (:mod:`.skating`)
    :func:`floor_height`, :func:`foot_skating`, :func:`skating_ratio` (GMD's)
Transitions and per-frame jumps (:mod:`.jumps`)
    :func:`jump_reference`, :func:`seam_jumps`, :func:`frame_jumps`, :func:`capture_max_jumps`
Smoothness (:mod:`.smoothness`)
    :func:`speed_profile`, :func:`ldlj` (log dimensionless jerk), :func:`sparc` (spectral arc length)
Against a ground truth, the LAFAN1 benchmark (:mod:`.ground_truth`)
    :func:`position_stats`, :func:`l2p`, :func:`l2q`, :func:`npss`
Against the database (:mod:`.windows`)
    :func:`window_nearest`, :func:`window_scores`, :func:`coverage`, :func:`local_diversity`,
    :func:`seed_diversity`, :func:`novelty`

Frame distance: the windows, novelty and diversity metrics compare :func:`pose_features` rows, scaled so that
the Euclidean distance of two rows is the root-mean-square distance of corresponding joints (metres) in the body
frame (horizontal centroid removed, facing aligned).
"""

from __future__ import annotations

from .ground_truth import l2p, l2q, npss, position_stats
from .jumps import JumpReference, capture_max_jumps, frame_jumps, jump_reference, seam_jumps
from .positions import (HORIZONTAL, UP, align_quaternions, body_frame, facing, foot_indices, global_quaternions,
                        pose_features, positions, positions_and_quaternions)
from .skating import floor_height, foot_skating, skating_ratio
from .smoothness import ldlj, sparc, speed_profile
from .windows import coverage, local_diversity, novelty, seed_diversity, window_nearest, window_scores

__all__ = [
    "UP", "HORIZONTAL", "positions", "positions_and_quaternions", "foot_indices", "facing", "body_frame", "pose_features",
    "global_quaternions", "align_quaternions", "floor_height", "foot_skating", "skating_ratio", "JumpReference",
    "jump_reference", "seam_jumps", "frame_jumps", "capture_max_jumps", "speed_profile", "ldlj", "sparc",
    "position_stats", "l2p", "l2q", "npss", "window_nearest",
    "window_scores", "coverage", "local_diversity", "seed_diversity", "novelty",
]
