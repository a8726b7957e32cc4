"""Procedural CMU-skeleton motion: walking, running (straight or turning) and dance.

The generator writes the real file formats (ASF + AMC), which the workflow then
parses with the real readers. It is a kinematic gait model, not a physics
simulation:

* **Legs** follow periodic joint-angle curves (cubic splines through textbook
  gait key values for hip flexion, knee flexion and ankle), left and right half
  a cycle apart; **arms** swing opposite to the legs; the spine counter-rotates.
* **Stride, cadence, speed, arm swing, lean and turning rate** vary per trial
  (seeded), and a smooth random perturbation is added to every angle.
* **Root translation** comes from the feet: while a foot is in stance the root
  moves so that the foot stays planted (no foot skate by construction); during
  running flight phases the root follows a ballistic parabola. The root height
  puts the lowest stance foot on the ground (y = 0), so walking alternates
  single-foot contacts and running has flight phases in which both feet are in
  the air.
* **Turning**: the heading integrates a yaw rate (a constant veer, or a smooth
  90 degree turn), applied to the root rotation and to the root's velocity.
* **Dance**: free-form sums of slow sinusoids on every joint within its limits,
  a slow spin and sway of the root, feet kept on the ground.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.ndimage import gaussian_filter1d
from scipy.spatial.transform import Rotation

from ..motion import Motion
from ..kinematics import forward_kinematics, joint_euler
from ..skeleton import ROT_DOFS, Joint, Skeleton

KINDS = ("walk_straight", "walk_turn", "run_straight", "run_turn", "dance")

# name, parent, direction, length, axis (deg, XYZ), dofs, limits
# Proportions of an adult CMU subject (ASF length units: 1 unit = 1/0.45 inch).
_TEMPLATE = [
    ("lowerback", "root", (0.02, 0.99, -0.11), 2.03, (0, 0, 0), "rx ry rz", [(-20, 45), (-30, 30), (-30, 30)]),
    ("upperback", "lowerback", (0.02, 1.0, 0.0), 2.03, (0, 0, 0), "rx ry rz", [(-20, 45), (-30, 30), (-30, 30)]),
    ("thorax", "upperback", (0.01, 1.0, 0.06), 2.06, (0, 0, 0), "rx ry rz", [(-20, 45), (-30, 30), (-30, 30)]),
    ("lowerneck", "thorax", (0.0, 0.99, 0.12), 1.72, (0, 0, 0), "rx ry rz", [(-20, 45), (-30, 30), (-30, 30)]),
    ("upperneck", "lowerneck", (0.01, 0.99, -0.13), 1.74, (0, 0, 0), "rx ry rz", [(-20, 45), (-30, 30), (-30, 30)]),
    ("head", "upperneck", (0.0, 1.0, -0.06), 1.74, (0, 0, 0), "rx ry rz", [(-20, 45), (-30, 30), (-30, 30)]),
    ("rclavicle", "thorax", (-0.96, 0.22, -0.2), 3.6, (0, 0, 0), "ry rz", [(-10, 20), (-20, 0)]),
    ("rhumerus", "rclavicle", (-1, 0, 0), 5.3, (180, 30, 90), "rx ry rz", [(-90, 60), (-90, 90), (-90, 90)]),
    ("rradius", "rhumerus", (-1, 0, 0), 3.6, (180, 30, 90), "rx", [(-10, 170)]),
    ("rwrist", "rradius", (-1, 0, 0), 1.8, (0, -90, -90), "ry", [(-180, 0)]),
    ("rhand", "rwrist", (-1, 0, 0), 0.6, (0, -90, -90), "rx rz", [(-90, 90), (-45, 45)]),
    ("rfingers", "rhand", (-1, 0, 0), 0.5, (0, -90, -90), "rx", [(0, 90)]),
    ("rthumb", "rwrist", (-0.707, 0, 0.707), 0.7, (-90, -45, 0), "rx rz", [(-45, 45), (-45, 45)]),
    ("lclavicle", "thorax", (0.96, 0.22, -0.2), 3.6, (0, 0, 0), "ry rz", [(-20, 10), (0, 20)]),
    ("lhumerus", "lclavicle", (1, 0, 0), 5.3, (180, -30, -90), "rx ry rz", [(-60, 90), (-90, 90), (-90, 90)]),
    ("lradius", "lhumerus", (1, 0, 0), 3.6, (180, -30, -90), "rx", [(-10, 170)]),
    ("lwrist", "lradius", (1, 0, 0), 1.8, (0, 90, 90), "ry", [(-180, 0)]),
    ("lhand", "lwrist", (1, 0, 0), 0.6, (0, 90, 90), "rx rz", [(-90, 90), (-45, 45)]),
    ("lfingers", "lhand", (1, 0, 0), 0.5, (0, 90, 90), "rx", [(0, 90)]),
    ("lthumb", "lwrist", (0.707, 0, 0.707), 0.7, (-90, 45, 0), "rx rz", [(-45, 45), (-45, 45)]),
    ("rhipjoint", "root", (-0.65, -0.74, 0.19), 2.55, (0, 0, 0), "", []),
    ("rfemur", "rhipjoint", (-0.342, -0.94, 0), 7.6, (0, 0, -20), "rx ry rz", [(-160, 20), (-70, 70), (-70, 60)]),
    ("rtibia", "rfemur", (-0.342, -0.94, 0), 7.95, (0, 0, -20), "rx", [(-10, 170)]),
    ("rfoot", "rtibia", (-0.1, -0.27, 0.96), 2.3, (-90, 0, -20), "rx rz", [(-45, 90), (-20, 70)]),
    ("rtoes", "rfoot", (0, 0, 1), 1.15, (-90, 0, -20), "rx", [(-90, 20)]),
    ("lhipjoint", "root", (0.65, -0.74, 0.19), 2.55, (0, 0, 0), "", []),
    ("lfemur", "lhipjoint", (0.342, -0.94, 0), 7.6, (0, 0, 20), "rx ry rz", [(-160, 20), (-70, 70), (-60, 70)]),
    ("ltibia", "lfemur", (0.342, -0.94, 0), 7.95, (0, 0, 20), "rx", [(-10, 170)]),
    ("lfoot", "ltibia", (0.1, -0.27, 0.96), 2.3, (-90, 0, 20), "rx rz", [(-45, 90), (-70, 20)]),
    ("ltoes", "lfoot", (0, 0, 1), 1.15, (-90, 0, 20), "rx", [(-90, 20)]),
]

LENGTH_UNIT = 0.45  # ASF ':units length' of CMU files


def subject_seed(subject: str, seed: int) -> int:
    from ..config import derive_seed

    return derive_seed(seed, "subject", subject)


def cmu_like_skeleton(subject: str = "syn", seed: int = 0) -> Skeleton:
    """A CMU-layout skeleton (31 joints, 62 DOF) with per-subject proportions.

    Overall scale varies by +-8 % and every bone length by +-3 % (seeded by
    ``subject`` and ``seed``).
    """
    rng = np.random.default_rng(subject_seed(subject, seed))
    scale = 1.0 + rng.uniform(-0.08, 0.08)
    joints = [Joint("root", -1, np.zeros(3), np.zeros(3), ["tx", "ty", "tz", "rx", "ry", "rz"])]
    index = {"root": 0}
    tails = {"root": np.zeros(3)}
    lengths: dict[str, float] = {}
    for name, parent, d, length, axis, dofs, lim in _TEMPLATE:
        d = np.asarray(d, float)
        d = d / np.linalg.norm(d)
        # left/right pairs share their length variation (symmetric subject)
        key = name[1:] if name[0] in "lr" and name not in ("lowerback", "lowerneck") else name
        if key not in lengths:
            lengths[key] = length * scale * (1.0 + rng.uniform(-0.03, 0.03))
        L = lengths[key]
        joints.append(
            Joint(name, index[parent], tails[parent].copy(), d * L, dofs.split(), np.asarray(axis, float), "XYZ",
                  [tuple(map(float, x)) for x in lim], d, L)
        )
        index[name] = len(joints) - 1
        tails[name] = d * L
    return Skeleton(joints, length_to_m=(1.0 / LENGTH_UNIT) * 2.54 / 100.0, name=subject)


# --- gait key curves (phase 0 = heel strike of that leg), degrees ----------
# hip: positive = flexion (thigh forward); knee: positive = flexion.
_WALK = {
    "phase": [0.0, 0.12, 0.3, 0.5, 0.62, 0.75, 0.87, 1.0],
    "hip": [28, 24, 8, -10, -4, 18, 30, 28],
    "knee": [3, 16, 8, 8, 38, 60, 20, 3],
    "ankle": [0, -6, 2, 12, -15, -2, 2, 0],  # positive = dorsiflexion
    "stance": (0.0, 0.6),
}
_RUN = {
    "phase": [0.0, 0.15, 0.35, 0.5, 0.7, 0.85, 1.0],
    "hip": [30, 20, -8, -5, 35, 45, 30],
    "knee": [20, 42, 18, 70, 105, 45, 20],
    "ankle": [5, 14, -18, -10, 5, 8, 5],
    "stance": (0.0, 0.36),
}


def _rot(axis: str, angles_deg) -> Rotation:
    """Rotations about one axis, one per frame (angles in degrees)."""
    return Rotation.from_euler(axis, np.reshape(np.asarray(angles_deg, float), (-1, 1)), degrees=True)


def _periodic(table, key):
    return CubicSpline(table["phase"], table[key], bc_type="periodic")


def _smooth_noise(rng, n, sigma_frames, amp, dims=1):
    x = rng.standard_normal((n + 6 * int(sigma_frames), dims))
    x = gaussian_filter1d(x, sigma_frames, axis=0)[3 * int(sigma_frames): 3 * int(sigma_frames) + n]
    x /= max(np.std(x), 1e-9)
    return amp * x


def _in_window(phase, window):
    a, b = window
    return (phase >= a) & (phase < b)


class _Pose:
    """Collect per-joint local rotations (3-DOF joints) or DOF values."""

    def __init__(self, skeleton: Skeleton, n: int):
        self.sk = skeleton
        self.n = n
        self.values = np.zeros((n, skeleton.n_dof))
        self.sl = skeleton.dof_slices()

    def set_dof(self, joint: str, dof: str, v):
        j = self.sk[joint]
        col = self.sl[joint].start + j.dofs.index(dof)
        self.values[:, col] = v

    def set_world_aligned(self, joint: str, rot: Rotation):
        """Give a 3-DOF joint the local rotation ``rot`` (axes of the rest pose)."""
        self.values[:, self.sl[joint]] = joint_euler(self.sk[joint], rot)


def _arm_rotation(side: str, swing_deg, abduct_deg, n):
    """Arms hang down from the T-pose (rotate about z) then swing about x."""
    down = _rot("z", np.full(n, -(75.0 - abduct_deg) if side == "l" else 75.0 - abduct_deg))
    swing = _rot("x", -np.asarray(swing_deg))
    return swing * down


def generate_motion(kind: str, frames: int, seed: int, skeleton: Skeleton | None = None,
                    fps: float = 120.0, name: str = "") -> Motion:
    """Generate one synthetic trial.

    Parameters
    ----------
    kind : {"walk_straight", "walk_turn", "run_straight", "run_turn", "dance"}
    frames : int
    seed : int
        Controls every per-trial variation (speed, stride, cadence, turning, style, noise).
    skeleton : Skeleton, optional
        Defaults to :func:`cmu_like_skeleton`.
    fps : float

    Returns
    -------
    Motion with the skeleton's 62 CMU DOF columns (degrees, length units).
    """
    if kind not in KINDS:
        raise ValueError(f"unknown motion kind {kind!r}; expected one of {KINDS}")
    if frames < 10:
        raise ValueError(f"frames must be >= 10, got {frames}")
    sk = skeleton if skeleton is not None else cmu_like_skeleton()
    rng = np.random.default_rng(seed)
    n = int(frames)
    t = np.arange(n) / fps
    P = _Pose(sk, n)
    if kind == "dance":
        _dance(P, rng, t, fps)
    else:
        _locomotion(P, rng, t, fps, kind)
    return Motion(P.values, sk, fps, name or kind)


def _locomotion(P: _Pose, rng, t, fps, kind):
    n = len(t)
    run = kind.startswith("run")
    table = _RUN if run else _WALK
    cadence = rng.uniform(1.35, 1.55) if run else rng.uniform(0.85, 1.0)  # gait cycles per second
    stride = rng.uniform(0.85, 1.1)  # scales hip amplitude
    arm_amp = rng.uniform(12, 22) if not run else rng.uniform(25, 40)
    lean = rng.uniform(2, 6) + (6 if run else 0)
    # cadence drifts slowly (+-4 %)
    rate = cadence * (1 + 0.04 * _smooth_noise(rng, n, fps * 0.8, 1.0)[:, 0])
    phase = rng.uniform(0, 1) + np.cumsum(rate) / fps
    ph_l = np.mod(phase, 1.0)
    ph_r = np.mod(phase + 0.5, 1.0)
    hip, knee, ankle = (_periodic(table, k) for k in ("hip", "knee", "ankle"))
    noise = lambda amp: _smooth_noise(rng, n, fps * 0.25, amp)[:, 0]  # noqa: E731
    for side, ph in (("l", ph_l), ("r", ph_r)):
        flex = stride * hip(ph) + noise(1.5)
        abd = 3.0 + noise(1.0)
        sgn = 1.0 if side == "l" else -1.0
        # the CMU rest pose splays the legs 20 degrees outward: bring them in
        femur = _rot("x", -flex) * _rot("z", sgn * (abd - 20.0))
        P.set_world_aligned(f"{side}femur", femur)
        P.set_dof(f"{side}tibia", "rx", np.clip(knee(ph) * (0.9 + 0.1 * stride) + noise(1.5), 0, 150))
        P.set_dof(f"{side}foot", "rx", -ankle(ph) + noise(1.0))
        P.set_dof(f"{side}toes", "rx", np.where(_in_window(ph, (0.45, 0.62)), -20 * np.sin(np.pi * (ph - 0.45) / 0.17), 0.0))
        # arms swing opposite to the same-side leg
        P.set_world_aligned(f"{side}humerus", _arm_rotation(side, -arm_amp * np.sin(2 * np.pi * (ph + 0.5) + 0.3), 5.0, n))
        P.set_dof(f"{side}radius", "rx", (60 if run else 15) + (10 if run else 8) * np.sin(2 * np.pi * ph) + noise(2.0))
        P.set_dof(f"{side}wrist", "ry", -10.0 + noise(1.0))
    # spine: lean forward, counter-rotate against the pelvis
    twist = 6.0 * np.sin(2 * np.pi * ph_l) * (1.3 if run else 1.0)
    for j, share in (("lowerback", 0.4), ("upperback", 0.3), ("thorax", 0.3)):
        r = _rot("x", np.full(n, lean * share) + noise(0.5)) * _rot("y", twist * share)
        P.set_world_aligned(j, r)
    for j in ("lowerneck", "upperneck", "head"):
        P.set_world_aligned(j, _rot("x", -lean / 3 + noise(0.8)))
    # heading
    if kind.endswith("turn"):
        if rng.uniform() < 0.5:  # veer: constant yaw rate
            yaw_rate = rng.choice([-1, 1]) * rng.uniform(12, 30)
            heading = yaw_rate * t
        else:  # 90 degree turn, smooth, centred in the clip
            direction = rng.choice([-1, 1])
            centre = t[-1] * rng.uniform(0.4, 0.6)
            width = rng.uniform(0.35, 0.6)
            heading = direction * 90.0 / (1.0 + np.exp(-(t - centre) / (width / 4)))
            heading -= heading[0]
    else:
        heading = np.cumsum(noise(0.8)) / fps * 2.0  # slight wandering
    heading = heading + rng.uniform(-180, 180)
    pelvis_twist = -0.5 * twist
    root_rot = (_rot("y", heading + pelvis_twist)
                * _rot("x", np.full(n, lean * 0.3))
                * _rot("z", 2.0 * np.sin(2 * np.pi * ph_l) + noise(0.3)))
    _set_root_rotation(P, root_rot)
    _place_root(P, fps, stance=[_in_window(ph_l, table["stance"]), _in_window(ph_r, table["stance"])], run=run)


def _set_root_rotation(P: _Pose, rot: Rotation):
    j = P.sk.joints[0]
    rdofs = [d for d in j.dofs if d in ROT_DOFS]
    ang = joint_euler(j, rot)
    for k, d in enumerate(rdofs):
        P.set_dof("root", d, ang[:, k])


def _foot_points(sk: Skeleton):
    return [(sk.index("lfoot"), sk.index("ltoes")), (sk.index("rfoot"), sk.index("rtoes"))]


def _place_root(P: _Pose, fps, stance, run):
    """Root translation from the stance feet (see module docstring)."""
    sk = P.sk
    n = P.n
    sl = sk.dof_slices()["root"]
    tcols = [sl.start + sk.joints[0].dofs.index(d) for d in ("tx", "ty", "tz")]
    P.values[:, tcols] = 0.0
    pos = forward_kinematics(sk, P.values)  # root at origin
    feet = _foot_points(sk)
    # lowest point of each foot (ankle end or toe tip), relative to the root
    low = np.stack([np.min(np.stack([pos[:, a, 1], pos[:, b, 1]]), axis=0) for a, b in feet], axis=1)
    # horizontal velocity: keep the stance foot (its ball, the foot end) planted
    ball = np.stack([pos[:, a, :] for a, _ in feet], axis=1)  # (n, 2, 3)
    vel = np.zeros((n, 3))
    have = np.zeros(n, bool)
    dball = np.gradient(ball, axis=0)
    for k in range(2):
        m = stance[k]
        vel[m] -= dball[m, k]
        have[m] = True
    both = stance[0] & stance[1]
    vel[both] /= 2.0
    vel[:, 1] = 0.0
    idx = np.arange(n)
    if not have.all():
        for c in (0, 2):
            vel[~have, c] = np.interp(idx[~have], idx[have], vel[have, c]) if have.any() else 0.0
    horiz = np.cumsum(vel, axis=0)
    horiz -= horiz[0]
    # height: lowest stance foot on the ground; ballistic flight otherwise
    height = np.empty(n)
    anyst = stance[0] | stance[1]
    st_low = np.where(stance[0] & stance[1], np.minimum(low[:, 0], low[:, 1]),
                      np.where(stance[0], low[:, 0], low[:, 1]))
    height[anyst] = -st_low[anyst]
    if run and not anyst.all():
        g = 9.81 / sk.length_to_m / fps ** 2  # length units per frame^2
        # each flight window: parabola between take-off and landing heights
        k = 0
        while k < n:
            if anyst[k]:
                k += 1
                continue
            s = k
            while k < n and not anyst[k]:
                k += 1
            e = k  # first stance frame after the window (or n)
            h0 = height[s - 1] if s > 0 else -np.min(low[s])
            h1 = height[e] if e < n else h0
            T = e - s + 1
            tt = np.arange(1, e - s + 1)
            height[s:e] = h0 + (h1 - h0) * tt / T + 0.5 * g * tt * (T - tt)
        height = np.maximum(height, -np.min(low, axis=1))  # never through the floor
    elif not run:
        # walking: the lowest foot point is on the floor (the swing foot
        # never goes through it; support alternates left/right)
        height = -np.min(low, axis=1)
    P.values[:, tcols[0]] = horiz[:, 0]
    P.values[:, tcols[1]] = height
    P.values[:, tcols[2]] = horiz[:, 2]


def _dance(P: _Pose, rng, t, fps):
    n = len(t)
    sk = P.sk
    # A dance repeats phrases: every joint moves with harmonics of one phrase
    # period (3-5 s), so poses recur (as in real dance capture), plus a slow
    # non-repeating drift so no two phrases are identical.
    period = rng.uniform(3.0, 5.0)
    drift_t = t / period

    def wave(amp, fmin=0.15, fmax=0.9, k=3):
        out = np.zeros(n)
        for _ in range(k):
            f = max(1, int(round(rng.uniform(fmin, fmax) * period))) / period
            out += rng.uniform(0.3, 1.0) * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
        out += 0.08 * np.sin(2 * np.pi * rng.uniform(0.05, 0.12) * drift_t + rng.uniform(0, 2 * np.pi))
        return amp * out / k

    for j in ("lowerback", "upperback", "thorax"):
        P.set_world_aligned(j, Rotation.from_euler("xyz", np.stack([wave(8), wave(12), wave(8)], 1), degrees=True))
    for j in ("lowerneck", "upperneck", "head"):
        P.set_world_aligned(j, Rotation.from_euler("xyz", np.stack([wave(6), wave(10), wave(5)], 1), degrees=True))
    for side in ("l", "r"):
        raise_ = 40 + wave(45, 0.1, 0.5)
        swing = wave(50, 0.1, 0.6)
        sgn = 1 if side == "l" else -1
        arm = (_rot("x", -swing)
               * _rot("z", -sgn * np.clip(75 - raise_, -40, 90)))
        P.set_world_aligned(f"{side}humerus", arm)
        P.set_dof(f"{side}radius", "rx", np.clip(45 + wave(40, 0.1, 0.7), 0, 150))
        P.set_dof(f"{side}wrist", "ry", np.clip(-40 + wave(30), -170, 0))
        P.set_dof(f"{side}hand", "rx", wave(25))
        flex = 10 + wave(25, 0.2, 0.8)
        femur = _rot("x", -flex) * _rot("z", sgn * (6 + wave(10) - 20.0))
        P.set_world_aligned(f"{side}femur", femur)
        P.set_dof(f"{side}tibia", "rx", np.clip(flex * 1.2 + wave(15), 0, 130))
        P.set_dof(f"{side}foot", "rx", wave(10))
    spin = np.cumsum(wave(60, 0.05, 0.2) + rng.uniform(-40, 40)) / fps
    root_rot = _rot("y", spin + rng.uniform(-180, 180)) * Rotation.from_euler("xz", np.stack([wave(6), wave(6)], 1), degrees=True)
    _set_root_rotation(P, root_rot)
    # feet stay on the floor: root height = -lowest foot point; slow wander
    sl = sk.dof_slices()["root"]
    tx, ty, tz = (sl.start + sk.joints[0].dofs.index(d) for d in ("tx", "ty", "tz"))
    pos = forward_kinematics(sk, P.values)
    low = np.min(pos[:, [sk.index(j) for j in ("lfoot", "ltoes", "rfoot", "rtoes")], 1], axis=1)
    P.values[:, ty] = -low
    P.values[:, tx] = np.cumsum(wave(0.4, 0.05, 0.3))
    P.values[:, tz] = np.cumsum(wave(0.4, 0.05, 0.3))


def write_trial(amc_path, asf_path, kind: str, frames: int, seed: int, subject: str,
                subject_master_seed: int, fps: float = 120.0, name: str = "") -> Motion:
    """Generate one trial and write it as ASF + AMC (atomically)."""
    from ..io.amc import write_amc
    from ..io.asf import write_asf

    sk = cmu_like_skeleton(subject, subject_master_seed)
    motion = generate_motion(kind, frames, seed, sk, fps, name)
    write_asf(asf_path, sk, length_unit=LENGTH_UNIT)
    write_amc(amc_path, motion)
    return motion


def synthetic_motions(n_frames: int, trial_frames: int = 1000, seed: int = 0, kinds=None):
    """Synthetic CMU-skeleton trials (:mod:`animsynth.synth.mocap`) totalling ``n_frames``.

    Trial ``t`` has kind ``kinds[t % len(kinds)]`` and seed ``seed * 100003 + t``;
    the last trial is shortened to hit ``n_frames`` exactly.
    """
    kinds = list(kinds or KINDS)
    sk = cmu_like_skeleton("synscale", seed)
    out, left, t = [], int(n_frames), 0
    while left > 0:
        n = min(int(trial_frames), left)
        if n < 10:  # the generator needs >= 10 frames: fold the remainder into the previous trial
            break
        out.append(generate_motion(kinds[t % len(kinds)], n, seed * 100003 + t, sk, name=f"syn{t:04d}"))
        left -= n
        t += 1
    return out
