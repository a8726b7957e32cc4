"""Landmark Isomap (de Silva & Tenenbaum 2003) on a sparse neighbour graph, and the
``embed`` front end that picks exact or landmark Isomap by size.

Exact Isomap needs all-pairs geodesics: ``N^2`` memory and about ``N^2 log N``
time. Landmark Isomap needs geodesics from ``n`` landmarks only:

1. **Landmarks**: ``"maxmin"`` (de Silva & Tenenbaum's MaxMin: a seeded random
   first landmark, then repeatedly the frame farthest, in geodesic distance,
   from all landmarks chosen so far) or ``"random"`` (a seeded sample).
2. **Landmark geodesics**: ``scipy.sparse.csgraph.dijkstra(graph,
   indices=landmarks)`` -- an ``(n, N)`` matrix, never ``N x N``.
3. **Landmark MDS**: classical MDS of the landmarks' squared geodesics
   ``Delta_n``: ``B = -1/2 H Delta_n H``, eigenpairs ``(lambda_i, v_i)``,
   landmark coordinates ``L = [sqrt(lambda_i) v_i]``.
4. **Distance-based triangulation** of every frame ``x`` with squared geodesics
   ``delta_x`` to the landmarks: ``y_x = -1/2 L^# (delta_x - delta_mu)``,
   ``L^#`` rows ``v_i^T / sqrt(lambda_i)``, ``delta_mu`` the column mean of
   ``Delta_n``. Landmarks are placed exactly where step 3 put them.

The same applies to ST-Isomap: give the graph of the *adjusted* neighbour list
(:func:`.sparse_st.st_neighbours`).

Residual variance ``1 - R^2`` (geodesic vs embedded distances) of a landmark
embedding is estimated **on the landmark pairs only** (all ``N^2`` pairs are
what we avoid); :class:`EmbeddingResult` says which (``rv_on``). The
eigendecomposition is small (``n x n``); scikit-learn has no landmark MDS,
hence the ~20 lines here. Exact Isomap (:func:`exact_isomap`) is scikit-learn's
kernel-PCA step (``KernelPCA(kernel="precomputed")`` on ``-1/2 G^2``, as
``sklearn.manifold.Isomap`` does) on the all-pairs geodesics of the *given*
sparse graph (``Isomap`` itself would build its own graph).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import eigh
from scipy.sparse.csgraph import connected_components, dijkstra
from threadpoolctl import threadpool_limits

from .embedding import DisconnectedGraphError, residual_variance

log = logging.getLogger("animsynth.resequencing")

__all__ = ["EmbeddingResult", "choose_landmarks", "LandmarkIsomap", "exact_isomap", "embed",
           "residual_variance_pairs", "EMBED_METHODS"]

EMBED_METHODS = ("auto", "exact", "landmark")


@dataclass
class EmbeddingResult:
    """What :func:`embed` returns.

    Attributes
    ----------
    method : "exact" or "landmark" (what ran)
    embedding : array (frames, d)
    eigenvalues : array (d,), descending
    residual_variance : array (d,), ``1 - R^2`` for dimensions 1..d
    rv_on : "all frame pairs" or "landmark pairs (n)"
    landmarks : int array of landmark frames (empty for exact)
    """

    method: str
    embedding: np.ndarray
    eigenvalues: np.ndarray
    residual_variance: np.ndarray
    rv_on: str
    landmarks: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))


def _check_graph(graph):
    n = graph.shape[0]
    if graph.shape != (n, n):
        raise ValueError(f"graph must be square, got {graph.shape}")
    ncomp = int(connected_components(graph, directed=False)[0])
    if ncomp > 1:
        raise DisconnectedGraphError(f"the neighbour graph of {n} frames has {ncomp} connected components")
    return n


def residual_variance_pairs(geodesic, embedding, dims=None) -> np.ndarray:
    """``1 - R^2`` between a square geodesic matrix and the embedding's pairwise distances, for
    each leading dimension ``d`` in ``dims`` (default 1..d_max): the exact Isomap measure
    (:func:`.embedding.residual_variance`), applied here to the landmark pairs only."""
    return residual_variance(geodesic, embedding, dims)


def choose_landmarks(graph, n_landmarks: int, how: str = "maxmin", seed: int = 0):
    """Landmark frames and their geodesic rows.

    Returns
    -------
    landmarks : int array (n,)
    geo : array (n, frames), geodesic distances from each landmark
    """
    n = graph.shape[0]
    nl = int(n_landmarks)
    if nl < 3:
        raise ValueError(f"n_landmarks must be >= 3, got {n_landmarks}")
    nl = min(nl, n)
    rng = np.random.default_rng(seed)
    if how == "random":
        lm = np.sort(rng.choice(n, size=nl, replace=False))
        return lm, dijkstra(graph, directed=False, indices=lm)
    if how != "maxmin":
        raise ValueError(f"landmark choice must be 'maxmin' or 'random', got {how!r}")
    lm = [int(rng.integers(n))]
    rows = [dijkstra(graph, directed=False, indices=lm[0])]
    nearest = rows[0].copy()
    while len(lm) < nl:
        nxt = int(np.argmax(nearest))  # farthest from every landmark so far (ties: lowest index)
        if nearest[nxt] == 0:
            break  # every frame is a landmark (or a zero-distance copy of one)
        lm.append(nxt)
        rows.append(dijkstra(graph, directed=False, indices=nxt))
        np.minimum(nearest, rows[-1], out=nearest)
    return np.asarray(lm, np.int64), np.vstack(rows)


class LandmarkIsomap:
    """Landmark Isomap (de Silva & Tenenbaum 2003) on a sparse neighbour graph.

    Parameters
    ----------
    n_components : int, embedding dimension
    n_landmarks : int, landmarks (at most the number of frames)
    landmarks : "maxmin" or "random"
    seed : int, seeds the first MaxMin landmark / the random sample
    blas_threads : int or None, BLAS threads for the eigendecomposition
    eigen_tol : float, components whose eigenvalue is <= eigen_tol x the largest get coordinate 0

    Attributes
    ----------
    landmarks_ : int array (n,)
    landmark_geodesics_ : array (n, frames)
    embedding_ : array (frames, d)
    eigenvalues_ : array (d,), descending (landmark MDS)
    residual_variance_ : array (d,), on the landmark pairs only
    """

    def __init__(self, n_components: int = 2, n_landmarks: int = 500, landmarks: str = "maxmin", seed: int = 0,
                 blas_threads: int | None = 1, eigen_tol: float = 1e-9):
        self.eigen_tol = eigen_tol
        self.n_components = n_components
        self.n_landmarks = n_landmarks
        self.landmarks = landmarks
        self.seed = seed
        self.blas_threads = blas_threads

    def fit(self, graph):
        """Fit on a symmetric sparse graph ``(frames, frames)`` (e.g. :func:`.sparse.sparse_knn_graph`)."""
        n = _check_graph(graph)
        lm, geo = choose_landmarks(graph, self.n_landmarks, self.landmarks, self.seed)
        nl = lm.size
        d = int(self.n_components)
        if not 1 <= d < nl:
            raise ValueError(f"n_components={d} needs more than {nl} landmarks")
        D2 = geo[:, lm] ** 2
        D2 = 0.5 * (D2 + D2.T)
        H = np.eye(nl) - 1.0 / nl
        B = -0.5 * H @ D2 @ H
        with threadpool_limits(limits=self.blas_threads, user_api="blas"):
            lam, V = eigh(B, subset_by_index=[nl - d, nl - 1])
        lam, V = lam[::-1], V[:, ::-1]
        if not lam[0] > 0:
            raise ValueError("landmark MDS has no positive eigenvalue (all landmarks at one point?)")
        # Directions with (numerically) zero or negative eigenvalues carry no
        # geometry; triangulating along them divides rounding noise by
        # sqrt(lambda). They get coordinate 0 (e.g. a chain-like graph is 1-D).
        keep = lam > self.eigen_tol * lam[0]
        if not keep.all():
            log.info("landmark MDS: %d of %d components have eigenvalue <= %.0e x the largest; set to 0",
                     int((~keep).sum()), d, self.eigen_tol)
        Lsharp = np.zeros((d, nl))
        Lsharp[keep] = V.T[keep] / np.sqrt(lam[keep])[:, None]  # (d, nl)
        lam = np.where(keep, lam, 0.0)
        mu = D2.mean(axis=0)
        Y = np.empty((n, d))
        step = 20_000
        for s in range(0, n, step):
            delta = geo[:, s:s + step] ** 2  # (nl, block)
            Y[s:s + step] = (-0.5 * Lsharp @ (delta - mu[:, None])).T
        self.landmarks_ = lm
        self.landmark_geodesics_ = geo
        self.embedding_ = Y
        self.eigenvalues_ = lam
        self.residual_variance_ = residual_variance_pairs(geo[:, lm], Y[lm])
        return self

    def fit_transform(self, graph):
        return self.fit(graph).embedding_


def exact_isomap(graph, n_components: int = 2, blas_threads: int | None = 1):
    """Exact Isomap on a given sparse graph: all-pairs Dijkstra, then scikit-learn's kernel PCA.

    Returns ``(embedding (frames, d), eigenvalues (d,), geodesics (frames, frames))``.
    """
    n = _check_graph(graph)
    d = int(n_components)
    if not 1 <= d < n:
        raise ValueError(f"n_components={d} needs more than {n} frames")
    G = dijkstra(graph, directed=False)
    K = -0.5 * G ** 2
    from sklearn.decomposition import KernelPCA  # imported here: jobs that embed nothing skip scikit-learn

    kpca = KernelPCA(n_components=d, kernel="precomputed", eigen_solver="dense")
    with threadpool_limits(limits=blas_threads, user_api="blas"):
        Y = kpca.fit_transform(K)
    return Y, np.asarray(kpca.eigenvalues_), G


def embed(graph, n_components: int = 2, method: str = "auto", exact_max_frames: int = 4000,
          n_landmarks: int = 500, landmarks: str = "maxmin", seed: int = 0, blas_threads: int | None = 1
          ) -> EmbeddingResult:
    """Isomap embedding of a sparse neighbour graph: exact below a size, landmark above.

    Parameters
    ----------
    graph : sparse symmetric ``(frames, frames)``, connected
    n_components : int
    method : "auto" (exact when ``frames <= exact_max_frames``, else landmark), "exact" or "landmark"
    exact_max_frames : int, the "auto" threshold (exact needs ``frames^2`` floats)
    n_landmarks, landmarks, seed : as :class:`LandmarkIsomap`

    Returns
    -------
    EmbeddingResult, whose ``method`` says which ran (also logged)
    """
    if method not in EMBED_METHODS:
        raise ValueError(f"embedding method must be one of {EMBED_METHODS}, got {method!r}")
    n = graph.shape[0]
    run = method if method != "auto" else ("exact" if n <= int(exact_max_frames) else "landmark")
    if run == "exact":
        Y, lam, G = exact_isomap(graph, n_components, blas_threads)
        rv = residual_variance_pairs(G, Y)
        res = EmbeddingResult("exact", Y, lam, rv, "all frame pairs")
    else:
        li = LandmarkIsomap(n_components, n_landmarks, landmarks, seed, blas_threads).fit(graph)
        res = EmbeddingResult("landmark", li.embedding_, li.eigenvalues_, li.residual_variance_,
                              f"landmark pairs ({li.landmarks_.size})", li.landmarks_)
    log.info("Isomap embedding of %d frames: %s (%s requested, exact up to %d frames); RV on %s",
             n, res.method, method, exact_max_frames, res.rv_on)
    return res
