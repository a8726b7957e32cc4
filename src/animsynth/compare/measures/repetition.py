"""Repetition: the share of a motion's frames inside a window that repeats an earlier window of the same motion.

A long run of a motion graph can cycle over the same few transitions, motion matching can lock onto a short cycle,
a patch-based generator can paste the same patch again: the output then replays itself. The measure compares
every window of the output (``repetition_window_s``, 1 s) with every earlier window that does not overlap it, by
the window distance of :func:`~.windows.window_nearest` (the mean over the window's frames of the RMS joint
distance of the pose features, metres, in the body frame: where the body stands and which way it faces do not
count). A window closer than ``repetition_tolerance_m`` to an earlier one repeats it; every frame inside a
repeating window counts. A clip played three times in a row gives 2/3: its second and third playing repeat the
first.

The tolerance comes from the captures, not from any generator: over 66 CMU walk trials (every ASF/AMC walk of the
two CMU mirrors, 10,319 frames at 30 fps; ``benchmarks/capture_long_measures.py``) a capture's 1-s window never comes
closer than 1.27 cm to an earlier window of the same capture (5th percentile over the trials of each one's
closest pair 1.35 cm, median 2.1 cm): successive steps of a real walk are alike but not that alike. With 1 cm the
captures' own repetition share is 0 on every one of the 66 trials, and a replayed loop (distance 0) counts in
full. The measure is this project's; it follows the window distance of GANimator's coverage (Li et al. 2022) turned
on the motion itself.
"""

from __future__ import annotations

import numpy as np

from .metric_record import Metric

__all__ = ["earliest_repeat_distance", "repetition_share", "score_repetition", "RECORDS"]


def earliest_repeat_distance(features, window: int) -> np.ndarray:
    """The distance of each window of a motion to its nearest earlier window that does not overlap it.

    Parameters
    ----------
    features : ndarray, shape (T, F)
        Pose features (:func:`~.pose.pose_features`).
    window : int
        Window length (frames).

    Returns
    -------
    ndarray, shape (T - window + 1,)
        For the window starting at ``i``: the smallest window distance (m) to a window starting at ``k <= i -
        window``; ``inf`` where there is none (the first ``window`` windows).
    """
    from scipy.spatial.distance import cdist

    F = np.asarray(features, float)
    W = int(window)
    if F.ndim != 2 or W < 1:
        raise ValueError(f"features must have shape (T, F) and the window be >= 1 frame, got {F.shape}, {window}")
    n = F.shape[0] - W + 1
    if n <= 0:
        return np.zeros(0)
    D = cdist(F, F)
    C = D[:n, :n].copy()
    for m in range(1, W):  # window distance: the frame distances summed along the diagonals
        C += D[m:m + n, m:m + n]
    C /= W
    earlier = np.tri(n, n, -W, dtype=bool)  # k <= i - W: the earlier window ends before this one starts
    return np.where(earlier, C, np.inf).min(axis=1)


def repetition_share(features, window: int, tolerance_m: float) -> float:
    """The share of a motion's frames inside a window that repeats an earlier, non-overlapping window.

    Parameters
    ----------
    features : ndarray, shape (T, F)
        Pose features of the motion.
    window : int
        Window length (frames).
    tolerance_m : float
        A window whose distance to an earlier window (:func:`earliest_repeat_distance`) is at most this repeats it.

    Returns
    -------
    float
        In [0, 1]; NaN when the motion has fewer than two windows' frames (no window has an earlier one).
    """
    F = np.asarray(features, float)
    W = int(window)
    T = F.shape[0]
    if T < 2 * W:
        return float("nan")
    starts = np.flatnonzero(earliest_repeat_distance(F, W) <= float(tolerance_m))
    inside = np.zeros(T + 1)
    np.add.at(inside, starts, 1.0)
    np.add.at(inside, starts + W, -1.0)
    return float(np.mean(np.cumsum(inside)[:T] > 0))


def score_repetition(s) -> dict:
    """``repetition_share`` of the generated frames of ``s`` (:class:`~.scored.ScoredMotion`): windows of
    ``compare.metrics.repetition_window_s`` seconds, tolerance ``repetition_tolerance_m``."""
    window = max(int(round(s.setting("repetition_window_s") * s.fps)), 1)
    return {"repetition_share": repetition_share(s.features, window, s.setting("repetition_tolerance_m"))}


#: this module's column of the long track's table
RECORDS = (
    Metric("repetition_share", "share of frames", "lower", "", "repetition", "repetition: share of frames in a "
           "repeated window", margin=0.1, margin_why="a tenth of the run (2 s of 20 s) inside windows that replay an "
           "earlier second: one more pass of a 2-s loop, about the least a viewer notices as a loop",
           compute="repetition:score_repetition", tracks=("long",)),
)
