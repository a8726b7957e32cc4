"""The :class:`FaceGraphModel` estimator: threshold searches and region graphs.

**Thresholds.** For a target compression (node reduction, %) and tolerance,
the creation threshold (compression ``1 - sample nodes / original frames``)
and then the merge threshold (``1 - final nodes / sample nodes``) are found by
the step-halving search of :mod:`.search`. By default (``thresholds =
"per_sample"``, as in the paper) every sample gets its own creation and merge
threshold in every region; ``"global"`` searches one threshold per region over
all samples. The searches start from data-driven guesses with a first step of
a quarter of the guess.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from . import kernels
from .merging import Merger, merge_sample_graphs
from .preprocess import FaceDatabase
from .samplegraphs import (PoseStack, RegionData, SampleNodes, create_sample_graphs, creation_compression,
                           region_data, sample_nodes)
from .search import step_halving_search
from .similarity import pose_similarity

log = logging.getLogger("animsynth.facegraph.model")

#: First step of the threshold searches, as a fraction of the start threshold.
STEP0_FRACTION = 0.25


# ---------------------------------------------------------------------------
def _consecutive_similarity(rd: RegionData, lam, eps) -> np.ndarray:
    same = np.ones(rd.n_poses, bool)
    same[rd.offsets[:-1]] = False
    i = np.flatnonzero(same)
    r = rd.red
    return pose_similarity(rd.disp[i][:, r], rd.vel[i][:, r], rd.disp[i - 1][:, r], rd.vel[i - 1][:, r], lam, eps)


def _nn_similarity(nodes: SampleNodes, red, rng, k: int = 256) -> np.ndarray:
    """Plain distance sum from up to k random sample nodes to their nearest node of another sample.

    Exact, compiled (:func:`.kernels.nearest_other_sample`; written by hand: the
    distance is a sum of per-landmark Euclidean norms, which no
    scipy/scikit-learn neighbour search offers). The sum runs landmark by
    landmark (the order of a reduction over the strided landmark axis of
    ``D[None] - D[:, None]``, kept so that results do not change).

    Returns
    -------
    ndarray (<= k,), one value per query node that has nodes of another sample
    """
    q = rng.choice(nodes.n, size=min(k, nodes.n), replace=False)
    if len(q) == 0:
        return np.zeros(0)
    D = np.ascontiguousarray(nodes.disp[:, red], float)
    out = kernels.nearest_other_sample(D, np.ascontiguousarray(nodes.sample, np.int64), np.asarray(q, np.int64))
    return out[np.isfinite(out)]


class FaceGraphModel:
    """Region motion graphs of a facial-expression database.

    Parameters
    ----------
    creation_compression, merge_compression : float
        Target node reductions (%) of sample-graph creation and of merging.
    tolerance : float
        Accepted |achieved - target| (percentage points), for both stages
        unless ``creation_tolerance`` / ``merge_tolerance`` are given.
    creation_tolerance, merge_tolerance : float or None
        Per-stage tolerances (the paper's Table 1 gives one per stage).
    thresholds : {"per_sample", "global"}
        ``"per_sample"`` (the paper): every sample gets its own creation and
        merge threshold in every region, searched so that the sample's own
        compression lies in the target band. ``"global"``: one threshold per
        region and stage, searched on the compression over all samples.
    lam : float
        lambda of eq. 3.
    velocity_eps : float
        Speeds at or below this (px/frame) carry no direction (vinfl = 0).
    max_iterations : int
        Builds allowed per threshold search.
    min_step_fraction : float
        A search stops when its step falls below this fraction of its start value.
    procrustes : bool
        Rigid Procrustes alignment of absorbed nodes, propagated along the sample.
    seed : int
        Seeds the choice of the seed sample and the merge order.
    creation_thresholds, merge_thresholds : dict or None
        Fixed thresholds per region (skip the corresponding search).

    Attributes
    ----------
    graphs_ : dict region -> RegionGraph
    creation_thresholds_, merge_thresholds_ : dict region -> ndarray (S,)
        Threshold of every sample (the same value repeated in ``"global"`` mode;
        NaN merge threshold for the seed sample, which forms the initial graph).
    search_ : pandas.DataFrame, one row per region: thresholds (median over samples), achieved
        compressions, share of samples within the band, iterations, converged
    samples_ : pandas.DataFrame, one row per region and sample: thresholds and compressions
    seed_sample_ : int
    timings_ : dict (machine-dependent): ``creation_cpu_s`` / ``creation_wall_s``: the whole fit
        (threshold searches and graph build)
    """

    def __init__(self, creation_compression: float = 50.0, merge_compression: float = 50.0,
                 tolerance: float = 1.0, lam: float = 1.0, velocity_eps: float = 1e-2,
                 max_iterations: int = 40, procrustes: bool = True, seed: int = 0,
                 creation_thresholds: dict | None = None, merge_thresholds: dict | None = None,
                 thresholds: str = "per_sample", creation_tolerance: float | None = None,
                 merge_tolerance: float | None = None, min_step_fraction: float = 1e-3):
        self.creation_compression = creation_compression
        self.merge_compression = merge_compression
        self.tolerance = tolerance
        self.lam = lam
        self.velocity_eps = velocity_eps
        self.max_iterations = max_iterations
        self.procrustes = procrustes
        self.seed = seed
        self.creation_thresholds = creation_thresholds
        self.merge_thresholds = merge_thresholds
        self.thresholds = thresholds
        self.creation_tolerance = creation_tolerance
        self.merge_tolerance = merge_tolerance
        self.min_step_fraction = min_step_fraction

    def _check(self):
        for k in ("creation_compression", "merge_compression"):
            v = getattr(self, k)
            if not 0.0 <= float(v) < 100.0:
                raise ValueError(f"{k} must be in [0, 100), got {v}")
        if self.tolerance <= 0 or (self.creation_tolerance is not None and self.creation_tolerance <= 0) or \
                (self.merge_tolerance is not None and self.merge_tolerance <= 0):
            raise ValueError("tolerances must be > 0")
        if self.lam < 0 or self.velocity_eps < 0:
            raise ValueError("lam and velocity_eps must be >= 0")
        if self.thresholds not in ("per_sample", "global"):
            raise ValueError(f"thresholds must be 'per_sample' or 'global', got {self.thresholds!r}")

    # ------------------------------------------------------------------
    def _creation(self, stack, rdata, regions, lam, eps, tol):
        R, S = len(regions), len(stack.lengths)
        target = float(self.creation_compression)
        if self.creation_thresholds is not None:
            Tc = np.stack([np.broadcast_to(np.asarray(self.creation_thresholds[r], float), (S,)) for r in regions])
            return Tc, np.zeros((R, S), int)
        sims = [_consecutive_similarity(rdata[r], lam, eps) for r in regions]
        t0 = np.array([np.quantile(sim, target / 100.0) for sim in sims])
        t0 = np.maximum(t0, 1e-6)
        if self.thresholds == "global":
            res = step_halving_search(
                lambda T: creation_compression(create_sample_graphs(stack, T, lam), stack.forward)[0],
                target, tol, t0, t0 * STEP0_FRACTION, self.max_iterations, t0 * self.min_step_fraction)
            return np.repeat(res.threshold[:, None], S, 1), np.repeat(res.iterations[:, None], S, 1)
        cache = {"T": None, "C": np.zeros((R, S))}

        def ev(Tflat):
            T = Tflat.reshape(R, S)
            cols = np.arange(S) if cache["T"] is None else np.flatnonzero((T != cache["T"]).any(0))
            if cols.size:
                sub = PoseStack(stack.regions, stack.X[:, cols], stack.U[:, cols], stack.ok[:, cols],
                                stack.lengths[cols], stack.forward[cols])
                a = create_sample_graphs(sub, T[None][:, :, cols], lam)
                cache["C"][:, cols] = creation_compression(a, sub.forward, per_sample=True)[0]
            cache["T"] = T.copy()
            return cache["C"].ravel().copy()

        # start each sample at the quantile of its own consecutive-pose similarities
        T0 = np.empty((R, S))
        for i, r in enumerate(regions):
            sim = sims[i]
            cuts = np.cumsum(rdata[r].forward * 2 - 2)[:-1]
            for k, part in enumerate(np.split(sim, cuts)):
                T0[i, k] = np.quantile(part, target / 100.0) if part.size else t0[i]
        T0 = np.maximum(T0, 1e-6).ravel()
        res = step_halving_search(ev, target, tol, T0, T0 * STEP0_FRACTION, self.max_iterations,
                                  T0 * self.min_step_fraction)
        return res.threshold.reshape(R, S), res.iterations.reshape(R, S)

    def _merge(self, r, rd, nd, lam, eps, tol):
        """Merge the sample graphs of region ``r`` -> (graph, thresholds (S,), iterations (S,), compressions (S,))."""
        S = rd.n_samples
        target = float(self.merge_compression)
        order = self.order_
        thr = np.full(S, np.nan)
        its = np.zeros(S, int)
        comp = np.full(S, np.nan)
        if self.merge_thresholds is not None or self.thresholds == "global":
            if self.merge_thresholds is not None:
                T = np.broadcast_to(np.asarray(self.merge_thresholds[r], float), (S,))
                T = float(T[0]) if np.all(T == T[0]) else np.where(np.isfinite(T), T, 0.0)
            else:
                def ev(T):
                    return np.array([100.0 * (1.0 - merge_sample_graphs(rd, nd, float(T[0]), order, lam, eps,
                                                                        self.procrustes, count_only=True) / nd.n)])

                nn = _nn_similarity(nd, rd.red, np.random.default_rng(self.seed + 1))
                t0 = max(float(np.quantile(nn, target / 100.0)) if nn.size else 1.0, 1e-6)
                res = step_halving_search(ev, target, tol, t0, t0 * STEP0_FRACTION, self.max_iterations,
                                          t0 * self.min_step_fraction)
                T = float(res.threshold[0])
                its[:] = int(res.iterations[0])
            m = Merger(rd, nd, lam, eps, self.procrustes)
            Ts = np.broadcast_to(np.asarray(T, float), (S,))
            for s in order:
                comp[s] = m.merge(int(s), float(Ts[s]))
            thr[:] = Ts
            thr[order[0]] = np.nan
            comp[order[0]] = np.nan
            return m.finish(T if np.ndim(T) == 0 else thr), thr, its, comp
        m = Merger(rd, nd, lam, eps, self.procrustes)
        m.merge(int(order[0]), 0.0)  # the seed sample's graph is the initial graph
        nn = _nn_similarity(nd, rd.red, np.random.default_rng(self.seed + 1))
        t = max(float(np.quantile(nn, target / 100.0)) if nn.size else 1.0, 1e-6)
        for s in order[1:]:
            s = int(s)
            last = {}

            def ev(T, s=s, last=last):
                if last:
                    m.undo()
                last["T"] = float(T[0])
                last["c"] = m.merge(s, last["T"], trial=True)
                return np.array([last["c"]])

            res = step_halving_search(ev, target, tol, t, t * STEP0_FRACTION, self.max_iterations,
                                      t * self.min_step_fraction)
            thr[s] = float(res.threshold[0])
            its[s] = int(res.iterations[0])
            if last["T"] == thr[s]:  # the last trial is the result: keep it
                m.commit()
                comp[s] = last["c"]
            else:
                m.undo()
                comp[s] = m.merge(s, thr[s])
            t = max(thr[s], 1e-6)  # warm start for the next sample
        return m.finish(thr), thr, its, comp

    def fit(self, db: FaceDatabase) -> "FaceGraphModel":
        import pandas as pd

        self._check()
        bad = [db.names[k] for k in range(db.n_samples) if not np.all(np.isfinite(db.forward(k)))]
        if bad or not np.all(np.isfinite(db.mean_neutral)):
            raise ValueError(f"pre-processed database holds non-finite coordinates (samples {bad[:10]}); "
                             "refusing to build graphs")
        too_big = {r: len(ix) for r, ix in db.regions.items() if len(ix) > kernels.MAX_REGION_LANDMARKS}
        if too_big:
            raise ValueError(f"regions with more than {kernels.MAX_REGION_LANDMARKS} landmarks ({too_big}): the compiled "
                             "graph code sums at most that many per region in numpy's order; split the region")
        cpu0, wall0 = time.process_time(), time.perf_counter()
        lam, eps = float(self.lam), float(self.velocity_eps)
        tol_c = float(self.tolerance if self.creation_tolerance is None else self.creation_tolerance)
        tol_m = float(self.tolerance if self.merge_tolerance is None else self.merge_tolerance)
        rng = np.random.default_rng(self.seed)
        S = db.n_samples
        self.seed_sample_ = int(rng.integers(S))
        rest = np.array([s for s in range(S) if s != self.seed_sample_], int)
        self.order_ = np.concatenate([[self.seed_sample_], rng.permutation(rest)]).astype(int)
        rdata = region_data(db)
        regions = list(rdata)
        stack = PoseStack.from_region_data(rdata, eps)
        Tc, c_it = self._creation(stack, rdata, regions, lam, eps, tol_c)
        assign = create_sample_graphs(stack, Tc[None], lam)[0]
        c_ach = creation_compression(assign[None], stack.forward)[0]
        c_per = creation_compression(assign[None], stack.forward, per_sample=True)[0]
        graphs, rows, srows = {}, [], []
        self.creation_thresholds_, self.merge_thresholds_ = {}, {}
        for i, r in enumerate(regions):
            nd = sample_nodes(rdata[r], assign[i])
            g, Tm, m_it, m_per = self._merge(r, rdata[r], nd, lam, eps, tol_m)
            graphs[r] = g
            P, G, N = int(rdata[r].forward.sum()), nd.n, g.n_nodes
            m_ach = 100.0 * (1.0 - N / G)
            c_band = np.abs(c_per[i] - self.creation_compression) <= tol_c
            mk = np.isfinite(m_per)
            m_band = np.abs(m_per[mk] - self.merge_compression) <= tol_m
            if self.thresholds == "global":
                c_ok = abs(c_ach[i] - self.creation_compression) <= tol_c
                m_ok = abs(m_ach - self.merge_compression) <= tol_m
            else:
                c_ok, m_ok = bool(c_band.all()), bool(m_band.all())
            g.info.update(creation_threshold=float(np.median(Tc[i])), creation_compression=float(c_ach[i]),
                          merge_compression=float(m_ach), node_compression=100.0 * (1.0 - N / P))
            self.creation_thresholds_[r] = Tc[i].copy()
            self.merge_thresholds_[r] = Tm
            rows.append({"region": r, "threshold_mode": self.thresholds,
                         "creation_threshold": float(np.median(Tc[i])), "creation_achieved_pct": float(c_ach[i]),
                         "creation_in_band_pct": float(100.0 * c_band.mean()),
                         "creation_iterations": int(c_it[i].max()), "creation_converged": bool(c_ok),
                         "merge_threshold": float(np.nanmedian(Tm)), "merge_achieved_pct": float(m_ach),
                         "merge_in_band_pct": float(100.0 * m_band.mean()) if m_band.size else float("nan"),
                         "merge_iterations": int(m_it.max()), "merge_converged": bool(m_ok),
                         "frames": P, "sample_nodes": G, "nodes": N, "edges": g.n_edges})
            for s in range(S):
                srows.append({"region": r, "sample": db.names[s], "creation_threshold": float(Tc[i, s]),
                              "creation_pct": float(c_per[i, s]), "merge_threshold": float(Tm[s]),
                              "merge_pct": float(m_per[s])})
            if not (c_ok and m_ok):
                log.warning("region %s: compression band not reached everywhere (creation %.2f%% for %.3g +/- %.3g, "
                            "%.0f%% of samples in band; merge %.2f%% for %.3g +/- %.3g)", r, c_ach[i],
                            self.creation_compression, tol_c, 100.0 * c_band.mean(), m_ach,
                            self.merge_compression, tol_m)
        self.graphs_ = graphs
        self.search_ = pd.DataFrame(rows)
        self.samples_ = pd.DataFrame(srows)
        self.timings_ = {"creation_cpu_s": time.process_time() - cpu0, "creation_wall_s": time.perf_counter() - wall0}
        return self
