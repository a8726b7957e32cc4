"""Sample graphs (Algorithm 1 of Serra et al. 2018) of every region.

Every region (eyes, eyebrows, nose, mouth, cheeks+jaw) gets its own graph
built from the neutral -> peak -> neutral samples of a :class:`FaceDatabase`.
Each sample is walked pose by pose. The current node holds the running mean
of the poses merged into it and the velocities of the poses through which it
was entered (its incoming edges). The next pose is compared with the nodes of
its sample graph by eq. 3 (reduced landmarks, :mod:`.similarity`); if the
similarity is at most the creation threshold the pose is merged into the most
similar node, otherwise it opens a new node linked from the current one. The
walk runs in lock-step over all samples and regions (numpy), which is what
makes the threshold searches cheap; the threshold may differ per region and
per sample (per-sample thresholds, :mod:`.model`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .preprocess import FaceDatabase
from .regions import REGION_NAMES
from .similarity import pose_similarity


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
    thresholds : array (R,), (B, R) or (B, R, S)
        Creation threshold per region (B: several candidate sets at once),
        or per region and sample (per-sample thresholds).

    Returns
    -------
    assign : int array (B, R, S, Tmax)
        Node index of each pose within its sample graph (-1 beyond the sample's
        end); nodes are numbered in order of creation.
    """
    R, S0, T, L, _ = stack.X.shape
    thr = np.asarray(thresholds, float)
    if thr.ndim < 3:
        thr = np.atleast_2d(thr)[..., None]
    thr = np.broadcast_to(thr, (thr.shape[0], R, S0))
    B = thr.shape[0]
    Q = int(max_entries)
    order = np.argsort(-stack.lengths, kind="stable")  # longest first: active samples are a prefix
    thr = thr[:, :, order]
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
        unsure = (bs > bound) & (bound <= thr[:, :, :na])
        if unsure.any():  # a farther node might be more similar: evaluate all nodes there
            full = np.broadcast_to(np.arange(kc), (B, R, na, kc))
            scf = _alg1_scores(x, u, ok, mean, ent_u[:, :, :na], ent_ok[:, :, :na], ent_n[:, :, :na], full, lam, nn)
            scf = np.concatenate([np.take_along_axis(scf, cu[..., None], -1), scf], -1)
            jf = scf.argmin(-1)
            bf = np.where(jf == 0, cu, jf - 1)
            best = np.where(unsure, bf, best)
            bs = np.where(unsure, np.take_along_axis(scf, jf[..., None], -1)[..., 0], bs)
        merge = bs <= thr[:, :, :na]
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


def creation_compression(assign: np.ndarray, forward: np.ndarray, per_sample: bool = False) -> np.ndarray:
    """% node reduction of the sample graphs against the original (forward)
    frames: ``1 - sample nodes / frames`` -> (B, R), or per sample (B, R, S)."""
    nodes = assign.max(-1) + 1
    if per_sample:
        return 100.0 * (1.0 - nodes / forward)
    return 100.0 * (1.0 - nodes.sum(-1) / forward.sum())


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
    peak_dur: np.ndarray    # (G,) neutral-to-peak duration (forward frames) of the sample peaking in the node
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
    peak_dur[vnode[pv]] = rd.forward
    return SampleNodes(sample, first, count, disp, speed, peak, peak_dur, vnode, vlen,
                       rd.vel[vstart][:, rd.red], vfirst)
