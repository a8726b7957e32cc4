"""simplicial benchmarks: path following and vector-field evaluation speed.

Data: one leave-one-out fold of a synthetic walking subset (3 training clips,
about 1270 latent points, PCA to 2-D, and 4-D for the n-D row). Every row's
baseline is measured in the same run:

* ``path_ms_500_steps_<method>``: one 500-step field-following path with our
  low-overhead single-point path (scipy ``find_simplex`` on a (1, d) query
  with the issue-21279 guards, cKDTree for k-NN). Target (issue): well under
  50 ms. Baseline: the batch evaluator (:meth:`VectorField.evaluate`) called
  on one point per step for Delaunay, brute-force k-NN (sorting all
  distances) per step for k-NN.
* ``steps_per_s_<method>``: the same measurement as steps per second.
* ``field_eval_10k_points_<method>``: vectorised :meth:`VectorField.evaluate`
  on a 100 x 100 grid vs a Python loop of single-point evaluations; target
  ratio > 5.
* ``path_ms_500_steps_delaunay_4d``: Delaunay in a 4-D latent space (the
  paper's future work), same baseline as 2-D Delaunay.

Timings are machine-dependent (best of 3). Run: ``python benchmarks/bench_simplicial.py``.
"""

from __future__ import annotations

import time

import numpy as np

from animsynth.config import derive_seed
from animsynth.simplicial.experiment import fit_pca
from animsynth.simplicial.field import VectorField, idw_weights, training_vectors
from animsynth.simplicial.path import follow_field
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

STEPS = 500


def _fold(latent_dim=2):
    sk = cmu_like_skeleton("bench35", 7)
    trials = [generate_motion("walk_straight", n, derive_seed(5, "bench", i), sk).without_root()
              for i, n in enumerate((443, 360, 455, 454))]
    pca = fit_pca(trials[1:], latent_dim)
    clips = [pca.transform(t) for t in trials[1:]]
    X = np.vstack(clips)
    V = training_vectors(clips, "forward")
    return X, V, pca.transform(trials[0])[0]


def _best(fn, repeat=3):
    best = np.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


class _BatchPerStep:
    """Baseline: the vectorised batch evaluator called with one point per step."""

    def __init__(self, field: VectorField):
        self.f = field

    def __call__(self, q):
        v, fb = self.f.evaluate(q[None, :])
        return v[0], bool(fb[0])


class _NaiveKnn:
    def __init__(self, field: VectorField):
        self.f = field

    def __call__(self, q):
        d = np.linalg.norm(self.f.points_ - q, axis=1)
        nn = np.argsort(d)[: self.f.k_eff_]
        w = idw_weights(d[nn][None, :], self.f.hit_tol_)[0]
        return w @ self.f.vectors_[nn], False


def _path_rows(X, V, start, label=""):
    rows = []
    for method in ("delaunay", "knn"):
        f = VectorField(method, 16).fit(X, V)

        t, p = _best(lambda: follow_field(f, start, STEPS))
        naive = _BatchPerStep(f) if method == "delaunay" else _NaiveKnn(f)
        tb, pb = _best(lambda: follow_field(naive, start, STEPS))
        same = bool(np.allclose(p.points, pb.points, atol=1e-8))
        name = f"{method}{label}"
        rows.append({"family": "simplicial", "benchmark": f"path_ms_{STEPS}_steps_{name}", "value": round(t * 1e3, 2),
                     "unit": "ms", "baseline": ("batch VectorField.evaluate on one point per step" if method == "delaunay"
                                                else "brute-force k-NN (sort all distances) per step")
                     + ("; identical path" if same else "; PATH DIFFERS"),
                     "baseline_value": round(tb * 1e3, 2), "ratio": round(tb / t, 2), "target": "< 50 ms",
                     "meets_target": bool(t < 0.05 and same)})
        rows.append({"family": "simplicial", "benchmark": f"steps_per_s_{name}", "value": round(STEPS / t, 1),
                     "unit": "steps/s", "baseline": rows[-1]["baseline"], "baseline_value": round(STEPS / tb, 1),
                     "ratio": round(tb / t, 2), "target": "> 10000 steps/s (500 steps < 50 ms)",
                     "meets_target": bool(STEPS / t > 10000)})
    return rows


def run() -> list[dict]:
    X, V, start = _fold(2)
    rows = _path_rows(X, V, start)
    lo, hi = X.min(0), X.max(0)
    gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], 100), np.linspace(lo[1], hi[1], 100))
    Q = np.stack([gx.ravel(), gy.ravel()], axis=1)
    for method in ("delaunay", "knn"):
        f = VectorField(method, 16).fit(X, V)
        t, (vec, _) = _best(lambda: f.evaluate(Q))
        tl, loop = _best(lambda: np.array([f(q)[0] for q in Q]), repeat=1)
        same = bool(np.allclose(vec, loop, atol=1e-9))
        rows.append({"family": "simplicial", "benchmark": f"field_eval_10k_points_{method}", "value": round(t * 1e3, 2),
                     "unit": "ms", "baseline": "Python loop of single-point evaluations"
                     + ("; identical values" if same else "; VALUES DIFFER"),
                     "baseline_value": round(tl * 1e3, 2), "ratio": round(tl / t, 2), "target": "ratio > 5",
                     "meets_target": bool(tl / t > 5 and same)})
    X4, V4, s4 = _fold(4)
    f = VectorField("delaunay", 16).fit(X4, V4)

    t, p = _best(lambda: follow_field(f, s4, STEPS))
    tb, pb = _best(lambda: follow_field(_BatchPerStep(f), s4, STEPS), repeat=1)
    same = bool(np.allclose(p.points, pb.points, atol=1e-8))
    rows.append({"family": "simplicial", "benchmark": f"path_ms_{STEPS}_steps_delaunay_4d", "value": round(t * 1e3, 2),
                 "unit": "ms", "baseline": "batch VectorField.evaluate on one point per step"
                 + ("; identical path" if same else "; PATH DIFFERS"),
                 "baseline_value": round(tb * 1e3, 2), "ratio": round(tb / t, 2), "target": "< 200 ms (4-D, info)",
                 "meets_target": bool(t < 0.2 and same)})
    return rows


if __name__ == "__main__":
    import pandas as pd

    print(pd.DataFrame(run()).to_csv(index=False))
