"""Synthetic skirt character: a human-like mesh around the 18-joint skeleton, skinned,
driven by motion, with a flared skirt simulated as damped second-order dynamics.

The body (torso, head, neck, arms, hands, legs, feet) is a set of closed tubes
around the rig's bone segments, skinned with the automatic weights of
:func:`animsynth.skinning.skinning_weights` (so, given the true rig, the
body is exactly representable by linear blend skinning). The skirt is a
flared cone hanging from the waist. Its vertices are particles:

* the waistband ring is pinned to the hips;
* every other particle is pulled towards where a rigid skirt attached to the
  hips would be by a spring whose stiffness falls from waist to hem
  (``x'' = k(h) (x_rigid - x) - b x'``, a damped oscillator per particle; the
  rest shape already includes gravity's sag, so gravity is not added again);
* structural (ring and vertical) edges keep their rest length (position-based
  distance constraints), which couples the particles into a cloth;
* particles are pushed out of the thigh and shin capsules.

Integration is Verlet with several sub-steps per frame, so the skirt's shape
depends on the motion history (it lags, swings and flares). Because the
generator can re-simulate, it also gives ground truth for edited motions.

Motion comes from :func:`procedural_motion` (seeded synthetic dance / walk on
the 18-joint rig) or from any CMU-skeleton :class:`~animsynth.motion.Motion`
mapped with :func:`animsynth.skinning.cmu_motion_to_rig`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from ..skinning import JOINTS, Rig, forward, joint_transforms, lbs, skinning_weights

log = logging.getLogger("animsynth.synth.character")

EDITS = ("legs_x1.3", "lean_15deg", "arms_up_25deg", "speed_x1.3")


# --------------------------------------------------------------------------- geometry
def _frame(axis: np.ndarray):
    a = axis / np.linalg.norm(axis)
    ref = np.array([0.0, 0.0, 1.0]) if abs(a[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(a, ref)
    u /= np.linalg.norm(u)
    return u, np.cross(a, u)


def _tube(a, b, radii, n_around: int, n_rings: int, squash: float = 1.0, cap: bool = True):
    """Closed tube from a to b; ``radii`` = (r_a, r_b) or a callable of u in [0, 1]."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    axis = b - a
    u_dir, v_dir = _frame(axis)
    us = np.linspace(0, 1, n_rings)
    ang = np.linspace(0, 2 * np.pi, n_around, endpoint=False)
    verts = []
    for u in us:
        r = radii(u) if callable(radii) else radii[0] + (radii[1] - radii[0]) * u
        rx, rz = (r, r * squash) if np.isscalar(r) else r
        c = a + u * axis
        verts.append(c + np.outer(np.cos(ang) * rx, u_dir) + np.outer(np.sin(ang) * rz, v_dir))
    V = np.concatenate(verts)
    faces = []
    for i in range(n_rings - 1):
        for k in range(n_around):
            p, q = i * n_around + k, i * n_around + (k + 1) % n_around
            faces += [[p, q, q + n_around], [p, q + n_around, p + n_around]]
    if cap:
        n = len(V)
        V = np.vstack([V, a, b])
        for k in range(n_around):
            faces.append([n, (k + 1) % n_around, k])
            base = (n_rings - 1) * n_around
            faces.append([n + 1, base + k, base + (k + 1) % n_around])
    return V, np.array(faces, np.int64)


def _sphere(c, r, n_lat: int, n_lon: int):
    th = np.linspace(0, np.pi, n_lat + 2)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    V = [np.asarray(c) + r * np.stack([np.sin(t) * np.cos(ph), np.full_like(ph, np.cos(t)), np.sin(t) * np.sin(ph)], 1)
         for t in th]
    V = np.concatenate(V + [np.asarray(c)[None] + [[0, r, 0]], np.asarray(c)[None] - [[0, r, 0]]])
    faces = []
    for i in range(n_lat - 1):
        for k in range(n_lon):
            p, q = i * n_lon + k, i * n_lon + (k + 1) % n_lon
            faces += [[p, q + n_lon, q], [p, p + n_lon, q + n_lon]]
    top, bot = n_lat * n_lon, n_lat * n_lon + 1
    for k in range(n_lon):
        faces.append([top, k, (k + 1) % n_lon])
        b = (n_lat - 1) * n_lon
        faces.append([bot, b + (k + 1) % n_lon, b + k])
    return V, np.array(faces, np.int64)


@dataclass
class Character:
    """Rest mesh of the synthetic character.

    Attributes
    ----------
    rest : (V, 3); faces : (T, 3); part : (V,) part name index into ``parts``;
    skirt : (n_rings, n_around) vertex indices of the skirt grid (row 0 = waistband);
    rig : Rig; weights : (V, J) sparse automatic skinning weights.
    """

    rest: np.ndarray
    faces: np.ndarray
    part: np.ndarray
    parts: list
    skirt: np.ndarray
    rig: Rig
    weights: object


def build_character(rig: Rig, resolution: float = 1.0, skirt_rings: int = 16, skirt_around: int = 56,
                    skirt_length: float = 0.52, skirt_flare: float = 0.20) -> Character:
    """Build the rest mesh (a few thousand vertices) around ``rig``.

    ``resolution`` scales the number of body vertices; the skirt grid is
    ``skirt_rings x skirt_around``. Lengths are metres (Y up).
    """
    s = rig.starts
    e = rig.ends
    J = {n: i for i, n in enumerate(JOINTS)}
    h = max(e[J["head"], 1] - min(e[J["l_foot"], 1], e[J["r_foot"], 1]), 0.5)
    sc = h / 1.72
    na = lambda n: max(6, int(round(n * resolution)))  # noqa: E731
    pieces, names = [], []

    def add(name, VF):
        pieces.append(VF)
        names.append(name)

    hip_y = s[J["hips"], 1]
    top = e[J["chest"]]
    bottom = s[J["hips"]] - np.array([0, 0.08 * sc, 0])
    prof = lambda u: (sc * (0.15 - 0.03 * np.sin(np.pi * u * 0.9) + 0.035 * u**2), sc * 0.105)  # noqa: E731
    add("torso", _tube(bottom, top, prof, na(28), na(20)))
    add("neck", _tube(s[J["neck"]], e[J["neck"]] + (e[J["neck"]] - s[J["neck"]]) * 0.3, (0.05 * sc, 0.045 * sc), na(14), 4))
    hc = 0.5 * (s[J["head"]] + e[J["head"]])
    add("head", _sphere(hc, 0.105 * sc, na(12), na(18)))
    limb = {"upperarm": (0.052, 0.042, 10, 14), "forearm": (0.040, 0.030, 9, 12), "hand": (0.030, 0.022, 4, 10),
            "thigh": (0.085, 0.058, 12, 18), "shin": (0.055, 0.040, 12, 14), "foot": (0.040, 0.030, 5, 10)}
    for side in "lr":
        for part, (ra, rb, nr, nr_a) in limb.items():
            j = J[f"{side}_{part}"]
            a, b = s[j].copy(), e[j].copy()
            if part == "upperarm":  # start the sleeve a little inside the torso
                a = a + (a - b) * 0.05
            add(f"{side}_{part}", _tube(a, b, (ra * sc, rb * sc), na(nr_a), max(3, na(nr)),
                                        squash=0.6 if part in ("hand", "foot") else 1.0))
    # skirt: a flared cone hanging from the waist around the vertical axis through the hips
    waist_y = hip_y + 0.06 * sc
    ang = np.linspace(0, 2 * np.pi, skirt_around, endpoint=False)
    grid = []
    for i in range(skirt_rings):
        u = i / (skirt_rings - 1)
        y = waist_y - u * skirt_length * sc
        rx = sc * (0.165 + skirt_flare * u ** 1.2)
        rz = sc * (0.125 + skirt_flare * u ** 1.2)
        grid.append(np.stack([s[J["hips"], 0] + rx * np.cos(ang), np.full_like(ang, y),
                              s[J["hips"], 2] + rz * np.sin(ang)], 1))
    SV = np.concatenate(grid)
    SF = []
    for i in range(skirt_rings - 1):
        for k in range(skirt_around):
            p, q = i * skirt_around + k, i * skirt_around + (k + 1) % skirt_around
            SF += [[p, q, q + skirt_around], [p, q + skirt_around, p + skirt_around]]
    add("skirt", (SV, np.array(SF, np.int64)))
    verts, faces, part = [], [], []
    off = 0
    skirt_idx = None
    for k, (V, F) in enumerate(pieces):
        verts.append(V)
        faces.append(F + off)
        part.append(np.full(len(V), k))
        if names[k] == "skirt":
            skirt_idx = (off + np.arange(len(V))).reshape(skirt_rings, skirt_around)
        off += len(V)
    rest = np.concatenate(verts)
    weights = skinning_weights(rest, rig)
    return Character(rest, np.concatenate(faces), np.concatenate(part), names, skirt_idx, rig, weights)


# --------------------------------------------------------------------------- motion
def _smoothstep(x):
    x = np.clip(x, 0, 1)
    return x * x * (3 - 2 * x)


def procedural_motion(kind: str, frames: int, fps: float, seed: int, rig: Rig | None = None, speed: float = 1.0):
    """Seeded synthetic motion on the 18-joint rig (T-pose rest, facing +Z, left = +X).

    ``kind`` is ``"dance"`` (samba-like: hip sway and twist, stepping, arm
    waves, one full turn in the middle) or ``"walk"``. ``speed`` scales time
    (an edit: the same clip played faster).

    Returns root_t (F, 3) metres and angles (F, 18, 3) radians.
    """
    if kind not in ("dance", "walk"):
        raise ValueError(f"procedural motion kind must be 'dance' or 'walk', got {kind!r}")
    rng = np.random.default_rng(seed)
    J = {n: i for i, n in enumerate(JOINTS)}
    hip = (rig.starts[0] if rig is not None else np.array([0, 0.95, 0]))
    t = np.arange(frames) / fps * speed
    T = frames / fps * speed if speed != 1 else frames / fps
    T0 = frames / fps
    ph = rng.uniform(0, 2 * np.pi, 8)
    amp = rng.uniform(0.85, 1.15, 8)
    A = np.zeros((frames, 18, 3))
    rt = np.tile(hip, (frames, 1)).astype(float)
    w = 2 * np.pi * (1.0 if kind == "dance" else 0.9)
    s1 = np.sin(w * t)
    if kind == "dance":
        rt[:, 0] += 0.07 * amp[0] * np.sin(w * t / 2 + ph[0])
        rt[:, 2] += 0.10 * amp[1] * np.sin(w * t / 4 + ph[1])
        rt[:, 1] += -0.03 + 0.025 * np.cos(2 * w * t)
        spin = 2 * np.pi * _smoothstep((t - 0.45 * T0) / 1.6)
        A[:, J["hips"], 1] = 0.55 * amp[2] * np.sin(w * t / 4 + ph[2]) + spin
        A[:, J["hips"], 2] = 0.14 * amp[3] * s1
        A[:, J["hips"], 0] = 0.06 * np.sin(2 * w * t)
        A[:, J["spine"], 1] = -0.25 * np.sin(w * t / 4 + ph[2])
        A[:, J["spine"], 2] = -0.10 * s1
        A[:, J["chest"], 1] = -0.15 * s1
        A[:, J["head"], 0] = 0.08 * np.sin(2 * w * t)
        arm = 0.35 * amp[4] * np.sin(w * t / 2 + ph[4])
        A[:, J["l_upperarm"], 2] = -0.9 + arm
        A[:, J["r_upperarm"], 2] = 0.9 + arm
        A[:, J["l_upperarm"], 1] = -0.5 - 0.3 * s1
        A[:, J["r_upperarm"], 1] = 0.5 - 0.3 * s1
        A[:, J["l_forearm"], 1] = -0.9 - 0.3 * np.sin(w * t + ph[5])
        A[:, J["r_forearm"], 1] = 0.9 + 0.3 * np.sin(w * t + ph[5])
        step = 0.45 * amp[6]
        A[:, J["l_thigh"], 0] = -step * np.maximum(s1, 0) + 0.08
        A[:, J["r_thigh"], 0] = -step * np.maximum(-s1, 0) + 0.08
        A[:, J["l_thigh"], 2] = 0.08 * np.sin(w * t / 2 + ph[7])
        A[:, J["r_thigh"], 2] = -0.08 * np.sin(w * t / 2 + ph[7])
        A[:, J["l_shin"], 0] = 0.7 * step * np.maximum(s1, 0) ** 0.8 + 0.05
        A[:, J["r_shin"], 0] = 0.7 * step * np.maximum(-s1, 0) ** 0.8 + 0.05
    else:
        v = 1.1 * amp[0]
        yaw = 0.5 * np.sin(2 * np.pi * t / max(T, 1e-6) + ph[0])
        heading = np.cumsum(np.r_[0, np.diff(t)][:, None] * v * np.stack([np.sin(yaw), np.cos(yaw)], 1), axis=0)
        rt[:, 0] += heading[:, 0]
        rt[:, 2] += heading[:, 1]
        rt[:, 1] += 0.02 * np.cos(2 * w * t)
        A[:, J["hips"], 1] = yaw + 0.12 * s1
        A[:, J["hips"], 2] = 0.06 * s1
        A[:, J["spine"], 1] = -0.15 * s1
        A[:, J["l_upperarm"], 2] = -1.25
        A[:, J["r_upperarm"], 2] = 1.25
        A[:, J["l_upperarm"], 1] = 0.35 * s1
        A[:, J["r_upperarm"], 1] = 0.35 * s1
        A[:, J["l_forearm"], 1] = -0.3
        A[:, J["r_forearm"], 1] = 0.3
        A[:, J["l_thigh"], 0] = -0.45 * amp[6] * s1
        A[:, J["r_thigh"], 0] = 0.45 * amp[6] * s1
        A[:, J["l_shin"], 0] = 0.6 * np.maximum(np.sin(w * t - 0.8), 0)
        A[:, J["r_shin"], 0] = 0.6 * np.maximum(-np.sin(w * t - 0.8), 0)
        A[:, J["l_foot"], 0] = 0.15 * s1
        A[:, J["r_foot"], 0] = -0.15 * s1
    return rt, A


def edit_motion(root_t: np.ndarray, angles: np.ndarray, edit: str, regenerate=None):
    """The same clip with changed joint angles (ground truth comes from re-simulation).

    Edits: ``legs_x1.3`` (thigh/shin angles scaled by 1.3 about their clip
    mean), ``lean_15deg`` (spine bent 15 degrees forward), ``arms_up_25deg``
    (both upper arms raised 25 degrees), ``speed_x1.3`` (played 1.3 times
    faster: needs ``regenerate(speed)`` returning (root_t, angles), else the
    clip is resampled by linear interpolation and the end held).
    """
    J = {n: i for i, n in enumerate(JOINTS)}
    rt, A = root_t.copy(), angles.copy()
    if edit == "legs_x1.3":
        for n in ("l_thigh", "r_thigh", "l_shin", "r_shin"):
            m = A[:, J[n]].mean(axis=0)
            A[:, J[n]] = m + 1.3 * (A[:, J[n]] - m)
    elif edit == "lean_15deg":
        A[:, J["spine"], 0] += np.deg2rad(15)
    elif edit == "arms_up_25deg":
        A[:, J["l_upperarm"], 2] += np.deg2rad(25)
        A[:, J["r_upperarm"], 2] -= np.deg2rad(25)
    elif edit == "speed_x1.3":
        if regenerate is not None:
            return regenerate(1.3)
        F = len(rt)
        src = np.minimum(np.arange(F) * 1.3, F - 1)
        i0 = np.floor(src).astype(int)
        i1 = np.minimum(i0 + 1, F - 1)
        a = (src - i0)[:, None]
        rt = (1 - a) * root_t[i0] + a * root_t[i1]
        A = (1 - a[:, :, None]) * angles[i0] + a[:, :, None] * angles[i1]
    else:
        raise ValueError(f"unknown motion edit {edit!r}; known: {EDITS}")
    return rt, A


# --------------------------------------------------------------------------- simulation
@dataclass
class SkirtParams:
    """Skirt dynamics. Frequencies in Hz, damping in 1/s."""

    hem_frequency: float = 1.1
    waist_frequency: float = 8.0
    damping: float = 2.5
    substeps: int = 8
    constraint_iterations: int = 4
    collision_margin: float = 0.012


def simulate(char: Character, root_t: np.ndarray, angles: np.ndarray, fps: float,
             params: SkirtParams | None = None, preroll: int = 15) -> np.ndarray:
    """Animate the character: LBS body + simulated skirt. Returns vertices (F, V, 3).

    The pose of frame 0 is held for ``preroll`` frames first, so the skirt
    starts settled on the first pose.
    """
    p = params or SkirtParams()
    rig = char.rig
    W, S = forward(rig, root_t, angles)
    T = joint_transforms(rig, W, S)
    body = lbs(char.weights, char.rest, T)  # (F, V, 3)
    F = len(root_t)
    cloth = _Skirt(char, W, S, fps, p)
    out = np.empty((F, len(cloth.idx), 3))
    x = cloth.tgt[0].copy()
    xp = x.copy()
    for f in [0] * max(preroll, 0):
        x, xp = cloth.step(f, x, xp)
    for f in range(F):
        x, xp = cloth.step(f, x, xp)
        out[f] = x
    verts = body.copy()
    verts[:, cloth.idx] = out
    return verts


class _Skirt:
    """The skirt of :func:`simulate` as a mass-spring cloth (position Verlet): its vertices drawn towards a
    rigid skirt attached to the hips (stiffer at the waist), kept at their rest lengths along the rings,
    verticals and shear diagonals, and pushed out of capsules around the legs."""

    def __init__(self, char: Character, W, S, fps: float, p: SkirtParams):
        rig, sk = char.rig, char.skirt
        n_r, n_a = sk.shape
        self.idx = idx = sk.ravel()
        rest = char.rest[idx]
        self.W, self.S, self.p, self.rig = W, S, p, rig
        # rigid skirt target: attached to the hips
        self.tgt = np.einsum("fab,nb->fna", W[:, 0], rest - rig.starts[0]) + S[:, 0, None]
        u = np.repeat(np.linspace(0, 1, n_r), n_a)
        om_h, om_w = 2 * np.pi * p.hem_frequency, 2 * np.pi * p.waist_frequency
        self.k = (om_h + (om_w - om_h) * (1 - u) ** 2) ** 2
        self.pinned = pinned = u == 0
        # structural edges (rings, verticals) and shear diagonals
        g = np.arange(n_r * n_a).reshape(n_r, n_a)
        edges = np.concatenate([np.stack([g.ravel(), np.roll(g, -1, 1).ravel()], 1),
                                np.stack([g[:-1].ravel(), g[1:].ravel()], 1),
                                np.stack([g[:-1].ravel(), np.roll(g[1:], -1, 1).ravel()], 1)])
        L0 = np.linalg.norm(rest[edges[:, 0]] - rest[edges[:, 1]], axis=1)
        self.inv_m = (~pinned).astype(float)
        wsum = self.inv_m[edges[:, 0]] + self.inv_m[edges[:, 1]]
        ok = wsum > 0
        self.edges, self.L0, self.wsum = edges[ok], L0[ok], wsum[ok]
        self.deg = np.bincount(self.edges.ravel(), minlength=len(idx)).astype(float)
        J = {n: i for i, n in enumerate(JOINTS)}
        self.legs = [J[n] for n in ("l_thigh", "l_shin", "r_thigh", "r_shin")]
        self.leg_r = np.array([0.085, 0.055, 0.085, 0.055]) * (rig.ends[J["head"], 1] / 1.72) + p.collision_margin
        self.seg_len = np.linalg.norm(rig.ends[self.legs] - rig.starts[self.legs], axis=1)
        self.dt = 1.0 / (fps * p.substeps)
        self.decay = np.exp(-p.damping * self.dt)

    def step(self, f: int, x, xp):
        """``(x, x_previous)`` after frame ``f`` (``p.substeps`` substeps from frame ``f - 1``'s pose)."""
        p, dt, tgt, pinned = self.p, self.dt, self.tgt, self.pinned
        f0 = max(f - 1, 0)
        for s in range(1, p.substeps + 1):
            a = s / p.substeps
            tg = (1 - a) * tgt[f0] + a * tgt[f]
            xn = x + self.decay * (x - xp) + (dt * dt) * self.k[:, None] * (tg - x)
            xn[pinned] = tg[pinned]
            for _ in range(p.constraint_iterations):
                self._keep_lengths(xn)
            self._collide(xn, f0, f, a)
            xp, x = x, xn
        return x, xp

    def _keep_lengths(self, xn) -> None:
        """One iteration of the rest-length constraints on ``xn`` (in place)."""
        edges, inv_m = self.edges, self.inv_m
        d = xn[edges[:, 1]] - xn[edges[:, 0]]
        ln = np.maximum(np.linalg.norm(d, axis=1), 1e-9)
        corr = ((ln - self.L0) / (ln * self.wsum))[:, None] * d
        acc = np.zeros_like(xn)
        for c in range(3):
            acc[:, c] = np.bincount(edges[:, 0], corr[:, c] * inv_m[edges[:, 0]], len(xn)) - \
                np.bincount(edges[:, 1], corr[:, c] * inv_m[edges[:, 1]], len(xn))
        xn += 1.5 * acc / np.maximum(self.deg, 1)[:, None]

    def _collide(self, xn, f0: int, f: int, a: float) -> None:
        """Push ``xn`` (in place) out of the leg capsules (joint positions interpolated between frames)."""
        rig, S = self.rig, self.S
        for li, j in enumerate(self.legs):
            a0 = (1 - a) * S[f0, j] + a * S[f, j]
            Wj = self.W[f, j]
            axis = Wj @ (rig.ends[j] - rig.starts[j]) / self.seg_len[li]
            v = xn - a0
            tpar = np.clip(v @ axis, 0, self.seg_len[li])
            radial = v - tpar[:, None] * axis
            dist = np.linalg.norm(radial, axis=1)
            hit = (dist < self.leg_r[li]) & ~self.pinned
            if np.any(hit):
                xn[hit] += radial[hit] * ((self.leg_r[li] - dist[hit]) / np.maximum(dist[hit], 1e-9))[:, None]
