"""Synthetic CK+-layout facial-expression database (68 landmarks, neutral -> peak).

CK+ cannot be shipped and no open landmark-sequence dataset is reachable
offline, so the facegraph experiments run by default on this generator, which
writes the official CK+ layout (``Landmarks/Sxxx/yyy/...``, ``Emotion/...``)
that :func:`animsynth.io.ckplus.read_ckplus` then parses like the real thing.

Model (all random choices from one seeded ``numpy.random.Generator``):

* **Face shape.** A hand-made 68-point mean face in the iBUG/300-W landmark
  order (jaw 0-16, brows 17-26, nose 27-35, eyes 36-47, lips 48-67), about
  270 px wide from jaw to jaw and 265 px from brow to chin (a ~270 x 380 px face
  with the forehead) in a 640 x 490 CK+ image. Every subject gets its own
  scale, aspect, eye spacing, mouth width, nose length, jaw width, a smooth
  per-landmark shape offset, a head position and an in-plane tilt.
* **Expressions from action units.** Each FACS action unit (AU1, 2, 4, 5, 6,
  7, 9, 10, 12, 14, 15, 17, 20, 23, 24, 25, 26) is a landmark displacement
  field; each emotion is a set of AUs with weights after EMFACS prototypes
  (happy = 6+12+25, surprise = 1+2+5+25+26, fear = 1+2+4+5+20+25+26, ...;
  contempt is one-sided 12+14). Peaks are therefore label-specific while some
  regions share motion between labels (brows raise in fear and surprise, the
  jaw drops in both, the cheeks+jaw barely move in anger). Per-sequence
  intensity, per-AU jitter, per-subject AU style and occasional dropped minor
  AUs vary the peaks.
* **Timing.** Every AU follows an onset profile normalised to 0 at the first
  (neutral) frame and 1 at the last (peak) frame, like CK+. The profile is
  drawn per sequence from ``onset_shapes``: a sigmoid, an ease-in/out with
  overshoot (a damped oscillation settling on the peak), a two-phase onset (two
  sigmoids), or a cubic ease starting late; centre and steepness vary per
  sequence and each AU gets a small lag. The sigmoid pre-processing therefore
  does not fit every sequence exactly.
* **Paths, asymmetry, intensity, blinks.** Landmarks do not move on straight
  lines: each AU's displacement gets a sideways bend proportional to
  ``w (1 - w)`` of its onset ``w`` (``curvature``, random sign per AU). Each
  subject has a left/right intensity asymmetry (``asymmetry``), each sequence
  a log-normal intensity factor (``intensity_sd``), and with probability
  ``blink_probability`` a sequence contains a blink (eyelids closing and
  re-opening over a few frames, before the peak).
* **Nuisances.** Small rigid head motion (rotation, translation, scale that
  drift with the expression plus a slow wobble) and i.i.d. landmark jitter.
* **Database.** About 20 subjects and 70 labelled sequences whose emotion mix
  follows the CK+ label counts (anger 45, contempt 18, disgust 59, fear 25,
  happy 69, sadness 28, surprise 83), lengths 10-60 frames summing to the
  requested total (1,800 by default), plus a few unlabelled sequences with an
  empty ``Emotion`` folder, as in CK+.
"""

from __future__ import annotations

import os

import numpy as np
import pandas as pd

from ..atomic import atomic_write_text
from ..io.ckplus import EMOTIONS, CKSequence, write_sequence

# Unit mean face (x right, y down), iBUG 68-point order, hand-made after the
# usual 300-W mean shape; x spans ~0.08-0.97 (jaw), y ~0.18 (brows)-1.06 (chin).
MEAN_FACE_UNIT = np.array([
    (0.079, 0.339), (0.083, 0.457), (0.097, 0.576), (0.122, 0.692), (0.169, 0.800), (0.240, 0.896),
    (0.326, 0.977), (0.422, 1.043), (0.532, 1.061), (0.641, 1.040), (0.738, 0.972), (0.824, 0.890),
    (0.895, 0.792), (0.939, 0.682), (0.961, 0.562), (0.971, 0.442), (0.971, 0.322),
    (0.164, 0.249), (0.218, 0.204), (0.291, 0.192), (0.367, 0.204), (0.439, 0.233),
    (0.586, 0.228), (0.660, 0.196), (0.737, 0.182), (0.813, 0.193), (0.871, 0.235),
    (0.515, 0.319), (0.516, 0.396), (0.517, 0.474), (0.518, 0.553),
    (0.434, 0.604), (0.476, 0.621), (0.521, 0.634), (0.566, 0.619), (0.607, 0.602),
    (0.252, 0.331), (0.299, 0.303), (0.356, 0.303), (0.404, 0.339), (0.353, 0.350), (0.297, 0.350),
    (0.631, 0.334), (0.679, 0.296), (0.736, 0.295), (0.783, 0.321), (0.740, 0.342), (0.685, 0.344),
    (0.353, 0.746), (0.415, 0.719), (0.478, 0.707), (0.523, 0.717), (0.570, 0.705), (0.635, 0.716),
    (0.700, 0.739), (0.639, 0.805), (0.576, 0.835), (0.525, 0.842), (0.476, 0.838), (0.414, 0.810),
    (0.380, 0.750), (0.478, 0.745), (0.523, 0.749), (0.571, 0.743),
    (0.672, 0.744), (0.573, 0.777), (0.524, 0.783), (0.478, 0.778),
])
#: Pixels per template unit: jaw width ~270 px.
FACE_SCALE_PX = 303.0
IMAGE_SIZE = (640, 490)

# Left/right mirror of every landmark (image left <-> image right).
_MIRROR = np.arange(68)
for _a, _b in ([(i, 16 - i) for i in range(8)] + [(17, 26), (18, 25), (19, 24), (20, 23), (21, 22), (31, 35),
                (32, 34), (36, 45), (37, 44), (38, 43), (39, 42), (40, 47), (41, 46), (48, 54), (49, 53),
                (50, 52), (55, 59), (56, 58), (60, 64), (61, 63), (65, 67)]):
    _MIRROR[_a], _MIRROR[_b] = _b, _a

# Action units as displacements (px for a 270 px wide face) of image-left and
# centre landmarks; the image-right side is mirrored (dx negated).
_AU_LEFT = {
    1: {21: (0, -12), 20: (0, -9), 19: (0, -5), 18: (0, -2)},
    2: {17: (0, -9), 18: (0, -11), 19: (0, -9), 20: (0, -5), 21: (0, -2)},
    4: {21: (5, 9), 20: (3, 8), 19: (2, 6), 18: (1, 4), 17: (0, 2), 37: (0, 1.5), 38: (0, 1.5)},
    5: {37: (0, -4.5), 38: (0, -4.5), 36: (0, -0.8), 39: (0, -0.5)},
    6: {40: (0, -2.5), 41: (0, -2.5), 36: (-0.5, -1), 1: (0, -2), 2: (-1, -3), 3: (-1, -3), 48: (0, -1.5)},
    7: {40: (0, -3), 41: (0, -3), 37: (0, 1.5), 38: (0, 1.5)},
    9: {31: (-1.5, -5), 32: (0, -5), 33: (0, -4.5), 30: (0, -3), 29: (0, -1.5), 21: (1, 4), 20: (0, 2),
        39: (0, -1), 40: (0, -1.5), 49: (0, -2), 50: (0, -3), 51: (0, -3), 61: (0, -2), 62: (0, -2)},
    10: {49: (0, -5), 50: (0, -7), 51: (0, -8), 61: (0, -5), 62: (0, -6), 48: (0, -2), 60: (0, -2),
         31: (0, -1.5), 32: (0, -1)},
    12: {48: (-14, -9), 60: (-11, -7), 49: (-6, -4), 59: (-7, -3), 50: (-2, -1), 58: (-2, 0), 61: (-4, -2),
         67: (-4, -1), 57: (0, 1), 66: (0, 1), 2: (0, -2), 3: (-1, -2), 4: (0, -1)},
    14: {48: (-5, -1.5), 60: (-4, -1), 49: (-1.5, 0), 59: (-1.5, 0)},
    15: {48: (-1, 8), 60: (-0.5, 6), 49: (0, 3), 59: (0, 3), 61: (0, 1.5), 67: (0, 1.5), 4: (0, 1), 5: (0, 1)},
    17: {58: (0, -4), 57: (0, -5), 67: (0, -3.5), 66: (0, -4), 7: (0, -4), 8: (0, -5), 6: (0, -2.5),
         48: (0, 1.5), 60: (0, 1)},
    20: {48: (-11, 2), 60: (-9, 1.5), 49: (-5, 0.5), 59: (-6, 1), 61: (-3, 0), 67: (-3, 0), 50: (-1.5, 0),
         58: (-1.5, 0), 5: (-1, 0), 4: (-1.5, 0)},
    23: {48: (4, 0), 60: (3, 0), 49: (2, 0.5), 59: (2, -0.5), 50: (0, 1), 51: (0, 1), 57: (0, -1), 58: (0, -1)},
    24: {61: (0, 2), 62: (0, 2), 66: (0, -2), 67: (0, -2), 50: (0, 1.5), 51: (0, 1.5), 57: (0, -1.5), 58: (0, -1.5)},
    25: {58: (0, 4), 57: (0, 4.5), 59: (0, 3), 67: (0, 5), 66: (0, 6), 61: (0, -1), 62: (0, -1.5), 50: (0, -0.5)},
    26: {8: (0, 22), 7: (0, 20), 6: (0.5, 16), 5: (1, 11), 4: (1, 6), 3: (0.5, 2.5), 2: (0, 0.8), 57: (0, 19),
         58: (0, 18), 59: (1, 14), 66: (0, 19), 67: (0, 18), 48: (3, 7), 60: (3, 8), 49: (1, 1), 61: (0, 0.5)},
}
_CENTRE = {8, 27, 28, 29, 30, 33, 51, 57, 62, 66}

#: EMFACS-style prototypes: emotion -> {AU: weight}; "R" AUs are one-sided.
EMOTION_AUS = {
    "anger": {4: 1.0, 5: 0.5, 7: 1.0, 23: 1.0, 24: 0.6, 17: 0.4},
    "contempt": {"12R": 0.7, "14R": 1.0},
    "disgust": {9: 1.0, 10: 0.8, 4: 0.4, 15: 0.5, 17: 0.6},
    "fear": {1: 1.0, 2: 0.7, 4: 0.6, 5: 1.0, 20: 1.0, 25: 1.0, 26: 0.5},
    "happy": {6: 1.0, 12: 1.0, 25: 0.6},
    "sadness": {1: 1.0, 4: 0.7, 15: 1.0, 17: 0.6},
    "surprise": {1: 1.0, 2: 1.0, 5: 0.8, 25: 1.0, 26: 1.0},
}
#: Labelled-sequence counts per emotion in CK+ (Lucey et al. 2010).
CKPLUS_COUNTS = {"anger": 45, "contempt": 18, "disgust": 59, "fear": 25, "happy": 69, "sadness": 28, "surprise": 83}


def au_field(au) -> np.ndarray:
    """(68, 2) displacement of one action unit at full intensity (270 px face).

    ``au`` is an int (bilateral) or ``"<n>R"`` (only the image-left half,
    i.e. the subject's right side).
    """
    one_sided = isinstance(au, str)
    n = int(str(au).rstrip("R"))
    field = np.zeros((68, 2))
    for i, (dx, dy) in _AU_LEFT[n].items():
        field[i] += (dx, dy)
        if not one_sided and i not in _CENTRE:
            field[_MIRROR[i]] += (-dx, dy)
    if one_sided:
        for i in _CENTRE:  # centre points move half as much in a one-sided action
            field[i] *= 0.5
    return field


def _rot(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


def subject_face(rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """A random subject's neutral 68-point face (pixels) and its scale factor."""
    base = (MEAN_FACE_UNIT - MEAN_FACE_UNIT.mean(0)) * FACE_SCALE_PX
    scale = rng.uniform(0.92, 1.08)
    f = base * scale
    f[:, 1] *= rng.normal(1.0, 0.04)                       # face aspect
    eyes = np.r_[17:27, 36:48]
    side = np.sign(f[eyes, 0] - f[27:31, 0].mean())
    f[eyes, 0] += side * rng.normal(0.0, 3.0)                # eye spacing
    mouth = np.r_[48:68]
    mc = f[mouth].mean(0)
    f[mouth, 0] = mc[0] + (f[mouth, 0] - mc[0]) * rng.normal(1.0, 0.06)  # mouth width
    f[30:36, 1] += rng.normal(0.0, 4.0)                      # nose length
    jc = f[0:17, 0].mean()
    f[0:17, 0] = jc + (f[0:17, 0] - jc) * rng.normal(1.0, 0.04)  # jaw width
    smooth = rng.normal(0.0, 1.5, size=(68, 2))
    f += smooth
    theta = np.deg2rad(rng.normal(0.0, 2.0))
    centre = np.array([IMAGE_SIZE[0] / 2 + rng.normal(0, 12), IMAGE_SIZE[1] / 2 + 25 + rng.normal(0, 10)])
    return f @ _rot(theta).T + centre, float(scale)


def _sigmoid_weights(tau, centre, steep):
    s = 1.0 / (1.0 + np.exp(-steep * (tau - centre)))
    s0 = 1.0 / (1.0 + np.exp(steep * centre))
    s1 = 1.0 / (1.0 + np.exp(-steep * (1.0 - centre)))
    return (s - s0) / (s1 - s0)


ONSET_SHAPES = ("sigmoid", "overshoot", "two_phase", "ease")
_UPPER_LIDS = [37, 38, 43, 44]
_LOWER_LIDS = [40, 41, 46, 47]


def onset_profile(shape: str, tau: np.ndarray, centre: float, steep: float) -> np.ndarray:
    """Onset weight over normalised time ``tau`` (0 at the first frame, 1 at the last)."""
    if shape == "sigmoid":
        return _sigmoid_weights(tau, centre, steep)
    if shape == "two_phase":
        w = 0.55 * _sigmoid_weights(tau, 0.6 * centre, 1.5 * steep) + 0.45 * _sigmoid_weights(
            tau, min(0.9, centre + 0.3), 1.5 * steep)
        return (w - w[0]) / (w[-1] - w[0])
    x = np.clip((tau - (centre - 0.3)) / max(1.3 - centre, 1e-3), 0.0, None)
    if shape == "overshoot":
        a, b = 4.0, 9.0  # damped oscillation settling on the peak
        w = 1.0 - np.exp(-a * x) * (np.cos(b * x) + a / b * np.sin(b * x))
        return w / w[-1] if abs(w[-1]) > 1e-9 else w
    if shape == "ease":
        u = np.clip(x / max(x[-1], 1e-9), 0.0, 1.0)
        return u * u * (3.0 - 2.0 * u)
    raise ValueError(f"unknown onset shape {shape!r}; expected one of {list(ONSET_SHAPES)}")


def _perp(field: np.ndarray) -> np.ndarray:
    return np.stack([-field[:, 1], field[:, 0]], 1)


def expression_sequence(neutral: np.ndarray, face_scale: float, emotion: str | None, n_frames: int,
                        rng: np.random.Generator, style: dict | None = None, jitter_px: float = 0.6,
                        head_rotation_deg: float = 1.5, head_translation_px: float = 3.0, curvature: float = 0.35,
                        onset_shapes=ONSET_SHAPES, intensity_sd: float = 0.2,
                        blink_probability: float = 0.4) -> np.ndarray:
    """(n_frames, 68, 2) landmarks going from ``neutral`` to the peak of ``emotion``.

    ``emotion=None`` gives an unlabelled sequence (a random mild mix of AUs).
    ``style``: per-subject AU gains (int keys) and ``"asym"`` (left/right asymmetry).
    """
    style = style or {}
    tau = np.linspace(0.0, 1.0, n_frames)
    centre = rng.uniform(0.35, 0.6)
    steep = rng.uniform(8.0, 14.0)
    shape = str(onset_shapes[int(rng.integers(len(onset_shapes)))])
    disp = np.zeros((n_frames, 68, 2))
    if emotion is None:
        pool = [1, 2, 4, 6, 7, 12, 15, 17, 25]
        aus = {int(a): float(rng.uniform(0.2, 0.5)) for a in rng.choice(pool, size=2, replace=False)}
    else:
        aus = EMOTION_AUS[emotion]
    gain = float(np.exp(rng.normal(0.0, intensity_sd))) * 0.93
    for au, w in aus.items():
        if w < 0.7 and rng.random() < 0.2:
            continue  # minor AU left out of this performance
        amp = gain * w * rng.uniform(0.8, 1.2) * style.get(int(str(au).rstrip("R")), 1.0)
        lag = rng.normal(0.0, 0.05)
        wt = onset_profile(shape, tau, float(np.clip(centre + lag, 0.15, 0.85)), steep * rng.uniform(0.8, 1.25))
        field = amp * face_scale * au_field(au)
        bend = curvature * rng.choice([-1.0, 1.0]) * 4.0 * wt * (1.0 - wt)
        disp += wt[:, None, None] * field[None] + bend[:, None, None] * _perp(field)[None]
    # per-subject asymmetry: image-left landmarks stronger, image-right weaker (or the reverse)
    side = np.sign(neutral[:, 0] - neutral[:, 0].mean())
    disp *= (1.0 + float(style.get("asym", 0.0)) * side)[None, :, None]
    if rng.random() < blink_probability and n_frames >= 6:
        tb = rng.uniform(0.15, 0.7) * (n_frames - 1)
        width = rng.uniform(0.8, 1.6)
        bump = np.exp(-0.5 * ((np.arange(n_frames) - tb) / width) ** 2)
        bump -= bump[-1]
        height = np.abs(neutral[_LOWER_LIDS, 1] - neutral[_UPPER_LIDS, 1])
        disp[:, _UPPER_LIDS, 1] += 0.8 * bump[:, None] * height[None]
        disp[:, _LOWER_LIDS, 1] -= 0.1 * bump[:, None] * height[None]
    # rigid head motion about the face centre, drifting with the expression
    wh = _sigmoid_weights(tau, centre, steep)
    phase = rng.uniform(0, 2 * np.pi)
    wob = np.sin(2 * np.pi * rng.uniform(0.3, 1.0) * tau + phase) - np.sin(phase)
    theta = np.deg2rad(rng.normal(0.0, head_rotation_deg) * wh + 0.3 * wob)
    trans = (rng.normal(0.0, head_translation_px, size=2)[None] * wh[:, None]
             + rng.normal(0.0, 0.5, size=2)[None] * wob[:, None])
    scale = 1.0 + rng.normal(0.0, 0.015) * wh
    c = neutral.mean(0)
    out = np.empty_like(disp)
    for t in range(n_frames):
        p = (neutral + disp[t] - c) * scale[t]
        out[t] = p @ _rot(theta[t]).T + c + trans[t]
    out += rng.normal(0.0, jitter_px, size=out.shape)
    return out


def _largest_remainder(weights: dict, total: int) -> dict:
    keys = list(weights)
    w = np.array([weights[k] for k in keys], float)
    raw = w / w.sum() * total
    n = np.floor(raw).astype(int)
    order = np.argsort(-(raw - n), kind="stable")
    for i in order[: total - n.sum()]:
        n[i] += 1
    return dict(zip(keys, n.tolist()))


def _lengths(rng, n, total, lo, hi):
    if not lo * n <= total <= hi * n:
        raise ValueError(f"cannot split {total} frames into {n} sequences of {lo}-{hi} frames")
    mean = total / n
    ln = np.clip(np.round(np.exp(rng.normal(np.log(mean) - 0.04, 0.3, size=n))), lo, hi).astype(int)
    while ln.sum() != total:
        i = rng.integers(n)
        step = 1 if ln.sum() < total else -1
        if lo <= ln[i] + step <= hi:
            ln[i] += step
    return ln


def generate_sequences(n_subjects: int = 20, n_sequences: int = 70, total_frames: int = 1800,
                       n_unlabelled: int = 4, min_frames: int = 10, max_frames: int = 60, seed: int = 0,
                       jitter_px: float = 0.6, head_rotation_deg: float = 1.5,
                       head_translation_px: float = 3.0, curvature: float = 0.35, onset_shapes=ONSET_SHAPES,
                       asymmetry: float = 0.2, intensity_sd: float = 0.2,
                       blink_probability: float = 0.4) -> list[CKSequence]:
    """Generate the synthetic database in memory (see module docs)."""
    if n_subjects < 1 or n_sequences < 1:
        raise ValueError("need at least one subject and one labelled sequence")
    rng = np.random.default_rng(seed)
    counts = _largest_remainder(CKPLUS_COUNTS, n_sequences)
    emotions = [e for e, k in counts.items() for _ in range(k)]
    rng.shuffle(emotions)
    emotions = emotions + [None] * n_unlabelled
    lengths = list(_lengths(rng, n_sequences, total_frames, min_frames, max_frames))
    if n_unlabelled:
        lengths += list(_lengths(rng, n_unlabelled, int(round(total_frames / n_sequences * n_unlabelled)),
                                 min_frames, max_frames))
    ids = np.sort(rng.choice(np.arange(5, 1000), size=n_subjects, replace=False))
    subjects = []
    for sid in ids:
        face, sc = subject_face(rng)
        style = {au: float(rng.normal(1.0, 0.1)) for au in _AU_LEFT}
        style["asym"] = float(rng.normal(0.0, asymmetry))
        subjects.append((f"S{sid:03d}", face, sc, style))
    per_subject: dict[int, list[int]] = {i: [] for i in range(n_subjects)}
    for k in range(len(emotions)):
        per_subject[k % n_subjects].append(k)
    out = []
    for si, ks in per_subject.items():
        name, face, sc, style = subjects[si]
        for q, k in enumerate(ks, start=1):
            emo = emotions[k]
            lms = expression_sequence(face, sc, emo, int(lengths[k]), rng, style, jitter_px,
                                      head_rotation_deg, head_translation_px, curvature, tuple(onset_shapes),
                                      intensity_sd, blink_probability)
            out.append(CKSequence(name, f"{q:03d}", lms, None if emo is None else EMOTIONS.index(emo),
                                  np.arange(1, int(lengths[k]) + 1)))
    return out


def write_database(root, sequences: list[CKSequence]) -> pd.DataFrame:
    """Write ``sequences`` in the CK+ layout under ``root`` (+ a README); return a summary table."""
    os.makedirs(root, exist_ok=True)
    rows = []
    for s in sequences:
        write_sequence(root, s)
        rows.append({"subject": s.subject, "sequence": s.sequence, "emotion": s.label or "", "frames": s.n_frames})
    atomic_write_text(os.path.join(root, "README.txt"),
                      "SYNTHETIC data in the CK+ layout, written by animsynth.synth.faces.\n"
                      "It is not the Extended Cohn-Kanade database; it only mimics its file layout,\n"
                      "landmark scheme (68 points, image pixels) and label codes (0-7).\n")
    return pd.DataFrame(rows)


def generate_database(root, seed: int = 0, **kwargs) -> pd.DataFrame:
    """Generate and write the synthetic CK+-layout database; return the summary table."""
    return write_database(root, generate_sequences(seed=seed, **kwargs))
