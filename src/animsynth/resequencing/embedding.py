"""Neighbourhood graphs, the exact minimum connected k, Isomap and ST-Isomap.

Neighbourhood graph
-------------------
For a precomputed distance matrix ``D`` and an integer ``k``, frame ``i``'s
neighbours are the ``k`` frames ranked first in row ``i`` (self excluded,
ties broken by frame index: a stable sort). The graph has the edge ``{i, j}``
when ``j`` is among ``i``'s neighbours *or* ``i`` among ``j``'s -- the
undirected k-NN graph that scikit-learn's ``Isomap`` runs its shortest paths on
(``directed=False``). Edge weights are the distances.

Exact minimum k
---------------
Let ``r_i(j)`` be the rank of ``j`` in row ``i`` (1 = nearest). The edge
``{i, j}`` is present for every ``k >= K_ij = min(r_i(j), r_j(i))``, so the
graph for ``k`` is the set of edges with ``K_ij <= k`` and it is connected
exactly when ``k`` is at least the *bottleneck* (largest edge) of a minimum
spanning tree of the complete graph weighted by ``K``
(:func:`min_connected_k`). One argsort per configuration, then the MST of
the sparse graph ``{K_ij <= k}`` for the first doubled ``k`` (1, 2, 4, ...)
at which it is connected -- it holds every edge up to the bottleneck, so the
answer is exact; no Isomap fit. :func:`graph_components` cross-checks with
``scipy.sparse.csgraph.connected_components`` at ``k`` and ``k - 1``.

Edges that are *always* present (ST-Isomap's adjacent temporal neighbours)
enter with ``K_ij = 0``: they belong to every graph, and the minimum k is the
bottleneck of the MST over ``K`` (at least 1).

scikit-learn's ``Isomap`` silently *adds* edges between components when the
graph is disconnected; :class:`PrecomputedIsomap` refuses instead
(:class:`DisconnectedGraphError`). Geodesics are scipy's
``csgraph.shortest_path`` on our graph and the embedding is scikit-learn's
``KernelPCA`` of ``-G**2 / 2`` -- the two steps of scikit-learn's ``Isomap``,
run on a graph that may hold the always-present edges.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components, minimum_spanning_tree, shortest_path
from scipy.spatial.distance import pdist, squareform
from threadpoolctl import threadpool_limits

from .distances import check_distance_matrix

log = logging.getLogger("animsynth.resequencing")

__all__ = ["DisconnectedGraphError", "neighbor_ranks", "knn_graph", "graph_components", "min_connected_k",
           "temporal_adjacency",
           "PrecomputedIsomap", "STIsomap", "spatio_temporal_distances", "nontrivial_neighbors",
           "residual_variance", "checked_graph"]


class DisconnectedGraphError(ValueError):
    """The neighbourhood graph has more than one connected component."""


def neighbor_ranks(D) -> np.ndarray:
    """Rank of every frame in every row of ``D``: ``R[i, j]`` = 1 for ``i``'s nearest
    frame, ..., ``n - 1`` for the farthest; ``R[i, i] = 0``. Ties: lower index first."""
    D = np.asarray(D, float)
    n = D.shape[0]
    Dm = D.copy()
    np.fill_diagonal(Dm, -np.inf)  # self first (rank 0), even with duplicate frames
    order = np.argsort(Dm, axis=1, kind="stable")
    R = np.empty((n, n), dtype=np.int64)
    rows = np.arange(n)[:, None]
    R[rows, order] = np.arange(n)[None, :]
    return R


def _floor_zeros(D) -> np.ndarray:
    """Off-diagonal zeros (repeated frames) -> a tiny positive distance.

    Sparse graphs cannot hold zero-weight edges reliably (scipy may drop
    explicit zeros), so an exactly repeated frame is placed at distance
    ``1e-12 * max(D)`` from its copy. Ranks and connectivity are unchanged.
    """
    zeros = (D <= 0)
    np.fill_diagonal(zeros, False)
    if zeros.any():
        D = D.copy()
        D[zeros] = 1e-12 * max(float(D.max()), 1e-300)
        log.info("%d off-diagonal zero distances (repeated frames) floored to 1e-12*max", int(zeros.sum()) // 2)
    return D


def temporal_adjacency(n: int, window: int = 1) -> np.ndarray:
    """Bool ``(n, n)`` matrix of the adjacent temporal neighbours ``0 < |i - j| <= window``."""
    idx = np.arange(n)
    lag = np.abs(idx[:, None] - idx[None, :])
    return (lag >= 1) & (lag <= int(window))


def _adjacency(R, k: int, always=None) -> np.ndarray:
    A = (R >= 1) & (R <= k)
    if always is not None:
        A = A | np.asarray(always, bool)
    return A | A.T


def knn_graph(D, k: int, ranks=None, always=None) -> csr_matrix:
    """Undirected k-NN graph of a distance matrix (see module docstring), weighted by ``D``.

    ``always`` (bool ``(n, n)``, optional): edges present whatever ``k``
    (ST-Isomap's adjacent temporal neighbours)."""
    D = np.asarray(D, float)
    n = D.shape[0]
    if k < 0:
        raise ValueError(f"k must be >= 0, got {k}")
    R = neighbor_ranks(D) if ranks is None else ranks
    A = _adjacency(R, k, always)
    W = _floor_zeros(D)
    i, j = np.nonzero(A)
    return csr_matrix((W[i, j], (i, j)), shape=(n, n))


def graph_components(D, k: int, ranks=None, always=None) -> int:
    """Number of connected components of the k-NN graph of ``D`` (plus the ``always`` edges)."""
    n = np.asarray(D).shape[0]
    R = neighbor_ranks(D) if ranks is None else ranks
    A = _adjacency(R, k, always)
    i, j = np.nonzero(A)
    G = csr_matrix((np.ones(i.size), (i, j)), shape=(n, n))
    return int(connected_components(G, directed=False)[0])


def min_connected_k(D, ranks=None, always=None) -> int:
    """Smallest ``k >= 1`` whose undirected k-NN graph of ``D`` (plus the ``always``
    edges) is connected (exact).

    The bottleneck edge of a minimum spanning tree over the edge-appearance
    ranks ``K_ij = min(r_i(j), r_j(i))``, with ``K_ij = 0`` for always-present
    edges (module docstring). 0 for one frame.
    """
    D = np.asarray(D, float)
    n = D.shape[0]
    if n <= 1:
        return 0
    R = neighbor_ranks(D) if ranks is None else ranks
    K = np.minimum(R, R.T)
    np.fill_diagonal(K, n)  # never an edge
    if always is not None:
        a = np.asarray(always, bool)
        a = a | a.T
        np.fill_diagonal(a, False)
        K = np.where(a, 0, K)
    # The MST bottleneck only involves edges up to the answer: find a k whose graph is connected by doubling,
    # then take the MST of that sparse graph (exact, and far cheaper than an MST of all n^2 pairs).
    k = 1
    while True:
        i, j = np.nonzero(K <= k)
        G = csr_matrix((np.ones(i.size), (i, j)), shape=(n, n))
        if k >= n - 1 or connected_components(G, directed=False)[0] == 1:
            break
        k = min(2 * k, n - 1)
    W = csr_matrix((K[i, j] + 1.0, (i, j)), shape=(n, n))  # shifted by one: sparse MST drops zero weights
    mst = minimum_spanning_tree(W)
    return max(1, int(round(mst.data.max())) - 1)


def _check_k(k, n: int, what: str = "n_neighbors") -> int:
    if k is None:
        return None
    if int(k) != k or k < 1:
        raise ValueError(f"{what} must be a positive integer, got {k!r}")
    if k > n - 1:
        raise ValueError(f"{what}={k} needs more than {n} frames")
    return int(k)


class PrecomputedIsomap:
    """Isomap on a precomputed distance matrix that refuses disconnected graphs.

    The k-NN graph of :func:`knn_graph` (the graph scikit-learn's ``Isomap``
    builds, plus optional always-present edges), geodesics with scipy's
    ``csgraph.shortest_path`` and classical MDS with scikit-learn's
    ``KernelPCA`` of ``-G**2 / 2`` -- scikit-learn ``Isomap``'s own two steps,
    so the result equals ``Isomap(metric="precomputed")`` on a connected graph
    (checked in the tests and benchmarks).

    Parameters
    ----------
    n_neighbors : int or None
        ``k`` of the k-NN graph. ``None``: the exact minimum connected ``k``
        (:func:`min_connected_k`).
    n_components : int
        Embedding dimension (prefixes of the embedding are the lower-dimensional
        embeddings, so one fit with 10 components serves d = 1..10).
    path_method : str
        scipy ``shortest_path`` method (``"D"`` = Dijkstra, ``"auto"``).
    blas_threads : int or None
        BLAS threads for the eigendecomposition (``None`` = library default).
        One by default: workflow jobs run side by side on few cores, where
        spinning BLAS threads made the 800-frame eigendecomposition 10x slower.

    Attributes
    ----------
    n_neighbors_ : int
    graph_ : scipy.sparse.csr_matrix, the weighted graph the geodesics run on
    dist_matrix_ : ndarray (frames, frames), geodesic (shortest-path) distances
    embedding_ : ndarray (frames, n_components)
    eigenvalues_ : ndarray, kernel-PCA eigenvalues (descending)
    min_k_ : int, exact minimum connected k of the input

    Raises
    ------
    DisconnectedGraphError
        When ``n_neighbors`` leaves the graph disconnected (the message gives
        the smallest k that connects it).
    """

    def __init__(self, n_neighbors=None, n_components: int = 2, path_method: str = "D", blas_threads: int | None = 1):
        self.n_neighbors = n_neighbors
        self.n_components = n_components
        self.path_method = path_method
        self.blas_threads = blas_threads

    def fit(self, D, always=None):
        """Fit on distances ``D`` (frames, frames); ``always``: bool (frames, frames)
        edges kept whatever k (used by :class:`STIsomap`)."""
        D = check_distance_matrix(D)
        n = D.shape[0]
        if n < 3:
            raise ValueError(f"Isomap needs at least 3 frames, got {n}")
        R = neighbor_ranks(D)
        self.min_k_ = min_connected_k(D, ranks=R, always=always)
        k = _check_k(self.n_neighbors, n)
        k = self.min_k_ if k is None else k
        ncomp = graph_components(D, k, ranks=R, always=always)
        if ncomp > 1:
            raise DisconnectedGraphError(
                f"the {k}-NN graph of {n} frames has {ncomp} connected components; "
                f"the smallest k giving one component is {self.min_k_}")
        self.graph_ = knn_graph(D, k, ranks=R, always=always)
        self.dist_matrix_ = shortest_path(self.graph_, method=self.path_method, directed=False)
        nc = min(int(self.n_components), n - 1)
        from sklearn.decomposition import KernelPCA  # imported here: jobs that embed nothing skip scikit-learn

        kpca = KernelPCA(n_components=nc, kernel="precomputed", eigen_solver="dense")
        with threadpool_limits(limits=self.blas_threads, user_api="blas"):
            self.embedding_ = kpca.fit_transform(-0.5 * self.dist_matrix_ ** 2)
        self.n_neighbors_ = k
        self.eigenvalues_ = np.asarray(kpca.eigenvalues_)
        return self

    def fit_transform(self, D, always=None):
        return self.fit(D, always=always).embedding_


def nontrivial_neighbors(D, m: int, min_gap: int, allowed=None) -> np.ndarray:
    """The ``m`` nearest *non-trivial* neighbours of every frame (Jenkins & Mataric's KNTN).

    Scanning candidates by increasing distance, a frame ``j`` is trivial for
    ``i`` when ``|i - j| <= min_gap`` (same pass of the trajectory as ``i``) or
    ``|j - a| <= min_gap`` for a neighbour ``a`` already accepted (a pass
    already represented). So each accepted neighbour stands for a different
    pass of the motion near frame ``i``.

    ``allowed`` (bool matrix, optional) further restricts the candidates.

    Returns
    -------
    M : int array (frames, m), -1 where fewer than ``m`` exist.
    """
    D = np.asarray(D, float)
    n = D.shape[0]
    idx = np.arange(n)
    gate = np.abs(idx[:, None] - idx[None, :]) > min_gap
    allowed = gate if allowed is None else (gate & np.asarray(allowed, bool))
    M = np.full((n, m), -1, dtype=np.int64)
    for t in range(m):
        Dm = np.where(allowed, D, np.inf)
        j = np.argmin(Dm, axis=1)
        ok = np.isfinite(Dm[idx, j])
        M[ok, t] = j[ok]
        near = np.abs(idx[None, :] - j[:, None]) <= min_gap
        allowed &= ~(near & ok[:, None])
    return M


def check_st_params(c_atn, c_ctn, temporal_window, ctn_neighbors, ctn_min_gap, ctn_tolerance, ctn_reach) -> None:
    """Refuse ST-Isomap parameters that make no sense (shared by the dense and the sparse adjustment)."""
    for name, v in (("c_atn", c_atn), ("c_ctn", c_ctn)):
        if not (np.isfinite(v) and v >= 1.0):
            raise ValueError(f"config key 'resequencing.stisomap.{name}' must be >= 1 (it divides distances), got {v}")
    if temporal_window < 1:
        raise ValueError(f"temporal_window must be >= 1, got {temporal_window}")
    if ctn_min_gap < temporal_window:
        raise ValueError(f"ctn_min_gap ({ctn_min_gap}) must be >= temporal_window ({temporal_window})")
    if ctn_neighbors < 0 or ctn_tolerance < 0 or ctn_reach < 1:
        raise ValueError("ctn_neighbors and ctn_tolerance must be >= 0, ctn_reach >= 1")


def spatio_temporal_distances(D, temporal_window: int = 1, c_atn: float = 10.0, c_ctn: float = 10.0,
                              ctn_neighbors: int = 4, ctn_min_gap: int = 30, ctn_tolerance: int = 2,
                              ctn_reach: int = 6):
    """ST-Isomap's distance adjustment for one continuous sequence (Jenkins & Mataric 2004, Sec. 3).

    Constants named as in the paper: ``c_atn`` divides the distances of the
    *adjacent temporal neighbours* (ATN), ``c_ctn`` those of the *common
    temporal neighbours* (CTN).

    * ATN: ``0 < |i - j| <= temporal_window`` (the paper: the previous and next
      frame, ``temporal_window = 1``). Distance divided by ``c_atn``.
    * CTN: ``j`` is one of ``i``'s ``ctn_neighbors`` non-trivial neighbours
      (the paper's K-nearest non-trivial neighbours,
      :func:`nontrivial_neighbors`; ``ctn_min_gap`` frames define "the same
      pass" -- our parameter) among the frames *closer to i than i's own
      frames ``ctn_reach`` frames earlier and later* (our gate: a CTN is a real
      crossing, never a far frame that merely happens to be the nearest of its
      pass), and the relation persists one frame earlier and one frame later:
      ``i - 1`` has a non-trivial neighbour within ``ctn_tolerance`` frames
      (our slack) of ``j - 1`` and ``i + 1`` one within ``ctn_tolerance`` of
      ``j + 1`` (only the side that exists at the ends of the sequence): the
      two passes move the same way. Symmetrised; distance divided by ``c_ctn``.
    * Every other pair keeps its distance.

    Returns
    -------
    D_st : ndarray (frames, frames), the adjusted distances
    atn : bool ndarray (frames, frames), adjacent-temporal-neighbour pairs
    ctn : bool ndarray (frames, frames), common-temporal-neighbour pairs
    """
    D = check_distance_matrix(D)
    n = D.shape[0]
    check_st_params(c_atn, c_ctn, temporal_window, ctn_neighbors, ctn_min_gap, ctn_tolerance, ctn_reach)
    idx = np.arange(n)
    lag = np.abs(idx[:, None] - idx[None, :])
    atn = temporal_adjacency(n, temporal_window)
    ctn = np.zeros((n, n), bool)
    if ctn_neighbors > 0 and n > 2:
        back = np.where(idx - ctn_reach >= 0, D[idx, np.clip(idx - ctn_reach, 0, n - 1)], np.inf)
        fwd = np.where(idx + ctn_reach < n, D[idx, np.clip(idx + ctn_reach, 0, n - 1)], np.inf)
        reach = np.minimum(back, fwd)
        M = nontrivial_neighbors(D, ctn_neighbors, ctn_min_gap, allowed=D < reach[:, None])
        B = np.zeros((n, n), bool)
        rows = np.repeat(idx, M.shape[1])
        cols = M.ravel()
        ok = cols >= 0
        B[rows[ok], cols[ok]] = True
        # tolerance: B_tol[i, j] = any B[i, j-tol .. j+tol]
        Bt = B.copy()
        for s in range(1, ctn_tolerance + 1):
            Bt[:, s:] |= B[:, :-s]
            Bt[:, :-s] |= B[:, s:]
        prev_ok = np.ones((n, n), bool)  # i-1 neighbours j-1 (or i or j is the first frame)
        prev_ok[1:, 1:] = Bt[:-1, :-1]
        next_ok = np.ones((n, n), bool)  # i+1 neighbours j+1 (or i or j is the last frame)
        next_ok[:-1, :-1] = Bt[1:, 1:]
        ctn = B & prev_ok & next_ok
        ctn = ctn | ctn.T
        ctn &= lag > ctn_min_gap
    D_st = D.copy()
    D_st[atn] /= c_atn
    D_st[ctn] /= c_ctn
    return D_st, atn, ctn


class STIsomap:
    """Spatio-temporal Isomap (Jenkins & Mataric 2004), continuous version, for one sequence.

    1. Adjust the distances (:func:`spatio_temporal_distances`): adjacent
       temporal neighbours divided by ``c_atn``, common temporal neighbours by
       ``c_ctn``.
    2. Spatio-temporal neighbourhoods: every frame's adjacent temporal
       neighbours are *always* in its neighbourhood, plus its ``k`` nearest
       frames under the adjusted distances (undirected). The chain of frames
       is therefore connected at any k, and the minimum connected k is 1 --
       the value the paper reports for most of its ST-Isomap rows.
    3. Geodesics (Dijkstra) on that graph and classical MDS
       (:class:`PrecomputedIsomap` with the ATN as always-present edges).

    Frame windowing (the paper's optional step 1) is not used: the Lee
    metric's velocity term plays that role.

    Parameters
    ----------
    n_neighbors : int or None (None = exact minimum connected k, 1 on one sequence)
    n_components : int
    temporal_window : int, frames on each side that are adjacent temporal neighbours (paper: 1)
    c_atn : float >= 1, divisor of adjacent-temporal-neighbour distances (paper's constant; value ours)
    c_ctn : float >= 1, divisor of common-temporal-neighbour distances (paper's constant; value ours)
    ctn_neighbors : int, non-trivial neighbours examined per frame for CTN (paper's K of KNTN)
    ctn_min_gap : int, frames closer than this in time are the same pass, never CTN (ours)
    ctn_tolerance : int, frames of slack when following a CTN one frame forward/back (ours)
    ctn_reach : int, a CTN must be closer than the frame's own frames this many frames away (ours)
    path_method : str, shortest-path method (``"D"`` = Dijkstra)
    blas_threads : int or None, as :class:`PrecomputedIsomap`

    Attributes
    ----------
    dist_st_ : ndarray (frames, frames), adjusted distance matrix
    atn_, ctn_ : bool ndarray (frames, frames), the adjusted pairs
    n_neighbors_, min_k_, graph_, dist_matrix_, embedding_, eigenvalues_ : as :class:`PrecomputedIsomap`
    """

    def __init__(self, n_neighbors=None, n_components: int = 2, temporal_window: int = 1, c_atn: float = 10.0,
                 c_ctn: float = 10.0, ctn_neighbors: int = 4, ctn_min_gap: int = 30, ctn_tolerance: int = 2,
                 ctn_reach: int = 6, path_method: str = "D", blas_threads: int | None = 1):
        self.n_neighbors = n_neighbors
        self.n_components = n_components
        self.temporal_window = temporal_window
        self.c_atn = c_atn
        self.c_ctn = c_ctn
        self.ctn_neighbors = ctn_neighbors
        self.ctn_min_gap = ctn_min_gap
        self.ctn_tolerance = ctn_tolerance
        self.ctn_reach = ctn_reach
        self.path_method = path_method
        self.blas_threads = blas_threads

    def adjusted_distances(self, D):
        """Return (and store as ``dist_st_``) the spatio-temporally adjusted matrix."""
        self.dist_st_, self.atn_, self.ctn_ = spatio_temporal_distances(
            D, self.temporal_window, self.c_atn, self.c_ctn, self.ctn_neighbors, self.ctn_min_gap,
            self.ctn_tolerance, self.ctn_reach)
        return self.dist_st_

    def fit(self, D):
        Dst = self.adjusted_distances(D)
        iso = PrecomputedIsomap(self.n_neighbors, self.n_components, self.path_method,
                                self.blas_threads).fit(Dst, always=self.atn_)
        for a in ("n_neighbors_", "min_k_", "graph_", "dist_matrix_", "embedding_", "eigenvalues_"):
            setattr(self, a, getattr(iso, a))
        return self

    def fit_transform(self, D):
        return self.fit(D).embedding_


def residual_variance(geodesic, embedding, dims=None) -> np.ndarray:
    """Isomap residual variance ``1 - R^2`` between geodesic distances and the
    Euclidean distances of the first ``d`` embedding coordinates, for each ``d``.

    Parameters
    ----------
    geodesic : array (n, n)
    embedding : array (n, d_max), columns in decreasing eigenvalue order
    dims : iterable of int (default 1..d_max)

    Returns
    -------
    array of residual variances, one per ``d``
    """
    G = np.asarray(geodesic, float)
    Y = np.asarray(embedding, float)
    if not np.all(np.isfinite(G)):
        raise DisconnectedGraphError("geodesic distances contain inf: the graph is disconnected")
    dims = list(range(1, Y.shape[1] + 1)) if dims is None else list(dims)
    g = squareform(0.5 * (G + G.T), checks=False)
    out = []
    for d in dims:
        if d < 1 or d > Y.shape[1]:
            raise ValueError(f"dimension {d} outside 1..{Y.shape[1]}")
        e = pdist(Y[:, :d])
        if np.std(e) == 0 or np.std(g) == 0:
            out.append(np.nan)
            continue
        r = np.corrcoef(g, e)[0, 1]
        out.append(1.0 - r * r)
    return np.asarray(out)


def checked_graph(Dm, k: int, always=None, what: str = ""):
    """The ``k``-NN graph of ``Dm`` (plus the ``always`` edges), refused when it is disconnected."""
    ncomp = graph_components(Dm, k, always=always)
    if ncomp > 1:
        raise DisconnectedGraphError(f"{what}: the {k}-NN graph has {ncomp} components "
                                     f"(the smallest connected k is {min_connected_k(Dm, always=always)})")
    return knn_graph(Dm, k, always=always)
