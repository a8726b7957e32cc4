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

from . import kernels, merge_kernels
from .regiongraph import EDGE_EPS, RegionGraph
from .samplegraphs import RegionData, SampleNodes

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

    The visit loop is compiled (:func:`.merge_kernels.merge_sample`, numpy's arithmetic
    reproduced); the state lives in preallocated arrays: node sums and means
    (G, Lf, 2), reduced means (G, 2 Lr), and per incoming edge (at most one
    per visit) the velocity sum, mean (V, Lr, 2) and speeds (V, Lr), chained
    per node in creation order.
    """

    def __init__(self, rd: RegionData, nodes: SampleNodes, lam: float = 1.0, eps: float = 1e-2,
                 procrustes: bool = True):
        G, Lf = nodes.n, len(rd.landmarks)
        self.rd, self.nodes, self.lam, self.eps, self.procrustes = rd, nodes, float(lam), float(eps), procrustes
        self.red = np.ascontiguousarray(rd.red, np.int64)
        self.Lr = Lr = len(rd.red)
        self.M = np.ascontiguousarray(rd.neutral_ref, float)
        nv = len(nodes.visit_node)
        self._nodes = (np.ascontiguousarray(nodes.visit_node, np.int64), np.ascontiguousarray(nodes.visit_vel, float),
                       np.ascontiguousarray(nodes.visit_first, np.int64), np.ascontiguousarray(nodes.disp, float),
                       np.ascontiguousarray(nodes.count, float), np.ascontiguousarray(nodes.first, np.int64))
        self.Dsum = np.zeros((G, Lf, 2))
        self.Dmean = np.zeros((G, Lf, 2))
        self.Dred = np.zeros((G, Lr * 2))
        self.cnt = np.zeros(G)
        self.node_map = np.full(G, -1, np.int64)
        self.visit_map = np.zeros(nv, np.int64)
        self.vin_sum = np.zeros((nv, Lr, 2))
        self.vin_mean = np.zeros((nv, Lr, 2))
        self.vin_nrm = np.zeros((nv, Lr))   # landmark speeds of vin_mean (for vinfl)
        self.vin_cnt = np.zeros(nv)
        self.vin_owner = np.zeros(nv, np.int64)
        self._vin_prev = np.zeros(nv, np.int64)
        self._vin_next = np.full(nv, -1, np.int64)
        self._vin_oldtail = np.full(nv, -1, np.int64)
        self._head = np.full(G, -1, np.int64)
        self._tail = np.full(G, -1, np.int64)
        cap = int(np.diff(nodes.visit_first).max()) if nv else 0   # touched per trial <= visits of a sample
        self._u_node = np.zeros(cap, np.int64)
        self._u_Dsum = np.zeros((cap, Lf, 2))
        self._u_cnt = np.zeros(cap)
        self._node_stamp = np.zeros(G, np.int64)
        self._u_vin = np.zeros(cap, np.int64)
        self._u_vsum = np.zeros((cap, Lr, 2))
        self._u_vcnt = np.zeros(cap)
        self._u_vmean = np.zeros((cap, Lr, 2))
        self._u_vnrm = np.zeros((cap, Lr))
        self._vin_stamp = np.zeros(nv, np.int64)
        self._st = np.zeros(8, np.int64)   # n, ne, trial open, n0, ne0, undo counts (nodes, vins), stamp
        self._s = -1

    @property
    def n(self) -> int:
        return int(self._st[0])

    @property
    def ne(self) -> int:
        return int(self._st[1])

    def merge(self, s: int, threshold: float, trial: bool = False) -> float:
        """Merge sample ``s`` with ``threshold``; return its merge compression
        (%): ``100 * (1 - new final nodes / nodes of the sample)``."""
        self._s = int(s)
        return float(merge_kernels.merge_sample(
            int(s), float(threshold), bool(trial), self.lam, self.eps, bool(self.procrustes), self._st,
            *self._nodes[:5], self._nodes[5], self.red, self.M,
            self.Dsum, self.Dmean, self.Dred, self.cnt, self.node_map, self.visit_map,
            self.vin_sum, self.vin_mean, self.vin_nrm, self.vin_cnt, self.vin_owner, self._vin_prev, self._vin_next,
            self._vin_oldtail, self._head, self._tail,
            self._u_node, self._u_Dsum, self._u_cnt, self._node_stamp, self._u_vin, self._u_vsum, self._u_vcnt,
            self._u_vmean, self._u_vnrm, self._vin_stamp))

    def undo(self) -> None:
        """Revert the last ``trial`` merge."""
        if not self._st[2]:
            raise RuntimeError("no trial merge to undo")
        merge_kernels.undo_merge(self._s, self._st, self._nodes[5], self.red, self.Dsum, self.Dmean, self.Dred, self.cnt,
                        self.node_map, self.vin_sum, self.vin_mean, self.vin_nrm, self.vin_cnt, self.vin_owner,
                        self._vin_next, self._vin_oldtail, self._tail, self._u_node, self._u_Dsum, self._u_cnt,
                        self._u_vin, self._u_vsum, self._u_vcnt, self._u_vmean, self._u_vnrm)

    def commit(self) -> None:
        """Keep the last ``trial`` merge."""
        self._st[2] = 0

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
                                  else float(np.nanmedian(threshold))),
                "n_sample_nodes": int(nodes.n), "n_poses": int(rd.n_poses),
              "n_frames": int(rd.forward.sum())},
    )


def _edge_weights(edges, Dred, vin_mean, vin_owner, n, lam, eps) -> np.ndarray:
    """Node-to-node eq. 3 for every edge (min over incoming-velocity pairs) + EDGE_EPS
    (compiled, :func:`.kernels.edge_weights`)."""
    if len(edges) == 0:
        return np.zeros(0)
    order = np.argsort(vin_owner, kind="stable")
    own_sorted = vin_owner[order]
    lo = np.searchsorted(own_sorted, np.arange(n))
    hi = np.searchsorted(own_sorted, np.arange(n), side="right")
    w = kernels.edge_weights(np.ascontiguousarray(edges, np.int64), np.ascontiguousarray(Dred, float),
                          np.ascontiguousarray(vin_mean, float), order.astype(np.int64), lo.astype(np.int64),
                          hi.astype(np.int64), float(lam), float(eps))
    return w + EDGE_EPS
