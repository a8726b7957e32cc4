"""The motion graph G' of Gauch & Peters and its connectivity.

G' has one vertex per training frame (latent point). Its edges are

* the *clip edges* ``i -> i+1`` along every training clip, and
* *added edges* between points that are neighbours in the latent space, either
  because they share a Delaunay simplex (``method="delaunay"``) or because one
  is among the other's ``k`` nearest neighbours (``method="knn"``; an edge if
  *either* point is among the other's k nearest). ``method="kdelaunay"`` takes
  the union of both.

Every added (undirected) edge ``{i, j}`` is directed so that it agrees with the
motion there: ``i -> j`` when ``(x_j - x_i) . v_target > 0`` with
``v_target = (v_i + v_j) / 2`` the mean training vector of its end points,
``j -> i`` when negative. A dot product of exactly zero (e.g. duplicate points,
zero-length edge) gives *both* directions; their number is reported as
``n_ties_``.

Connectivity (:meth:`MotionGraph.connectivity`): the number of strongly
connected components of G', whether its undirected version is connected, and
whether the bipartite graph H is connected. H is our reading of the paper's
construction: one vertex per clip *end* (last frame) and one per clip *start*
(first frame); an edge joins ``end(a)`` and ``start(b)`` when ``start(b)`` is
reachable from ``end(a)`` by a directed path in G' (a generated walk can leave
clip a and enter clip b), and every clip joins its own start and end (the clip
itself). H connected means every clip can be chained to every other one.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import breadth_first_order, connected_components
from scipy.spatial import cKDTree

from .geometry import SafeDelaunay, unique_pairs

log = logging.getLogger("animsynth.simplicial.graph")

GRAPH_METHODS = ("delaunay", "knn", "kdelaunay")


def clip_edges(lengths) -> np.ndarray:
    """Directed edges ``i -> i+1`` inside every clip of the given lengths."""
    out, start = [], 0
    for n in lengths:
        n = int(n)
        if n > 1:
            i = np.arange(start, start + n - 1)
            out.append(np.stack([i, i + 1], axis=1))
        start += n
    return np.concatenate(out, axis=0) if out else np.zeros((0, 2), int)


def knn_pairs(points, k: int) -> np.ndarray:
    """Undirected pairs ``(i < j)``: j among the k nearest of i, or i of j.

    The point itself is never its own neighbour, even when duplicates exist.
    With fewer than ``k + 1`` points every point links to all others.
    """
    p = np.asarray(points, float)
    n = p.shape[0]
    if k < 1:
        raise ValueError(f"k must be >= 1, got {k}")
    if n < 2:
        return np.zeros((0, 2), int)
    kk = min(k + 1, n)
    _, idx = cKDTree(p).query(p, k=kk)
    idx = np.asarray(idx).reshape(n, kk)
    rows = np.repeat(np.arange(n), kk)
    cols = idx.ravel()
    keep = rows != cols
    rows, cols = rows[keep], cols[keep]
    # if a point's own index was not returned (duplicates), keep only k others
    counts = np.bincount(rows, minlength=n)
    if np.any(counts > k):
        order = np.lexsort((np.arange(rows.size), rows))
        rank = np.arange(rows.size) - np.repeat(np.cumsum(counts) - counts, counts)
        keep2 = np.empty(rows.size, bool)
        keep2[order] = rank < k
        rows, cols = rows[keep2], cols[keep2]
    e = np.sort(np.stack([rows, cols], axis=1), axis=1)
    return unique_pairs(e, n)


def orient_pairs(points, vectors, pairs):
    """Direct undirected pairs along the mean training vector of their ends.

    Returns
    -------
    edges : ndarray (E, 2) directed edges
    n_ties : int
        Pairs with a zero dot product (added in both directions).
    """
    pairs = np.asarray(pairs, int).reshape(-1, 2)
    if pairs.shape[0] == 0:
        return np.zeros((0, 2), int), 0
    x = np.asarray(points, float)
    v = np.asarray(vectors, float)
    i, j = pairs[:, 0], pairs[:, 1]
    dot = np.einsum("ij,ij->i", x[j] - x[i], 0.5 * (v[i] + v[j]))
    fwd = dot > 0
    bwd = dot < 0
    tie = ~(fwd | bwd)
    edges = np.concatenate([
        pairs[fwd],
        pairs[bwd][:, ::-1],
        pairs[tie],
        pairs[tie][:, ::-1],
    ], axis=0)
    return edges, int(tie.sum())


class MotionGraph:
    """G': clip edges plus oriented Delaunay / k-NN edges.

    Parameters
    ----------
    method : {"delaunay", "knn", "kdelaunay"}
    k : int
        Neighbours for k-NN (paper: 16).
    dup_tol, rank_tol : float
        Passed to :class:`~animsynth.simplicial.geometry.SafeDelaunay`.

    Attributes
    ----------
    edges_ : ndarray (E, 2)
        Unique directed edges ``(from, to)``.
    n_clip_edges_, n_added_pairs_, n_ties_ : int
    clip_starts_, clip_ends_ : ndarray
        First / last point index of every clip.
    triangulation_ : SafeDelaunay or None
    """

    def __init__(self, method: str = "delaunay", k: int = 16, dup_tol: float = 1e-9, rank_tol: float = 1e-9):
        self.method = method
        self.k = k
        self.dup_tol = dup_tol
        self.rank_tol = rank_tol

    def fit(self, points, vectors, lengths, triangulation: SafeDelaunay | None = None) -> "MotionGraph":
        if self.method not in GRAPH_METHODS:
            raise ValueError(f"simplicial method must be one of {GRAPH_METHODS}, got {self.method!r}")
        x = np.asarray(points, float)
        lengths = [int(n) for n in lengths]
        if sum(lengths) != x.shape[0]:
            raise ValueError(f"clip lengths sum to {sum(lengths)} but there are {x.shape[0]} points")
        self.n_ = x.shape[0]
        self.lengths_ = lengths
        ends = np.cumsum(lengths)
        self.clip_starts_ = ends - np.asarray(lengths)
        self.clip_ends_ = ends - 1
        ce = clip_edges(lengths)
        pairs = []
        self.triangulation_ = None
        if self.method in ("delaunay", "kdelaunay"):
            tri = triangulation if triangulation is not None else SafeDelaunay(self.dup_tol, self.rank_tol).fit(x)
            self.triangulation_ = tri
            pairs.append(tri.edges())
        if self.method in ("knn", "kdelaunay"):
            pairs.append(knn_pairs(x, self.k))
        pairs = unique_pairs(np.concatenate(pairs, axis=0), self.n_) if pairs else np.zeros((0, 2), int)
        self.n_added_pairs_ = int(pairs.shape[0])
        added, self.n_ties_ = orient_pairs(x, vectors, pairs)
        self.added_edges_ = added
        self.clip_edge_array_ = ce
        self.n_clip_edges_ = int(ce.shape[0])
        self.edges_ = unique_pairs(np.concatenate([ce, added], axis=0), self.n_)
        self.points_ = x
        if self.n_ties_:
            log.info("MotionGraph(%s): %d edge(s) with zero dot product added in both directions", self.method, self.n_ties_)
        return self

    def adjacency(self, weighted: bool = True) -> csr_matrix:
        """Sparse adjacency; weights are Euclidean edge lengths (tiny floor for zero-length edges)."""
        e = self.edges_
        if weighted:
            w = np.linalg.norm(self.points_[e[:, 1]] - self.points_[e[:, 0]], axis=1)
            w = np.maximum(w, 1e-12)
        else:
            w = np.ones(e.shape[0])
        return csr_matrix((w, (e[:, 0], e[:, 1])), shape=(self.n_, self.n_))

    def connectivity(self) -> dict:
        """Strong components of G', undirected connectivity, and H connectivity."""
        A = self.adjacency(weighted=False)
        n_scc, scc = connected_components(A, directed=True, connection="strong")
        n_weak, _ = connected_components(A, directed=False)
        nc = len(self.lengths_)
        # H: nodes 0..nc-1 = clip ends, nc..2nc-1 = clip starts
        h_rows, h_cols = list(range(nc)), list(range(nc, 2 * nc))  # each clip joins its start and end
        for a in range(nc):
            reach = breadth_first_order(A, int(self.clip_ends_[a]), directed=True, return_predecessors=False)
            reached = np.zeros(self.n_, bool)
            reached[reach] = True
            for b in range(nc):
                if b != a and reached[self.clip_starts_[b]]:
                    h_rows.append(a)
                    h_cols.append(nc + b)
        H = csr_matrix((np.ones(len(h_rows)), (h_rows, h_cols)), shape=(2 * nc, 2 * nc))
        n_h, _ = connected_components(H, directed=False)
        largest = int(np.bincount(scc).max()) if self.n_ else 0
        return {
            "n_edges": int(self.edges_.shape[0]),
            "n_clip_edges": self.n_clip_edges_,
            "n_added_pairs": self.n_added_pairs_,
            "n_tie_edges": self.n_ties_,
            "scc": int(n_scc),
            "largest_scc_frac": round(largest / max(self.n_, 1), 6),
            "undirected_connected": bool(n_weak == 1),
            "h_connected": bool(n_h == 1),
            "h_edges": int(len(h_rows) - nc),
        }
