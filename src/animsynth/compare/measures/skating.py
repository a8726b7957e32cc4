"""Foot skating: the floor height, the share of contact frames in which a foot slides (ours) and GMD's skating
ratio. Metres and m/s; the vertical axis is y."""

from __future__ import annotations

import numpy as np

from .metric_record import SENSITIVITY_SPEEDS, Metric, at_speed
from .pose import HORIZONTAL, UP

__all__ = ["floor_height", "foot_skating", "skating_ratio", "score_foot_skating", "score_skating_ratio_gmd",
           "score_skating_sensitivity", "score_transition_skating", "SKATE_SHARE", "SKATING_RATIO_GMD",
           "SENSITIVITY_METRICS", "RECORDS"]

_NAN = float("nan")


def floor_height(pos_list, foot_idx, percentile: float = 0.0) -> float:
    """The floor height (m): the ``percentile`` percentile of every foot joint's height over every frame of a
    set of motions (0: the lowest height any foot joint reaches).

    A low percentile (the compare family's default: 1) is robust to a few frames of a foot poking through
    the floor, which would otherwise lower the floor for the whole database (on CMU r2 the minimum is 2 mm
    where the 1st percentile is 1.7 cm).

    Parameters
    ----------
    pos_list : sequence of ndarray, each shape (T_i, J, 3)
    foot_idx : array of int
    percentile : float
        In [0, 100].

    Returns
    -------
    float
    """
    idx = np.asarray(foot_idx, dtype=np.int64)
    if not 0.0 <= float(percentile) <= 100.0:
        raise ValueError(f"percentile must lie in [0, 100], got {percentile!r}")
    h = np.concatenate([np.asarray(p, float)[:, idx, UP].ravel() for p in pos_list])
    return float(np.percentile(h, float(percentile)))


def skating_ratio(pos, fps: float, foot_idx, height_m: float = 0.05, speed_m_s: float = 0.5,
                  floor_m: float | None = None, window: int = 5) -> float:
    """GMD's skating ratio (Karunratanakul et al. 2023, Guided Motion Diffusion; after its evaluation code,
    ``calculate_skating_ratio`` in ``data_loaders/humanml/utils/metrics.py`` of korrawe/guided-motion-diffusion).

    Two foot joints (GMD: SMPL's left and right foot, joints 10 and 11, at the ball of each foot; here the
    ``left_ankle`` and ``right_ankle`` roles, whose segment ends are the balls of the feet). Per foot and frame
    step ``(t-1, t)``: *contact* when the height above the floor is below ``height_m`` in **both** frames;
    the foot *skates* on the step when, in contact, both the step's horizontal speed and that speed's mean over
    a centred ``window``-step box (zeros beyond the ends, as ``scipy.ndimage.uniform_filter1d(mode="constant")``)
    exceed ``speed_m_s``. A frame step skates when **either** foot skates on it; the ratio is the skating
    frame steps over **all** ``T - 1`` frame steps (not over contact steps as :func:`foot_skating`'s share, and
    not over joint-steps: one foot skating on every step gives 1, not 1/2).

    Where ours still differs from GMD's (unavoidable; ``docs/compare/metrics.md``, "Foot skating"): the steps are at
    the motion's own rate (the compare family's working rate, 30 fps on CMU) where GMD's are at HumanML3D's
    20 fps, so a step's speed is over 1/30 s and the 5-step mean spans 1/6 s instead of 1/4 s (the thresholds
    are m/s, so they carry over); the floor is the caller's (the compare family: the database's, as for
    :func:`foot_skating`) where GMD's samples stand on HumanML3D's floor (y = 0: each training clip shifted so
    that its lowest joint is at 0); and GMD scores every sample at its padded length of 196 frames, we the
    frames given.

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
        Metres, ``T >= 2``.
    fps : float
    foot_idx : array of int, shape (2,)
        The two feet (any number of foot joints is accepted; a step skates when any of them skates).
    height_m, speed_m_s : float
        GMD: 0.05 m, 0.5 m/s.
    floor_m : float, optional
        Floor height (m); ``None``: 0 (GMD's data stand on y = 0).
    window : int
        GMD: 5 steps.

    Returns
    -------
    float
        Skating frame steps / ``T - 1``.
    """
    from scipy.ndimage import uniform_filter1d

    pos = np.asarray(pos, float)
    if pos.ndim != 3 or pos.shape[0] < 2:
        raise ValueError(f"pos must have shape (T >= 2, J, 3), got {pos.shape}")
    P = pos[:, np.asarray(foot_idx, dtype=np.int64)]
    h = P[:, :, UP] - (0.0 if floor_m is None else float(floor_m))
    speed = np.linalg.norm(np.diff(P[:, :, HORIZONTAL], axis=0), axis=-1) * fps  # (T-1, feet)
    mean = uniform_filter1d(speed, size=int(window), axis=0, mode="constant")
    contact = (h[:-1] < height_m) & (h[1:] < height_m)
    skate = (contact & (speed > speed_m_s) & (mean > speed_m_s)).any(axis=1)  # either foot, (T-1,)
    return float(skate.sum()) / skate.size


def foot_skating(pos, fps: float, foot_idx, height_m: float, speed_m_s: float, floor_m: float | None = None) -> dict:
    """Contact share, skate share and skate distance of the foot joints.

    A foot joint is *in contact* at frame ``t`` (``t >= 1``) when its height above the floor is below
    ``height_m``; it *skates* there when, in addition, its horizontal speed (its horizontal displacement from
    ``t-1`` to ``t`` times ``fps``) exceeds ``speed_m_s``. Every foot joint and frame counts once.

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
        Metres (:func:`positions`), ``T >= 2``.
    fps : float
    foot_idx : array of int, shape (F,)
        The foot joints (:func:`foot_indices`).
    height_m : float
        Contact height threshold (m).
    speed_m_s : float
        Skating speed threshold (m/s).
    floor_m : float, optional
        Floor height (m); ``None``: the lowest foot height of ``pos`` itself. The compare family passes the
        database's floor (:func:`floor_height`) unless the config names one.

    Returns
    -------
    dict
        ``contact_share`` (contact joint-frames / all joint-frames), ``skate_share`` (skating / contact
        joint-frames; NaN without contact), ``skate_m_per_contact_frame`` (summed horizontal displacement of
        the skating joint-frames / contact joint-frames, m; NaN without contact).
    """
    pos = np.asarray(pos, float)
    if pos.ndim != 3 or pos.shape[0] < 2:
        raise ValueError(f"pos must have shape (T >= 2, J, 3), got {pos.shape}")
    P = pos[:, np.asarray(foot_idx, dtype=np.int64)]
    floor = float(P[:, :, UP].min()) if floor_m is None else float(floor_m)
    contact = (P[1:, :, UP] - floor) < height_m
    step = np.linalg.norm(np.diff(P[:, :, HORIZONTAL], axis=0), axis=-1)
    skate = contact & (step * fps > speed_m_s)
    n = int(contact.sum())
    return {
        "contact_share": n / contact.size,
        "skate_share": float(skate.sum()) / n if n else _NAN,
        "skate_m_per_contact_frame": float(step[skate].sum()) / n if n else _NAN,
    }


# ----------------------------------------------------------------------------- the records' computations
# Each takes a :class:`~.scored.ScoredMotion` ``s``: every generated frame is scored with the step into it from the
# frame before (the start's last frame for the first), against the clip's floor (``s.ref.floor``).


def _contact_speed(s) -> tuple[float, float]:
    return s.setting("contact_height_m"), s.setting("skate_speed_m_s")


def _gmd_feet(s) -> np.ndarray:
    return s.ref.foot_idx[[0, 2]]  # left_ankle, right_ankle: the balls of the feet


def score_foot_skating(s) -> dict:
    """``contact_share``, ``skate_share``, ``skate_m_per_contact_frame`` (:func:`foot_skating`) of ``s``."""
    height, speed = _contact_speed(s)
    return foot_skating(s.pos[s.context - 1:], s.fps, s.ref.foot_idx, height, speed, s.ref.floor)


def score_skating_ratio_gmd(s) -> dict:
    """``skating_ratio_gmd`` (:func:`skating_ratio`, the balls of the feet) of ``s``."""
    height, speed = _contact_speed(s)
    return {"skating_ratio_gmd": skating_ratio(s.pos[s.context - 1:], s.fps, _gmd_feet(s), height, speed, s.ref.floor)}


def score_skating_sensitivity(s) -> dict:
    """The skate share and the GMD-style ratio of ``s`` at every speed threshold of
    :data:`~.metric_record.SENSITIVITY_SPEEDS` (``<name>_at_<speed>``)."""
    height, pos, out = s.setting("contact_height_m"), s.pos[s.context - 1:], {}
    for v in SENSITIVITY_SPEEDS:
        out[at_speed("skate_share", v)] = foot_skating(pos, s.fps, s.ref.foot_idx, height, v, s.ref.floor)["skate_share"]
        out[at_speed("skating_ratio_gmd", v)] = skating_ratio(pos, s.fps, _gmd_feet(s), height, v, s.ref.floor)
    return out


def score_transition_skating(s) -> dict:
    """``transition_skate_share``: the skate share of the frames within ``compare.metrics.transition_window`` of a
    seam of ``s``, pooled over its seams (contact joint-frames near seams; NaN without any)."""
    height, speed = _contact_speed(s)
    w, c = int(s.mcfg["transition_window"]), s.context
    n_contact = n_skate = 0.0
    for seam in s.seams:
        lo, hi = c + max(int(seam) - w, 0), c + min(int(seam) + w, s.n_frames - 1)
        part = foot_skating(s.pos[lo - 1:hi + 1], s.fps, s.ref.foot_idx, height, speed, s.ref.floor)
        nc = part["contact_share"] * (hi - lo + 1) * len(s.ref.foot_idx)
        n_contact += nc
        n_skate += (part["skate_share"] * nc) if nc else 0.0
    return {"transition_skate_share": n_skate / n_contact if n_contact else _NAN}


# ----------------------------------------------------------------------------- the records
SKATE_SHARE = Metric("skate_share", "share of contact joint-frames", "lower", "floor", "skate share",
                     "foot skating: share of contact frames", exploratory=True, skating_claim=True,
                     margin=0.05, margin_why="5 percentage points of contact joint-frames: in a 2-s walk (about four "
                     "stances of 15 frames) some 3 more sliding frames per foot joint, about the smallest slide an "
                     "animator would go in to fix", compute="skating:score_foot_skating")
SKATING_RATIO_GMD = Metric("skating_ratio_gmd", "share of frame steps (GMD)", "lower", "floor", "GMD skating ratio",
                           "skating ratio (GMD-style)", margin=0.05,
                           margin_why="5 percentage points of frame steps, as for the skate share",
                           compute="skating:score_skating_ratio_gmd")
_SENSITIVITY = (SKATE_SHARE, SKATING_RATIO_GMD)
#: the skating metrics measured again at each of :data:`~.metric_record.SENSITIVITY_SPEEDS` (the
#: ``<name>_at_<speed>`` columns, :func:`~.metric_record.at_speed`: no direction, the unit of the metric at that speed)
SENSITIVITY_METRICS = tuple(m.name for m in _SENSITIVITY)
#: this module's columns, in their order in ``metrics.csv``
RECORDS = (
    Metric("contact_share", "share of foot joint-frames", "", "floor", compute="skating:score_foot_skating"),
    SKATE_SHARE,
    Metric("skate_m_per_contact_frame", "m", "lower", "floor", compute="skating:score_foot_skating"),
    Metric("transition_skate_share", "share of contact joint-frames near seams", "lower", "seams",
           "skate share near seams", "skating near seams: share", exploratory=True, skating_claim=True, margin=0.05,
           margin_why="5 percentage points of the contact joint-frames near seams, as for the skate share",
           compute="skating:score_transition_skating"),
    SKATING_RATIO_GMD,
    *(Metric(at_speed(m.name, v), f"{m.unit}, {v:g} m/s", "", m.needs, compute="skating:score_skating_sensitivity")
      for m in _SENSITIVITY for v in SENSITIVITY_SPEEDS),
)
