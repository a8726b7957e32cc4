"""compare: the long track's thresholds measured on real captures (never on generators' results).

Every walk trial in ASF/AMC of the two CMU mirrors (``<shared>/cmu_mocap`` and ``<shared>/cmu_mocap_many``,
``<shared>`` = ``../shared/data`` or ``ANIMSYNTH_SHARED_DATA``; a trial whose kind or CMU description says "walk"),
resampled to the comparison's 30 fps, scored as the long track's measures score a motion
(:mod:`animsynth.compare.measures.repetition`, :mod:`animsynth.compare.measures.root`):

* **repetition**: each 1-s window's distance to its nearest earlier, non-overlapping window of the same capture
  (:func:`~animsynth.compare.measures.repetition.earliest_repeat_distance`): per trial its smallest, then the
  smallest, 5th percentile and median over trials, and the captures' repetition share at candidate tolerances;
* **still frames**: the share of frames below candidate (root, pose) speed floors, and the speed percentiles;
* **root height and tilt**: each trial's range.

Run: ``python benchmarks/capture_long_measures.py`` (about a minute of one core). The values it prints are those
``docs/compare/metrics.md`` quotes ("Thresholds from the captures").
"""

from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np

from animsynth.compare import measures as M
from animsynth.compare.measures.repetition import earliest_repeat_distance, repetition_share
from animsynth.compare.measures.root import pose_speed, root_speed, root_tilt_deg
from animsynth.compare.protocol import resample
from animsynth.io import read_amc, read_asf

REPO = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("ANIMSYNTH_SHARED_DATA", REPO.parent / "shared" / "data"))
FPS, WINDOW = 30.0, 30
TOLERANCES = (0.005, 0.01, 0.012, 0.02, 0.03)
FLOORS = ((0.05, 0.05), (0.1, 0.1), (0.15, 0.15), (0.2, 0.2))


def walks():
    """(trial, Motion at 30 fps) of every readable ASF/AMC walk of the two mirrors."""
    for mirror in ("cmu_mocap", "cmu_mocap_many"):
        base = SHARED / mirror
        for r in csv.DictReader(open(base / "trials.csv")):
            if not r["file"].endswith(".amc") or "walk" not in (r["kind"] + r["cmu_description"]).lower():
                continue
            subject = r["subject"]
            try:
                sk = read_asf(base / "subjects" / subject / f"{subject}.asf")
                yield r["trial"], resample(read_amc(base / r["file"], sk, float(r["fps"])), FPS)
            except (OSError, ValueError) as exc:
                print(f"skipped {r['trial']}: {exc}")


def main() -> None:
    closest, shares, still, speeds, ranges, frames = [], [], [], [], [], 0
    for trial, m in walks():
        pos = M.positions(m)
        F = M.pose_features(pos, M.facing(m))
        frames += len(F)
        d = earliest_repeat_distance(F, WINDOW)
        if np.isfinite(d).any():
            closest.append(float(d[np.isfinite(d)].min()))
            shares.append([repetition_share(F, WINDOW, t) for t in TOLERANCES])
        rv, pv = root_speed(pos, FPS), pose_speed(F, FPS)
        still.append([float(np.mean((rv < a) & (pv < b))) for a, b in FLOORS])
        speeds.append((rv, pv, trial))
        tilt = root_tilt_deg(m.skeleton, m.values)
        ranges.append((trial, pos[:, 0, 1].min(), pos[:, 0, 1].max(), tilt.min(), tilt.max()))
    c = np.array(closest)
    print(f"{len(speeds)} walk trials, {frames} frames at {FPS:g} fps; {len(c)} long enough for two 1-s windows")
    print(f"closest earlier 1-s window (m): min {c.min():.4f}, 5th percentile {np.percentile(c, 5):.4f}, "
          f"median {np.median(c):.4f}")
    s = np.array(shares)
    for k, t in enumerate(TOLERANCES):
        print(f"  tolerance {t:g} m: captures' repetition share mean {s[:, k].mean():.3f}, max {s[:, k].max():.3f}, "
              f"trials above 0: {int((s[:, k] > 0).sum())}")
    st = np.array(still)
    for k, (a, b) in enumerate(FLOORS):
        print(f"  still below root {a:g} m/s and pose {b:g} m/s: mean share {st[:, k].mean():.3f}, "
              f"max {st[:, k].max():.3f}")
    rv = np.concatenate([x[0] for x in speeds])
    pv = np.concatenate([x[1] for x in speeds])
    moving = rv > 0.5
    print(f"pose speed (m/s) of frames whose root moves above 0.5 m/s: 1st percentile "
          f"{np.percentile(pv[moving], 1):.3f}, 5th {np.percentile(pv[moving], 5):.3f}")
    for trial, h0, h1, a0, a1 in ranges:
        print(f"  {trial}: root height {h0:.3f}-{h1:.3f} m, tilt {a0:.1f}-{a1:.1f} deg")


if __name__ == "__main__":
    main()
