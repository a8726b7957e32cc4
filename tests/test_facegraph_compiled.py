"""The compiled (numba) graph creation of facegraph against a numpy route written here.

``animsynth.facegraph.kernels`` runs Algorithm 1, the merge loop (with its trial
merges and undo), the edge weights and the nearest-node search compiled. This
module writes each of them again in numpy, straight from the algorithm's
definition (eq. 3 via :mod:`animsynth.facegraph.similarity`, no pruning, a full
snapshot instead of an undo log), and fits the same database both ways in this
process: once through the library, once with every compiled kernel swapped for
its numpy counterpart (and the kernels themselves made to raise, so nothing
compiled is left on that route).

Integer and structural outputs (node counts, assignments, edges, visit and
merge counts, label masks, the threshold searches' iteration counts) must be
identical; floats (mean displacements, speeds, edge weights, thresholds) agree
to a tight relative tolerance. Nothing is compared with numbers stored from
another machine: numpy's SIMD summation order depends on the CPU, so the last
bits of a float computed through numpy or BLAS cannot travel between machines.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from animsynth.facegraph import FaceGraphModel, FacePreprocessor, kernels, merge_kernels
from animsynth.facegraph import merging, model as model_mod
from animsynth.facegraph.merging import Merger, _finish_graph, _rigid2d
from animsynth.facegraph.model import _nn_similarity
from animsynth.facegraph.regiongraph import EDGE_EPS
from animsynth.facegraph.samplegraphs import PoseStack, create_sample_graphs, region_data, sample_nodes
from animsynth.facegraph.similarity import node_similarity, vinfl
from animsynth.synth.faces import generate_sequences

DB_KWARGS = dict(n_subjects=3, n_sequences=8, total_frames=200, n_unlabelled=0, seed=5)
CONFIGS = {
    "per_sample": dict(creation_compression=50, merge_compression=50, seed=7),
    "per_stage_tolerances": dict(creation_compression=20, merge_compression=70, creation_tolerance=10,
                                 merge_tolerance=20, seed=0),
    "global": dict(creation_compression=50, merge_compression=50, seed=7, thresholds="global"),
    "no_procrustes": dict(creation_compression=30, merge_compression=40, seed=1, procrustes=False),
}
RTOL = 1e-9   # floats: the two routes sum in different orders (and numpy's order depends on the CPU)
EXACT_FIELDS = ("visits", "pose_count", "merge_count", "label_mask", "peak_mask", "peak_dur_n", "edges",
                "start_of_sample", "peak_of_sample")
FLOAT_FIELDS = ("disp", "speed", "weights", "peak_dur_mean", "peak_dur_std")


# ----------------------------------------------------------------------------- the numpy route
def numpy_walk(X, U, OK, threshold, lam, Q):
    """Algorithm 1 for one sample. X, U: (T, L, 2) poses and unit velocities; OK: (T, L) 1 where the
    velocity has a direction. Every node is scored by eq. 3 (minimum over its entering velocities); the
    current node wins ties, then the lowest index; the pose joins the best node if its score is at most
    the threshold, else opens a new node. Returns the node of every pose."""
    T, L = OK.shape
    means, cnt = np.zeros((T, L, 2)), np.zeros(T)
    ent_u, ent_ok, ent_n = np.zeros((T, Q, L, 2)), np.zeros((T, Q, L)), np.zeros(T, int)
    means[0], cnt[0], ent_u[0, 0], ent_ok[0, 0], ent_n[0] = X[0], 1, U[0], OK[0], 1
    n, cur, out = 1, 0, [0]
    for t in range(1, T):
        dist = np.sqrt(((X[t] - means[:n]) ** 2).sum(-1))                              # (n, L)
        cos = np.abs((U[t] * ent_u[:n]).sum(-1))                                        # (n, Q, L)
        vi = (1.0 - np.minimum(cos, 1.0)) * ent_ok[:n] * OK[t]
        sc = (dist[:, None] * (1.0 + lam * vi)).sum(-1)                                 # (n, Q)
        sc[np.arange(Q)[None] >= ent_n[:n, None]] = np.inf
        sc = sc.min(1)
        j = int(np.argmin(sc))
        if sc[cur] <= sc[j]:
            j = cur
        if sc[j] > threshold:
            j, n = n, n + 1
        cnt[j] += 1
        means[j] += (X[t] - means[j]) / cnt[j]
        if j != cur and ent_n[j] < Q:
            ent_u[j, ent_n[j]], ent_ok[j, ent_n[j]] = U[t], OK[t]
            ent_n[j] += 1
        cur = j
        out.append(j)
    return np.array(out)


def numpy_create_sample_graphs(stack, thresholds, lam=1.0, max_entries=3):
    """:func:`create_sample_graphs` (same arguments and result), sample by sample in numpy."""
    R, S, T = stack.X.shape[:3]
    thr = np.asarray(thresholds, float)
    if thr.ndim < 3:
        thr = np.atleast_2d(thr)[..., None]
    thr = np.broadcast_to(thr, (thr.shape[0], R, S))
    out = np.full(thr.shape + (T,), -1, np.int64)
    for b in range(thr.shape[0]):
        for r in range(R):
            for s in range(S):
                n = stack.lengths[s]
                out[b, r, s, :n] = numpy_walk(stack.X[r, s, :n], stack.U[r, s, :n], stack.ok[r, s, :n],
                                              thr[b, r, s], lam, max_entries)
    return out


class NumpyMerger:
    """:class:`animsynth.facegraph.merging.Merger` (same interface), written from the merge's definition:
    a sample node is absorbed into the final node of smallest node-to-node eq. 3 (minimum over that node's
    incoming-edge velocities; first in node and edge creation order on ties) if it is at most the
    threshold, else becomes a new node; on absorption a rigid Procrustes fit aligns it and its transform
    is carried along the sample. A trial merge snapshots the whole state; undo restores it."""

    def __init__(self, rd, nodes, lam=1.0, eps=1e-2, procrustes=True):
        G, Lf, Lr, nv = nodes.n, len(rd.landmarks), len(rd.red), len(nodes.visit_node)
        self.rd, self.nodes, self.lam, self.eps, self.procrustes = rd, nodes, float(lam), float(eps), procrustes
        self.state = dict(n=0, ne=0, Dsum=np.zeros((G, Lf, 2)), cnt=np.zeros(G), node_map=np.full(G, -1),
                          visit_map=np.zeros(nv, int), vin_sum=np.zeros((nv, Lr, 2)), vin_cnt=np.zeros(nv),
                          vin_owner=np.zeros(nv, int), vin_key={}, vin_of=[])
        self._saved = None

    @property
    def n(self):
        return self.state["n"]

    def merge(self, s, threshold, trial=False):
        st, nd, rd = self.state, self.nodes, self.rd
        self._saved = copy.deepcopy(st) if trial else None
        M, red, T = rd.neutral_ref, rd.red, float(threshold)
        n0 = st["n"]
        R = tr = None
        prev = -1
        for v in range(nd.visit_first[s], nd.visit_first[s + 1]):
            g = nd.visit_node[v]
            qv = nd.visit_vel[v] if R is None else nd.visit_vel[v] @ R.T
            f = st["node_map"][g]
            if f < 0:
                qd = nd.disp[g] if R is None else (M + nd.disp[g]) @ R.T + tr - M
                n = st["n"]
                best = -1
                if n:
                    Dmean = st["Dsum"][:n] / st["cnt"][:n, None, None]
                    dist = np.sqrt(((Dmean[:, red] - qd[red]) ** 2).sum(-1))          # (n, Lr)
                    cand = [j for j in np.flatnonzero(dist.sum(-1) <= T) if st["vin_of"][j]]
                    if cand:
                        rows = np.concatenate([[j] * len(st["vin_of"][j]) for j in cand])
                        ent = np.concatenate([st["vin_of"][j] for j in cand])
                        vmean = st["vin_sum"][ent] / st["vin_cnt"][ent, None, None]
                        sc = (dist[rows] * (1.0 + self.lam * vinfl(qv[None], vmean, self.eps))).sum(-1)
                        k = int(np.argmin(sc))
                        if sc[k] <= T:
                            best = int(rows[k])
                c = nd.count[g]
                if best >= 0:
                    if self.procrustes:
                        Ra, ta = _rigid2d(M + qd, M + Dmean[best])
                        qd = (M + qd) @ Ra.T + ta - M
                        qv = qv @ Ra.T
                        R, tr = (Ra, ta) if R is None else (Ra @ R, Ra @ tr + ta)
                    f = best
                    st["Dsum"][f] += c * qd
                    st["cnt"][f] += c
                else:
                    f = n
                    st["n"] = n + 1
                    st["Dsum"][f], st["cnt"][f] = c * qd, c
                    st["vin_of"].append([])
                st["node_map"][g] = f
            e = st["vin_key"].get((f, prev))
            if e is None:
                e = st["vin_key"][(f, prev)] = st["ne"]
                st["ne"] += 1
                st["vin_owner"][e], st["vin_sum"][e], st["vin_cnt"][e] = f, qv, 1.0
                st["vin_of"][f].append(e)
            else:
                st["vin_sum"][e] += qv
                st["vin_cnt"][e] += 1.0
            st["visit_map"][v] = f
            prev = f
        k = nd.first[s + 1] - nd.first[s]
        return 100.0 * (1.0 - (st["n"] - n0) / max(k, 1))

    def undo(self):
        if self._saved is None:
            raise RuntimeError("no trial merge to undo")
        self.state, self._saved = self._saved, None

    def commit(self):
        self._saved = None

    def finish(self, threshold_info):
        st = self.state
        n, ne = st["n"], st["ne"]
        return _finish_graph(self.rd, self.nodes, st["node_map"], st["visit_map"], n,
                             st["Dsum"][:n] / st["cnt"][:n, None, None], st["cnt"][:n],
                             st["vin_sum"][:ne] / st["vin_cnt"][:ne, None, None], st["vin_owner"][:ne],
                             self.lam, self.eps, threshold_info)


def numpy_edge_weights(edges, Dred, vin_mean, vin_owner, n, lam, eps):
    """Node-to-node eq. 3 of every edge (minimum over incoming-velocity pairs) + EDGE_EPS."""
    return np.array([node_similarity(Dred[a], vin_mean[vin_owner == a], Dred[b], vin_mean[vin_owner == b], lam, eps)
                     for a, b in edges]).reshape(-1) + EDGE_EPS


def numpy_nn_similarity(nodes, red, rng, k=256):
    """Distance sum from up to k random nodes to the nearest node of another sample, all pairs."""
    q = rng.choice(nodes.n, size=min(k, nodes.n), replace=False)
    D = nodes.disp[:, red]
    d = np.sqrt(((D[None] - D[q][:, None]) ** 2).sum(-1)).sum(-1)                       # (k, G)
    d[nodes.sample[None, :] == nodes.sample[q][:, None]] = np.inf
    out = d.min(1) if len(q) else np.zeros(0)
    return out[np.isfinite(out)]


KERNELS = {kernels: ("alg1_all", "alg1_walk", "edge_weights", "nearest_other_sample"),
           merge_kernels: ("merge_sample", "undo_merge")}


@pytest.fixture
def numpy_route(monkeypatch):
    """Swap every compiled kernel's caller for the numpy route; the kernels themselves raise."""
    monkeypatch.setattr(model_mod, "create_sample_graphs", numpy_create_sample_graphs)
    monkeypatch.setattr(model_mod, "Merger", NumpyMerger)
    monkeypatch.setattr(merging, "Merger", NumpyMerger)   # merge_sample_graphs (global threshold search)
    monkeypatch.setattr(merging, "_edge_weights", numpy_edge_weights)
    monkeypatch.setattr(model_mod, "_nn_similarity", numpy_nn_similarity)

    def compiled(*a, **k):
        raise AssertionError("a compiled kernel ran on the numpy route")

    for module, names in KERNELS.items():
        for name in names:
            monkeypatch.setattr(module, name, compiled)


# ----------------------------------------------------------------------------- data
@pytest.fixture(scope="module")
def small_db():
    return FacePreprocessor().fit_transform(generate_sequences(**DB_KWARGS), source="compiled vs numpy")


@pytest.fixture(scope="module")
def compiled_fits(small_db):
    return {name: FaceGraphModel(**c).fit(small_db) for name, c in CONFIGS.items()}


def _check_same_fit(got, want):
    assert got.seed_sample_ == want.seed_sample_ and np.array_equal(got.order_, want.order_)
    assert list(got.graphs_) == list(want.graphs_)
    for r, g in got.graphs_.items():
        w = want.graphs_[r]
        assert (g.n_nodes, g.n_edges) == (w.n_nodes, w.n_edges), r
        for k in EXACT_FIELDS:
            np.testing.assert_array_equal(getattr(g, k), getattr(w, k), err_msg=f"{r}.{k}")
        for k in FLOAT_FIELDS:
            np.testing.assert_allclose(getattr(g, k), getattr(w, k), rtol=RTOL, atol=1e-12, err_msg=f"{r}.{k}")
        np.testing.assert_allclose(got.creation_thresholds_[r], want.creation_thresholds_[r], rtol=RTOL)
        np.testing.assert_allclose(got.merge_thresholds_[r], want.merge_thresholds_[r], rtol=RTOL)
    ints = ["frames", "sample_nodes", "nodes", "edges", "creation_iterations", "merge_iterations",
            "creation_converged", "merge_converged"]
    assert got.search_[ints].equals(want.search_[ints])
    pct = ["creation_achieved_pct", "merge_achieved_pct", "creation_in_band_pct", "merge_in_band_pct"]
    np.testing.assert_array_equal(got.search_[pct].to_numpy(), want.search_[pct].to_numpy())  # ratios of counts
    np.testing.assert_array_equal(got.samples_[["creation_pct", "merge_pct"]].to_numpy(),
                                  want.samples_[["creation_pct", "merge_pct"]].to_numpy())


# ----------------------------------------------------------------------------- tests
@pytest.mark.parametrize("config", list(CONFIGS))
def test_compiled_fit_matches_the_numpy_route(small_db, compiled_fits, numpy_route, config):
    got = compiled_fits[config]
    want = FaceGraphModel(**CONFIGS[config]).fit(small_db)
    assert sum(g.n_nodes for g in want.graphs_.values()) > 50   # a real graph, not a trivial one
    _check_same_fit(got, want)


def test_numpy_route_runs_nothing_compiled(small_db, numpy_route):
    """The comparison above would be empty if the model still reached a compiled kernel."""
    with pytest.raises(AssertionError, match="compiled kernel"):
        create_sample_graphs(PoseStack.from_region_data(region_data(small_db)), np.ones(5))


@pytest.mark.parametrize("threshold", [0.3, 2.0, 10.0])
def test_compiled_walk_matches_numpy(small_db, threshold):
    stack = PoseStack.from_region_data(region_data(small_db))
    got = create_sample_graphs(stack, np.full(len(stack.regions), threshold))
    want = numpy_create_sample_graphs(stack, np.full(len(stack.regions), threshold))
    assert (got.max(-1) > 0).any() and (got.max(-1) < stack.lengths - 1).any()   # merges and new nodes
    np.testing.assert_array_equal(got, want)


def test_compiled_trial_merges_and_undo_match_numpy(small_db):
    """A per-sample threshold search's pattern: trial, undo, trial again, commit; then a plain merge."""
    rd = region_data(small_db)
    stack = PoseStack.from_region_data(rd)
    assign = create_sample_graphs(stack, np.full(len(rd), 2.0))[0]
    r = "mouth"
    nd = sample_nodes(rd[r], assign[list(rd).index(r)])
    ms = Merger(rd[r], nd), NumpyMerger(rd[r], nd)
    comps = [[], []]
    for i, m in enumerate(ms):
        m.merge(0, 0.0)
        for s in range(1, rd[r].n_samples):
            comps[i].append(m.merge(s, 1.0, trial=True))
            m.undo()
            comps[i].append(m.merge(s, 4.0 + s % 3, trial=True))
            if s % 2:
                m.commit()
            else:
                m.undo()
                comps[i].append(m.merge(s, 3.0))
    assert comps[0] == comps[1] and len(set(comps[0])) > 3
    g, w = ms[0].finish(3.0), ms[1].finish(3.0)
    assert g.n_nodes == w.n_nodes == ms[0].n == ms[1].n
    np.testing.assert_array_equal(ms[0].node_map, ms[1].state["node_map"])
    np.testing.assert_array_equal(ms[0].visit_map, ms[1].state["visit_map"])
    for k in EXACT_FIELDS:
        np.testing.assert_array_equal(getattr(g, k), getattr(w, k), err_msg=k)
    for k in FLOAT_FIELDS:
        np.testing.assert_allclose(getattr(g, k), getattr(w, k), rtol=RTOL, atol=1e-12, err_msg=k)


@pytest.mark.parametrize("threshold", [0.3, 2.0, 10.0])
def test_pruned_nearest_node_search_matches_all_pairs(small_db, threshold):
    rd = region_data(small_db)
    stack = PoseStack.from_region_data(rd)
    assign = create_sample_graphs(stack, np.full(len(rd), threshold))[0]
    for i, r in enumerate(rd):
        nd = sample_nodes(rd[r], assign[i])
        want = numpy_nn_similarity(nd, rd[r].red, np.random.default_rng(4))
        got = _nn_similarity(nd, rd[r].red, np.random.default_rng(4))
        assert want.size > 0
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
