"""simplicial benchmarks: batched field following against the plain per-step scipy loop.

Data: one leave-one-out fold of a synthetic walking subset of real size (3
training clips, about 1,270 latent points, PCA to 2-D, the paper's ``half``
training vectors, k = 16). Rows (family ``simplicial``, unit ``steps/s``):

* ``steps_per_s_1_path_<method>``: one 500-step path with
  :func:`~animsynth.simplicial.path.follow_batch`. Target: at least 2x the
  baseline.
* ``steps_per_s_1000_paths_<method>``: 1,000 paths (starts at seeded random
  training frames plus a small offset) advanced together for 100 steps, steps
  summed over paths. Target: at least 1,000,000 steps/s.

Baseline of every row, measured in the same run: the loop a user would write
with scipy alone, one path at a time, one step at a time:
``Delaunay.find_simplex`` on the current point, 1/D^2 weights over the
simplex's vertices (``cKDTree.query(k=16)`` outside the hull), or
``cKDTree.query(k=16)`` with 1/D^2 weights for k-NN (timed on 1 path, and on
20 of the 1,000 paths for the 1,000-path rows; its rate does not depend on how
many paths there are). Every row also checks that the batched paths equal the
baseline's (to float tolerance over the first 20 steps, before chaotic
divergence of rounding differences can matter) and says so in ``baseline``.

Ours: :func:`~animsynth.simplicial.path.follow_batch` runs every step of
every path in one compiled (numba) call: Delaunay walks from the previous
step's simplex, k-NN scans certified per-training-point neighbour lists, and
1,000 paths are spread over numba's threads. The numba code is compiled (or
loaded from its on-disk cache) in an untimed warm-up.

Timings are machine-dependent (best of 3; ``value`` and ``baseline_value``
are wall-clock rates, the CPU-time rates of both and the load average are in
the row's ``baseline`` text: on a shared machine the CPU-time rates are the
steadier figure). Run: ``python benchmarks/bench_simplicial.py``.
"""

from __future__ import annotations

import os
import time

# numba's OpenMP threads would otherwise spin after each parallel run, taking CPU from the baseline timed next
# (and adding to its CPU time); set before numba starts its threads
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numpy as np  # noqa: E402
from scipy.spatial import Delaunay, cKDTree  # noqa: E402
import numba  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

from animsynth.config import derive_seed  # noqa: E402
from animsynth.simplicial.folds import fit_pca  # noqa: E402
from animsynth.simplicial.field import FieldStack, VectorField, training_vectors  # noqa: E402
from animsynth.simplicial.path import follow_batch  # noqa: E402
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion  # noqa: E402
from animsynth.benchmark_tables import benchmark_row  # noqa: E402

K = 16
# full size (the performance targets) and demo size (seconds, for the default and tiny runs)
SIZES = {
    "full": dict(frames=(443, 360, 455, 454), steps_1=500, steps_many=100, n_paths=1000, n_baseline=20, repeat=3),
    "demo": dict(frames=(150, 120, 140, 130), steps_1=200, steps_many=40, n_paths=200, n_baseline=5, repeat=1),
}
BASELINE = "plain scipy loop (Delaunay.find_simplex / cKDTree.query per step, one path at a time)"


def _fold(latent_dim=2, frames=SIZES["full"]["frames"]):
    sk = cmu_like_skeleton("bench35", 7)
    trials = [generate_motion("walk_straight", n, derive_seed(5, "bench", i), sk).without_root()
              for i, n in enumerate(frames)]
    pca = fit_pca(trials[1:], latent_dim)
    clips = [pca.transform(t) for t in trials[1:]]
    X = np.vstack(clips)
    V = training_vectors(clips, "half")
    return X, V, pca.transform(trials[0])[0]


def plain_scipy_path(tri: Delaunay, tree: cKDTree, X, V, start, steps: int, method: str, k: int = K):
    """The baseline: one path, one step at a time, with scipy calls written as a user would."""
    x = np.array(start, float)
    out = [x]
    for _ in range(steps):
        if method == "delaunay":
            s = tri.find_simplex(x)
            if s >= 0:
                idx = tri.simplices[s]
                d = np.linalg.norm(X[idx] - x, axis=1)
            else:
                d, idx = tree.query(x, k=k)
        else:
            d, idx = tree.query(x, k=k)
        w = 1.0 / d ** 2
        x = x + (w @ V[idx]) / w.sum()
        out.append(x)
    return np.array(out)


def _best(fn, repeat=3):
    best, cpu, out = np.inf, np.inf, None
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        best = min(best, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    return best, cpu, out


def _row(name, value, base, cpu, base_cpu, same, target_txt, target):
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return benchmark_row("simplicial", name, round(value, 1), "steps/s", better="higher",
                         baseline=f"{BASELINE}; CPU-time rates ours {cpu:.0f} vs baseline {base_cpu:.0f} steps/s "
                                  f"(wall {value:.0f} vs {base:.0f}; load average {load:.1f}; "
                                  f"{numba.get_num_threads()} numba thread(s)); "
                                  + ("same paths" if same else "PATHS DIFFER"),
                         baseline_value=round(base, 1), digits=2, target=target_txt,
                         meets_target=target(value, base) and same)


def run(size: str = "full") -> list[dict]:
    """Benchmark rows; ``size`` "full" (the targets) or "demo" (fewer paths and steps, seconds)."""
    # one BLAS thread: idle BLAS threads spinning after the PCA would take CPU from (and show up in) the timings
    with threadpool_limits(limits=1, user_api="blas"):
        return _run(**SIZES[size])


def _run(frames, steps_1, steps_many, n_paths, n_baseline, repeat) -> list[dict]:
    STEPS_1, STEPS_MANY, N_PATHS, N_BASELINE_PATHS = steps_1, steps_many, n_paths, n_baseline
    X, V, start = _fold(2, frames)
    # the baseline uses scipy on the same (duplicate-free) points our field uses
    rows = []
    rng = np.random.default_rng(derive_seed(5, "bench", "starts"))
    for method in ("delaunay", "knn"):
        f = VectorField(method, K).fit(X, V)
        P, Vu = f.points_, f.vectors_
        tri, tree = Delaunay(P), cKDTree(P)
        stack = FieldStack([f])
        plain_scipy_path(tri, tree, P, Vu, start, 5, method)

        starts = P[rng.integers(0, len(P), N_PATHS)] + 1e-3 * np.ptp(P, axis=0) * rng.normal(size=(N_PATHS, P.shape[1]))
        # warm-up, untimed: numba compilation (or its cache), barycentric transforms, neighbour lists
        follow_batch(stack, start[None], 5)
        t, c, ours = _best(lambda: follow_batch(stack, start[None], STEPS_1), repeat)
        tb, cb, base = _best(lambda: plain_scipy_path(tri, tree, P, Vu, start, STEPS_1, method), repeat)
        same = bool(np.allclose(ours.points[:21, 0], base[:21], rtol=0, atol=1e-9 * np.ptp(P)))
        rows.append(_row(f"steps_per_s_1_path_{method}", STEPS_1 / t, STEPS_1 / tb, STEPS_1 / c, STEPS_1 / cb, same,
                         ">= 2x baseline", lambda v, b: v >= 2 * b))

        follow_batch(stack, starts, 2)  # warm-up of the parallel code, after the one-path baseline
        t, c, ours = _best(lambda: follow_batch(stack, starts, STEPS_MANY), repeat)
        sub = starts[:N_BASELINE_PATHS]
        tb, cb, base = _best(lambda: [plain_scipy_path(tri, tree, P, Vu, s, STEPS_MANY, method) for s in sub], repeat=1)
        same = all(np.allclose(ours.points[:21, j], base[j][:21], rtol=0, atol=1e-9 * np.ptp(P))
                   for j in range(N_BASELINE_PATHS))
        n_ours, n_base = N_PATHS * STEPS_MANY, N_BASELINE_PATHS * STEPS_MANY
        rows.append(_row(f"steps_per_s_{N_PATHS}_paths_{method}", n_ours / t, n_base / tb, n_ours / c, n_base / cb, same,
                         ">= 1,000,000 steps/s", lambda v, b: v >= 1e6))
    return rows


if __name__ == "__main__":
    import pandas as pd

    pd.set_option("display.width", 250)
    print(pd.DataFrame(run()).to_csv(index=False))
