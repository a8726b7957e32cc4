"""Measured smoothness of a re-sequenced motion (what the paper judged by eye).

All measures are computed on the *played* motion (:func:`~animsynth.generator.play_path`)
and, for reference, on the original trial:

* **pose jumps**: per step, the pose distance ``sqrt(sum_j theta_j^2)`` where
  ``theta_j`` is the rotation angle (radians, full angle) between the two
  frames' local rotations of non-root joint ``j``. Reported as ratios to the
  original's mean, 95th percentile and maximum.
* **joint-angle jerk**: the third time derivative of the joint rotations,
  from body-frame angular velocities ``omega_t = 2 log(q_t^{-1} q_{t+1}) * fps``
  (rad/s), differenced twice (rad/s^3); per frame the norm over all non-root
  joints; reported as the mean (and ratio to the original's mean) and as the
  number of *jerk events*: frames whose jerk exceeds the largest jerk of the
  original trial (a visible jerk that the capture never contains).
* **root sliding**: reversals of the root's forward speed (horizontal root
  velocity projected on the heading), counting sign changes among frames whose
  speed exceeds ``speed_threshold`` (m/s); a count per played motion (the
  original's rate per second is given for reference).
* **foot skate**: mean horizontal speed (m/s) of the foot joints (ball and
  toe tip of each foot) while in contact: height within ``contact_height`` of
  that joint's ground -- its lowest height in the original trial -- at both
  ends of the step.
"""

from __future__ import annotations

import logging

import numpy as np

from ..kinematics import forward_kinematics, local_rotations, quaternions, root_translation
from .features import relative_log

log = logging.getLogger("animsynth.resequencing")

__all__ = ["joint_quats", "transitions", "pass_jumps", "classify_path", "TransitionReference", "transition_measures",
           "pose_steps", "jerk_magnitude", "root_reversals", "foot_ground", "foot_skate", "Reference", "smoothness"]


def joint_quats(motion) -> np.ndarray:
    """Local quaternions (frames, joints, 4) of the non-root joints with rotational DOF."""
    sk = motion.skeleton
    q = quaternions(sk, motion.values)
    keep = [i for i, j in enumerate(sk.joints) if i > 0 and j.rot_dofs]
    return q[:, keep, :]


def pose_steps(q) -> np.ndarray:
    """Pose distance between consecutive frames (radians), ``q`` (frames, joints, 4) -> (frames-1,)."""
    q = np.asarray(q, float)
    if q.shape[0] < 2:
        return np.zeros(0)
    theta = 2.0 * np.linalg.norm(relative_log(q[:-1], q[1:]), axis=-1)  # (F-1, J), full angle
    return np.sqrt(np.sum(theta ** 2, axis=1))


def jerk_magnitude(q, fps: float) -> np.ndarray:
    """Norm over joints of the angular jerk (rad/s^3) per frame, (frames-3,)."""
    q = np.asarray(q, float)
    if q.shape[0] < 4:
        return np.zeros(0)
    omega = 2.0 * relative_log(q[:-1], q[1:]) * fps  # (F-1, J, 3) rad/s
    jerk = np.diff(omega, n=2, axis=0) * fps * fps
    return np.sqrt(np.sum(jerk ** 2, axis=(1, 2)))


def root_reversals(motion, speed_threshold: float = 0.1) -> int:
    """Number of reversals of the root's forward speed (see module docstring)."""
    sk = motion.skeleton
    n = motion.values.shape[0]
    if n < 3:
        return 0
    p = root_translation(sk, motion.values) * sk.length_to_m
    R = local_rotations(sk, motion.values)[0]
    f = R.apply(np.array([0.0, 0.0, 1.0]))[:, [0, 2]]
    f /= np.maximum(np.linalg.norm(f, axis=1, keepdims=True), 1e-12)
    v = np.diff(p[:, [0, 2]], axis=0) * motion.fps
    s = np.sum(v * f[:-1], axis=1)
    sig = np.sign(s[np.abs(s) > speed_threshold])
    return int(np.count_nonzero(sig[1:] != sig[:-1]))


def foot_joints(skeleton) -> tuple[str, ...]:
    """The joints of :data:`animsynth.joints.FOOT_ROLES` in ``skeleton`` (raises JointRoleError naming a missing
    role)."""
    from ..joints import FOOT_ROLES, resolve_roles

    return tuple(resolve_roles(skeleton, FOOT_ROLES))


def _foot_positions(motion, joints):
    sk = motion.skeleton
    if joints is None:
        joints = foot_joints(sk)
    pos = forward_kinematics(sk, motion.values) * sk.length_to_m
    return pos[:, [sk.index(j) for j in joints], :]


def foot_joints_of(motion) -> tuple[str, ...]:
    return foot_joints(motion.skeleton)


def foot_ground(motion, joints=None) -> np.ndarray:
    """Lowest height (metres) of each foot joint over a motion: its ground level."""
    return _foot_positions(motion, joints)[:, :, 1].min(axis=0)


def foot_skate(motion, ground, contact_height: float = 0.02, joints=None) -> tuple[float, float]:
    """Mean horizontal foot speed during contact (m/s) and the fraction of contact steps.

    A foot joint is in contact on a step when its height is within
    ``contact_height`` of its ``ground`` (per joint, from the original trial)
    at both ends of the step. Returns ``(nan, 0.0)`` when no joint is ever in contact.
    """
    P = _foot_positions(motion, joints)
    if P.shape[0] < 2:
        return float("nan"), 0.0
    contact = (P[:, :, 1] - np.asarray(ground)[None, :]) <= contact_height
    both = contact[:-1] & contact[1:]
    speed = np.linalg.norm(np.diff(P[:, :, [0, 2]], axis=0), axis=-1) * motion.fps
    frac = float(both.mean())
    if not both.any():
        return float("nan"), frac
    return float(speed[both].mean()), frac


def _ratio(a, b):
    return float(a / b) if (np.isfinite(a) and np.isfinite(b) and b > 0) else float("nan")


class Reference:
    """Measures of the original trial that re-sequenced motions are compared with."""

    def __init__(self, original, contact_height: float = 0.02, speed_threshold: float = 0.1,
                 foot_joints=None):
        self.contact_height = float(contact_height)
        self.speed_threshold = float(speed_threshold)
        self.foot_joints = foot_joints_of(original) if foot_joints is None else tuple(foot_joints)
        q = joint_quats(original)
        self.steps = pose_steps(q)
        self.jerk = jerk_magnitude(q, original.fps)
        self.ground = foot_ground(original, self.foot_joints)
        self.skate, _ = foot_skate(original, self.ground, self.contact_height, self.foot_joints)
        dur = max((original.values.shape[0] - 1) / original.fps, 1e-9)
        self.reversals_per_s = root_reversals(original, self.speed_threshold) / dur
        if self.steps.size == 0 or self.jerk.size == 0:
            raise ValueError("the original motion needs at least 4 frames")


def smoothness(reference: Reference, played, path) -> dict:
    """Smoothness measures of ``played`` (the motion of frame-index ``path``) against the original.

    * ``jump_*_ratio``: pose steps of ``played`` over the original's (mean, 95th percentile, max).
    * ``jerk_mean_ratio``: mean jerk over the original's mean jerk; ``jerk_events``:
      frames whose jerk exceeds the largest jerk of the original trial.
    * ``root_reversals`` (count in the played motion; the original's rate per second for
      reference), ``foot_skate_mps`` (and the original's).

    NaN where the path is too short (steps need 2 frames, jerk 4).
    """
    ref = reference
    path = np.asarray(path, dtype=np.int64)
    steps = np.diff(path)
    qp = joint_quats(played)
    sp = pose_steps(qp)
    jp = jerk_magnitude(qp, played.fps)
    skp, frac = foot_skate(played, ref.ground, ref.contact_height, ref.foot_joints)
    nan = float("nan")
    if path.size < 4:
        log.warning("path of %d frames: jerk needs >= 4 frames (NaN)", path.size)
    return {
        "frames": int(path.size),
        "temporal_steps": int(np.count_nonzero(np.abs(steps) == 1)),
        "backward_steps": int(np.count_nonzero(steps < 0)),
        "jumps": int(np.count_nonzero(np.abs(steps) > 1)),
        "jump_mean_ratio": _ratio(sp.mean(), ref.steps.mean()) if sp.size else nan,
        "jump_p95_ratio": _ratio(np.percentile(sp, 95), np.percentile(ref.steps, 95)) if sp.size else nan,
        "jump_max_ratio": _ratio(sp.max(), ref.steps.max()) if sp.size else nan,
        "jerk_mean": float(jp.mean()) if jp.size else nan,
        "jerk_mean_ratio": _ratio(jp.mean(), ref.jerk.mean()) if jp.size else nan,
        "jerk_events": int(np.count_nonzero(jp > ref.jerk.max())) if jp.size else nan,
        "root_reversals": root_reversals(played, ref.speed_threshold),
        "root_reversals_per_s_original": ref.reversals_per_s,
        "foot_skate_mps": skp,
        "foot_skate_original_mps": ref.skate,
        "contact_fraction": frac,
    }


def transitions(path) -> np.ndarray:
    """Indices ``t`` of the steps ``path[t-1] -> path[t]`` that are *non-temporal*
    transitions: a jump to a frame that is neither the next nor the previous one."""
    path = np.asarray(path, dtype=np.int64)
    return np.flatnonzero(np.abs(np.diff(path)) != 1) + 1


def pass_jumps(path, same_pass: int) -> np.ndarray:
    """The transitions that jump to *another pass* of the capture: ``|path[t] - path[t-1]| > same_pass``
    (the others skip or hold frames of the same pass)."""
    path = np.asarray(path, dtype=np.int64)
    return np.flatnonzero(np.abs(np.diff(path)) > int(same_pass)) + 1


def classify_path(path, same_pass: int | None = None) -> str:
    """What a path plays.

    * ``"replays"``: every step is the next frame (the capture as recorded);
    * ``"replays_backwards"``: only next/previous frames, at least one previous;
    * ``"skips"``: non-temporal transitions, but all within ``same_pass``
      frames (the capture played forwards or backwards with frames dropped
      or held) -- only when ``same_pass`` is given;
    * ``"resequences"``: at least one jump to another pass (any non-temporal
      transition when ``same_pass`` is None).
    """
    path = np.asarray(path, dtype=np.int64)
    if transitions(path).size:
        if same_pass is None or pass_jumps(path, same_pass).size:
            return "resequences"
        return "skips"
    return "replays_backwards" if np.any(np.diff(path) < 0) else "replays"


def _step_velocities(q, fps: float) -> np.ndarray:
    """Angular velocity of every forward step (rad/s, full angle): (frames-1, joints, 3)."""
    return 2.0 * relative_log(q[:-1], q[1:]) * fps


class TransitionReference:
    """The capture's typical frame-to-frame changes that transitions are judged against.

    * ``step``: mean pose step (radians, :func:`pose_steps`);
    * ``vel``: mean over the capture of ``||w_{s+1} - w_{s-1}||`` (rad/s), the
      change of the step velocity across one step -- what a transition at
      step ``s`` changes;
    * ``acc``: mean of ``||(w_{s+2} - w_{s+1}) - (w_{s-1} - w_{s-2})||``,
      the change of acceleration across one step;
    * ``skate``: the capture's mean contact foot speed (:func:`foot_skate`).
    """

    def __init__(self, original, contact_height: float = 0.02, foot_joints=None):
        q = joint_quats(original)
        if q.shape[0] < 6:
            raise ValueError("the original motion needs at least 6 frames")
        w = _step_velocities(q, original.fps)
        self.fps = float(original.fps)
        self.step = float(pose_steps(q).mean())
        self.vel = float(np.linalg.norm((w[2:] - w[:-2]).reshape(len(w) - 2, -1), axis=1).mean())
        a = np.diff(w, axis=0)  # a[s] = w[s+1] - w[s]
        self.acc = float(np.linalg.norm((a[3:] - a[:-3]).reshape(len(a) - 3, -1), axis=1).mean())
        self.contact_height = float(contact_height)
        self.foot_joints = foot_joints_of(original) if foot_joints is None else tuple(foot_joints)
        self.ground = foot_ground(original, self.foot_joints)
        self.skate, _ = foot_skate(original, self.ground, self.contact_height, self.foot_joints)


def transition_measures(reference: TransitionReference, played, full_path, first: int, last: int,
                        window: int) -> list[dict]:
    """Smoothness of every non-temporal transition of a played path.

    Parameters
    ----------
    reference : :class:`TransitionReference` of the original trial
    played : Motion of ``full_path`` (the path inside its context frames)
    full_path : int array (frames,), frame indices of ``played``
    first, last : positions in ``full_path`` of the path's first and last frame
        (the context frames outside are never counted as transitions)
    window : frames on each side of a transition for its foot-skate window

    Returns one dict per transition (position ``t`` = the step ``t-1 -> t``):
    ``pose_jump_ratio`` (the step's pose distance over the capture's mean step),
    ``velocity_jump_ratio`` (``||w_t - w_{t-2}||``, step velocities after and
    before the transition step, over the capture's same quantity),
    ``accel_jump_ratio`` (``||(w_{t+1} - w_t) - (w_{t-2} - w_{t-3})||`` over
    the capture's), ``foot_skate_ratio`` (mean contact foot speed within
    ``window`` frames of the transition over the capture's). NaN where the
    played motion has too few frames on a side.
    """
    ref = reference
    full_path = np.asarray(full_path, dtype=np.int64)
    q = joint_quats(played)
    w = _step_velocities(q, played.fps)  # w[s]: step s -> s+1
    steps = pose_steps(q)
    P = _foot_positions(played, ref.foot_joints)
    contact = (P[:, :, 1] - np.asarray(ref.ground)[None, :]) <= ref.contact_height
    both = contact[:-1] & contact[1:]
    speed = np.linalg.norm(np.diff(P[:, :, [0, 2]], axis=0), axis=-1) * played.fps
    F = q.shape[0]
    out = []
    for t in transitions(full_path[first:last + 1]) + first:
        s = t - 1  # the transition step s -> s+1 = t
        row = {"position": int(t - first), "from_frame": int(full_path[t - 1]), "to_frame": int(full_path[t]),
               "lag": int(full_path[t] - full_path[t - 1]),
               "pose_jump_ratio": _ratio(steps[s], ref.step)}
        if s - 1 >= 0 and s + 1 < F - 1:
            row["velocity_jump_ratio"] = _ratio(np.linalg.norm(w[s + 1] - w[s - 1]), ref.vel)
        else:
            row["velocity_jump_ratio"] = float("nan")
        if s - 2 >= 0 and s + 2 < F - 1:
            row["accel_jump_ratio"] = _ratio(np.linalg.norm((w[s + 2] - w[s + 1]) - (w[s - 1] - w[s - 2])), ref.acc)
        else:
            row["accel_jump_ratio"] = float("nan")
        lo, hi = max(0, s - window), min(F - 1, s + window + 1)
        sel = both[lo:hi]
        row["foot_skate_ratio"] = (_ratio(float(speed[lo:hi][sel].mean()), ref.skate) if sel.any()
                                   else float("nan"))
        out.append(row)
    return out
