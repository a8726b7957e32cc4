"""Sample graphs (Algorithm 1 of Serra et al. 2018) of every region.

Every region (eyes, eyebrows, nose, mouth, cheeks+jaw) gets its own graph
built from the neutral -> peak -> neutral samples of a :class:`FaceDatabase`.
Each sample is walked pose by pose. The current node holds the running mean
of the poses merged into it and the velocities of the poses through which it
was entered (its incoming edges). The next pose is compared with the nodes of
its sample graph by eq. 3 (reduced landmarks, :mod:`.similarity`); if the
similarity is at most the creation threshold the pose is merged into the most
similar node, otherwise it opens a new node linked from the current one. The
walks are compiled (numba, :mod:`.kernels`), which is what makes the threshold
searches cheap; the threshold may differ per region and per sample
(per-sample thresholds, :mod:`.model`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import kernels
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


def create_sample_graphs(stack: PoseStack, thresholds, lam: float = 1.0, max_entries: int = 3) -> np.ndarray:
    """Algorithm 1 for every sample and region at once.

    Each pose of a neutral-peak-neutral sample is compared (eq. 3, reduced
    landmarks) with every node of its sample graph so far: a node's position is
    the running mean of its poses and its velocities are those of the poses
    through which it was entered (one per visit, the first ``max_entries``
    kept), the similarity being the minimum over them. The pose is merged into
    the most similar node (the current node on ties) when that similarity is at
    most the threshold, otherwise it opens a new node; a change of node is an
    edge. The time-reversed half thus folds back onto the forward nodes.

    The walks run compiled, one sample at a time (:func:`.kernels.alg1_all`), with
    the arithmetic of eq. 3 over the zero-padded landmark axis of the stack.

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
    thr = np.ascontiguousarray(np.broadcast_to(thr, (thr.shape[0], R, S0)))
    out = np.empty(thr.shape + (T,), np.int64)
    kernels.alg1_all(np.ascontiguousarray(stack.X, float), np.ascontiguousarray(stack.U, float),
                  np.ascontiguousarray(stack.ok, float), np.ascontiguousarray(stack.lengths, np.int64), thr,
                  float(lam), int(max_entries), out)
    return out


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
