"""The body as a whole over a long run: standing still (freezing) and leaving the capture's root height or tilt
(drift).

Freezing
    A frame is *still* when the root's horizontal speed is below ``still_root_speed_m_s`` and the pose speed (the
    RMS joint speed in the body frame: the distance of consecutive :func:`~.pose.pose_features` rows times
    the frame rate) is below ``still_pose_speed_m_s``: the character neither travels nor moves its limbs. A
    field follower that settles into a fixed point, a motion matcher that stops, a graph stuck on a held pose
    all stand still. ``still_share`` is the share of the generated frames that are still (each with the step into
    it from the frame before); ``freezing_share`` is how far it exceeds the held-out capture's own still share
    (every held-out frame after the start, whatever their number): a generator standing where the person stood
    does not freeze. The floors come from the captures (``docs/compare/metrics.md``, "Freezing and drift").
Drift
    A frame *drifts* when its root height leaves the capture's range of root heights, widened by
    ``drift_height_tolerance_m`` on each side, or its root tilt (the angle between the root's up axis and the
    vertical, degrees) leaves the capture's range of tilts widened by ``drift_tilt_tolerance_deg``. The
    capture's ranges are over every frame of the clip's database and of its held-out trial (the same subject on
    the same skeleton). ``drift_share`` is the share of the generated frames that drift: a root sinking into the
    floor, floating up, or a body keeling over.

Both measures are this project's; the still share follows the usual "standing" labels of locomotion data (speed
below a floor), the drift the root-height sanity checks of motion synthesis papers, here against the capture's
own range.
"""

from __future__ import annotations

import numpy as np

from .metric_record import Metric
from .pose import HORIZONTAL, UP

__all__ = ["root_speed", "pose_speed", "still_frames", "root_tilt_deg", "drift_share", "score_still",
           "score_freezing", "score_drift", "RECORDS"]

_NAN = float("nan")


def root_speed(pos, fps: float) -> np.ndarray:
    """Horizontal speed of the root joint (joint 0) per frame step, m/s, shape (T - 1,), from (T, J, 3) positions."""
    p = np.asarray(pos, float)[:, 0, HORIZONTAL]
    return np.linalg.norm(np.diff(p, axis=0), axis=-1) * float(fps)


def pose_speed(features, fps: float) -> np.ndarray:
    """RMS joint speed in the body frame per frame step, m/s, shape (T - 1,), from (T, F) pose features."""
    return np.linalg.norm(np.diff(np.asarray(features, float), axis=0), axis=-1) * float(fps)


def still_frames(pos, features, fps: float, root_floor_m_s: float, pose_floor_m_s: float) -> np.ndarray:
    """Which frame steps are still: root horizontal speed below ``root_floor_m_s`` and pose speed below
    ``pose_floor_m_s``.

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
        Metres; joint 0 is the root.
    features : ndarray, shape (T, F)
        The same frames' pose features.
    fps : float
    root_floor_m_s, pose_floor_m_s : float

    Returns
    -------
    ndarray of bool, shape (T - 1,)
        Frame ``t + 1`` (the step into it) is still.
    """
    return (root_speed(pos, fps) < root_floor_m_s) & (pose_speed(features, fps) < pose_floor_m_s)


def root_tilt_deg(skeleton, values) -> np.ndarray:
    """The angle (degrees) between the root's up axis and the vertical, per frame, shape (T,).

    The root's world rotation applied to the up axis (y): 0 for a root as upright as in the rest pose."""
    from ...kinematics import root_rotation

    up = np.zeros(3)
    up[UP] = 1.0
    return np.degrees(np.arccos(np.clip(root_rotation(skeleton, values).apply(up)[:, UP], -1.0, 1.0)))


def drift_share(height, tilt, height_range, tilt_range, height_tol_m: float, tilt_tol_deg: float) -> float:
    """The share of frames whose root height or root tilt leaves the capture's range, widened by the tolerances.

    Parameters
    ----------
    height, tilt : ndarray, shape (T,)
        Root height (m) and root tilt (degrees) of the scored frames.
    height_range, tilt_range : (float, float)
        The capture's smallest and largest root height and tilt.
    height_tol_m, tilt_tol_deg : float
        The widening on each side.

    Returns
    -------
    float
        In [0, 1]; NaN for no frame.
    """
    h, a = np.asarray(height, float), np.asarray(tilt, float)
    if h.size == 0:
        return _NAN
    out = ((h < height_range[0] - height_tol_m) | (h > height_range[1] + height_tol_m)
           | (a < tilt_range[0] - tilt_tol_deg) | (a > tilt_range[1] + tilt_tol_deg))
    return float(np.mean(out))


def _still_share(pos, facing, s) -> float:
    """The still share of frames ``1:`` of ``pos`` (each with the step from the frame before)."""
    from .pose import pose_features

    if pos.shape[0] < 2:
        return _NAN
    still = still_frames(pos, pose_features(pos, facing), s.fps, s.setting("still_root_speed_m_s"),
                         s.setting("still_pose_speed_m_s"))
    return float(np.mean(still))


def _generated_still_share(s) -> float:
    c = s.context
    return _still_share(s.pos[c - 1:], s.facing[c - 1:], s)


def _capture_still_share(s) -> float:
    """The held-out capture's still share: every held-out frame after the start (memoised per clip)."""
    def compute(_ref):
        c = s.context
        return _still_share(s.ref.held_pos[c - 1:], s.ref.held_facing[c - 1:], s)

    return s.ref.shared("capture_still_share", compute)


def score_still(s) -> dict:
    """``still_share`` of the generated frames of ``s`` (:class:`~.scored.ScoredMotion`)."""
    return {"still_share": s.shared("still_share", _generated_still_share)}


def score_freezing(s) -> dict:
    """``freezing_share``: the generated frames' still share beyond the held-out capture's (0 when at most it)."""
    gen, cap = s.shared("still_share", _generated_still_share), _capture_still_share(s)
    return {"freezing_share": float(max(gen - cap, 0.0)) if np.isfinite(gen) and np.isfinite(cap) else _NAN}


def _capture_ranges(s) -> tuple:
    """The (min, max) root height and root tilt over the clip's database and held-out trial (memoised per clip)."""
    def compute(_ref):
        heights = [p[:, 0, UP] for p in (*s.ref.db_pos, s.ref.held_pos)]
        tilts = [root_tilt_deg(m.skeleton, m.values) for m in (*s.clip.database, s.clip.held_out)]
        h, a = np.concatenate(heights), np.concatenate(tilts)
        return (float(h.min()), float(h.max())), (float(a.min()), float(a.max()))

    return s.ref.shared("capture_root_ranges", compute)


def score_drift(s) -> dict:
    """``drift_share`` of the generated frames of ``s``: root height or tilt outside the capture's ranges."""
    height_range, tilt_range = _capture_ranges(s)
    tilt = root_tilt_deg(s.motion.skeleton, s.motion.values)
    return {"drift_share": drift_share(s.generated_pos[:, 0, UP], tilt, height_range, tilt_range,
                                       s.setting("drift_height_tolerance_m"), s.setting("drift_tilt_tolerance_deg"))}


#: this module's columns of the long track's table, in their order
RECORDS = (
    Metric("still_share", "share of frames", "", "", compute="root:score_still", tracks=("long",)),
    Metric("freezing_share", "share of frames beyond the capture's", "lower", "reference", "freezing",
           "freezing: still beyond the capture", margin=0.05, margin_why="1 s of a 20-s run standing still where the "
           "person moved: a stop a user sees as the character getting stuck", compute="root:score_freezing",
           tracks=("long",)),
    Metric("drift_share", "share of frames", "lower", "database", "drift", "drift: root height or tilt outside the "
           "capture's range", margin=0.05, margin_why="1 s of a 20-s run with the body sunk, floating or keeled over "
           "beyond anything the capture does", compute="root:score_drift", tracks=("long",)),
)
