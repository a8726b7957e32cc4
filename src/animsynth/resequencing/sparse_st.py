"""ST-Isomap on neighbour lists: Jenkins & Mataric's adjustment without an N x N matrix.

:func:`st_neighbours` applies the adjustment (:func:`.embedding.spatio_temporal_distances`) to a neighbour
list (:mod:`.sparse`: rows of a frame's nearest other frames) of a database of several sequences: temporal
neighbours (same sequence, ``|i - j| <= temporal_window``) are added to the lists and divided by ``c_atn``;
common temporal neighbours are found among the candidates (non-trivial, within the frame's reach, persistent
one frame earlier and later) and divided by ``c_ctn``. Pairs not in a list keep their (larger) distance and are
never adjusted, so the first ``m`` entries of the re-sorted lists are the exact adjusted neighbours. Sequence
boundaries count as the ends of a sequence. As in the dense version (``always=`` of
:func:`.embedding.knn_graph`), the adjacent temporal neighbours are edges whatever k: :func:`st_always_edges`
gives them, and :func:`.sparse.sparse_min_connected_k` / :func:`.sparse.sparse_knn_graph` take them as
``always=`` (so one sequence alone has minimum k 1).
"""

from __future__ import annotations

import numpy as np

from .embedding import check_st_params

__all__ = ["st_always_edges", "st_neighbours", "temporal_pairs"]


def _check_sequence(sequence, n: int | None = None) -> np.ndarray:
    seq = np.asarray(sequence, np.int64)
    if seq.ndim != 1 or (n is not None and seq.shape != (n,)) or np.any(np.diff(seq) < 0):
        raise ValueError("sequence must be (frames,) with each sequence's frames contiguous")
    return seq


def temporal_pairs(sequence, temporal_window: int = 1) -> np.ndarray:
    """Adjacent temporal neighbours of a database: frame pairs ``(i, j)``, ``i < j``,
    of one sequence with ``j - i <= temporal_window``. Int array ``(E, 2)``."""
    seq = _check_sequence(sequence)
    frame = np.arange(seq.size)
    stop = np.searchsorted(seq, seq, side="right")
    out = [np.zeros((0, 2), np.int64)]
    for lag in range(1, int(temporal_window) + 1):
        a = frame[frame + lag < stop]
        out.append(np.stack([a, a + lag], 1))
    return np.concatenate(out)


def st_always_edges(sequence, temporal_window: int = 1, c_atn: float = 10.0, pair_distance=None):
    """ST-Isomap's always-present edges: the adjacent temporal neighbours
    (:func:`temporal_pairs`) weighted by their base distance divided by ``c_atn``,
    the same weight :func:`st_neighbours` lists them with.

    Returns ``(pairs (E, 2), weights (E,))`` for ``always=`` of
    :func:`.sparse.sparse_knn_graph` (and ``pairs`` for :func:`.sparse.sparse_min_connected_k`).
    """
    if pair_distance is None:
        raise ValueError("pair_distance is required (the base metric for arbitrary frame pairs)")
    if not c_atn > 0:
        raise ValueError(f"c_atn must be > 0, got {c_atn!r}")
    p = temporal_pairs(sequence, temporal_window)
    w = pair_distance(p[:, 0], p[:, 1]) / float(c_atn) if p.size else np.zeros(0)
    return p, np.asarray(w, float)


def st_neighbours(dist, idx, sequence, temporal_window: int = 1, c_atn: float = 10.0, c_ctn: float = 10.0,
                  ctn_neighbors: int = 4, ctn_min_gap: int = 30, ctn_tolerance: int = 2, ctn_reach: int = 6,
                  pair_distance=None):
    """ST-Isomap's adjustment (Jenkins & Mataric 2004) on a neighbour list of a database.

    The rules are those of :func:`.embedding.spatio_temporal_distances`, with
    the non-trivial neighbours of a frame searched among its candidates, and
    frames of different sequences never temporal and always non-trivial.

    Parameters
    ----------
    dist, idx : the neighbour list ``(frames, m)`` of the base metric
    sequence : int array (frames,), sequence id of each frame (frames of one
        sequence contiguous and in time order)
    pair_distance : callable ``(i, j) -> distances`` of the base metric for
        frame-index arrays (needed for the temporal neighbours and the reach
        test; e.g. ``lambda i, j: np.linalg.norm(X[i] - X[j], axis=1)`` for L2)
    other parameters : as :func:`.embedding.spatio_temporal_distances`

    Returns
    -------
    dist_st, idx_st : arrays ``(frames, m)``, the exact adjusted neighbour list
    n_ctn : int, number of common-temporal-neighbour pairs (each counted once)
    """
    dist = np.asarray(dist, float)
    idx = np.asarray(idx, np.int64)
    seq = _check_sequence(sequence, idx.shape[0])
    check_st_params(c_atn, c_ctn, temporal_window, ctn_neighbors, ctn_min_gap, ctn_tolerance, ctn_reach)
    if pair_distance is None:
        raise ValueError("pair_distance is required (the base metric for arbitrary frame pairs)")
    if ctn_neighbors > 0 and idx.shape[0] > 2:
        M = _ctn_candidates(dist, idx, seq, pair_distance, ctn_neighbors, ctn_min_gap, ctn_reach)
        pairs = _persistent_pairs(M, seq, ctn_min_gap, ctn_tolerance)
    else:
        pairs = np.zeros((0, 2), np.int64)
    # temporal neighbours: every same-sequence pair within the window
    tp = temporal_pairs(seq, temporal_window)
    ti = np.concatenate([tp[:, 0], tp[:, 1]])
    tj = np.concatenate([tp[:, 1], tp[:, 0]])
    td = pair_distance(ti, tj) / c_atn if ti.size else np.zeros(0)
    dist_st, idx_st = _merge_adjusted(dist, idx, (ti, tj, td), pairs, pair_distance, c_ctn)
    return dist_st, idx_st, int(pairs.shape[0])


def _seq_bounds(seq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each frame's sequence start and one past its sequence's last frame."""
    return np.searchsorted(seq, seq, side="left"), np.searchsorted(seq, seq, side="right")


def _same_seq_lag(seq: np.ndarray, a, b) -> np.ndarray:
    """|a - b| for frames of one sequence, a huge lag across sequences."""
    return np.where(seq[a] == seq[b], np.abs(a - b), np.iinfo(np.int64).max // 4)


def _ctn_candidates(dist, idx, seq, pair_distance, ctn_neighbors: int, ctn_min_gap: int, ctn_reach: int):
    """Each frame's non-trivial neighbours among its candidates, nearest first: ``(frames, ctn_neighbors)``
    frame indices, -1 where fewer were found. A candidate counts when it is more than ``ctn_min_gap`` frames away
    (or in another sequence), closer than the frame's reach (its distance ``ctn_reach`` frames back or ahead), and
    not in the pass of one already kept."""
    n, m = idx.shape
    frame = np.arange(n)
    start, stop = _seq_bounds(seq)
    M = np.full((n, max(ctn_neighbors, 0)), -1, np.int64)
    back = np.full(n, np.inf)
    fwd = np.full(n, np.inf)
    hb = frame - ctn_reach >= start
    hf = frame + ctn_reach < stop
    back[hb] = pair_distance(frame[hb], frame[hb] - ctn_reach)
    fwd[hf] = pair_distance(frame[hf], frame[hf] + ctn_reach)
    reach = np.minimum(back, fwd)
    filled = np.zeros(n, np.int64)
    for t in range(m):
        j = idx[:, t]
        ok = (_same_seq_lag(seq, frame, j) > ctn_min_gap) & (dist[:, t] < reach) & (filled < ctn_neighbors)
        for s in range(ctn_neighbors):  # a pass already represented is trivial
            a = M[:, s]
            ok &= ~((a >= 0) & (_same_seq_lag(seq, a, j) <= ctn_min_gap))
        rows = np.flatnonzero(ok)
        M[rows, filled[rows]] = j[rows]
        filled[rows] += 1
    return M


def _persistent_pairs(M, seq, ctn_min_gap: int, ctn_tolerance: int) -> np.ndarray:
    """The common temporal neighbours: pairs ``(i, j)``, ``i < j``, of :func:`_ctn_candidates` ``M`` that persist
    one frame earlier and later (within ``ctn_tolerance`` frames), where those frames exist; ``(P, 2)``."""
    start, stop = _seq_bounds(seq)
    ci, cs = np.nonzero(M >= 0)
    cj = M[ci, cs]

    def follows(src, dst, has):
        res = np.ones(src.size, bool)
        h = has
        near = np.abs(M[src[h]] - dst[h][:, None]) <= ctn_tolerance
        near &= M[src[h]] >= 0
        near &= seq[M[src[h]].clip(0)] == seq[dst[h]][:, None]
        res[h] = near.any(axis=1)
        return res

    has_prev = (ci - 1 >= start[ci]) & (cj - 1 >= start[cj])
    has_next = (ci + 1 < stop[ci]) & (cj + 1 < stop[cj])
    keep = follows(ci - 1, cj - 1, has_prev) & follows(ci + 1, cj + 1, has_next)
    ci, cj = ci[keep], cj[keep]
    pairs = np.unique(np.stack([np.minimum(ci, cj), np.maximum(ci, cj)], 1), axis=0)
    return pairs[_same_seq_lag(seq, pairs[:, 0], pairs[:, 1]) > ctn_min_gap]


def _merge_adjusted(dist, idx, temporal, pairs, pair_distance, c_ctn: float):
    """Merge, per row, the listed pairs (base distance) with the temporal ones (``temporal`` = both directions'
    rows, columns and adjusted distances) and the common temporal neighbours ``pairs`` (base distance /
    ``c_ctn``); the adjusted value wins over the listed one; each row sorted by (value, column), its first ``m``
    kept: ``(dist_st, idx_st)``."""
    n, m = idx.shape
    ti, tj, td = temporal
    ci = np.concatenate([pairs[:, 0], pairs[:, 1]])
    cj = np.concatenate([pairs[:, 1], pairs[:, 0]])
    rows = np.concatenate([np.repeat(np.arange(n), m), ti, ci])
    cols = np.concatenate([idx.ravel(), tj, cj])
    vals = np.concatenate([dist.ravel(), td, np.zeros(ci.size)])
    kind = np.concatenate([np.zeros(n * m, np.int8), np.ones(ti.size, np.int8), np.full(ci.size, 2, np.int8)])
    # a CTN pair's value: its base distance (from the list, or computed) / c_ctn
    if ci.size:
        vals[kind == 2] = pair_distance(ci, cj) / c_ctn
    # one entry per (row, col): the adjusted value wins over the listed one (it is smaller or equal)
    order = np.lexsort((-kind, cols, rows))
    r_s, c_s = rows[order], cols[order]
    first = np.ones(r_s.size, bool)
    first[1:] = (r_s[1:] != r_s[:-1]) | (c_s[1:] != c_s[:-1])
    sel = order[first]
    rows, cols, vals = rows[sel], cols[sel], vals[sel]
    # per row: sort by (value, col) and keep the first m
    order = np.lexsort((cols, vals, rows))
    rows, cols, vals = rows[order], cols[order], vals[order]
    counts = np.bincount(rows, minlength=n)
    if counts.min() < m:  # every row keeps its m listed columns, so this is a bug
        raise RuntimeError("a frame has fewer adjusted candidates than the list width")
    offs = np.concatenate([[0], np.cumsum(counts)[:-1]])
    take = (offs[:, None] + np.arange(m)[None, :]).ravel()
    return vals[take].reshape(n, m), cols[take].reshape(n, m)
