"""Metrics that score a generated motion against the capture it was built from.

Pure numpy functions (scipy where it helps). Every length is in metres, every speed in m/s, every acceleration
in m/s^2; the vertical axis is y (:data:`UP`), as in CMU ASF/AMC and BVH. ``docs/compare.md`` (section
"Metrics") defines each metric, names its source and says where ours differs from it.

The metric list
    :data:`METRICS` (every column of ``metrics.csv`` with its unit and which way is better),
    :data:`METRIC_NAMES`, :data:`SENSITIVITY_SPEEDS`: read by the scoring job, the tables, the verdicts and the
    figures, which therefore never import the jobs (nor, through them, the generators)

Positions and features
    :func:`positions` (forward kinematics in metres), :func:`foot_indices`, :func:`facing`,
    :func:`body_frame`, :func:`pose_features`, :func:`global_quaternions`, :func:`align_quaternions`
Foot skating
    :func:`floor_height`, :func:`foot_skating`, :func:`skating_ratio` (GMD's)
Transitions and per-frame jumps
    :func:`jump_reference`, :func:`seam_jumps`, :func:`frame_jumps`
Smoothness
    :func:`speed_profile`, :func:`ldlj` (log dimensionless jerk), :func:`sparc` (spectral arc length)
Against a ground truth (LAFAN1 benchmark)
    :func:`position_stats`, :func:`l2p`, :func:`l2q`, :func:`npss`
Against the database
    :func:`window_nearest`, :func:`window_scores`, :func:`coverage`, :func:`local_diversity`,
    :func:`seed_diversity`, :func:`novelty`

Frame distance: the windows, novelty and diversity metrics compare :func:`pose_features` rows, scaled so that
the Euclidean distance of two rows is the root-mean-square distance of corresponding joints (metres) in the body
frame (horizontal centroid removed, facing aligned).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..joints import FOOT_ROLES, resolve_roles
from ..kinematics import HORIZONTAL as _KIN_HORIZONTAL
from ..kinematics import UP as _KIN_UP
from ..kinematics import facing as _hip_facing
from ..kinematics import forward_kinematics

__all__ = [
    "METRICS", "METRIC_NAMES", "SENSITIVITY_SPEEDS",
    "UP", "positions", "foot_indices", "facing", "body_frame", "pose_features",
    "global_quaternions", "align_quaternions", "floor_height", "foot_skating", "skating_ratio", "JumpReference",
    "jump_reference", "seam_jumps", "frame_jumps", "capture_max_jumps", "speed_profile", "ldlj", "sparc",
    "position_stats", "l2p", "l2q", "npss", "window_nearest",
    "window_scores", "coverage", "local_diversity", "seed_diversity", "novelty",
]

#: the skating threshold sensitivity speeds (m/s) of the ``*_at_<speed>`` columns
SENSITIVITY_SPEEDS = (0.15, 0.3, 0.5)
#: every metric column of metrics.csv: (column, unit, which way is better: "lower", "higher" or "" for
#: a descriptive number)
METRICS = (
    ("contact_share", "share of foot joint-frames", ""),
    ("skate_share", "share of contact joint-frames", "lower"),
    ("skate_m_per_contact_frame", "m", "lower"),
    ("transition_skate_share", "share of contact joint-frames near seams", "lower"),
    ("skating_ratio_gmd", "share of frame steps (GMD)", "lower"),
    *((f"skate_share_at_{v:g}", f"share of contact joint-frames, {v:g} m/s", "") for v in SENSITIVITY_SPEEDS),
    *((f"skating_ratio_gmd_at_{v:g}", f"share of frame steps (GMD), {v:g} m/s", "") for v in SENSITIVITY_SPEEDS),
    ("velocity_jump_p95", "m/s", "lower"),
    ("velocity_jump_max", "m/s", "lower"),
    ("velocity_jump_over_capture", "share of frames", "lower"),
    ("accel_jump_p95", "m/s^2", "lower"),
    ("accel_jump_max", "m/s^2", "lower"),
    ("accel_jump_over_capture", "share of frames", "lower"),
    ("n_seams", "seams", ""),
    ("seams_per_s", "1/s", ""),
    ("transitions_kept", "transitions before pruning", ""),
    # at the seams a generator reports (secondary: they trust the generator's own seams)
    ("velocity_jump", "m/s", ""),
    ("velocity_jump_ratio", "x capture median", ""),
    ("velocity_jump_pct", "percentile in capture", ""),
    ("accel_jump", "m/s^2", ""),
    ("accel_jump_ratio", "x capture median", ""),
    ("accel_jump_pct", "percentile in capture", ""),
    ("ldlj", "log dimensionless jerk", "higher"),
    ("sparc", "spectral arc length", "higher"),
    ("l2p", "LAFAN1 L2P (run statistics)", "lower"),
    ("l2p_m", "m", "lower"),
    ("l2q", "LAFAN1 L2Q", "lower"),
    ("npss", "NPSS", "lower"),
    ("coverage", "share of database windows", "higher"),
    ("local_diversity_m", "m", ""),
    ("seed_diversity_m", "m", "higher"),
    ("novelty_median_m", "m", ""),
    ("copy_share", "share of frames", ""),
)
METRIC_NAMES = [m for m, _u, _b in METRICS]
#: Index of the vertical axis (y up: the canonical frame of :mod:`animsynth.kinematics`).
UP = _KIN_UP
#: Indices of the horizontal axes (x, z).
_HORIZONTAL = list(_KIN_HORIZONTAL)
_NAN = float("nan")


# ---------------------------------------------------------------------------------------------------------------
# positions and features
# ---------------------------------------------------------------------------------------------------------------
def positions(motion) -> np.ndarray:
    """World joint positions in metres.

    Parameters
    ----------
    motion : Motion

    Returns
    -------
    ndarray, shape (T, J, 3)
        The *end* of every joint's segment (:func:`animsynth.kinematics.forward_kinematics` with
        ``ends=True``: for an ASF bone its tip, so the foot roles give the ball and the toe tip), times
        ``skeleton.length_to_m``.
    """
    sk = motion.skeleton
    return forward_kinematics(sk, motion.values, ends=True) * float(sk.length_to_m)


def foot_indices(skeleton, overrides: dict | None = None) -> np.ndarray:
    """Indices of the :data:`animsynth.joints.FOOT_ROLES` joints (left ankle, left toe, right ankle, right toe).

    Parameters
    ----------
    skeleton : Skeleton
    overrides : dict, optional
        ``{role: joint name}`` (config ``joint_roles``), over the skeleton's own :attr:`roles`.

    Returns
    -------
    ndarray of int, shape (4,)

    Raises
    ------
    animsynth.joints.JointRoleError
        A role has no joint (the message names the role and the joints available).
    """
    return np.array([skeleton.index(n) for n in resolve_roles(skeleton, FOOT_ROLES, overrides)], dtype=np.int64)


def facing(motion, overrides: dict | None = None) -> np.ndarray:
    """Horizontal facing direction of the body per frame, from the hips and the up axis.

    ``cross(left_hip - right_hip, up)`` from the world positions of the hip-role joints, projected onto the
    floor (:func:`animsynth.kinematics.facing`, the one definition the workflow uses): it does not depend on
    the root's rotation convention or the rest pose. A frame whose hips are vertically aligned takes the
    facing of the nearest frame that has one.

    Parameters
    ----------
    motion : Motion
    overrides : dict, optional
        Joint-role overrides (``left_hip``, ``right_hip``).

    Returns
    -------
    ndarray, shape (T, 2)
        Unit vectors ``(x, z)``.
    """
    return _hip_facing(motion.skeleton, motion.values, overrides, name=motion.name)


def _rotate_to(v: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """Rotate vectors ``v (..., 3)`` about the vertical so that ``forward (..., 2)`` (x, z) becomes +z."""
    fx, fz = forward[..., 0], forward[..., 1]
    out = np.empty_like(v)
    out[..., 0] = (fz * v[..., 0] - fx * v[..., 2])
    out[..., 1] = v[..., 1]
    out[..., 2] = (fx * v[..., 0] + fz * v[..., 2])
    return out


def body_frame(pos: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """Joint positions in the body frame: horizontal centroid removed, facing turned to +z.

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
        Metres.
    forward : ndarray, shape (T, 2)
        Unit facing vectors (:func:`facing`).

    Returns
    -------
    ndarray, shape (T, J, 3)
        Height (y) unchanged: a floating or sunken body stays distinguishable.
    """
    pos = np.asarray(pos, float)
    forward = np.asarray(forward, float)
    if forward.shape != (pos.shape[0], 2):
        raise ValueError(f"forward has shape {forward.shape}, expected ({pos.shape[0]}, 2)")
    p = pos.copy()
    p[:, :, _HORIZONTAL] -= p[:, :, _HORIZONTAL].mean(axis=1, keepdims=True)
    return _rotate_to(p, forward[:, None, :])


def pose_features(pos: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """Per-frame pose features: :func:`body_frame` flattened and divided by ``sqrt(J)``.

    The Euclidean distance between two rows is the root-mean-square distance of corresponding joints (m).

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
    forward : ndarray, shape (T, 2)

    Returns
    -------
    ndarray, shape (T, 3 J)
    """
    b = body_frame(pos, forward)
    return b.reshape(b.shape[0], -1) / np.sqrt(b.shape[1])


def align_quaternions(q: np.ndarray, ref: np.ndarray | None = None) -> np.ndarray:
    """Choose the sign of unit quaternions (``q`` and ``-q`` are one rotation).

    Parameters
    ----------
    q : ndarray, shape (T, J, 4)
    ref : ndarray, shape (T, J, 4), optional
        ``None``: continuous over time (each frame in the hemisphere of the previous one, as LAFAN1 prepares
        its data). Given: each quaternion in the hemisphere of ``ref`` at the same frame and joint (the
        nearest of the two signs).

    Returns
    -------
    ndarray, shape (T, J, 4)
    """
    q = np.asarray(q, float)
    if ref is not None:
        ref = np.asarray(ref, float)
        if ref.shape != q.shape:
            raise ValueError(f"quaternion arrays differ in shape: {q.shape} vs {ref.shape}")
        return np.where((np.sum(q * ref, axis=-1) < 0)[..., None], -q, q)
    if q.shape[0] < 2:
        return q.copy()
    step = np.where(np.sum(q[1:] * q[:-1], axis=-1) < 0, -1.0, 1.0)
    sign = np.concatenate([np.ones((1,) + step.shape[1:]), np.cumprod(step, axis=0)])
    return q * sign[..., None]


def global_quaternions(motion) -> np.ndarray:
    """World rotation of every joint as unit quaternions, scalar last, continuous over time.

    Parameters
    ----------
    motion : Motion

    Returns
    -------
    ndarray, shape (T, J, 4)
    """
    _, W = forward_kinematics(motion.skeleton, motion.values, world_rotations=True)
    return align_quaternions(np.stack([r.as_quat() for r in W], axis=1))


# ---------------------------------------------------------------------------------------------------------------
# foot skating
# ---------------------------------------------------------------------------------------------------------------
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

    Where ours still differs from GMD's (unavoidable; ``docs/compare.md``, "Foot skating"): the steps are at
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
    speed = np.linalg.norm(np.diff(P[:, :, _HORIZONTAL], axis=0), axis=-1) * fps  # (T-1, feet)
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
    step = np.linalg.norm(np.diff(P[:, :, _HORIZONTAL], axis=0), axis=-1)
    skate = contact & (step * fps > speed_m_s)
    n = int(contact.sum())
    return {
        "contact_share": n / contact.size,
        "skate_share": float(skate.sum()) / n if n else _NAN,
        "skate_m_per_contact_frame": float(step[skate].sum()) / n if n else _NAN,
    }


# ---------------------------------------------------------------------------------------------------------------
# transitions
# ---------------------------------------------------------------------------------------------------------------
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


# ---------------------------------------------------------------------------------------------------------------
# smoothness
# ---------------------------------------------------------------------------------------------------------------
def speed_profile(pos, fps: float) -> np.ndarray:
    """Mean joint speed per step (m/s).

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
    fps : float

    Returns
    -------
    ndarray, shape (T-1,)
        ``mean_j |p_j(t) - p_j(t-1)| * fps`` for ``t = 1 .. T-1``.
    """
    pos = np.asarray(pos, float)
    if pos.ndim != 3:
        raise ValueError(f"pos must have shape (T, J, 3), got {pos.shape}")
    return np.linalg.norm(np.diff(pos, axis=0), axis=-1).mean(axis=1) * fps


def _speed(x, fps) -> np.ndarray:
    x = np.asarray(x, float)
    v = speed_profile(x, fps) if x.ndim == 3 else x
    if v.ndim != 1:
        raise ValueError(f"expected a speed profile (N,) or positions (T, J, 3), got shape {x.shape}")
    return v


def ldlj(x, fps: float) -> float:
    """Log dimensionless jerk of a speed profile (Balasubramanian et al. 2015).

    ``LDLJ = -ln( (t2 - t1)^3 / v_peak^2 * integral (d^2 v / dt^2)^2 dt )`` with the second derivative by
    second differences and the integral by the rectangle rule; the duration is ``t2 - t1 = N / fps``, as the
    reference implementation (siva82kb/SPARC ``log_dimensionless_jerk``) takes it. Higher (closer to zero) is
    smoother; a minimum-jerk point-to-point movement gives ``-ln(204.8) = -5.322`` whatever its
    amplitude and duration (the finite differences are off by about ``5 / (duration * fps)``).

    Parameters
    ----------
    x : ndarray, shape (N,) or (T, J, 3)
        A speed profile (m/s) sampled at ``fps``, or positions (then :func:`speed_profile`).
    fps : float

    Returns
    -------
    float
        NaN for a profile of fewer than 3 samples or zero peak speed; +inf when the jerk integral is zero.
    """
    v = _speed(x, fps)
    if v.size < 3:
        return _NAN
    peak = float(np.max(np.abs(v)))
    if peak == 0.0:
        return _NAN
    duration = v.size / fps
    integral = float(np.sum((np.diff(v, 2) * fps * fps) ** 2)) / fps
    if integral == 0.0:
        return float("inf")
    return float(-np.log(duration ** 3 / peak ** 2 * integral))


def sparc(x, fps: float, pad_level: int = 4, cutoff_hz: float = 10.0, amplitude_threshold: float = 0.05) -> float:
    """Spectral arc length of a speed profile (Balasubramanian et al. 2012, 2015).

    The magnitude spectrum of the profile, zero-padded to ``2 ** (ceil(log2 N) + pad_level)`` samples and
    normalised by its value at 0 Hz, is cut at the adaptive frequency ``f_c``: the highest frequency up to
    ``cutoff_hz`` at which it is still at least ``amplitude_threshold``. SPARC is minus the arc length of that
    piece with frequency normalised by ``f_c``. Closer to zero is smoother; it does not change when the profile
    is scaled.

    Parameters
    ----------
    x : ndarray, shape (N,) or (T, J, 3)
        A speed profile (m/s) sampled at ``fps``, or positions (then :func:`speed_profile`).
    fps : float
    pad_level, cutoff_hz, amplitude_threshold
        The method's published parameters (4, 10 Hz, 0.05).

    Returns
    -------
    float
        NaN for fewer than 2 samples, a profile whose mean is zero, or a spectrum below the threshold at every
        frequency above 0 Hz.
    """
    from scipy.fft import fft

    v = _speed(x, fps)
    if v.size < 2:
        return _NAN
    n_fft = int(2 ** (int(np.ceil(np.log2(v.size))) + int(pad_level)))
    mag = np.abs(fft(v, n=n_fft))[: n_fft // 2 + 1]
    if mag[0] == 0.0:
        return _NAN
    mag = mag / mag[0]
    freq = np.arange(mag.size) * fps / n_fft
    inband = np.flatnonzero((freq <= cutoff_hz) & (mag >= amplitude_threshold))
    last = int(inband[-1])
    if last == 0:
        return _NAN
    f, m = freq[: last + 1], mag[: last + 1]
    return float(-np.sum(np.sqrt((np.diff(f) / (f[-1] - f[0])) ** 2 + np.diff(m) ** 2)))


# ---------------------------------------------------------------------------------------------------------------
# against a ground truth (LAFAN1 benchmark)
# ---------------------------------------------------------------------------------------------------------------
def position_stats(pos_list, forward_list, window: int, stride: int, context: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation of every joint coordinate over windows of the database (LAFAN1's L2P stats).

    Windows of ``window`` frames start every ``stride`` frames of each clip. Each window is moved so that the
    mean horizontal centroid of its frames is at the origin and turned about the vertical so that the facing at
    its frame ``context - 1`` (the last context frame) is +z; the statistics run over every frame of every
    window.

    Parameters
    ----------
    pos_list : sequence of ndarray, each shape (T_i, J, 3)
        Metres.
    forward_list : sequence of ndarray, each shape (T_i, 2)
        :func:`facing` of each clip.
    window, stride, context : int
        LAFAN1: 50, 20, 10 at 30 fps.

    Returns
    -------
    mean, std : ndarray, shape (J, 3)
    """
    if not 1 <= context <= window:
        raise ValueError(f"context ({context}) must lie in 1..window ({window})")
    frames = []
    for pos, fwd in zip(pos_list, forward_list):
        pos, fwd = np.asarray(pos, float), np.asarray(fwd, float)
        for s in range(0, pos.shape[0] - window + 1, stride):
            w = pos[s:s + window].copy()
            w[:, :, _HORIZONTAL] -= w[:, :, _HORIZONTAL].mean(axis=(0, 1))
            frames.append(_rotate_to(w, fwd[s + context - 1]))
    if not frames:
        raise ValueError(f"no clip has a window of {window} frames")
    allf = np.concatenate(frames)
    return allf.mean(axis=0), allf.std(axis=0)


def l2p(gen_pos, gt_pos, std, forward=None) -> float:
    """L2P: mean over frames of the L2 norm of the normalised global position error (LAFAN1).

    ``L2P = mean_t sqrt( sum_{j,c} ((gen - gt)_{t,j,c} / std_{j,c})^2 )``; the dataset mean of LAFAN1's
    normalisation cancels in the difference.

    Parameters
    ----------
    gen_pos, gt_pos : ndarray, shape (T, J, 3)
        Metres, world frame.
    std : ndarray, shape (J, 3), or None
        :func:`position_stats`; ``None``: no normalisation (the error in metres).
    forward : ndarray, shape (2,), optional
        The facing the statistics were aligned to (the ground truth's at its last context frame): the errors
        are turned into that frame before the per-coordinate normalisation. ``None``: world axes.

    Returns
    -------
    float
    """
    d = np.asarray(gen_pos, float) - np.asarray(gt_pos, float)
    if d.ndim != 3:
        raise ValueError(f"positions must have shape (T, J, 3), got {d.shape}")
    if forward is not None:
        d = _rotate_to(d, np.asarray(forward, float) / np.linalg.norm(forward))
    if std is not None:
        std = np.asarray(std, float)
        if std.shape != d.shape[1:]:
            raise ValueError(f"std has shape {std.shape}, expected {d.shape[1:]}")
        if np.any(std <= 0):
            raise ValueError("std has a zero entry: a joint coordinate never varies in the database windows")
        d = d / std
    return float(np.mean(np.sqrt(np.sum(d ** 2, axis=(1, 2)))))


def l2q(gen_q, gt_q) -> float:
    """L2Q: mean over frames of the L2 norm of the global quaternion error (LAFAN1), sign-aligned.

    Each generated quaternion takes the sign nearer the ground truth's (:func:`align_quaternions`), so one
    joint rotated by ``theta`` from the truth adds ``(2 sin(theta / 4))^2`` under the square root.

    Parameters
    ----------
    gen_q, gt_q : ndarray, shape (T, J, 4)
        Unit global quaternions (:func:`global_quaternions`).

    Returns
    -------
    float
    """
    gt_q = np.asarray(gt_q, float)
    d = align_quaternions(gen_q, gt_q) - gt_q
    return float(np.mean(np.sqrt(np.sum(d ** 2, axis=(1, 2)))))


def npss(gen, gt, spectrum: str = "real", quaternions: bool = False) -> float:
    """NPSS: normalised power spectrum similarity (Gopalakrishnan et al. 2019, as in the LAFAN1 benchmark).

    Per feature dimension ``d`` (trailing axes flattened) the power over the FFT bins along time is
    normalised to sum to 1; the earth mover's distance between the ground truth's and the generated
    cumulative spectra is the L1 norm of their difference (in bins); NPSS is the average of the EMDs weighted
    by the ground truth's total power per dimension. Lower is more similar; 0 for identical signals.

    Parameters
    ----------
    gen, gt : ndarray, shape (T, ...)
        One generated sequence and its ground truth (LAFAN1: global quaternions, (T, J, 4)).
    spectrum : {"real", "power"}
        ``"real"``: the square of the real part of the FFT, what the LAFAN1 benchmark and the authors' code
        compute; ``"power"``: ``|FFT|^2``, the power spectrum of the paper's text (invariant to a circular
        time shift).
    quaternions : bool
        Inputs are quaternions (T, J, 4): ``gt`` is made continuous over time and ``gen`` takes the sign of
        ``gt`` per frame and joint before the spectra (:func:`align_quaternions`).

    Returns
    -------
    float
        Dimensions whose ground truth has zero power carry zero weight and are left out; a generated dimension
        with zero power has a zero cumulative spectrum. NaN when every ground-truth dimension has zero power.
    """
    from scipy.fft import fft

    gen, gt = np.asarray(gen, float), np.asarray(gt, float)
    if gen.shape != gt.shape:
        raise ValueError(f"generated and ground-truth shapes differ: {gen.shape} vs {gt.shape}")
    if quaternions:
        gt = align_quaternions(gt)
        gen = align_quaternions(gen, gt)
    gen, gt = gen.reshape(gen.shape[0], -1), gt.reshape(gt.shape[0], -1)
    if spectrum == "real":
        pg, pt = np.real(fft(gen, axis=0)) ** 2, np.real(fft(gt, axis=0)) ** 2
    elif spectrum == "power":
        pg, pt = np.abs(fft(gen, axis=0)) ** 2, np.abs(fft(gt, axis=0)) ** 2
    else:
        raise ValueError(f"spectrum must be 'real' or 'power', got {spectrum!r}")
    tg, tt = pg.sum(axis=0), pt.sum(axis=0)
    keep = tt > 0
    if not keep.any():
        return _NAN
    cg = np.cumsum(np.divide(pg, tg, out=np.zeros_like(pg), where=tg > 0), axis=0)
    ct = np.cumsum(pt[:, keep] / tt[keep], axis=0)
    emd = np.sum(np.abs(cg[:, keep] - ct), axis=0)
    return float(np.average(emd, weights=tt[keep]))


# ---------------------------------------------------------------------------------------------------------------
# against the database: windows, novelty, diversity
# ---------------------------------------------------------------------------------------------------------------
def _seq_list(x) -> list[np.ndarray]:
    if isinstance(x, np.ndarray) and x.ndim == 2:
        return [np.asarray(x, float)]
    out = [np.asarray(a, float) for a in x]
    for a in out:
        if a.ndim != 2:
            raise ValueError(f"feature sequences must have shape (T, F), got {a.shape}")
    return out


def window_nearest(a, b, length: int, block: int = 4096) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Nearest-window distances between two sets of feature sequences, both ways.

    The distance of window ``[i, i + length)`` of a sequence of ``a`` to window ``[k, k + length)`` of a
    sequence of ``b`` is the mean over its ``length`` frames of the frame distance (Euclidean distance of
    feature rows; m for :func:`pose_features`). Windows never cross the end of a sequence.

    Parameters
    ----------
    a, b : ndarray (T, F) or sequence of them
    length : int
        Window length (frames).
    block : int
        Frames of a ``b`` sequence compared at once (memory: ``len(a_i) * block`` floats).

    Returns
    -------
    a_min : list of ndarray, one per ``a`` sequence, shape (T_i - length + 1,)
        Distance of each window of ``a`` to its nearest window of ``b`` (inf if ``b`` has none).
    b_min : list of ndarray, one per ``b`` sequence, shape (T_k - length + 1,)
        Distance of each window of ``b`` to its nearest window of ``a``.
    """
    from scipy.spatial.distance import cdist

    A, B = _seq_list(a), _seq_list(b)
    L = int(length)
    if L < 1:
        raise ValueError(f"window length must be >= 1, got {length}")
    a_min = [np.full(max(x.shape[0] - L + 1, 0), np.inf) for x in A]
    b_min = [np.full(max(y.shape[0] - L + 1, 0), np.inf) for y in B]
    step = max(int(block), 1)
    for ia, x in enumerate(A):
        na = x.shape[0] - L + 1
        if na <= 0:
            continue
        for ib, y in enumerate(B):
            nb = y.shape[0] - L + 1
            for k0 in range(0, max(nb, 0), step):
                k1 = min(k0 + step, nb)
                D = cdist(x, y[k0:k1 + L - 1])
                C = D[0:na, 0:k1 - k0].copy()
                for m in range(1, L):
                    C += D[m:m + na, m:m + k1 - k0]
                C /= L
                np.minimum(a_min[ia], C.min(axis=1), out=a_min[ia])
                np.minimum(b_min[ib][k0:k1], C.min(axis=0), out=b_min[ib][k0:k1])
    return a_min, b_min


def window_scores(gen, db, length: int, threshold_m: float) -> dict:
    """:func:`coverage` and :func:`local_diversity` from one pass of :func:`window_nearest`.

    Returns
    -------
    dict
        ``coverage`` (share of database windows covered), ``local_diversity`` (m).
    """
    g_min, d_min = window_nearest(gen, db, length)
    d = np.concatenate([np.zeros(0), *d_min])
    g = np.concatenate([np.zeros(0), *g_min])
    return {
        "coverage": float(np.mean(d < threshold_m)) if d.size and g.size else _NAN,
        "local_diversity": float(g.mean()) if g.size and d.size else _NAN,
    }


def coverage(gen, db, length: int, threshold_m: float) -> float:
    """Share of database windows whose nearest generated window lies closer than ``threshold_m`` (GANimator).

    Parameters
    ----------
    gen : ndarray (T, F) or sequence of them
        Generated feature sequences (:func:`pose_features`); several seeds are pooled.
    db : ndarray (T, F) or sequence of them
        The database clips' features.
    length : int
        Window length (frames).
    threshold_m : float
        Mean frame distance (m) below which a window counts as covered.

    Returns
    -------
    float
        In [0, 1]; NaN when either side has no window.
    """
    return window_scores(gen, db, length, threshold_m)["coverage"]


def local_diversity(gen, db, length: int) -> float:
    """Mean distance (m) of each generated window to its nearest database window (GANimator's local diversity).

    Parameters
    ----------
    gen, db : ndarray (T, F) or sequence of them
    length : int

    Returns
    -------
    float
        0 for a generator that replays database windows; NaN when either side has no window.
    """
    return window_scores(gen, db, length, np.inf)["local_diversity"]


def seed_diversity(features) -> float:
    """Mean distance (m) between the outputs of different seeds from one start, frame by frame.

    ``mean over seed pairs (a, b) of mean_t |f_a(t) - f_b(t)|`` over the frames both have (an average
    pairwise distance in the manner of DLow's APD).

    Parameters
    ----------
    features : sequence of ndarray, each shape (T_s, F)
        :func:`pose_features` of each seed's output.

    Returns
    -------
    float
        0 when every seed gives the same motion; NaN for fewer than two seeds.
    """
    F = _seq_list(features)
    if len(F) < 2:
        return _NAN
    vals = []
    for i in range(len(F)):
        for j in range(i + 1, len(F)):
            n = min(F[i].shape[0], F[j].shape[0])
            vals.append(np.linalg.norm(F[i][:n] - F[j][:n], axis=1).mean())
    return float(np.mean(vals))


def novelty(gen, db, tolerance_m: float) -> dict:
    """Distance of each generated frame to its nearest database frame.

    Parameters
    ----------
    gen : ndarray (T, F) or sequence of them
        Generated :func:`pose_features`.
    db : ndarray (T, F) or sequence of them
        The database's features.
    tolerance_m : float
        A generated frame whose nearest database frame is at most this far (m) counts as a copy.

    Returns
    -------
    dict
        ``novelty_median_m`` (median nearest-frame distance, m), ``copy_share`` (share of generated frames
        that are copies).
    """
    from scipy.spatial import cKDTree

    G, D = _seq_list(gen), _seq_list(db)
    g, d = np.concatenate(G), np.concatenate(D)
    if g.shape[0] == 0 or d.shape[0] == 0:
        return {"novelty_median_m": _NAN, "copy_share": _NAN}
    if g.shape[1] != d.shape[1]:
        raise ValueError(f"generated features have {g.shape[1]} columns, the database's {d.shape[1]}")
    dist, _ = cKDTree(d).query(g, k=1)
    return {"novelty_median_m": float(np.median(dist)), "copy_share": float(np.mean(dist <= tolerance_m))}
