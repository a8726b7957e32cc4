"""compare benchmarks: building Kovar et al.'s motion graph (ours) against fairmotion's on the same clips.

Data: the re-sequencing study's walk, run and dance clips together (``resequencing_trials`` of
``config/cmu.yaml``: CMU 35_01, 35_17 and 05_02, 358 + 167 + 1,123 frames at 120 fps) read from
``../shared/data/cmu_mocap`` when it is there, else synthetic clips of the same kinds and lengths (the row's
name says which), resampled to 30 fps (every 4th frame: 413 frames), the compare family's working rate.

Rows (family ``compare``, unit ``s``, CPU seconds by ``time.process_time``; the wall-clock times and the
load average are in the row's ``baseline`` text):

* ``motion_graph_build_cpu_s_<data>_walk_run_dance``: :meth:`animsynth.compare.generators.motiongraph.MotionGraph.fit`
  (forward kinematics, all-pairs window distances, local minima, threshold, largest strongly connected
  component, per-frame rotations for the output) at its defaults, best of three. Target: <= 10 s CPU on the
  2-core build machine. Baseline, measured once in the same run: fairmotion 0.0.4's build on the same clips
  (:class:`animsynth.compare.generators.fairmotion_peer.FairmotionGraph.fit`: BVH writing and fairmotion's BVH loading,
  its velocities, ``construct`` and ``reduce("scc")``), CPU including its worker process (fairmotion compares
  node pairs in a ``multiprocessing`` pool, here of one process); ratio = fairmotion / ours (lower is better:
  above 1, ours is faster; :func:`animsynth.benchmark_tables.benchmark_row`). When fairmotion
  is not installed the row says why and has no baseline.
* ``motion_graph_build_cpu_s_<data>_walk_run_dance_120fps`` (full size only, report only): the same build at
  the capture rate (1,648 frames), to show how the all-pairs step grows.

Demo size: synthetic clips cut to 60 frames each at 30 fps, one repeat.
Run: ``python benchmarks/bench_compare.py`` (prints the rows as CSV).
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import yaml
from threadpoolctl import threadpool_limits

from animsynth.config import trial_records
from animsynth.compare.generators.fairmotion_peer import FairmotionGraph, FairmotionUnavailable
from animsynth.compare.generators.motiongraph import MotionGraph
from animsynth.motion import Motion
from animsynth.benchmark_tables import benchmark_row
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

REPO = Path(__file__).resolve().parents[1]
CMU = Path(os.environ.get("ANIMSYNTH_SHARED_DATA", REPO.parent / "shared" / "data")) / "cmu_mocap"
FPS = 30.0
TARGET_S = 10.0
# full size (the target) and demo size (seconds)
SIZES = {"full": dict(cmu=True, crop=None, repeat=3, capture_rate_row=True),
         "demo": dict(cmu=False, crop=60, repeat=1, capture_rate_row=False)}
SYNTHETIC = {"walk": ("walk_straight", 358, "bench35"), "run": ("run_straight", 167, "bench35"),
             "dance": ("dance", 1123, "bench05")}


def _clips(cmu: bool, step: int, crop: int | None) -> tuple[list[Motion], str]:
    """The walk, run and dance clips at ``120 / step`` fps: CMU when present (and ``cmu``), else synthetic."""
    cfg = yaml.safe_load((REPO / "config" / "cmu.yaml").read_text())
    trials = {t["id"]: t for t in trial_records(cfg["trials"])}
    ids = [cfg["resequencing_trials"][k] for k in ("walk", "run", "dance")]
    if cmu and all((CMU / trials[i]["amc"]).is_file() and (CMU / trials[i]["asf"]).is_file() for i in ids):
        from animsynth.io import read_amc, read_asf

        full = [read_amc(CMU / trials[i]["amc"], read_asf(CMU / trials[i]["asf"])) for i in ids]
        label = "cmu_" + "_".join(ids)
    else:
        full = [generate_motion(kind, n, 3 + k, cmu_like_skeleton(subject, 7), fps=120.0, name=name)
                for k, (name, (kind, n, subject)) in enumerate(SYNTHETIC.items())]
        label = "synthetic"
    clips = [Motion(m.values[::step][:crop], m.skeleton, m.fps / step, m.name) for m in full]
    return clips, label


def _cpu_wall(fn):
    """CPU seconds (this process and its reaped children) and wall seconds of ``fn()``."""
    t0, c0, w0 = os.times(), time.process_time(), time.perf_counter()
    out = fn()
    t1 = os.times()
    children = (t1.children_user - t0.children_user) + (t1.children_system - t0.children_system)
    return time.process_time() - c0 + children, time.perf_counter() - w0, out


def _best(fn, repeat):
    runs = [_cpu_wall(fn) for _ in range(repeat)]
    return min(r[0] for r in runs), min(r[1] for r in runs), runs[-1][2]


def run(size: str = "full") -> list[dict]:
    """Benchmark rows; ``size`` "full" (the target; CMU clips when present) or "demo" (short synthetic clips)."""
    p = SIZES[size]
    rows = []
    with threadpool_limits(limits=1, user_api="blas"):
        clips, label = _clips(p["cmu"], 4, p["crop"])
        frames = sum(c.n_frames for c in clips)
        cpu, wall, graph = _best(lambda: MotionGraph().fit(clips), p["repeat"])
        try:
            fm_cpu, fm_wall, fm = _cpu_wall(lambda: FairmotionGraph(pool=True).fit(clips))
            base = (f"fairmotion {fm.fairmotion_version_} MotionGraph build on the same clips (BVH, its loader, "
                    f"velocities, construct, reduce scc; {fm.n_nodes_} nodes of 15 frames kept), CPU incl. its "
                    f"worker process, 1 run; wall ours {wall:.2f} s, fairmotion {fm_wall:.2f} s")
            fm_value = fm_cpu
        except FairmotionUnavailable as e:
            base, fm_value = f"fairmotion not run: {e.reason}; wall ours {wall:.2f} s", None
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
        rows.append(benchmark_row(
            "compare", f"motion_graph_build_cpu_s_{label}_walk_run_dance", round(cpu, 3), "s", better="lower",
            baseline=f"{base}; {frames} frames at {FPS:g} fps; ours best of {p['repeat']}: {graph.n_nodes_} "
                     f"frames in the graph, {len(graph.transitions_)} transitions; load average {load:.1f}",
            baseline_value=None if fm_value is None else round(fm_value, 3), digits=1,
            target=f"<= {TARGET_S:g} s CPU (2 cores)", meets_target=cpu <= TARGET_S))
        if p["capture_rate_row"]:
            full_rate, label = _clips(p["cmu"], 1, None)
            k = int(round(full_rate[0].fps / 3))  # the same 1/3 s window at the capture rate
            cpu, wall, graph = _best(lambda: MotionGraph(window=k).fit(full_rate), p["repeat"])
            rows.append(benchmark_row(
                "compare", f"motion_graph_build_cpu_s_{label}_walk_run_dance_120fps", round(cpu, 3), "s",
                better="lower", baseline=f"none; {sum(c.n_frames for c in full_rate)} frames at "
                                         f"{full_rate[0].fps:g} fps, window {k}; wall {wall:.2f} s; "
                                         f"{graph.n_nodes_} frames in the graph"))
    return rows


if __name__ == "__main__":
    import pandas as pd

    print(pd.DataFrame(run()).to_csv(index=False))
