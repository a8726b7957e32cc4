"""Re-synthesis evaluation behind Table 1 and the baseline comparison.

Every database sample is re-synthesised from its own neutral node to a random
valid peak node of its label and compared with the original (pre-processed,
aligned) neutral -> peak sequence:

* **duration difference** (frames): ``|synthesised frames - original frames|``
  (its signed mean is reported too: negative = synthesis shorter);
* **landmark difference** (pixels): the synthesis is resampled (linear, same
  time span) to the original length; mean Euclidean distance over frames and
  the 68 landmarks;
* **velocity-angle difference** (%): angle between the original and the
  (resampled) synthesised landmark velocities, as a percentage of 180 degrees,
  averaged over the frames and landmarks where both speeds exceed
  ``min_speed`` px/frame (directions of still landmarks are noise).

Each measure is averaged per sample; tables report the mean and standard
deviation over samples. Synthesis time is wall-clock (machine-dependent).
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
    """Mean angle (% of 180 deg) between the velocities of two (T, L, 2)
    sequences where both speeds exceed ``min_speed``; NaN if nowhere."""
    if a.shape[0] < 2:
        return float("nan")
    va, vb = np.gradient(a, axis=0), np.gradient(b, axis=0)
    na, nb = np.sqrt((va ** 2).sum(-1)), np.sqrt((vb ** 2).sum(-1))
    ok = (na > min_speed) & (nb > min_speed)
    if not ok.any():
        return float("nan")
    cos = (va * vb).sum(-1)[ok] / (na[ok] * nb[ok])
    return float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).mean() / 180.0 * 100.0)


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


def evaluate_resynthesis(db: FaceDatabase, synth: FaceSynthesizer, seed: int = 0, min_speed: float = 0.05,
                         samples=None) -> pd.DataFrame:
    """Re-synthesise samples (default: all) -> one row per sample (see module docs).

    The random peak choice (and noise, if the synthesiser has any) of sample
    ``s`` uses ``numpy.random.default_rng([seed, s])``.
    """
    rows = []
    for s in (range(db.n_samples) if samples is None else samples):
        rng = np.random.default_rng([int(seed), int(s)])
        start = synth.start_nodes(sample=s)
        t0 = time.perf_counter()
        anim = synth.synthesize([int(db.emotions[s])], start=start, rng=rng)
        dt = time.perf_counter() - t0
        row = {"sample": db.names[s], "label": EMOTIONS[int(db.emotions[s])]}
        row.update(compare(db.forward(s), anim.disp, min_speed))
        row["timing_synthesis_ms"] = 1000.0 * dt
        rows.append(row)
    return pd.DataFrame(rows)


def summarise(per_sample: pd.DataFrame) -> dict:
    """Mean and std over samples of the per-sample measures."""
    out = {}
    for col, name in (("duration_diff", "duration_diff_frames"), ("duration_signed", "duration_signed_frames"),
                      ("landmark_diff_px", "landmark_diff_px"),
                      ("velocity_angle_diff_pct", "velocity_angle_diff_pct"),
                      ("timing_synthesis_ms", "timing_synthesis_ms")):
        v = per_sample[col].to_numpy(float)
        v = v[np.isfinite(v)]
        out[name] = float(v.mean()) if v.size else float("nan")
        out[name + "_sd"] = float(v.std()) if v.size else float("nan")
    return out
