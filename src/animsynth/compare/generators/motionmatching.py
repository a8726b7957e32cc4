"""Motion matching (Clavet 2016; the baseline of Holden et al. 2020, "Learned Motion Matching").

A reimplementation written from the papers and the documented constants of Holden's MIT-licensed
reference (github.com/orangeduck/Motion-Matching); no code copied. The estimator follows the common
interface of :mod:`animsynth.compare.generators.registry` (``fit(database)``, ``generate(start, length, seed)``).

Features (every database frame, in the frame's own root frame: the root's ground point turned so that
its facing, :func:`animsynth.kinematics.rotation_heading` of :func:`animsynth.kinematics.rest_forward`, is +Z; metres and m/s):

==========================  ====  ======  ==========================================================
group                       dims  weight  what
==========================  ====  ======  ==========================================================
left, right foot position   3+3   0.75    the ankle joints (roles ``left_ankle`` / ``right_ankle``)
left, right foot velocity   3+3   1       backward difference (a clip's first frame: its second's)
hip velocity                3     1       the root joint
trajectory positions        6     1       root ground position (x, z) 1/3, 2/3 and 1 s ahead
trajectory directions       6     1.5     facing direction (x, z) at the same times
==========================  ====  ======  ==========================================================

Trajectory frames beyond a clip's end are clamped to its last frame (as the reference). Each group's
columns are centred and divided by the group's mean per-dimension standard deviation, then multiplied
by the group's weight (the trajectory groups' weights times ``trajectory_weight``; 0: the ablation row
that matches on the pose only). The cost is the squared Euclidean distance.

Search (the reference's loop): a search every ``search_s`` (0.1 s) and whenever the current clip
ends; its query is the current database frame's pose features (at the first search: the start's last
frame's own) with the query trajectory. The current frame continues unless a candidate is strictly
cheaper; candidates are every database frame except each clip's last ``exclude_s`` (1/3 s) and, in
the current clip, the frames within ``exclude_s`` of the current frame. After a match on frame ``j``
the character plays ``j + 1, j + 2, ...``.

Inertialization (at every switch, the start's entry included): the offset between the pose shown
and the matched frame (joint rotations, root tilt and height, root ground velocity and turning rate
in the facing frame), and between their velocities, decays by the critically damped spring of the
reference (:func:`animsynth.kinematics.decay_spring`, half-life ``inertialize_halflife_s`` = 0.1 s) and is added to every
played frame. The root is integrated from the start's last frame with the played frames' own ground
steps and turns (offsets included).

Query trajectory (the protocol: every generator sees only the start): a steady "gamepad" from the
start only. The desired ground velocity is the start's mean root velocity (its displacement over its
duration, m/s), zero when slower than ``deadzone_m_s`` (0.2 m/s), held for the whole rollout; the
desired facing is its direction (no velocity: the start's last facing). At each search the future
positions and facings come from the reference's springs (:func:`animsynth.kinematics.spring_position`,
:func:`animsynth.kinematics.spring_angle`, half-life ``trajectory_halflife_s`` = 0.27 s) started from the generated root's
position, velocity (backward difference; acceleration taken as zero) and facing and turning rate.
``generate(..., trajectory=motion)`` replaces the gamepad with a given future (the known-answer tests:
a clip's own continuation), its root positions and facings read relative to the generated root.

Query protocols (the rows of the compare family): ``motion_matching`` (the gamepad from the start),
``motion_matching_pose`` (trajectory weights 0: the pose only) and ``motion_matching_traj``
(:class:`MotionMatchingTrajectory`, ``query = "future_trajectory"``): the query trajectory is the held-out
future itself, which the runner passes as ``trajectory``. That row sees information no other generator sees
(where the capture went next): it measures how well the database and the matching follow a known path, not
how a generator continues a start on its own.

Foot locking and leg IK (``foot_lock=True``, the reference's default ``ik_enabled``;
:mod:`animsynth.compare.generators.footlock`): the database's frames are labelled in contact where the foot's contact
point (the end of the ankle role's segment: the ball of the foot, the reference's toe bone) moves slower
than ``contact_speed_m_s`` (0.15 m/s), median-filtered over ``contact_filter_s`` (0.1 s; the reference: 6
frames at 60 fps). While playing, a foot whose played frame starts a contact is locked where it is (at its
median contact height in the database), stays there until its contact ends or the animation's point is more
than ``unlock_radius_m`` (0.2 m) away, and every lock and release is blended by the same critically damped
spring (``foot_lock_halflife_s``, 0.1 s); hips and knees are then turned by analytic two-bone IK so the heels
reach the targets less the animation's heel-to-contact vectors, kept ``ik_max_length_buffer_m`` (0.015 m)
short of full extension, and the feet are turned back to the animation's world orientation.
These constants are the reference's (``ik_unlock_radius``, ``ik_blending_halflife``,
``ik_max_length_buffer``, and its database script's contact speed and filter). What differs (details in
:mod:`animsynth.compare.generators.footlock`): the foot keeps the animation's world orientation instead of the heel
look-at, with no toe alignment with the floor (``ik_toe_length``); the knee turns about its own DOF axis and
the result is written back to the skeleton's Euler DOF (an ankle with two DOF drops the rest); heights
come from the database (lock height: the foot's median contact height; the floor clamp: its lowest
height) instead of a floor at 0 with ``ik_foot_height`` 0.02 m. ``foot_lock=False`` is the ablation: the
matching and blending alone (exactly the output of this class before foot locking was added).

Departures from the reference: offline, so there is no separate simulated character, no trajectory
adjustment or clamping of the character to the simulation and no bounding-box acceleration of the search
(brute force over at most a few thousand frames). Deterministic: the seed is not used (seed diversity 0).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ...joints import resolve_roles
from ...kinematics import (forward_kinematics, ground_heading, qexp, qinv, qlog, qmul, rest_forward, wrap_radians,
                          yaw_rotation)
from ...springs import decay_spring, spring_angle, spring_position
from ...motion import Motion
from .footlock import contact_labels, contact_points, hip_knee_ankle, lock_contacts, place_feet
from ...generator import Database, Generator
from .poses import Track, decode, encode

__all__ = ["MotionMatching", "make_motion_matching", "pose_features", "trajectory_features"]


# ----------------------------------------------------------------------------- features


def _foot_joints(skeleton) -> list[int]:
    return [skeleton.index(n) for n in resolve_roles(skeleton, ("left_ankle", "right_ankle"))]


def _velocity(x: np.ndarray, fps: float) -> np.ndarray:
    """Backward differences times fps; the first row takes the second's."""
    d = np.diff(x, axis=0) * fps
    return np.concatenate([d[:1], d], axis=0)


def pose_features(motion: Motion, yaw: np.ndarray) -> np.ndarray:
    """The pose part of the features of every frame (>= 2 frames): ``(T, 15)`` = left and right foot
    positions, left and right foot velocities, hip velocity, each (x, y, z) in the frame's root frame
    (metres, m/s); ``yaw (T,)`` the frames' facing yaw (:func:`animsynth.compare.generators.poses.encode`)."""
    sk, fps = motion.skeleton, float(motion.fps)
    pos = forward_kinematics(sk, motion.values, ends=False) * float(sk.length_to_m)
    turn = yaw_rotation(-yaw)
    feet = _foot_joints(sk)
    root = pos[:, 0].copy()
    root[:, 1] = 0.0
    out = [turn.apply(pos[:, f] - root) for f in feet]
    out += [turn.apply(_velocity(pos[:, f], fps)) for f in feet]
    out.append(turn.apply(_velocity(pos[:, 0], fps)))
    return np.hstack(out)


def trajectory_features(ground: np.ndarray, yaw: np.ndarray, future_ground: np.ndarray,
                        future_yaw: np.ndarray) -> np.ndarray:
    """Future root positions and facings relative to the present: ``(T, 12)`` = 3 positions (x, z) then 3
    directions (x, z).

    ``ground (T, 2)`` and ``yaw (T,)`` the present root, ``future_ground (T, 3, 2)`` and ``future_yaw (T, 3)``
    the future ones (metres, radians)."""
    T = ground.shape[0]
    rel = future_ground - ground[:, None, :]
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    # the inverse of the yaw turn on (x, z): x' = c x - s z, z' = s x + c z
    px = c * rel[..., 0] - s * rel[..., 1]
    pz = s * rel[..., 0] + c * rel[..., 1]
    dy = future_yaw - yaw[:, None]
    pos = np.stack([px, pz], axis=-1).reshape(T, 6)
    dirs = np.stack([np.sin(dy), np.cos(dy)], axis=-1).reshape(T, 6)
    return np.hstack([pos, dirs])


#: feature groups: (name, columns, weight key)
GROUPS = (("left_foot_position", slice(0, 3), 0), ("right_foot_position", slice(3, 6), 0),
          ("left_foot_velocity", slice(6, 9), 1), ("right_foot_velocity", slice(9, 12), 1),
          ("hip_velocity", slice(12, 15), 2), ("trajectory_positions", slice(15, 21), 3),
          ("trajectory_directions", slice(21, 27), 4))


# ----------------------------------------------------------------------------- the estimator


class MotionMatching(Generator):
    """Motion matching with inertialization (Clavet 2016; Holden et al. 2020's baseline), a reimplementation.

    Parameters
    ----------
    trajectory_weight : float, multiplies the trajectory groups' weights (1: the reference; 0: pose only)
    weights : 5 floats, foot position, foot velocity, hip velocity, trajectory position, trajectory direction
        (the reference: 0.75, 1, 1, 1, 1.5)
    search_s : float, seconds between searches (0.1)
    exclude_s : float, candidates skipped at each clip's end and around the current frame (1/3 s)
    future_s : 3 floats, the trajectory times (1/3, 2/3, 1 s)
    inertialize_halflife_s : float, half-life of the transition offsets (0.1 s)
    trajectory_halflife_s : float, half-life of the gamepad springs (0.27 s)
    deadzone_m_s : float, a start slower than this asks to stand (0.2 m/s)
    foot_lock : bool, the reference's foot locking and two-bone leg IK (True, its default; False: the ablation)
    unlock_radius_m : float, a locked foot is released when the animation's is farther than this (0.2 m)
    foot_lock_halflife_s : float, half-life of the lock and release blends (0.1 s)
    ik_max_length_buffer_m : float, the IK keeps the leg this much short of full extension (0.015 m)
    contact_speed_m_s : float, a database frame's foot is in contact below this speed (0.15 m/s)
    contact_filter_s : float, median filter of the contact labels (0.1 s)

    Attributes
    ----------
    db_ : Database
    track_ : poses.Track of the database frames (clips concatenated; steps and turns within clips)
    features_ : ndarray (N, 27), normalised and weighted features
    mean_, scale_ : ndarray (27,), the normalisation (weighted feature = (raw - mean_) / scale_ * weight)
    weight_ : ndarray (27,)
    candidates_ : bool array (N,), frames a search may pick
    angular_velocity_ : ndarray (N, J + 1, 3), joint and tilt angular velocities (rad/s)
    root_velocity_ : ndarray (N, 4), derivative of height, ground velocity (x, z) and turning rate
    search_frames_, exclude_frames_, future_frames_ : the times in frames
    forward_ : ndarray (3,), the skeleton's rest forward direction (facing yaw 0)
    legs_ : int ndarray (2, 3), hip, knee and ankle joints of the left and right legs (foot locking)
    contacts_ : bool ndarray (N, 2), the database frames' contact labels (foot locking)
    contact_height_, floor_ : ndarray (2,), each foot's median contact height and lowest height (m)
    """

    name = "motion_matching"

    def __init__(self, trajectory_weight: float = 1.0, weights=(0.75, 1.0, 1.0, 1.0, 1.5), search_s: float = 0.1,
                 exclude_s: float = 1.0 / 3.0, future_s=(1.0 / 3.0, 2.0 / 3.0, 1.0), inertialize_halflife_s: float = 0.1,
                 trajectory_halflife_s: float = 0.27, deadzone_m_s: float = 0.2, foot_lock: bool = True,
                 unlock_radius_m: float = 0.2, foot_lock_halflife_s: float = 0.1, ik_max_length_buffer_m: float = 0.015,
                 contact_speed_m_s: float = 0.15, contact_filter_s: float = 0.1):
        self.trajectory_weight = trajectory_weight
        self.weights = weights
        self.search_s = search_s
        self.exclude_s = exclude_s
        self.future_s = future_s
        self.inertialize_halflife_s = inertialize_halflife_s
        self.trajectory_halflife_s = trajectory_halflife_s
        self.deadzone_m_s = deadzone_m_s
        self.foot_lock = foot_lock
        self.unlock_radius_m = unlock_radius_m
        self.foot_lock_halflife_s = foot_lock_halflife_s
        self.ik_max_length_buffer_m = ik_max_length_buffer_m
        self.contact_speed_m_s = contact_speed_m_s
        self.contact_filter_s = contact_filter_s

    # -- per-frame state -------------------------------------------------------------------------------

    def _state(self, track: Track, fps: float, m_per_unit: float):
        """Channels the inertializer works on: rotations (T, J+1, 4) (tilt first) and vectors (T, 4) = height,
        ground velocity (x, z) and turning rate (m, m/s, rad/s); with their velocities."""
        q = np.concatenate([track.tilt[:, None, :], track.rotations], axis=1)
        vec = np.column_stack([track.height * m_per_unit, track.step * m_per_unit * fps, track.turn * fps])
        return q, vec

    @staticmethod
    def _angular_velocity(q: np.ndarray, fps: float, starts=None) -> np.ndarray:
        """Backward-difference angular velocities (T, J, 3) of quaternions (T, J, 4); a clip's first frame
        takes its second's."""
        T, J, _ = q.shape
        w = np.zeros((T, J, 3))
        if T > 1:
            a = Rotation.from_quat(q[1:].reshape(-1, 4))
            b = Rotation.from_quat(q[:-1].reshape(-1, 4))
            w[1:] = (a * b.inv()).as_rotvec().reshape(T - 1, J, 3) * fps
        firsts = [0] if starts is None else starts
        for s in firsts:
            if s + 1 < T:
                w[s] = w[s + 1]
        return w

    @staticmethod
    def _vec_velocity(v: np.ndarray, fps: float, starts=None) -> np.ndarray:
        d = np.zeros_like(v)
        d[1:] = np.diff(v, axis=0) * fps
        for s in ([0] if starts is None else starts):
            if s + 1 < len(v):
                d[s] = d[s + 1]
        return d

    def fit(self, database, native_clips=None) -> "MotionMatching":
        """Build the feature database (``native_clips``: ignored, it runs at the working rate)."""
        self.db_ = db = Database(database)
        sk, fps = db.skeleton, db.fps
        if len(tuple(self.weights)) != 5:
            raise ValueError(f"motion matching: weights needs 5 values, got {self.weights!r}")
        if float(self.trajectory_weight) < 0:
            raise ValueError(f"motion matching: trajectory_weight must be >= 0, got {self.trajectory_weight}")
        self.search_frames_ = max(1, int(round(float(self.search_s) * fps)))
        self.exclude_frames_ = max(1, int(round(float(self.exclude_s) * fps)))
        self.future_frames_ = np.array([max(1, int(round(float(s) * fps))) for s in self.future_s], np.int64)
        m = float(sk.length_to_m)
        self.forward_ = fwd = rest_forward(sk)
        tracks = [encode(c, fwd) for c in db.clips]
        cat = {k: np.concatenate([getattr(t, k) for t in tracks]) for k in ("rotations", "tilt", "height", "step",
                                                                             "turn", "yaw", "ground")}
        self.track_ = Track(tracks[0].joints, **cat)
        starts = np.flatnonzero(db.frame == 0)
        stops = np.append(starts[1:], db.n_frames)  # one past each clip's last frame
        self.starts_, self.stops_ = starts, stops
        raw_pose = np.vstack([pose_features(c, t.yaw) for c, t in zip(db.clips, tracks)])
        # trajectory: frames ahead clamped to the clip's last
        idx = np.arange(db.n_frames)
        stop_of = stops[db.clip]
        ahead = np.minimum(idx[:, None] + self.future_frames_[None, :], stop_of[:, None] - 1)
        g = self.track_.ground * m
        raw = np.hstack([raw_pose, trajectory_features(g, self.track_.yaw, g[ahead], self.track_.yaw[ahead])])
        w = np.asarray(self.weights, float)
        tw = float(self.trajectory_weight)
        mean = raw.mean(axis=0)
        scale = np.ones(raw.shape[1])
        weight = np.ones(raw.shape[1])
        for _name, cols, k in GROUPS:
            s = float(raw[:, cols].std(axis=0).mean())
            scale[cols] = s if s > 1e-12 else 1.0
            weight[cols] = w[k] * (tw if k >= 3 else 1.0)
        self.mean_, self.scale_, self.weight_ = mean, scale, weight
        self.features_ = self._normalise(raw)
        self.candidates_ = db.frame < (stop_of - starts[db.clip] - self.exclude_frames_)
        if not self.candidates_.any():
            raise ValueError(f"motion matching: no database frame is a candidate (every clip is shorter than "
                             f"{self.exclude_frames_ + 1} frames at {fps:g} fps)")
        q, vec = self._state(self.track_, fps, m)
        self.rot_, self.vec_ = q, vec
        self._memo_ = None
        self.angular_velocity_ = self._angular_velocity(q, fps, starts)
        self.root_velocity_ = self._vec_velocity(vec, fps, starts)
        if self.foot_lock:
            self._fit_contacts(db)
        return self

    def _fit_contacts(self, db: Database) -> None:
        """Leg chains, the database's contact labels and heights (foot locking)."""
        for key in ("unlock_radius_m", "foot_lock_halflife_s", "contact_speed_m_s"):
            if not float(getattr(self, key)) > 0:
                raise ValueError(f"motion matching: {key} must be > 0, got {getattr(self, key)!r}")
        if float(self.ik_max_length_buffer_m) < 0 or float(self.contact_filter_s) < 0:
            raise ValueError("motion matching: ik_max_length_buffer_m and contact_filter_s must be >= 0")
        sk, fps = db.skeleton, db.fps
        self.legs_ = hip_knee_ankle(sk)
        pts = [contact_points(sk, c.values, self.legs_) for c in db.clips]
        self.contacts_ = np.vstack([contact_labels(p, fps, float(self.contact_speed_m_s), float(self.contact_filter_s))
                                    for p in pts])
        heights = np.vstack(pts)[:, :, 1]
        self.floor_ = heights.min(axis=0)
        self.contact_height_ = np.array([float(np.median(heights[self.contacts_[:, f], f]))
                                         if self.contacts_[:, f].any() else float(self.floor_[f]) for f in range(2)])

    def _normalise(self, raw: np.ndarray) -> np.ndarray:
        return (raw - self.mean_) / self.scale_ * self.weight_

    # -- query trajectories ---------------------------------------------------------------------------

    def _gamepad(self, start_ground: np.ndarray, start_yaw: float, fps: float):
        """Desired ground velocity (2,) m/s and facing yaw from the start's root ground positions (m)."""
        duration = (start_ground.shape[0] - 1) / fps
        vel = (start_ground[-1] - start_ground[0]) / duration
        if float(np.linalg.norm(vel)) < float(self.deadzone_m_s):
            return np.zeros(2), float(start_yaw)
        return vel, float(ground_heading(vel))

    def _predict(self, ground: np.ndarray, yaw: np.ndarray, goal_v: np.ndarray, goal_yaw: float, fps: float):
        """Future ground positions (3, 2) and yaws (3,) from the last two generated root states."""
        dt = self.future_frames_ / fps
        v = (ground[-1] - ground[-2]) * fps
        pos = spring_position(ground[-1][None, :], v[None, :], np.zeros((1, 2)), goal_v[None, :],
                              float(self.trajectory_halflife_s), dt[:, None])
        rate = float(wrap_radians(yaw[-1] - yaw[-2])) * fps
        ang = spring_angle(float(yaw[-1]), rate, goal_yaw, float(self.trajectory_halflife_s), dt)
        return pos, ang

    # -- generation -----------------------------------------------------------------------------------

    def generate(self, start: Motion, length: int, seed: int, trajectory: Motion | None = None,
                 native_start: Motion | None = None) -> Motion:
        """``length`` frames after ``start``; ``seed`` is not used (deterministic).

        Parameters
        ----------
        start : Motion (>= 2 frames), the context
        length : int
        seed : int, ignored (kept for the common interface)
        trajectory : Motion, optional; the true future (frame 0 follows the start's last) whose root
            positions and facings replace the gamepad query (clamped to its last frame)
        native_start : ignored (it runs at the working rate)

        ``meta``: ``seams``, ``source_frames`` (the database frame each output frame plays, before the
        offsets), ``costs`` (cost of the frame chosen at each search), ``search_frames`` (output frames
        whose pose follows a search), ``switches`` (searches that changed frame, the entry included); with
        foot locking ``contact_targets`` (length, 2, 3) (where each foot's contact point was sent, m),
        ``contact_locked`` and ``contact_states`` (length, 2) (locked; the played frame's label).

        Deterministic, so the last rollout is kept and a call with the same start, length and trajectory (the
        family's other seeds) returns a copy of it instead of computing it again.
        """
        self._check_start(start, length)
        traj = b"" if trajectory is None else np.asarray(trajectory.values, float).tobytes()
        key = (int(length), np.asarray(start.values, float).tobytes(), traj)
        memo = getattr(self, "_memo_", None)
        if memo is not None and memo[0] == key:
            m = memo[1]
            return Motion(m.values.copy(), m.skeleton, m.fps, m.name,
                          {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in m.meta.items()})
        out = self._rollout(start, length, trajectory)
        self._memo_ = (key, out)
        return Motion(out.values.copy(), out.skeleton, out.fps, out.name,
                      {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in out.meta.items()})

    def _rollout(self, start: Motion, length: int, trajectory: Motion | None) -> Motion:
        db, length = self.db_, int(length)
        sk, fps = db.skeleton, db.fps
        m = float(sk.length_to_m)
        st = encode(start, self.forward_)
        sq, svec = self._state(st, fps, m)
        # the start's last frame as a source of offsets: rotations, angular velocity, root vector, its velocity
        start_src = (sq[-1], self._angular_velocity(sq, fps)[-1], svec[-1], self._vec_velocity(svec, fps)[-1])
        s_pose = pose_features(start, st.yaw)[-1]
        # generated root history (ground in metres, yaw), the start's first
        ground = list(st.ground * m)
        yaws = list(st.yaw)
        goals = self._goals(start, st, trajectory, fps, m)
        hl = float(self.inertialize_halflife_s)
        dt = 1.0 / fps
        n_j = sq.shape[1]
        off = (np.tile([0.0, 0.0, 0.0, 1.0], (n_j, 1)), np.zeros((n_j, 3)), np.zeros(4), np.zeros(4))
        cur = -1  # database frame shown (-1: the start's last frame)
        timer = 0
        out_q = np.empty((length, n_j, 4))
        out_vec = np.empty((length, 4))
        played = np.empty(length, np.int64)
        seams, costs, searched, switches = [], [], [], 0
        for t in range(length):
            end = cur >= 0 and cur + 1 >= self.stops_[db.clip[cur]]
            if cur < 0 or timer <= 0 or end:
                timer = self.search_frames_
                q = self._query(cur, s_pose, ground, yaws, goals, fps)
                best, best_cost = self._best_frame(q, cur, end)
                costs.append(best_cost)
                searched.append(t)
                if best != cur:
                    switches += 1
                    off = self._switch_offsets(off, start_src if cur < 0 else self._source(cur), best)
                    if t > 0:
                        seams.append(t)
                    cur = best
            # play the next frame with the decayed offsets
            cur += 1
            timer -= 1
            off_q, off_w, off_x, off_v = off
            rv, off_w = decay_spring(qlog(off_q), off_w, hl, dt)
            off_q = qexp(rv)
            off_x, off_v = decay_spring(off_x, off_v, hl, dt)
            off = (off_q, off_w, off_x, off_v)
            out_q[t] = qmul(off_q, self.rot_[cur])
            out_vec[t] = self.vec_[cur] + off_x
            played[t] = cur
            _advance_root(ground, yaws, out_vec[t], fps)  # the generated root (for the next query)
        values = decode(sk, out_q[:, 1:], out_q[:, 0], out_vec[:, 0] / m, out_vec[:, 1:3] / (m * fps),
                        out_vec[:, 3] / fps, np.asarray(start.values, float)[-1], self.forward_)
        extra = {}
        if self.foot_lock:
            values, extra = self._lock_feet(start, values, played)
        return self._motion(values, length, seams, db.sources(played), costs=np.asarray(costs),
                            search_frames=np.asarray(searched, np.int64), switches=int(switches), **extra)

    def _goals(self, start: Motion, st, trajectory: Motion | None, fps: float, m: float):
        """What the queries steer towards: ``(goal_v, goal_yaw, None, None)`` from the gamepad (no ``trajectory``),
        else ``(None, None, ground, yaw)`` of the start followed by the given future trajectory."""
        if trajectory is None:
            goal_v, goal_yaw = self._gamepad(st.ground * m, float(st.yaw[-1]), fps)
            return goal_v, goal_yaw, None, None
        if trajectory.columns != start.columns:
            raise ValueError("motion matching: the trajectory's DOF columns differ from the start's")
        joined = Motion(np.vstack([start.values, trajectory.values]), self.db_.skeleton, fps, "trajectory")
        ft = encode(joined, self.forward_)
        return None, None, ft.ground * m, ft.yaw

    def _query(self, cur: int, s_pose, ground: list, yaws: list, goals, fps: float) -> np.ndarray:
        """The normalised query at a search: the pose features of the frame shown (the start's last while
        ``cur < 0``) and the trajectory features of the future the goals give (predicted from the gamepad, or
        read from the given trajectory)."""
        goal_v, goal_yaw, fut_ground, fut_yaw = goals
        now = len(ground) - 1  # index of the current frame in the start + generated timeline
        if fut_ground is None:
            fg, fy = self._predict(np.asarray(ground[-2:]), np.asarray(yaws[-2:]), goal_v, goal_yaw, fps)
        else:
            k = np.minimum(now + self.future_frames_, fut_ground.shape[0] - 1)
            fg, fy = fut_ground[k], fut_yaw[k]
        traj = trajectory_features(np.asarray(ground[-1])[None, :], np.array([yaws[-1]]), fg[None],
                                   fy[None])[0]
        if cur < 0:
            return self._normalise(np.concatenate([s_pose, traj]))
        q = self.features_[cur].copy()
        q[15:] = self._normalise(np.concatenate([np.zeros(15), traj]))[15:]
        return q

    def _best_frame(self, q: np.ndarray, cur: int, end: bool) -> tuple[int, float]:
        """``(frame, cost)``: the candidate frame nearest the query ``q``, or the frame shown ``cur`` when it is at
        least as near and its clip has not ``end``-ed; frames of the clip shown within ``exclude_frames_`` of it are
        left out."""
        db = self.db_
        cost = np.sum((self.features_ - q) ** 2, axis=1)
        ok = self.candidates_.copy()
        best_cost = np.inf
        if cur >= 0:
            same = db.clip == db.clip[cur]
            ok &= ~(same & (np.abs(db.frame - db.frame[cur]) < self.exclude_frames_))
            if not end:
                best_cost = float(cost[cur])
        best = cur if np.isfinite(best_cost) else -1
        if ok.any():
            j = int(np.flatnonzero(ok)[np.argmin(cost[ok])])
            if cost[j] < best_cost:
                best, best_cost = j, float(cost[j])
        if best < 0:  # pragma: no cover - fit ensures candidates exist
            raise RuntimeError("motion matching: no frame to play")
        return best, best_cost

    def _source(self, cur: int):
        """Database frame ``cur`` as a source of offsets: rotations, angular velocity, root vector, its velocity."""
        return self.rot_[cur], self.angular_velocity_[cur], self.vec_[cur], self.root_velocity_[cur]

    def _switch_offsets(self, off, src, best: int):
        """The inertialization offsets ``(q, w, x, v)`` after switching from the pose ``src`` shown now to database
        frame ``best``: the old offsets plus the difference between the two."""
        off_q, off_w, off_x, off_v = off
        src_q, src_w, src_x, src_v = src
        oq = qmul(qmul(off_q, src_q), qinv(self.rot_[best]))
        oq[oq[:, 3] < 0] *= -1
        return (oq, off_w + src_w - self.angular_velocity_[best], off_x + src_x - self.vec_[best],
                off_v + src_v - self.root_velocity_[best])

    def _lock_feet(self, start: Motion, values: np.ndarray, played: np.ndarray):
        """The reference's foot locking and two-bone IK on the decoded frames (:mod:`.footlock`)."""
        sk, fps = self.db_.skeleton, self.db_.fps
        prev = contact_points(sk, np.asarray(start.values, float)[-1:], self.legs_)
        starts, W = forward_kinematics(sk, values, ends=False, world_rotations=True)
        pts = np.stack([starts[:, a] + W[a].apply(sk.joints[a].tail) for a in self.legs_[:, 2]], axis=1)
        pts *= float(sk.length_to_m)
        targets, locked = lock_contacts(pts, self.contacts_[played], fps, prev[-1], self.contact_height_,
                                        float(self.unlock_radius_m), float(self.foot_lock_halflife_s))
        targets[:, :, 1] = np.maximum(targets[:, :, 1], self.floor_[None, :])
        out = values.copy()
        for f in range(2):
            move = np.linalg.norm(targets[:, f] - pts[:, f], axis=1) > 1e-9
            if move.any():  # the legs are separate subtrees: one forward kinematics serves both
                idx = np.flatnonzero(move)
                out[idx] = place_feet(sk, out[idx], self.legs_[f], targets[idx, f], float(self.ik_max_length_buffer_m),
                                      fk=(starts[idx], [w[idx] for w in W]))
        return out, {"contact_targets": targets, "contact_locked": locked,
                     "contact_states": self.contacts_[played].copy()}


def _advance_root(ground: list, yaws: list, vec: np.ndarray, fps: float) -> None:
    """Append the next generated root (ground position, yaw) after one frame of the root vector ``vec`` (its
    forward, sideways and turning rates in the body's frame)."""
    yaw_prev = yaws[-1]
    step = vec[1:3] / fps
    c, s = np.cos(yaw_prev), np.sin(yaw_prev)
    ground.append(ground[-1] + np.array([c * step[0] + s * step[1], -s * step[0] + c * step[1]]))
    yaws.append(yaw_prev + vec[3] / fps)


class MotionMatchingTrajectory(MotionMatching):
    """:class:`MotionMatching` whose query trajectory is the held-out future (the row ``motion_matching_traj``).

    ``query = "future_trajectory"``: the compare family's runner passes the held-out frames after the start as
    ``trajectory`` to :meth:`generate`, which then requires it (without it this would be the gamepad row).
    """

    name = "motion_matching_traj"
    query = "future_trajectory"

    def generate(self, start: Motion, length: int, seed: int, trajectory: Motion | None = None,
                 native_start: Motion | None = None) -> Motion:
        if trajectory is None:
            raise ValueError(f"{self.name}: its query is the future trajectory: pass trajectory= (the held-out "
                             "frames after the start)")
        return super().generate(start, length, seed, trajectory=trajectory)


def make_motion_matching(cfg: dict | None = None, trajectory_weight: float | None = None,
                         name: str | None = None, foot_lock: bool | None = None,
                         future_trajectory: bool = False) -> MotionMatching:
    """An unfitted :class:`MotionMatching` from a config block (its keys are the parameters; ``None``: the
    reference's constants); ``trajectory_weight`` overrides the block's (0: the pose-only ablation row),
    ``foot_lock`` its foot locking (``False``: the ablation without the reference's foot locking and IK),
    ``future_trajectory`` makes it a :class:`MotionMatchingTrajectory` (the query is the held-out future) and
    ``name`` the generator's name (the row, e.g. ``motion_matching_pose``)."""
    kw = dict(cfg or {})
    if trajectory_weight is not None:
        kw["trajectory_weight"] = trajectory_weight
    if foot_lock is not None:
        kw["foot_lock"] = bool(foot_lock)
    gen = (MotionMatchingTrajectory if future_trajectory else MotionMatching)(**kw)
    if name is not None:
        gen.name = name
    return gen
