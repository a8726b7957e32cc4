"""Re-sequencing without an N x N matrix: sparse neighbour graphs for large databases.

The dense pipeline (:mod:`.distances`, :mod:`.embedding`) builds every frame
pair's distance and all-pairs geodesics: memory grows like N^2, so a database
of many trials (10^4 - 10^5 frames) does not fit. This module keeps only each
frame's nearest candidates, found with a spatial index (scikit-learn
``NearestNeighbors``, a ball tree / k-d tree chosen by scikit-learn).

Neighbour lists
---------------
A *neighbour list* is a pair ``(dist, idx)`` of arrays ``(frames, m)``: row
``i`` holds frame ``i``'s ``m`` nearest other frames in increasing distance
(ties broken by frame index, as :func:`.embedding.neighbor_ranks`), the frame
itself excluded. ``m`` is the *candidate count*: every k used later (graph,
minimum k) must be <= ``m``.

* L2 on the linearised features (:func:`l2_neighbours`): the index answers
  exactly.
* The Lee et al. metric (:func:`lee_neighbours`) is not a norm of a fixed
  vector, so it cannot be indexed directly. Each frame is mapped to a vector
  ``e`` whose squared Euclidean distance is the metric with ``sin(theta)`` in
  place of the joint angle ``theta = arccos|<q_i, q_j>|`` (the quaternion
  outer product ``q q^T`` is sign-free and ``||q q^T - p p^T||_F^2 = 2 sin^2
  theta``); the velocity and root terms are plain Euclidean already. As
  ``sin theta <= theta <= (pi/2) sin theta`` on ``[0, pi/2]``,
  ``|e_i - e_j|^2 <= lee(i, j) <= (pi/2)^2 |e_i - e_j|^2``. The index returns
  ``ceil(margin * m)`` candidates by ``|e_i - e_j|`` (``margin`` = 2 by
  default); the exact metric is computed on those and the ``m`` best kept.
  The result is *certified*: when the ``m``-th exact value is <= the largest
  candidate's index distance, no frame outside the candidates can be closer
  (its exact value is >= its index distance). Rows that fail the check are
  queried again with twice the candidates until they pass (at worst all
  frames), so the lists are exact whatever the margin; the margin only sets
  how much work the first pass does (``stats['rows_requeried']``).

Minimum k
---------
As in :mod:`.embedding`: the edge ``{i, j}`` exists for ``k >=
K_ij = min(r_i(j), r_j(i))``. A neighbour list knows ``r_i(j)`` for ``r <= m``;
for a pair known from one side only the other rank is ``> m``, so the known
rank *is* ``K_ij``. The minimum connected k is the bottleneck of a minimum
spanning tree of the sparse graph weighted by ``K`` (scipy), and it is exact
as long as it is <= ``m``; otherwise :class:`CandidateCountError` says how
many candidates are needed at least.

ST-Isomap
---------
Jenkins & Mataric's adjustment on neighbour lists lives in :mod:`.sparse_st`
(:func:`.sparse_st.st_neighbours`, :func:`.sparse_st.st_always_edges`);
:func:`sparse_graph` applies it.
"""

from __future__ import annotations

import logging
import math
from contextlib import nullcontext
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import connected_components, minimum_spanning_tree

from .distances import PAPER_WEIGHTS, joint_weights
from .embedding import DisconnectedGraphError
from .features import MotionFeatures, angular_velocity
from .paths import shortest_path_frames
from .sparse_st import st_always_edges, st_neighbours

log = logging.getLogger("animsynth.resequencing")

__all__ = ["CandidateCountError", "concat_features", "l2_neighbours", "lee_index_vectors", "lee_pair_metric",
           "lee_neighbours", "sparse_knn_graph", "sparse_min_connected_k", "shortest_path", "SparseGraph",
           "sparse_graph", "LEE_INDEX_RATIO"]

#: Upper bound of lee / index-distance (squared metric): (pi/2)^2 (module docstring).
LEE_INDEX_RATIO = (math.pi / 2.0) ** 2


class CandidateCountError(ValueError):
    """A k (or the minimum connected k) needs more candidates than the neighbour lists hold."""


# ----------------------------------------------------------------------------- databases


def concat_features(features) -> tuple[list, np.ndarray]:
    """A database of motions: the list of :class:`MotionFeatures` and each frame's sequence id.

    Parameters
    ----------
    features : MotionFeatures or sequence of them (same joints)

    Returns
    -------
    feats : list of MotionFeatures
    sequence : int array (frames,), index of each frame's motion in ``feats``
    """
    feats = [features] if isinstance(features, MotionFeatures) else list(features)
    if not feats:
        raise ValueError("empty database: no motions")
    names = feats[0].joint_names
    for f in feats[1:]:
        if list(f.joint_names) != list(names):
            raise ValueError("database motions have different joints; they cannot share one metric")
    seq = np.concatenate([np.full(f.n_frames, s, dtype=np.int64) for s, f in enumerate(feats)])
    return feats, seq


def _sorted_rows(dist, idx):
    """Sort each row by (distance, index): the tie-breaking of :func:`.embedding.neighbor_ranks`."""
    order = np.lexsort((idx, dist), axis=1) if dist.size else np.zeros_like(idx)
    return np.take_along_axis(dist, order, 1), np.take_along_axis(idx, order, 1)


def _drop_self(dist, idx, m: int):
    """Remove frame ``i`` from row ``i`` (or the last entry when absent) and keep ``m`` columns."""
    n = idx.shape[0]
    self_hit = idx == np.arange(n)[:, None]
    # rows without self (duplicates filled the list): drop the farthest entry instead
    none = ~self_hit.any(axis=1)
    self_hit[none, -1] = True
    first = np.argmax(self_hit, axis=1)
    keep = np.ones_like(self_hit)
    keep[np.arange(n), first] = False
    dist = dist[keep].reshape(n, -1)[:, :m]
    idx = idx[keep].reshape(n, -1)[:, :m]
    return dist, idx


def _check_m(m, n: int, what: str = "n_candidates") -> int:
    if int(m) != m or m < 1:
        raise ValueError(f"{what} must be a positive integer, got {m!r}")
    if m > n - 1:
        raise CandidateCountError(f"{what}={m} needs more than {n} frames")
    return int(m)


def _index(X, algorithm: str, leaf_size: int, n_jobs):
    from sklearn.neighbors import NearestNeighbors  # only the large-database route needs it

    return NearestNeighbors(algorithm=algorithm, leaf_size=leaf_size, n_jobs=n_jobs).fit(X)


# ----------------------------------------------------------------------------- L2


def l2_neighbours(X, n_candidates: int, algorithm: str = "auto", leaf_size: int = 40, n_jobs=1):
    """Exact ``n_candidates`` nearest frames of every frame under L2, from a spatial index.

    Parameters
    ----------
    X : array (frames, dims), e.g. the linearised features (:meth:`MotionFeatures.linearised`)
    n_candidates : int, neighbours kept per frame (``m``)
    algorithm, leaf_size, n_jobs : passed to ``sklearn.neighbors.NearestNeighbors``

    Returns
    -------
    dist : array (frames, m), increasing per row
    idx : int array (frames, m)
    """
    X = np.asarray(X, float)
    if X.ndim != 2:
        raise ValueError(f"features must be (frames, dims), got {X.shape}")
    if not np.all(np.isfinite(X)):
        bad = int(np.argwhere(~np.isfinite(X))[0, 0])
        raise ValueError(f"frame {bad} has a non-finite feature")
    n = X.shape[0]
    m = _check_m(n_candidates, n)
    nn = _index(X, algorithm, leaf_size, n_jobs)
    dist, idx = nn.kneighbors(X, n_neighbors=min(n, m + 1))
    dist, idx = _drop_self(*_sorted_rows(dist, idx), m)
    return dist, idx


# ----------------------------------------------------------------------------- Lee metric


def _lee_parts(features, weights, nu: float, include_global: bool):
    """Per-frame arrays of the Lee metric for a database (module docstring).

    Returns ``(qa, wa, vel, root)``: unit quaternions of the weighted joints
    ``(frames, a, 4)``, their weights ``(a,)``, the weighted velocity vector
    ``(frames, v)`` (``sqrt(nu)`` and the joint weights folded in) and the
    root-position vector ``(frames, 3)`` or None.
    """
    feats, _ = concat_features(features)
    w = joint_weights(feats[0].joint_names, PAPER_WEIGHTS if weights is None else weights,
                      getattr(feats[0], "roles", None))
    if not (np.isfinite(nu) and nu >= 0):
        raise ValueError(f"nu must be finite and >= 0, got {nu}")
    active = np.flatnonzero(w > 0)
    qa = np.concatenate([f.quats[:, active, :] for f in feats])
    qa = qa / np.linalg.norm(qa, axis=-1, keepdims=True)
    n = qa.shape[0]
    vel = [np.zeros((n, 0))]
    if nu > 0 and active.size:
        om = np.concatenate([angular_velocity(f.quats[:, active, :] / np.linalg.norm(f.quats[:, active, :], axis=-1,
                                                                                      keepdims=True), f.fps)
                             for f in feats])
        vel.append((om * np.sqrt(w[active])[None, :, None]).reshape(n, -1) * math.sqrt(nu))
    root = None
    if include_global:
        root = np.concatenate([f.root_pos for f in feats])
        if nu > 0:
            pv = np.concatenate([np.gradient(f.root_pos, axis=0) * f.fps if f.n_frames > 1
                                 else np.zeros_like(f.root_pos) for f in feats])
            vel.append(pv * math.sqrt(nu))
    return qa, w[active], np.hstack(vel), root


def lee_index_vectors(features, weights=None, nu: float = 0.01, include_global: bool = False) -> np.ndarray:
    """Vectors ``e`` with ``|e_i - e_j|^2 <= lee(i, j) <= (pi/2)^2 |e_i - e_j|^2`` (module docstring).

    Per weighted joint the 10 distinct entries of ``q q^T`` (off-diagonal ones
    times sqrt 2) scaled by ``sqrt(w / 2)``, then the weighted velocities and,
    with ``include_global``, the root position. Shape ``(frames, 10 a + v [+ 3])``.
    """
    qa, wa, vel, root = _lee_parts(features, weights, nu, include_global)
    n, a, _ = qa.shape
    iu, ju = np.triu_indices(4)
    scale = np.where(iu == ju, 1.0, math.sqrt(2.0))
    outer = qa[:, :, iu] * qa[:, :, ju] * scale[None, None, :]  # (n, a, 10)
    outer *= np.sqrt(wa / 2.0)[None, :, None]
    parts = [outer.reshape(n, -1), vel]
    if root is not None:
        parts.append(root)
    return np.hstack(parts)


def lee_pair_metric(parts, i, j, sqrt: bool = False) -> np.ndarray:
    """The exact (squared) Lee metric for frame pairs ``(i[p], j[p])`` from :func:`_lee_parts` output."""
    qa, wa, vel, root = parts
    i = np.asarray(i, np.int64)
    j = np.asarray(j, np.int64)
    out = np.empty(i.shape)
    flat_i, flat_j, flat_o = i.ravel(), j.ravel(), out.reshape(-1)
    step = 200_000
    for s in range(0, flat_i.size, step):
        a, b = flat_i[s:s + step], flat_j[s:s + step]
        c = np.abs(np.einsum("pjc,pjc->pj", qa[a], qa[b]))
        np.clip(c, 0.0, 1.0, out=c)
        d = (np.arccos(c) ** 2) @ wa
        if vel.shape[1]:
            d += np.sum((vel[a] - vel[b]) ** 2, axis=1)
        if root is not None:
            d += np.sum((root[a] - root[b]) ** 2, axis=1)
        flat_o[s:s + step] = d
    np.maximum(out, 0.0, out=out)
    return np.sqrt(out) if sqrt else out


def lee_neighbours(features, n_candidates: int, weights=None, nu: float = 0.01, include_global: bool = False,
                   sqrt: bool = False, margin: float = 2.0, algorithm: str = "auto", leaf_size: int = 40, n_jobs=1,
                   return_stats: bool = False):
    """Exact ``n_candidates`` nearest frames under the Lee et al. metric, without an N x N matrix.

    Candidates come from a spatial index on :func:`lee_index_vectors`
    (``ceil(margin * n_candidates)`` per frame), the exact metric is computed on
    them and the result certified; uncertified rows are re-queried with twice
    the candidates (module docstring). ``margin`` >= 1 changes the work, never
    the result.

    Parameters
    ----------
    features : MotionFeatures or list of them (a database; velocities per motion)
    n_candidates : int, neighbours kept per frame (``m``)
    weights, nu, include_global, sqrt : as :func:`.distances.lee_distances`
    margin : float >= 1, first-pass candidates per kept neighbour
    return_stats : also return ``{"first_pass": int, "rows_requeried": int, "max_candidates": int}``

    Returns
    -------
    dist : array (frames, m), the exact metric (squared unless ``sqrt``), increasing per row
    idx : int array (frames, m)
    """
    if not (np.isfinite(margin) and margin >= 1.0):
        raise ValueError(f"margin must be >= 1, got {margin}")
    parts = _lee_parts(features, weights, nu, include_global)
    E = lee_index_vectors(features, weights, nu, include_global)
    n = E.shape[0]
    m = _check_m(n_candidates, n)
    nn = _index(E, algorithm, leaf_size, n_jobs)
    first = min(n - 1, int(math.ceil(margin * m)))
    dist = np.empty((n, m))
    idx = np.empty((n, m), np.int64)
    todo = np.arange(n)
    c = first
    requeried = 0
    while todo.size:
        ed, ei = nn.kneighbors(E[todo], n_neighbors=min(n, c + 1))
        ed = ed ** 2
        # drop self per row (keep c columns)
        sd, si = _drop_self(ed, ei, c)
        exact = lee_pair_metric(parts, np.repeat(todo[:, None], si.shape[1], 1), si)
        exact, si = _sorted_rows(exact, si)
        ok = (exact[:, m - 1] <= sd[:, -1]) | (c >= n - 1)
        done = todo[ok]
        dist[done] = exact[ok, :m]
        idx[done] = si[ok, :m]
        if c == first:
            first_ok = int(ok.sum())
        todo = todo[~ok]
        if todo.size:
            requeried += int(todo.size)
            c = min(n - 1, 2 * c)
    if sqrt:
        dist = np.sqrt(dist)
    stats = {"first_pass": first_ok, "rows_requeried": requeried, "max_candidates": int(c)}
    log.info("Lee neighbours: %d frames, m=%d, %d first-pass candidates; %d rows re-queried (up to %d)",
             n, m, first, requeried, c)
    return (dist, idx, stats) if return_stats else (dist, idx)


# ----------------------------------------------------------------------------- graphs and minimum k


def _floor(dist):
    """Zero distances (repeated frames) -> a tiny positive weight (sparse graphs drop zeros)."""
    d = np.asarray(dist, float)
    if np.any(d <= 0):
        d = d.copy()
        d[d <= 0] = 1e-12 * max(float(d.max()), 1e-300)
    return d


def _check_always_pairs(pairs, n: int) -> np.ndarray:
    p = np.asarray(pairs, np.int64).reshape(-1, 2)
    if p.size and (p.min() < 0 or p.max() >= n or np.any(p[:, 0] == p[:, 1])):
        raise ValueError(f"always-present edges must join two different frames in [0, {n})")
    return p


def sparse_knn_graph(dist, idx, k: int, always=None) -> csr_matrix:
    """Undirected k-NN graph from a neighbour list: ``{i, j}`` when ``j`` is among ``i``'s
    first ``k`` or ``i`` among ``j``'s (the graph of :func:`.embedding.knn_graph`), weighted
    by the distances. Symmetric CSR ``(frames, frames)``.

    ``always``: optional ``(pairs (E, 2), weights (E,))``, edges present whatever
    ``k`` (ST-Isomap's adjacent temporal neighbours, :func:`.sparse_st.st_always_edges`).
    A pair that is also listed keeps the smaller of its two weights.

    Raises
    ------
    CandidateCountError if ``k`` exceeds the lists' candidate count.
    """
    dist = np.asarray(dist, float)
    idx = np.asarray(idx, np.int64)
    n, m = idx.shape
    if int(k) != k or k < 1:
        raise ValueError(f"k must be a positive integer, got {k!r}")
    if k > m:
        raise CandidateCountError(f"k={k} exceeds the {m} candidates per frame; build the neighbour lists "
                                  f"with n_candidates >= {k}")
    rows = np.repeat(np.arange(n), k)
    cols = idx[:, :k].ravel()
    w = _floor(dist[:, :k]).ravel()
    if always is not None:
        ap = _check_always_pairs(always[0], n)
        aw = np.asarray(always[1], float).ravel()
        if aw.shape != (ap.shape[0],):
            raise ValueError("always-present edges need one weight per pair")
        rows, cols, w = np.concatenate([rows, ap[:, 0]]), np.concatenate([cols, ap[:, 1]]), np.concatenate([w, _floor(aw)])
        # one weight per undirected pair: the smallest
        a, b = np.minimum(rows, cols), np.maximum(rows, cols)
        order = np.lexsort((w, b, a))
        a, b, w = a[order], b[order], w[order]
        first = np.ones(a.size, bool)
        first[1:] = (a[1:] != a[:-1]) | (b[1:] != b[:-1])
        a, b, w = a[first], b[first], w[first]
        return coo_matrix((np.concatenate([w, w]), (np.concatenate([a, b]), np.concatenate([b, a]))),
                          shape=(n, n)).tocsr()
    G = coo_matrix((np.concatenate([w, w]), (np.concatenate([rows, cols]), np.concatenate([cols, rows]))),
                   shape=(n, n)).tocsr()
    # duplicates (i in j's list and j in i's) were summed: take the single weight instead
    G.sum_duplicates()
    A = coo_matrix((np.ones(2 * rows.size), (np.concatenate([rows, cols]), np.concatenate([cols, rows]))),
                   shape=(n, n)).tocsr()
    A.sum_duplicates()
    G.data /= A.data  # pairs listed from both sides carry the same distance
    return G


def sparse_min_connected_k(idx, n_components_check: bool = True, always=None) -> int:
    """Exact smallest k >= 1 whose undirected k-NN graph is connected, from a neighbour list.

    MST bottleneck over ``K_ij = min(r_i(j), r_j(i))`` on the sparse graph of
    listed pairs (module docstring); ``always`` (int pairs ``(E, 2)``, e.g. the
    first item of :func:`.sparse_st.st_always_edges`) are edges at every k, as in
    :func:`.embedding.min_connected_k`. 0 for one frame.

    Raises
    ------
    CandidateCountError
        The listed pairs leave the graph disconnected: the minimum k exceeds the
        candidate count ``m`` (the message says so; rebuild with more candidates).
    """
    idx = np.asarray(idx, np.int64)
    n, m = idx.shape
    if n <= 1:
        return 0
    rank = np.broadcast_to(np.arange(1, m + 1, dtype=float), (n, m)).ravel()
    rows = np.repeat(np.arange(n), m)
    cols = idx.ravel()
    if always is not None:  # rank 0.5: present at every k >= 1 (a sparse matrix drops zeros)
        ap = _check_always_pairs(always, n)
        rank = np.concatenate([rank, np.full(ap.shape[0], 0.5)])
        rows, cols = np.concatenate([rows, ap[:, 0]]), np.concatenate([cols, ap[:, 1]])
    # K_ij = min of the two ranks where both are listed
    i2 = np.minimum(rows, cols)
    j2 = np.maximum(rows, cols)
    key = i2 * n + j2
    order = np.lexsort((rank, key))
    key_s = key[order]
    first = np.ones(key_s.size, bool)
    first[1:] = key_s[1:] != key_s[:-1]
    sel = order[first]
    K = csr_matrix((rank[sel], (i2[sel], j2[sel])), shape=(n, n))
    ncomp = int(connected_components(K, directed=False)[0])
    if ncomp > 1:
        raise CandidateCountError(
            f"the graph of all {m} candidates per frame has {ncomp} components: the minimum connected k "
            f"is more than {m}; rebuild the neighbour lists with more candidates")
    mst = minimum_spanning_tree(K)
    return max(1, int(math.ceil(mst.data.max()))) if mst.nnz else 1


def shortest_path(graph, start: int, end: int):
    """Single-source Dijkstra re-sequencing on a sparse graph: ``(frame path, cost)``.

    :func:`.paths.shortest_path_frames` (scipy ``dijkstra(indices=start)``), which
    already runs on sparse graphs; raises :class:`.embedding.DisconnectedGraphError`
    when ``end`` is unreachable.
    """
    return shortest_path_frames(graph, start, end)


# ----------------------------------------------------------------------------- the method's graph, once


@dataclass
class SparseGraph:
    """What :func:`sparse_graph` built: the (ST-adjusted) neighbour lists ``dist``, ``idx`` ``(frames, m)``,
    ST-Isomap's always-kept edges (``None`` for Isomap), the smallest connecting k, the k used and the graph
    (symmetric CSR ``(frames, frames)``)."""

    dist: np.ndarray
    idx: np.ndarray
    always: tuple | None
    min_k: int
    k: int
    graph: csr_matrix


def _untimed(name: str, **info):
    return nullcontext(info)


def sparse_graph(neighbours, sequence, method: str = "isomap", n_candidates: int = 20, k=None,
                 st: dict | None = None, grow: bool = True, step=_untimed) -> SparseGraph:
    """The Isomap / ST-Isomap neighbourhood graph of a database from neighbour lists, the steps in order:
    list the candidates (``neighbours``), ST-Isomap's adjustment (:func:`.sparse_st.st_neighbours`) and always-kept edges
    (:func:`.sparse_st.st_always_edges`), the smallest connecting k (:func:`sparse_min_connected_k`), the k-NN graph
    (:func:`sparse_knn_graph`) at ``max(min k, k)``.

    Used by :class:`.generator.Resequencer` (``grow=True``) and the cost harness (:mod:`.cost`, ``grow=False``,
    ``step`` its recorder's timer).

    Parameters
    ----------
    neighbours : callable ``m -> (dist, idx, pair)``: the neighbour lists ``(frames, m)`` of ``m`` candidates
        per frame and the metric's pair distance ``pair(i, j) -> (E,)`` between frame index arrays ``i``, ``j``
        (``(E,)`` each; what the ST adjustment re-measures). The metric is the caller's: L2
        (:func:`l2_neighbours`) for the estimator, L2 or the Lee route (:func:`lee_neighbours`) for the harness
    sequence : (frames,) int array, the trial of every frame (:func:`concat_features`)
    method : {"isomap", "stisomap"}
    n_candidates : int, candidates listed per frame
    k : int or None, neighbours of the graph; fewer than the smallest connecting k (or None) gives that k
    st : dict, optional, ST-Isomap's parameters in frames (keyword arguments of :func:`.sparse_st.st_neighbours`); the
        always-kept edges read ``temporal_window`` and ``c_atn`` with their defaults (1, 10.0) where absent
    grow : bool
        ``True`` (the estimator): at most ``frames - 1`` candidates, doubled until the smallest connecting k
        fits in the lists, and listed again when the k used exceeds them. ``False`` (the cost harness, which
        measures one listing): ``n_candidates`` as given, a :class:`CandidateCountError` propagates
    step : callable ``(name, **info) -> context manager`` yielding a dict, optional
        Times the steps: ``"neighbours"`` (listing and ST adjustment, ``info`` ``candidates``) and ``"min_k"``
        (``info["min_k"]`` set); e.g. :meth:`animsynth.scale.Steps.step`. Called for every listing (once with
        ``grow=False``). Default: untimed.

    Returns
    -------
    SparseGraph
    """
    if method not in ("isomap", "stisomap"):
        raise ValueError(f"unknown method {method!r} (isomap, stisomap)")
    seq = np.asarray(sequence)
    n = int(seq.size)
    st = dict(st or {})

    def listed(m):
        with step("neighbours", candidates=m):
            dist, idx, pair = neighbours(m)
            always = None
            if method == "stisomap":
                dist, idx, _ = st_neighbours(dist, idx, seq, pair_distance=pair, **st)
                always = st_always_edges(seq, st.get("temporal_window", 1), st.get("c_atn", 10.0), pair)
        return dist, idx, always

    m = min(int(n_candidates), n - 1) if grow else n_candidates
    while True:
        dist, idx, always = listed(m)
        try:
            with step("min_k") as info:
                kmin = sparse_min_connected_k(idx, always=None if always is None else always[0])
                info["min_k"] = kmin
            break
        except CandidateCountError:
            if not grow or m >= n - 1:
                raise
            m = min(2 * m, n - 1)
    kk = max(int(kmin), int(k or 0))
    if grow and kk > idx.shape[1]:
        dist, idx, _ = listed(min(kk, n - 1))
    return SparseGraph(dist, idx, always, int(kmin), kk, sparse_knn_graph(dist, idx, kk, always=always))


__all__ += ["DisconnectedGraphError"]
