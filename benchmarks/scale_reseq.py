"""Re-sequencing a 100,000-frame database on one machine (opt-in: config/scale.yaml).

Not a ``bench_*.py`` file, so the default ``benchmarks`` rule does not run it
(it takes minutes). Rows (family ``resequencing``), same columns as
results/benchmarks.csv:

* ``reseq_<N>_frames_total_s``: CPU seconds of neighbours (index + features),
  exact minimum k, Landmark Isomap embedding and one Dijkstra path, measured in
  a fresh process (:func:`animsynth.scale.measure`). Target <= 300 s.
  Baseline: the dense pipeline (28 GB extrapolated at 22,000 frames from earlier
  measurements) is not run; ``baseline`` says so.
* ``reseq_<N>_frames_peak_mb``: the largest per-step peak resident memory of
  that process (interpreter and libraries included). Target <= 4,000 MB.

Run: ``python benchmarks/scale_reseq.py [FRAMES]`` (prints the rows as CSV).
"""

from __future__ import annotations

import sys

from animsynth import scale
from animsynth.benchmark_tables import benchmark_row

DEFAULT_CFG = {"trial_frames": 1000,
               "resequencing": {"metric": "l2", "method": "isomap", "n_candidates": 20, "k": 10, "n_landmarks": 500,
                                "landmarks": "maxmin", "exact_max_frames": 4000},
               "benchmark": {"target_cpu_s": 300, "target_peak_mb": 4000}}


def run(frames: int = 100_000, cfg: dict | None = None, seed: int = 0, cmu_mirror: str | None = None) -> list[dict]:
    cfg = cfg or DEFAULT_CFG
    c = cfg["resequencing"]
    rows = scale.measure("resequencing_steps", n=int(frames), metric=c["metric"], method=c["method"],
                         n_candidates=c["n_candidates"], k=c["k"], embedding="landmark", exact_max_frames=c["exact_max_frames"],
                         n_landmarks=c["n_landmarks"], landmarks=c["landmarks"], seed=seed,
                         trial_frames=cfg["trial_frames"], cmu_mirror=cmu_mirror)
    n = rows[0]["n"]
    tag = f"{n // 1000}k" if n % 1000 == 0 else str(n)
    cpu = sum(r["cpu_s"] for r in rows)
    wall = sum(r["wall_s"] for r in rows)
    peak = max(r["peak_mb"] for r in rows)
    steps = "; ".join(f"{r['step']} {r['cpu_s']:.1f} s CPU / {r['peak_mb']:.0f} MB" for r in rows)
    t_cpu, t_mb = float(cfg["benchmark"]["target_cpu_s"]), float(cfg["benchmark"]["target_peak_mb"])
    info = {"metric": c["metric"], "method": c["method"], "min_k": rows[1].get("min_k"), "k": rows[0].get("k"),
            "embedding_method": rows[2].get("embedding_method"), "steps": steps, "wall_s": round(wall, 2)}
    base = "dense N x N pipeline: not run (N^2 memory; ~28 GB at 22,000 frames)"
    return [
        benchmark_row("resequencing", f"reseq_{tag}_frames_total_s", round(cpu, 2), "s CPU", better="lower",
                      baseline=base, target=f"<= {t_cpu:g}", meets_target=cpu <= t_cpu, **info),
        benchmark_row("resequencing", f"reseq_{tag}_frames_peak_mb", round(peak, 1), "MB", better="lower",
                      baseline=base, target=f"<= {t_mb:g}", meets_target=peak <= t_mb, **info),
    ]


if __name__ == "__main__":
    import pandas as pd

    print(pd.DataFrame(run(int(sys.argv[1]) if len(sys.argv) > 1 else 100_000)).to_csv(index=False))
