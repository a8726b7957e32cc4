"""Region motion graphs: sample graphs (Algorithm 1), merging, node data.

Every region (eyes, eyebrows, nose, mouth, cheeks+jaw) gets its own graph
built from the neutral -> peak -> neutral samples of a :class:`FaceDatabase`.

**Sample graphs (Algorithm 1).** Each sample is walked pose by pose. The
current node holds the running mean of the poses merged into it and the
velocity of the pose through which it was entered (its incoming edge). The
next pose is compared with the current node by eq. 3 (reduced landmarks,
:mod:`.similarity`); if the similarity is at most the creation threshold the
pose is merged into the node (a *consecutive merge*), otherwise it opens a new
node linked from the current one. A sample graph is therefore a chain whose
nodes are runs of similar consecutive poses. The walk runs in lock-step over
all samples and regions (numpy), which is what makes the threshold search
cheap.

**Merging.** The final graph starts from a seed sample chosen at random from
a seeded generator; its nodes, then those of every other sample (seeded random
order), are merged in chain order: a sample node is absorbed into the most
similar final node (node-to-node eq. 3: mean displacements, minimum over
incoming-edge velocities) if that similarity is at most the merge threshold,
otherwise it becomes a new final node. On absorption the sample node's pose is
aligned to the final node by a rigid Procrustes fit (rotation + translation,
no scaling) and that transform is propagated to the sample's following nodes.
Edges are the sample chains' transitions mapped to final nodes (self-loops
dropped); weights are the node-to-node similarity (plus 1e-9 so that
``scipy.sparse.csgraph`` keeps zero-similarity edges).

**Thresholds.** For a target compression (node reduction, %) and tolerance,
the creation threshold (compression ``1 - sample nodes / original frames``)
and then the merge threshold (``1 - final nodes / sample nodes``) are found per
region by the step-halving search of :mod:`.search`. The searches start from
data-driven guesses - the quantile at the target of the similarities of
consecutive poses (creation) and of the distances of sample nodes to their
nearest node of another sample (merging) - with a first step of a quarter of
that guess.

**Node data.** Mean displacement of all region landmarks, CK+ label mask of the
samples passing through, peak-label mask (labels whose peak pose is in the
node), mean consecutive-merge count (mean run length of the visits), mean
landmark speed, and for peak nodes the mean and std of the peak duration
(forward frames from entering the peak node to the peak frame). Most peak
nodes hold the peak of a single sample and so have no spread of their own;
for them the stored std is that of the peak durations of the same label in the
region (0 if that label has a single sample), so duration noise stays possible.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import csr_matrix

from ..io.atomic import atomic_path
from .preprocess import FaceDatabase
from .regions import REGION_NAMES
from .search import step_halving_search
from .similarity import pose_similarity, vinfl

log = logging.getLogger("animsynth.facegraph.graph")

EDGE_EPS = 1e-9
#: First step of the threshold searches, as a fraction of the start threshold.
STEP0_FRACTION = 0.25


# ---------------------------------------------------------------------------
# data of one region
@dataclass
class RegionData:
    """Neutral-peak-neutral poses of one region (flat over samples)."""

    name: str
    landmarks: np.ndarray      # (Lf,) landmark ids
    red: np.ndarray            # (Lr,) positions of the reduced landmarks within ``landmarks``
    disp: np.ndarray           # (P, Lf, 2)
    vel: np.ndarray            # (P, Lf, 2)
    offsets: np.ndarray        # (S+1,) pose offsets of samples
    forward: np.ndarray        # (S,) forward lengths F
    emotions: np.ndarray       # (S,)
    neutral_ref: np.ndarray    # (Lf, 2) mean neutral of the region

    @property
    def n_poses(self) -> int:
        return int(self.disp.shape[0])

    @property
    def n_samples(self) -> int:
        return int(len(self.forward))


def region_data(db: FaceDatabase) -> dict[str, RegionData]:
    """Split a database into per-region neutral-peak-neutral pose arrays."""
    xs, vs = zip(*(db.npn(s) for s in range(db.n_samples)))
    X = np.concatenate(xs)
    V = np.concatenate(vs)
    lengths = np.array([len(x) for x in xs])
    offsets = np.concatenate([[0], np.cumsum(lengths)])
    out = {}
    for r in REGION_NAMES:
        lm = np.asarray(db.regions[r], int)
        pos = {int(v): i for i, v in enumerate(lm)}
        red = np.array([pos[int(i)] for i in db.reduced[r]], int)
        out[r] = RegionData(r, lm, red, X[:, lm], V[:, lm], offsets, np.asarray(db.lengths, int),
                            np.asarray(db.emotions, int), db.mean_neutral[lm])
    return out


# ---------------------------------------------------------------------------
# Algorithm 1, vectorised over samples, regions and a batch of thresholds
@dataclass
class PoseStack:
    """Reduced-landmark poses of all regions, padded to (R, S, Tmax, Lmax, 2).

    Velocities are stored as unit vectors (``U``) plus a flag ``ok`` (speed >
    eps), which is all eq. 3 needs of them.
    """

    regions: tuple
    X: np.ndarray
    U: np.ndarray
    ok: np.ndarray
    lengths: np.ndarray   # (S,) n-p-n lengths
    forward: np.ndarray   # (S,) forward lengths

    @classmethod
    def from_region_data(cls, rdata: dict[str, RegionData], eps: float = 1e-2) -> "PoseStack":
        regions = tuple(rdata)
        first = rdata[regions[0]]
        lengths = np.diff(first.offsets)
        S, T = len(lengths), int(lengths.max())
        L = max(len(rd.red) for rd in rdata.values())
        X = np.zeros((len(regions), S, T, L, 2))
        V = np.zeros_like(X)
        for ri, r in enumerate(regions):
            rd = rdata[r]
            for s in range(S):
                o, n = rd.offsets[s], lengths[s]
                X[ri, s, :n, : len(rd.red)] = rd.disp[o:o + n][:, rd.red]
                V[ri, s, :n, : len(rd.red)] = rd.vel[o:o + n][:, rd.red]
        U, ok = _unit(V, eps)
        return cls(regions, X, U, ok, lengths, first.forward.copy())


def _unit(v, eps):
    n = np.sqrt((v * v).sum(-1))
    ok = n > eps
    return np.where(ok[..., None], v / np.where(ok, n, 1.0)[..., None], 0.0), ok.astype(float)


def create_sample_graphs(stack: PoseStack, thresholds, lam: float = 1.0, max_entries: int = 3,
                         n_candidates: int = 4) -> np.ndarray:
    """Algorithm 1 for every sample and region at once.

    Each pose of a neutral-peak-neutral sample is compared (eq. 3, reduced
    landmarks) with every node of its sample graph so far: a node's position is
    the running mean of its poses and its velocities are those of the poses
    through which it was entered (one per visit, the first ``max_entries``
    kept), the similarity being the minimum over them. The pose is merged into
    the most similar node (the current node on ties) when that similarity is at
    most the threshold, otherwise it opens a new node; a change of node is an
    edge. The time-reversed half thus folds back onto the forward nodes.

    Exact but pruned: since eq. 3 >= sum of landmark distances >= Frobenius
    distance, eq. 3 is evaluated only for the current node and the
    ``n_candidates`` nodes nearest in Frobenius distance; when the best of them
    is not below the next node's Frobenius distance (so a farther node could
    still win) the full set of nodes of that sample is evaluated.

    Parameters
    ----------
    thresholds : array (R,) or (B, R)
        Creation threshold per region (B: several candidate sets at once).

    Returns
    -------
    assign : int array (B, R, S, Tmax)
        Node index of each pose within its sample graph (-1 beyond the sample's
        end); nodes are numbered in order of creation.
    """
    thr = np.atleast_2d(np.asarray(thresholds, float))
    B = thr.shape[0]
    R, S0, T, L, _ = stack.X.shape
    Q = int(max_entries)
    order = np.argsort(-stack.lengths, kind="stable")  # longest first: active samples are a prefix
    lengths = stack.lengths[order]
    X = stack.X[:, order]
    U = stack.U[:, order]
    OK = stack.ok[:, order]
    F = L * 2
    shape = (B, R, S0)
    node_mean = np.zeros(shape + (T, L, 2))
    node_sq = np.zeros(shape + (T,))
    node_cnt = np.zeros(shape + (T,))
    ent_u = np.zeros(shape + (T, Q, L, 2))
    ent_ok = np.zeros(shape + (T, Q, L))
    ent_n = np.zeros(shape + (T,), int)
    node_mean[..., 0, :, :] = X[:, :, 0]
    node_sq[..., 0] = (X[:, :, 0] ** 2).sum((-1, -2))
    node_cnt[..., 0] = 1
    ent_u[..., 0, 0, :, :] = U[:, :, 0]
    ent_ok[..., 0, 0, :] = OK[:, :, 0]
    ent_n[..., 0] = 1
    n_nodes = np.ones(shape, int)
    cur = np.zeros(shape, int)
    assign = np.full(shape + (T,), -1, int)
    assign[..., 0] = 0
    kmax = 1
    for t in range(1, T):
        na = int(np.searchsorted(-lengths, -t, side="left"))  # samples with length > t
        if na == 0:
            break
        kc = kmax
        x, u, ok = X[:, :na, t], U[:, :na, t], OK[:, :na, t]  # (R, na, L, 2), (R, na, L)
        mean = node_mean[:, :, :na, :kc]
        nn = n_nodes[:, :, :na]
        cu = cur[:, :, :na]
        xf = x.reshape(R, na, F)
        xm = np.matmul(mean.reshape(B, R, na, kc, F), np.broadcast_to(xf[None, ..., None], (B, R, na, F, 1)))
        frob2 = (xf ** 2).sum(-1)[None, :, :, None] + node_sq[:, :, :na, :kc] - 2.0 * xm[..., 0]
        frob2 = np.where(np.arange(kc) < nn[..., None], frob2, np.inf)
        m = min(n_candidates, kc)
        if kc > m:
            part = np.argpartition(frob2, m, axis=-1)
            cand = part[..., :m]
            bound = np.sqrt(np.maximum(np.take_along_axis(frob2, part[..., m:m + 1], -1)[..., 0], 0.0))
        else:
            cand = np.broadcast_to(np.arange(kc), (B, R, na, kc))
            bound = np.full((B, R, na), np.inf)
        cand = np.concatenate([cu[..., None], cand], -1)  # current node first (wins ties)
        sc = _alg1_scores(x, u, ok, mean, ent_u[:, :, :na], ent_ok[:, :, :na], ent_n[:, :, :na], cand, lam, nn)
        j = sc.argmin(-1)
        best = np.take_along_axis(cand, j[..., None], -1)[..., 0]
        bs = np.take_along_axis(sc, j[..., None], -1)[..., 0]
        unsure = (bs > bound) & (bound <= thr[:, :, None])
        if unsure.any():  # a farther node might be more similar: evaluate all nodes there
            full = np.broadcast_to(np.arange(kc), (B, R, na, kc))
            scf = _alg1_scores(x, u, ok, mean, ent_u[:, :, :na], ent_ok[:, :, :na], ent_n[:, :, :na], full, lam, nn)
            scf = np.concatenate([np.take_along_axis(scf, cu[..., None], -1), scf], -1)
            jf = scf.argmin(-1)
            bf = np.where(jf == 0, cu, jf - 1)
            best = np.where(unsure, bf, best)
            bs = np.where(unsure, np.take_along_axis(scf, jf[..., None], -1)[..., 0], bs)
        merge = bs <= thr[:, :, None]
        target = np.where(merge, best, nn)
        bi, ri, si = np.meshgrid(np.arange(B), np.arange(R), np.arange(na), indexing="ij")
        bi, ri, si, ti = bi.ravel(), ri.ravel(), si.ravel(), target.ravel()
        c = node_cnt[bi, ri, si, ti] + 1.0
        newmean = node_mean[bi, ri, si, ti] + (x[ri, si] - node_mean[bi, ri, si, ti]) / c[:, None, None]
        node_mean[bi, ri, si, ti] = newmean
        node_sq[bi, ri, si, ti] = (newmean ** 2).sum((-1, -2))
        node_cnt[bi, ri, si, ti] = c
        enter = (ti != cu.ravel()) & (ent_n[bi, ri, si, ti] < Q)
        b_, r_, s_, k_ = bi[enter], ri[enter], si[enter], ti[enter]
        q_ = ent_n[b_, r_, s_, k_]
        ent_u[b_, r_, s_, k_, q_] = u[r_, s_]
        ent_ok[b_, r_, s_, k_, q_] = ok[r_, s_]
        ent_n[b_, r_, s_, k_] += 1
        n_nodes[:, :, :na] = nn + ~merge
        cur[:, :, :na] = target
        assign[:, :, :na, t] = target
        kmax = int(n_nodes.max())
    out = np.empty_like(assign)
    out[:, :, order] = assign
    return out


def _alg1_scores(x, u, ok, mean, ent_u, ent_ok, ent_n, cand, lam, nn):
    """Eq. 3 of the current poses against candidate nodes -> (B, R, na, m)."""
    B, R, na, m = cand.shape
    bi = np.arange(B)[:, None, None, None]
    ri = np.arange(R)[None, :, None, None]
    si = np.arange(na)[None, None, :, None]
    mc = mean[bi, ri, si, cand]                                  # (B, R, na, m, L, 2)
    d = x[None, :, :, None] - mc
    dist = np.sqrt((d * d).sum(-1))                              # (B, R, na, m, L)
    eu = ent_u[bi, ri, si, cand]                                 # (B, R, na, m, Q, L, 2)
    eo = ent_ok[bi, ri, si, cand]                                # (B, R, na, m, Q, L)
    en = ent_n[bi, ri, si, cand]                                 # (B, R, na, m)
    cos = np.abs((u[None, :, :, None, None] * eu).sum(-1))       # (B, R, na, m, Q, L)
    vi = (1.0 - np.minimum(cos, 1.0)) * eo * ok[None, :, :, None, None, :]
    sc = dist.sum(-1)[..., None] + lam * (dist[..., None, :] * vi).sum(-1)
    Q = eu.shape[4]
    sc = np.where(np.arange(Q) < en[..., None], sc, np.inf).min(-1)
    return np.where(cand < nn[..., None], sc, np.inf)


def create_sample_graph_reference(X: np.ndarray, V: np.ndarray, threshold: float, lam: float = 1.0,
                                  eps: float = 1e-2, max_entries: int = 3) -> np.ndarray:
    """Algorithm 1 for one sample, written directly (no vectorisation, no pruning).

    ``X``, ``V``: (T, L, 2) poses and velocities (reduced landmarks). Returns the
    node index of every pose; :func:`create_sample_graphs` gives the same
    result for all samples at once (used to check and benchmark it).
    """
    means, cnts, ents, cur, assign = [X[0].copy()], [1], [[V[0]]], 0, [0]
    for t in range(1, len(X)):
        sc = np.array([min(pose_similarity(X[t], V[t], m, e, lam, eps) for e in es) for m, es in zip(means, ents)])
        j = int(np.argmin(sc))
        if sc[cur] <= sc[j]:
            j = cur
        if sc[j] <= threshold:
            cnts[j] += 1
            means[j] = means[j] + (X[t] - means[j]) / cnts[j]
        else:
            j = len(means)
            means.append(X[t].copy())
            cnts.append(1)
            ents.append([])
        if j != cur and len(ents[j]) < max_entries:
            ents[j].append(V[t])
        cur = j
        assign.append(j)
    return np.array(assign)


def creation_compression(assign: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """% node reduction of the sample graphs against the original (forward)
    frames: ``1 - sample nodes / frames`` -> (B, R)."""
    nodes = (assign.max(-1) + 1).sum(-1)
    return 100.0 * (1.0 - nodes / forward.sum())


@dataclass
class SampleNodes:
    """Nodes and visits of all sample graphs of one region.

    A *visit* is a maximal run of consecutive poses in one node; visits are
    listed in time order per sample, nodes in order of creation.
    """

    sample: np.ndarray      # (G,) sample of each node
    first: np.ndarray       # (S+1,) node offsets per sample
    count: np.ndarray       # (G,) poses merged
    disp: np.ndarray        # (G, Lf, 2) mean displacement
    speed: np.ndarray       # (G, Lf) mean landmark speed
    peak: np.ndarray        # (G,) bool: holds the sample's peak pose
    peak_dur: np.ndarray    # (G,) forward frames from entering the peak visit to the peak frame
    visit_node: np.ndarray  # (V,) global node id
    visit_len: np.ndarray   # (V,)
    visit_vel: np.ndarray   # (V, Lr, 2) velocity of the entering pose
    visit_first: np.ndarray  # (S+1,) visit offsets per sample

    @property
    def n(self) -> int:
        return int(len(self.sample))


def sample_nodes(rd: RegionData, assign: np.ndarray) -> SampleNodes:
    """Node and visit data of the sample graphs from Algorithm 1's assignment (S, Tmax)."""
    S = rd.n_samples
    n_per = assign.max(-1) + 1
    first = np.concatenate([[0], np.cumsum(n_per)])
    gid = np.concatenate([assign[s, : rd.offsets[s + 1] - rd.offsets[s]] + first[s] for s in range(S)])
    G = int(first[-1])
    count = np.bincount(gid, minlength=G).astype(float)
    disp = np.zeros((G, len(rd.landmarks), 2))
    np.add.at(disp, gid, rd.disp)
    disp /= count[:, None, None]
    speed = np.zeros((G, len(rd.landmarks)))
    np.add.at(speed, gid, np.sqrt((rd.vel ** 2).sum(-1)))
    speed /= count[:, None]
    sample = np.repeat(np.arange(S), n_per)
    vstart = np.flatnonzero(np.r_[True, gid[1:] != gid[:-1]] | np.isin(np.arange(rd.n_poses), rd.offsets[:-1]))
    vlen = np.diff(np.r_[vstart, rd.n_poses])
    vnode = gid[vstart]
    vfirst = np.searchsorted(vstart, rd.offsets)
    peak_pose = rd.offsets[:-1] + rd.forward - 1
    pv = np.searchsorted(vstart, peak_pose, side="right") - 1
    peak = np.zeros(G, bool)
    peak_dur = np.zeros(G, int)
    peak[vnode[pv]] = True
    peak_dur[vnode[pv]] = peak_pose - vstart[pv] + 1
    return SampleNodes(sample, first, count, disp, speed, peak, peak_dur, vnode, vlen,
                       rd.vel[vstart][:, rd.red], vfirst)


# ---------------------------------------------------------------------------
# the final graph of one region
@dataclass
class RegionGraph:
    """A region motion graph (see module docs for the node data)."""

    name: str
    landmarks: np.ndarray        # (Lf,) landmark ids
    red: np.ndarray              # (Lr,) reduced positions in ``landmarks``
    disp: np.ndarray             # (N, Lf, 2) mean displacement
    speed: np.ndarray            # (N, Lf) mean landmark speed (px/frame)
    merge_count: np.ndarray      # (N,) mean consecutive-merge count (poses per visit)
    pose_count: np.ndarray       # (N,) poses absorbed
    visits: np.ndarray           # (N,) sample nodes absorbed
    label_mask: np.ndarray       # (N,) uint8 bit e = a sample of emotion e passes through
    peak_mask: np.ndarray        # (N,) uint8 bit e = a sample of emotion e peaks here
    peak_dur_mean: np.ndarray    # (N,) NaN for non-peak nodes
    peak_dur_std: np.ndarray     # (N,) (label-pooled for single-peak nodes, see module docs)
    peak_dur_n: np.ndarray       # (N,) peak durations observed in the node
    edges: np.ndarray            # (E, 2) int
    weights: np.ndarray          # (E,)
    start_of_sample: np.ndarray  # (S,) node holding each sample's first (neutral) pose
    peak_of_sample: np.ndarray   # (S,) node holding each sample's peak pose
    info: dict = field(default_factory=dict)

    @property
    def n_nodes(self) -> int:
        return int(self.disp.shape[0])

    @property
    def n_edges(self) -> int:
        return int(self.edges.shape[0])

    def csr(self) -> csr_matrix:
        if getattr(self, "_csr", None) is None:
            n = self.n_nodes
            self._csr = csr_matrix((self.weights, (self.edges[:, 0], self.edges[:, 1])), shape=(n, n))
        return self._csr

    def undirected(self) -> csr_matrix:
        if getattr(self, "_und", None) is None:
            a = self.csr()
            self._und = ((a + a.T) > 0).astype(np.int8).tocsr()
        return self._und

    def peak_nodes(self, emotion: int) -> np.ndarray:
        return np.flatnonzero(self.peak_mask & np.uint8(1 << int(emotion)))

    def nbytes(self) -> int:
        """Bytes of what synthesis needs, as float32/int32: per node the mean
        displacement (Lf x 2), mean speed (Lf), merge count, peak mean/std and
        the two label masks (counted as 4 bytes each); per edge two ids and a weight."""
        lf = len(self.landmarks)
        return 4 * (self.n_nodes * (3 * lf + 5) + 3 * self.n_edges)

    # -- storage -----------------------------------------------------------
    _ARRAYS = ("landmarks", "red", "disp", "speed", "merge_count", "pose_count", "visits", "label_mask",
               "peak_mask", "peak_dur_mean", "peak_dur_std", "peak_dur_n", "edges", "weights", "start_of_sample",
               "peak_of_sample")

    def to_arrays(self, prefix: str) -> dict:
        d = {f"{prefix}{k}": getattr(self, k) for k in self._ARRAYS}
        d[f"{prefix}info"] = np.array(repr(sorted(self.info.items())))
        return d

    @classmethod
    def from_arrays(cls, z, prefix: str, name: str) -> "RegionGraph":
        import ast

        kw = {k: np.array(z[f"{prefix}{k}"]) for k in cls._ARRAYS}
        info = dict(ast.literal_eval(str(z[f"{prefix}info"])))
        return cls(name=name, info=info, **kw)


def save_graphs(path, graphs: dict[str, RegionGraph], meta: dict | None = None) -> None:
    arrays = {}
    for r, g in graphs.items():
        arrays.update(g.to_arrays(f"{r}__"))
    arrays["regions"] = np.array(list(graphs))
    arrays["meta"] = np.array(repr(sorted((meta or {}).items())))
    with atomic_path(path, suffix=".npz") as tmp:
        np.savez_compressed(tmp, **arrays)


def load_graphs(path) -> tuple[dict[str, RegionGraph], dict]:
    import ast

    with np.load(path, allow_pickle=False) as z:
        regions = [str(r) for r in z["regions"]]
        graphs = {r: RegionGraph.from_arrays(z, f"{r}__", r) for r in regions}
        meta = dict(ast.literal_eval(str(z["meta"])))
    return graphs, meta


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


def merge_sample_graphs(rd: RegionData, nodes: SampleNodes, threshold: float, order: np.ndarray,
                        lam: float = 1.0, eps: float = 1e-2, procrustes: bool = True,
                        count_only: bool = False):
    """Merge the sample graphs of one region into the final graph.

    Samples are taken in ``order`` (seed sample first) and their visits in time
    order; a sample node is placed (absorbed or added) at its first visit, so
    every incoming edge's predecessor is already placed and the incoming-edge
    velocities can be kept per (node, predecessor). Candidate final nodes are
    pruned with the Frobenius lower bound of eq. 3 (exact result).

    Returns the number of final nodes if ``count_only`` (same procedure, no
    node data), else a :class:`RegionGraph`.
    """
    G, Lf = nodes.n, len(rd.landmarks)
    red = rd.red
    Lr = len(red)
    M = rd.neutral_ref
    T = float(threshold)
    T2 = T * T
    Dsum = np.empty((G, Lf, 2))
    Dmean = np.empty((G, Lf, 2))
    Dred = np.empty((G, Lr * 2))
    Dsq = np.empty(G)
    cnt = np.zeros(G)
    node_map = np.full(G, -1, int)
    nv = len(nodes.visit_node)
    vin_sum = np.empty((nv, Lr, 2))
    vin_mean = np.empty_like(vin_sum)
    vin_cnt = np.zeros(nv)
    vin_owner = np.empty(nv, int)
    vin_of: list[list[int]] = []
    vin_key: dict[tuple[int, int], int] = {}
    visit_map = np.empty(nv, int)
    visit_node, visit_vel, visit_first = nodes.visit_node, nodes.visit_vel, nodes.visit_first
    n = ne = 0
    for s in order:
        R = None
        tr = None
        prev = -1
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
                qr = qd[red].ravel()
                best = -1
                if n:
                    frob2 = Dsq[:n] + qr @ qr - 2.0 * (Dred[:n] @ qr)
                    cand = np.flatnonzero(frob2 <= T2 + 1e-12)  # eq. 3 >= distance sum >= Frobenius
                    if cand.size:
                        diff = Dred[cand].reshape(-1, Lr, 2) - qd[red]
                        dist = np.sqrt((diff * diff).sum(-1))  # (c, Lr)
                        ok = dist.sum(-1) <= T
                        if ok.any():
                            cand, dist = cand[ok], dist[ok]
                            if cand.size == 1:
                                ent = np.asarray(vin_of[cand[0]])
                                rows = np.zeros(len(ent), int)
                            else:
                                lists = [vin_of[c] for c in cand]
                                ent = np.concatenate(lists)
                                rows = np.repeat(np.arange(cand.size), [len(x) for x in lists])
                            sc = (dist[rows] * (1.0 + lam * vinfl(qv[None], vin_mean[ent], eps))).sum(-1)
                            j = int(np.argmin(sc))
                            if sc[j] <= T:
                                best = int(cand[rows[j]])
                c = nodes.count[g]
                if best >= 0:
                    if procrustes:
                        Ra, ta = _rigid2d(M + qd, M + Dmean[best])
                        qd = (M + qd) @ Ra.T + ta - M
                        qv = qv @ Ra.T
                        if R is None:
                            R, tr = Ra, ta
                        else:
                            R, tr = Ra @ R, Ra @ tr + ta
                    f = best
                    Dsum[f] += c * qd
                    cnt[f] += c
                else:
                    f = n
                    n += 1
                    Dsum[f] = c * qd
                    cnt[f] = c
                    vin_of.append([])
                Dmean[f] = Dsum[f] / cnt[f]
                Dred[f] = Dmean[f][red].ravel()
                Dsq[f] = Dred[f] @ Dred[f]
                node_map[g] = f
            key = (f, prev)
            e = vin_key.get(key)
            if e is None:
                e = vin_key[key] = ne
                vin_owner[e] = f
                vin_sum[e] = qv
                vin_cnt[e] = 1.0
                vin_mean[e] = qv
                vin_of[f].append(e)
                ne += 1
            else:
                vin_sum[e] += qv
                vin_cnt[e] += 1.0
                vin_mean[e] = vin_sum[e] / vin_cnt[e]
            visit_map[vi_] = f
            prev = f
    if count_only:
        return n
    return _finish_graph(rd, nodes, node_map, visit_map, n, Dmean[:n], cnt[:n], vin_mean[:ne], vin_owner[:ne],
                         lam, eps, threshold)


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
        info={"merge_threshold": float(threshold), "n_sample_nodes": int(nodes.n), "n_poses": int(rd.n_poses),
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


# ---------------------------------------------------------------------------
def _consecutive_similarity(rd: RegionData, lam, eps) -> np.ndarray:
    same = np.ones(rd.n_poses, bool)
    same[rd.offsets[:-1]] = False
    i = np.flatnonzero(same)
    r = rd.red
    return pose_similarity(rd.disp[i][:, r], rd.vel[i][:, r], rd.disp[i - 1][:, r], rd.vel[i - 1][:, r], lam, eps)


def _nn_similarity(nodes: SampleNodes, red, rng, k: int = 256) -> np.ndarray:
    """Plain distance sum from up to k random sample nodes to their nearest other node."""
    q = rng.choice(nodes.n, size=min(k, nodes.n), replace=False)
    D = nodes.disp[:, red]
    out = []
    for i in q:
        d = np.sqrt(((D - D[i]) ** 2).sum(-1)).sum(-1)
        d[nodes.sample == nodes.sample[i]] = np.inf  # other samples only
        out.append(d.min())
    out = np.asarray(out)
    return out[np.isfinite(out)]


class FaceGraphModel:
    """Region motion graphs of a facial-expression database.

    Parameters
    ----------
    creation_compression, merge_compression : float
        Target node reductions (%) of sample-graph creation and of merging.
    tolerance : float
        Accepted |achieved - target| (percentage points).
    lam : float
        lambda of eq. 3.
    velocity_eps : float
        Speeds at or below this (px/frame) carry no direction (vinfl = 0).
    max_iterations : int
        Builds allowed per threshold search.
    procrustes : bool
        Rigid Procrustes alignment of absorbed nodes, propagated along the sample.
    seed : int
        Seeds the choice of the seed sample and the merge order.
    creation_thresholds, merge_thresholds : dict or None
        Fixed thresholds per region (skip the corresponding search).

    Attributes
    ----------
    graphs_ : dict region -> RegionGraph
    creation_thresholds_, merge_thresholds_ : dict region -> float
    search_ : pandas.DataFrame, one row per region with achieved compressions, iterations, converged
    seed_sample_ : int
    timings_ : dict (machine-dependent): ``search_s`` (threshold searches), ``build_s`` (one build at
        the final thresholds: Algorithm 1 + merging + node data)
    """

    def __init__(self, creation_compression: float = 50.0, merge_compression: float = 50.0,
                 tolerance: float = 1.0, lam: float = 1.0, velocity_eps: float = 1e-2,
                 max_iterations: int = 40, procrustes: bool = True, seed: int = 0,
                 creation_thresholds: dict | None = None, merge_thresholds: dict | None = None):
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

    def _check(self):
        for k in ("creation_compression", "merge_compression"):
            v = getattr(self, k)
            if not 0.0 <= float(v) < 100.0:
                raise ValueError(f"{k} must be in [0, 100), got {v}")
        if self.tolerance <= 0:
            raise ValueError("tolerance must be > 0")
        if self.lam < 0 or self.velocity_eps < 0:
            raise ValueError("lam and velocity_eps must be >= 0")

    def fit(self, db: FaceDatabase) -> "FaceGraphModel":
        import pandas as pd

        self._check()
        lam, eps = float(self.lam), float(self.velocity_eps)
        rng = np.random.default_rng(self.seed)
        S = db.n_samples
        self.seed_sample_ = int(rng.integers(S))
        rest = np.array([s for s in range(S) if s != self.seed_sample_], int)
        self.order_ = np.concatenate([[self.seed_sample_], rng.permutation(rest)]).astype(int)
        rdata = region_data(db)
        regions = list(rdata)
        t_start = time.perf_counter()
        stack = PoseStack.from_region_data(rdata, eps)
        # -- creation thresholds
        if self.creation_thresholds is not None:
            Tc = np.array([float(self.creation_thresholds[r]) for r in regions])
            c_it = np.zeros(len(regions), int)
            c_ok = np.ones(len(regions), bool)
        else:
            t0 = np.array([np.quantile(_consecutive_similarity(rdata[r], lam, eps), self.creation_compression / 100.0)
                           for r in regions])
            t0 = np.maximum(t0, 1e-6)
            res = step_halving_search(
                lambda T: creation_compression(create_sample_graphs(stack, T, lam), stack.forward)[0],
                self.creation_compression, self.tolerance, t0, t0 * STEP0_FRACTION, self.max_iterations)
            Tc, c_it, c_ok = res.threshold, res.iterations, res.converged
        assign = create_sample_graphs(stack, Tc, lam)[0]
        c_ach = creation_compression(assign[None], stack.forward)[0]
        nodes = {r: sample_nodes(rdata[r], assign[i]) for i, r in enumerate(regions)}
        # -- merge thresholds (one search per region)
        Tm, m_it, m_ok, m_ach = {}, {}, {}, {}
        for r in regions:
            nd = nodes[r]
            if self.merge_thresholds is not None:
                Tm[r], m_it[r], m_ok[r] = float(self.merge_thresholds[r]), 0, True
                continue

            def ev(T, r=r, nd=nd):
                return np.array([100.0 * (1.0 - merge_sample_graphs(rdata[r], nd, float(T[0]), self.order_, lam, eps,
                                                                    self.procrustes, count_only=True) / nd.n)])

            nn = _nn_similarity(nd, rdata[r].red, np.random.default_rng(self.seed + 1))
            t0 = max(float(np.quantile(nn, self.merge_compression / 100.0)) if nn.size else 1.0, 1e-6)
            res = step_halving_search(ev, self.merge_compression, self.tolerance, t0, t0 * STEP0_FRACTION,
                                      self.max_iterations)
            Tm[r], m_it[r], m_ok[r] = float(res.threshold[0]), int(res.iterations[0]), bool(res.converged[0])
        search_s = time.perf_counter() - t_start
        # -- one clean, timed build at the final thresholds
        t_build = time.perf_counter()
        assign = create_sample_graphs(stack, Tc, lam)[0]
        graphs = {}
        for i, r in enumerate(regions):
            nd = sample_nodes(rdata[r], assign[i])
            graphs[r] = merge_sample_graphs(rdata[r], nd, Tm[r], self.order_, lam, eps, self.procrustes)
        build_s = time.perf_counter() - t_build
        rows = []
        for i, r in enumerate(regions):
            g = graphs[r]
            P, G, N = int(rdata[r].forward.sum()), nodes[r].n, g.n_nodes
            m_ach[r] = 100.0 * (1.0 - N / G)
            g.info.update(creation_threshold=float(Tc[i]), creation_compression=float(c_ach[i]),
                          merge_compression=float(m_ach[r]), node_compression=100.0 * (1.0 - N / P))
            rows.append({"region": r, "creation_threshold": float(Tc[i]), "creation_achieved_pct": float(c_ach[i]),
                         "creation_iterations": int(c_it[i]), "creation_converged": bool(c_ok[i]),
                         "merge_threshold": Tm[r], "merge_achieved_pct": m_ach[r], "merge_iterations": m_it[r],
                         "merge_converged": m_ok[r], "frames": P, "sample_nodes": G, "nodes": N, "edges": g.n_edges})
            if not (c_ok[i] and m_ok[r]):
                log.warning("region %s: compression target not reached within %.3g points (creation %.2f%% for "
                            "%.2f%%, merge %.2f%% for %.2f%%)", r, self.tolerance, c_ach[i],
                            self.creation_compression, m_ach[r], self.merge_compression)
        self.graphs_ = graphs
        self.creation_thresholds_ = {r: float(Tc[i]) for i, r in enumerate(regions)}
        self.merge_thresholds_ = dict(Tm)
        self.search_ = pd.DataFrame(rows)
        self.timings_ = {"search_s": search_s, "build_s": build_s}
        return self
