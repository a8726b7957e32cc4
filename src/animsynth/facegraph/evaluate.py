"""Re-synthesis evaluation behind Table 1 and the baseline comparison.

As in the paper, every database sample is compared with its synthesised
counterpart: the synthesis from the sample's own neutral node to the sample's
own peak node in every region (same source and peak). Two extra columns show
what the graph adds:

* **random peak**: from the sample's neutral node to a random valid peak node
  of its label (seeded), as a user asking for "a happy face" would get;
* **linear**: straight-line interpolation from the neutral pose to the
  sample's peak pose over the mean duration of the other samples of its label
  (what one would do without a graph).

Measures (per sample; tables report mean and standard deviation over samples):

* **duration difference** (frames): ``|synthesised frames - original frames|``
  (its signed mean is reported too: negative = synthesis shorter);
* **landmark difference** (pixels): the synthesis is resampled (linear, same
  time span) to the original length; mean Euclidean distance over frames and
  the 68 landmarks;
* **velocity-angle difference** (%): angle between the original and the
  (resampled) synthesised landmark velocities, as a percentage of 90 degrees
  (the paper's definition: 0 % = same direction, 100 % = perpendicular,
  opposite directions give 200 %), averaged over the frames and landmarks
  where both speeds exceed ``min_speed`` px/frame (directions of still
  landmarks are noise).

Synthesis time is wall-clock (machine-dependent) and kept in ``timing_``
columns.
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from ..io.ckplus import EMOTIONS
from .preprocess import FaceDatabase
from .synthesis import FaceSynthesizer, resample


def landmark_difference(a: np.ndarray, b: np.ndarray) -> float:
    """Mean Euclidean landmark distance of two equally long (T, L, 2) sequences."""
    return float(np.sqrt(((a - b) ** 2).sum(-1)).mean())


def velocity_angle_difference(a: np.ndarray, b: np.ndarray, min_speed: float = 0.05) -> float:
    """Mean angle (% of 90 deg: 100 = perpendicular) between the velocities of
    two (T, L, 2) sequences where both speeds exceed ``min_speed``; NaN if nowhere."""
    if a.shape[0] < 2:
        return float("nan")
    va, vb = np.gradient(a, axis=0), np.gradient(b, axis=0)
    na, nb = np.sqrt((va ** 2).sum(-1)), np.sqrt((vb ** 2).sum(-1))
    ok = (na > min_speed) & (nb > min_speed)
    if not ok.any():
        return float("nan")
    cos = (va * vb).sum(-1)[ok] / (na[ok] * nb[ok])
    return float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).mean() / 90.0 * 100.0)


def compare(original: np.ndarray, synthesised: np.ndarray, min_speed: float = 0.05) -> dict:
    """Duration, landmark and velocity-angle differences of one re-synthesis."""
    syn = resample(synthesised, original.shape[0])
    return {
        "frames_original": int(original.shape[0]),
        "frames_synth": int(synthesised.shape[0]),
        "duration_diff": abs(int(synthesised.shape[0]) - int(original.shape[0])),
        "duration_signed": int(synthesised.shape[0]) - int(original.shape[0]),
        "landmark_diff_px": landmark_difference(original, syn),
        "velocity_angle_diff_pct": velocity_angle_difference(original, syn, min_speed),
    }


def linear_interpolation(peak: np.ndarray, n: int) -> np.ndarray:
    """(n, L, 2) straight line from zero displacement (neutral) to ``peak`` (L, 2)."""
    w = np.linspace(0.0, 1.0, max(int(n), 1))
    return w[:, None, None] * np.asarray(peak, float)[None]


def evaluate_resynthesis(db: FaceDatabase, synth: FaceSynthesizer, seed: int = 0, min_speed: float = 0.05,
                         samples=None, extras: bool = True) -> pd.DataFrame:
    """Re-synthesise samples (default: all) -> one row per sample (see module docs).

    Columns: the counterpart's measures (``duration_diff`` ...), and with
    ``extras`` the same measures prefixed ``random_`` and ``linear_``. The
    random peak choice (and noise, if the synthesiser has any) of sample ``s``
    uses ``numpy.random.default_rng([seed, s])``.
    """
    rows = []
    for s in (range(db.n_samples) if samples is None else samples):
        s = int(s)
        start = synth.start_nodes(sample=s)
        own = {r: int(g.peak_of_sample[s]) for r, g in synth.graphs.items()}
        t0 = time.perf_counter()
        anim = synth.synthesize([int(db.emotions[s])], start=start, rng=np.random.default_rng([int(seed), s]),
                                peak_nodes=own)
        dt = time.perf_counter() - t0
        orig = db.forward(s)
        row = {"sample": db.names[s], "label": EMOTIONS[int(db.emotions[s])]}
        row.update(compare(orig, anim.disp, min_speed))
        if extras:
            rnd = synth.synthesize([int(db.emotions[s])], start=start, rng=np.random.default_rng([int(seed), s]))
            row.update({f"random_{k}": v for k, v in compare(orig, rnd.disp, min_speed).items()
                        if k != "frames_original"})
            same = np.flatnonzero((db.emotions == db.emotions[s]) & (np.arange(db.n_samples) != s))
            n = int(np.rint(db.lengths[same].mean())) if same.size else int(db.lengths.mean())
            lin = linear_interpolation(orig[-1], n)
            row.update({f"linear_{k}": v for k, v in compare(orig, lin, min_speed).items()
                        if k != "frames_original"})
        row["timing_synthesis_ms"] = 1000.0 * dt
        rows.append(row)
    return pd.DataFrame(rows)


MEASURES = (("duration_diff", "duration_diff_frames"), ("duration_signed", "duration_signed_frames"),
            ("landmark_diff_px", "landmark_diff_px"), ("velocity_angle_diff_pct", "velocity_angle_diff_pct"))


def summarise(per_sample: pd.DataFrame) -> dict:
    """Mean and std over samples of the per-sample measures (and of their ``random_`` /
    ``linear_`` variants and the synthesis time where present)."""
    out = {}
    cols = [(c, n) for c, n in MEASURES]
    for pre in ("random_", "linear_"):
        cols += [(pre + c, pre + n) for c, n in MEASURES if pre + c in per_sample]
    if "timing_synthesis_ms" in per_sample:
        cols.append(("timing_synthesis_ms", "timing_synthesis_ms"))
    for col, name in cols:
        v = per_sample[col].to_numpy(float)
        v = v[np.isfinite(v)]
        out[name] = float(v.mean()) if v.size else float("nan")
        out[name + "_sd"] = float(v.std()) if v.size else float("nan")
    return out
