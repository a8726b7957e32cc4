"""Merging the sample graphs of a region into its final graph.

The final graph starts from a seed sample chosen at random from a seeded
generator; the nodes of every other sample (seeded random order) are merged in
chain order: a sample node is absorbed into the most similar final node
(node-to-node eq. 3: mean displacements, minimum over incoming-edge
velocities) if that similarity is at most the merge threshold, otherwise it
becomes a new final node. On absorption the sample node's pose is aligned to
the final node by a rigid Procrustes fit (rotation + translation, no scaling)
and that transform is propagated to the sample's following nodes. Edges are
the sample chains' transitions mapped to final nodes (self-loops dropped);
weights are the node-to-node similarity (plus ``EDGE_EPS``).

The merge threshold is either one value for the region or one per sample
(:class:`Merger` can merge a sample on trial, measure how many of its nodes
were absorbed and undo it, which the per-sample threshold search uses).
"""

from __future__ import annotations

import math

import numpy as np

from .regiongraph import EDGE_EPS, RegionGraph
from .samplegraphs import RegionData, SampleNodes
from .similarity import vinfl

#: ``np.add.reduce`` is what ``ndarray.sum`` calls, without its Python wrapper (same result).
_sum = np.add.reduce


# ---------------------------------------------------------------------------
def _rigid2d(a: np.ndarray, b: np.ndarray):
    """Rotation R and translation t with ``a @ R.T + t ~ b`` (2-D, no scaling)."""
    ma, mb = a.mean(0), b.mean(0)
    a0, b0 = a - ma, b - mb
    dot = float((a0 * b0).sum())
    cross = float((a0[:, 0] * b0[:, 1] - a0[:, 1] * b0[:, 0]).sum())
    h = math.hypot(dot, cross)
    c, s = (dot / h, cross / h) if h > 0 else (1.0, 0.0)
    R = np.array([[c, -s], [s, c]])
    return R, mb - R @ ma


class Merger:
    """Incremental merging of the sample graphs of one region (see module docs).

    Samples are merged one at a time (:meth:`merge`), their visits in time
    order; a sample node is placed (absorbed or added) at its first visit, so
    every incoming edge's predecessor is already placed and the incoming-edge
    velocities can be kept per (node, predecessor). Candidate final nodes are
    pruned with the Frobenius lower bound of eq. 3 (exact result). A merge made
    with ``trial=True`` keeps an undo log and is reverted by :meth:`undo`, so
    a per-sample threshold search can try thresholds on the real state.
    """

    def __init__(self, rd: RegionData, nodes: SampleNodes, lam: float = 1.0, eps: float = 1e-2,
                 procrustes: bool = True):
        G, Lf = nodes.n, len(rd.landmarks)
        self.rd, self.nodes, self.lam, self.eps, self.procrustes = rd, nodes, float(lam), float(eps), procrustes
        self.red = rd.red
        self.Lr = len(rd.red)
        self.M = rd.neutral_ref
        self.Dsum = np.empty((G, Lf, 2))
        self.Dmean = np.empty((G, Lf, 2))
        self.Dred = np.empty((G, self.Lr * 2))
        self.Dsq = np.empty(G)
        self.cnt = np.zeros(G)
        self.node_map = np.full(G, -1, int)
        nv = len(nodes.visit_node)
        self.vin_sum = np.empty((nv, self.Lr, 2))
        self.vin_mean = np.empty_like(self.vin_sum)
        self.vin_nrm = np.empty((nv, self.Lr))   # landmark speeds of vin_mean (for vinfl)
        self.vin_cnt = np.zeros(nv)
        self.vin_owner = np.empty(nv, int)
        self.vin_of: list[list[int]] = []
        self.vin_key: dict[tuple[int, int], int] = {}
        self.visit_map = np.empty(nv, int)
        self.n = 0
        self.ne = 0
        self._undo = None

    def _touch_node(self, f):
        u = self._undo
        if u is not None and f < u["n"] and f not in u["nodes"]:
            u["nodes"][f] = (self.Dsum[f].copy(), self.cnt[f])

    def _touch_vin(self, e):
        u = self._undo
        if u is not None and e < u["ne"] and e not in u["vins"]:
            u["vins"][e] = (self.vin_sum[e].copy(), self.vin_cnt[e], self.vin_mean[e].copy(), self.vin_nrm[e].copy())

    def merge(self, s: int, threshold: float, trial: bool = False) -> float:
        """Merge sample ``s`` with ``threshold``; return its merge compression
        (%): ``100 * (1 - new final nodes / nodes of the sample)``."""
        nodes, red, Lr, M, lam, eps = self.nodes, self.red, self.Lr, self.M, self.lam, self.eps
        T = float(threshold)
        T2 = T * T
        n0 = self.n
        self._undo = None
        if trial:
            self._undo = {"n": self.n, "ne": self.ne, "nodes": {}, "vins": {}, "vin_of_len": {}, "keys": [], "s": s}
        Dsum, Dmean, Dred, Dsq, cnt, node_map = self.Dsum, self.Dmean, self.Dred, self.Dsq, self.cnt, self.node_map
        vin_sum, vin_mean, vin_cnt, vin_owner, vin_of, vin_key = (self.vin_sum, self.vin_mean, self.vin_cnt,
                                                                  self.vin_owner, self.vin_of, self.vin_key)
        visit_node, visit_vel, visit_first = nodes.visit_node, nodes.visit_vel, nodes.visit_first
        n, ne = self.n, self.ne
        R = None
        tr = None
        prev = -1
        vin_nrm = self.vin_nrm
        procrustes = self.procrustes
        Lf = M.shape[0]
        for vi_ in range(visit_first[s], visit_first[s + 1]):
            g = visit_node[vi_]
            qv = visit_vel[vi_]
            if R is not None:
                qv = qv @ R.T
            f = node_map[g]
            if f < 0:
                qd = nodes.disp[g]
                if R is not None:
                    qd = (M + qd) @ R.T + tr - M
                qdr = qd[red]
                qr = qdr.ravel()
                best = -1
                if n:
                    frob2 = Dsq[:n] + qr @ qr - 2.0 * (Dred[:n] @ qr)
                    cand = np.flatnonzero(frob2 <= T2 + 1e-12)  # eq. 3 >= distance sum >= Frobenius
                    if cand.size:
                        diff = Dred[cand].reshape(-1, Lr, 2) - qdr
                        dist = np.sqrt(_sum(diff * diff, -1))  # (c, Lr)
                        ok = _sum(dist, -1) <= T
                        if ok.any():
                            cand, dist = cand[ok], dist[ok]
                            if cand.size == 1:
                                ent = vin_of[cand[0]]
                                rows = np.zeros(len(ent), int)
                            else:
                                lists = [vin_of[c] for c in cand]
                                ent = np.concatenate(lists)
                                rows = np.repeat(np.arange(cand.size), [len(x) for x in lists])
                            # vinfl(qv, vin_mean[ent]) with the stored speeds (same arithmetic)
                            vb = vin_mean[ent]
                            qn = np.sqrt(_sum(qv * qv, -1))
                            okv = (qn > eps) & (vin_nrm[ent] > eps)
                            den = np.where(okv, qn * vin_nrm[ent], 1.0)
                            cos = np.where(okv, _sum(qv * vb, -1) / den, 1.0)
                            vi = 1.0 - np.minimum(np.abs(cos), 1.0)
                            sc = _sum(dist[rows] * (1.0 + lam * vi), -1)
                            j = int(np.argmin(sc))
                            if sc[j] <= T:
                                best = int(cand[rows[j]])
                c = nodes.count[g]
                if best >= 0:
                    if procrustes:
                        # _rigid2d(M + qd, M + Dmean[best]), inlined
                        a = M + qd
                        b = M + Dmean[best]
                        ma = _sum(a, 0) / Lf
                        mb = _sum(b, 0) / Lf
                        a0 = a - ma
                        b0 = b - mb
                        dot = float(_sum(a0 * b0, None))
                        cross = float(_sum(a0[:, 0] * b0[:, 1] - a0[:, 1] * b0[:, 0], None))
                        h = math.hypot(dot, cross)
                        cs, sn = (dot / h, cross / h) if h > 0 else (1.0, 0.0)
                        Ra = np.array([[cs, -sn], [sn, cs]])
                        ta = mb - Ra @ ma
                        qd = a @ Ra.T + ta - M
                        qv = qv @ Ra.T
                        if R is None:
                            R, tr = Ra, ta
                        else:
                            R, tr = Ra @ R, Ra @ tr + ta
                    f = best
                    if self._undo is not None:
                        self._touch_node(f)
                    Dsum[f] += c * qd
                    cnt[f] += c
                else:
                    f = n
                    n += 1
                    Dsum[f] = c * qd
                    cnt[f] = c
                    vin_of.append([])
                dm = Dsum[f] / cnt[f]
                Dmean[f] = dm
                dr = dm[red].ravel()
                Dred[f] = dr
                Dsq[f] = dr @ dr
                node_map[g] = f
            key = (f, prev)
            e = vin_key.get(key)
            if e is None:
                e = vin_key[key] = ne
                vin_owner[e] = f
                vin_sum[e] = qv
                vin_cnt[e] = 1.0
                vin_mean[e] = qv
                vin_nrm[e] = np.sqrt(_sum(qv * qv, -1))
                if self._undo is not None:
                    self._undo["keys"].append(key)
                    if f < n0 and f not in self._undo["vin_of_len"]:
                        self._undo["vin_of_len"][f] = len(vin_of[f])
                vin_of[f].append(e)
                ne += 1
            else:
                if self._undo is not None:
                    self._touch_vin(e)
                vin_sum[e] += qv
                vin_cnt[e] += 1.0
                vm = vin_sum[e] / vin_cnt[e]
                vin_mean[e] = vm
                vin_nrm[e] = np.sqrt(_sum(vm * vm, -1))
            self.visit_map[vi_] = f
            prev = f
        self.n, self.ne = n, ne
        k = nodes.first[s + 1] - nodes.first[s]
        return 100.0 * (1.0 - (n - n0) / max(k, 1))

    def undo(self) -> None:
        """Revert the last ``trial`` merge."""
        u = self._undo
        if u is None:
            raise RuntimeError("no trial merge to undo")
        red = self.red
        for f, (dsum, c) in u["nodes"].items():
            self.Dsum[f] = dsum
            self.cnt[f] = c
            self.Dmean[f] = dsum / c
            self.Dred[f] = self.Dmean[f][red].ravel()
            self.Dsq[f] = self.Dred[f] @ self.Dred[f]
        for e, (vs, vc, vm, vn) in u["vins"].items():
            self.vin_sum[e], self.vin_cnt[e], self.vin_mean[e], self.vin_nrm[e] = vs, vc, vm, vn
        for key in u["keys"]:
            del self.vin_key[key]
        for f, ln in u["vin_of_len"].items():
            del self.vin_of[f][ln:]
        del self.vin_of[u["n"]:]
        s = u["s"]
        self.node_map[self.nodes.first[s]:self.nodes.first[s + 1]] = -1
        self.n, self.ne = u["n"], u["ne"]
        self._undo = None

    def commit(self) -> None:
        """Keep the last ``trial`` merge."""
        self._undo = None

    def finish(self, threshold_info) -> RegionGraph:
        """The final :class:`RegionGraph` after every sample was merged."""
        n, ne = self.n, self.ne
        return _finish_graph(self.rd, self.nodes, self.node_map, self.visit_map, n, self.Dmean[:n], self.cnt[:n],
                             self.vin_mean[:ne], self.vin_owner[:ne], self.lam, self.eps, threshold_info)


def merge_sample_graphs(rd: RegionData, nodes: SampleNodes, threshold, order: np.ndarray,
                        lam: float = 1.0, eps: float = 1e-2, procrustes: bool = True,
                        count_only: bool = False):
    """Merge the sample graphs of one region with fixed threshold(s).

    ``threshold``: one value, or one per sample (array (S,), indexed by sample).
    Returns the number of final nodes if ``count_only`` (same procedure, no
    node data), else a :class:`RegionGraph`.
    """
    m = Merger(rd, nodes, lam, eps, procrustes)
    thr = np.broadcast_to(np.asarray(threshold, float), (rd.n_samples,))
    for s in order:
        m.merge(int(s), float(thr[s]) if np.isfinite(thr[s]) else 0.0)
    if count_only:
        return m.n
    return m.finish(float(threshold) if np.ndim(threshold) == 0 else np.asarray(threshold, float))


def _finish_graph(rd, nodes, node_map, visit_map, n, Dmean, cnt, vin_mean, vin_owner, lam, eps,
                  threshold) -> RegionGraph:
    visits = np.bincount(visit_map, minlength=n)
    speed = np.zeros((n, len(rd.landmarks)))
    np.add.at(speed, node_map, nodes.speed * nodes.count[:, None])
    speed /= cnt[:, None]
    emo = rd.emotions[nodes.sample]
    label_mask = np.zeros(n, np.uint8)
    np.bitwise_or.at(label_mask, node_map, (1 << emo).astype(np.uint8))
    peak_mask = np.zeros(n, np.uint8)
    pk = np.flatnonzero(nodes.peak)
    np.bitwise_or.at(peak_mask, node_map[pk], (1 << emo[pk]).astype(np.uint8))
    pd_mean = np.full(n, np.nan)
    pd_std = np.full(n, np.nan)
    pd_n = np.zeros(n, int)
    dur = nodes.peak_dur[pk].astype(float)
    for f in np.unique(node_map[pk]):
        durs = dur[node_map[pk] == f]
        pd_mean[f], pd_std[f], pd_n[f] = durs.mean(), durs.std(), durs.size
    # a node holding a single peak has no spread of its own: store the spread of
    # the peak durations of its label(s) in this region instead
    for f in np.flatnonzero(pd_n == 1):
        same = (emo[pk][:, None] == np.flatnonzero([(int(peak_mask[f]) >> e) & 1 for e in range(8)])[None]).any(1)
        pd_std[f] = dur[same].std() if same.sum() > 1 else 0.0
    # edges: consecutive visits of every sample, mapped to final nodes
    vs = np.repeat(np.arange(len(nodes.visit_first) - 1), np.diff(nodes.visit_first))
    same = vs[1:] == vs[:-1]
    a, b = visit_map[:-1][same], visit_map[1:][same]
    keep = a != b
    e = np.unique(np.stack([a[keep], b[keep]], 1), axis=0) if keep.any() else np.zeros((0, 2), int)
    weights = _edge_weights(e, Dmean[:, rd.red], vin_mean, vin_owner, n, lam, eps)
    S = rd.n_samples
    start_of = visit_map[nodes.visit_first[:-1]]
    peak_of = np.empty(S, int)
    peak_of[nodes.sample[pk]] = node_map[pk]
    return RegionGraph(
        name=rd.name, landmarks=rd.landmarks, red=rd.red, disp=Dmean, speed=speed,
        merge_count=cnt / np.maximum(visits, 1), pose_count=cnt, visits=visits, label_mask=label_mask,
        peak_mask=peak_mask, peak_dur_mean=pd_mean, peak_dur_std=pd_std, peak_dur_n=pd_n, edges=e.astype(int),
        weights=weights,
        start_of_sample=start_of, peak_of_sample=peak_of,
        info={"merge_threshold": (float(threshold) if np.ndim(threshold) == 0
                                  else float(np.nanmedian(threshold))), "n_sample_nodes": int(nodes.n), "n_poses": int(rd.n_poses),
              "n_frames": int(rd.forward.sum())},
    )


def _edge_weights(edges, Dred, vin_mean, vin_owner, n, lam, eps) -> np.ndarray:
    """Node-to-node eq. 3 for every edge (min over incoming-velocity pairs) + EDGE_EPS."""
    if len(edges) == 0:
        return np.zeros(0)
    order = np.argsort(vin_owner, kind="stable")
    own_sorted = vin_owner[order]
    lo = np.searchsorted(own_sorted, np.arange(n))
    hi = np.searchsorted(own_sorted, np.arange(n), side="right")
    ka, kb = hi[edges[:, 0]] - lo[edges[:, 0]], hi[edges[:, 1]] - lo[edges[:, 1]]
    npair = ka * kb
    eid = np.repeat(np.arange(len(edges)), npair)
    # index of each pair within its edge -> (i, j) entries
    within = np.arange(npair.sum()) - np.repeat(np.cumsum(npair) - npair, npair)
    ia = order[lo[edges[eid, 0]] + within // kb[eid]]
    ib = order[lo[edges[eid, 1]] + within % kb[eid]]
    dist = np.sqrt(((Dred[edges[:, 0]] - Dred[edges[:, 1]]) ** 2).sum(-1))  # (E, Lr)
    sc = (dist[eid] * (1.0 + lam * vinfl(vin_mean[ia], vin_mean[ib], eps))).sum(-1)
    w = np.full(len(edges), np.inf)
    np.minimum.at(w, eid, sc)
    return w + EDGE_EPS
