"""Compiled per-step loops for field following (numba).

Why by hand: a path's next point depends on the field at its current point,
so the steps of one path cannot be vectorised, and the per-call overhead of
numpy/scipy (microseconds per call, several calls per step) dominates a step
that is a few dozen floating-point operations. scipy has no warm-started
point location (``Delaunay.find_simplex`` searches afresh for every point)
and no incremental k-NN query; neither can be called from compiled code. So
the whole multi-step loop of every path runs here, and only the rare steps
that need the reference machinery return to Python
(:func:`animsynth.simplicial.path.follow_batch` drives this).

Per path and step:

Delaunay (1/D^2 weights, full-rank triangulation)
    Walk from the simplex the path was in one step earlier across the face
    opposite the most negative barycentric coordinate (``Delaunay.transform``
    and ``Delaunay.neighbors``), at most ``max_walk`` faces. A point found
    *strictly* inside a simplex (every coordinate > ``HINT_EPS``) is in no
    other simplex, so that is the simplex ``find_simplex`` returns. A walk that
    crosses a hull facet, with the point outside a hull facet by clearly more
    than the hit tolerance (the test :meth:`SafeDelaunay.find` applies), is
    outside: k-NN fallback, flagged. Anything else (faces, vertices, the
    tolerance band of the hull, degenerate simplices, long walks) is
    returned to Python for the reference evaluation.
k-NN (and the outside-hull fallback)
    Certified candidate lists: every training point ``a`` carries its L
    nearest training points by increasing distance (one ``cKDTree.query`` for
    all of them when the tables are built; L = 16 k by default). A path keeps
    an anchor ``a`` (the training point nearest to it one step earlier). At
    ``x`` with ``e = |x - a|``, a point at distance ``D_a`` from ``a`` is at
    least ``D_a - e`` from ``x`` (triangle inequality), so the scan of a's
    list stops, certified, at the first listed point with ``D_a - e`` above
    the k-th distance found so far (with a relative margin of 1e-12 and an
    absolute one of 1e-12 times the bounding-box diagonal for rounding); no
    later point, listed or not, can be among the k nearest. Near the data
    this reads about twice k points. An uncertified scan moves the anchor to
    the nearest point it found and tries again; if that does not help, the
    exact k nearest are found by brute force over all training points when
    ``brute`` is set (a few microseconds for a fold of ~1,300 points, less
    than one return to Python), else the step goes to Python. Exact distance
    ties at the k-th neighbour are broken by scan order here and by the
    tree's order in ``cKDTree.query``; they have measure zero for real data
    and change only which of two equidistant points is used.

Weights are ``m / D^2`` (``m`` = merged duplicates) with the hit rule of
:meth:`VectorField.__call__`; summation order and the single normalising
division differ from it, so a step agrees with the reference to float
rounding (about 1e-16 relative; along a path such differences can grow like
any perturbation of the field's flow).

``status[p]`` is 0 when path p is finished and 1 when the step at ``t[p]``
needs the reference evaluation.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .geometry import HINT_EPS

#: certification margin (relative) of the candidate lists
CERT_MARGIN = 1e-12


@njit(cache=True, inline="always")
def _locate(x, s, TT, nbr, max_walk):
    """Walk from simplex ``s`` toward ``x``: (simplex, code 0 inside / 1 crossed a hull facet / 2 give up)."""
    d = x.shape[0]
    for _ in range(max_walk):
        bsum = 0.0
        bmin = np.inf
        jmin = -1
        nan = False
        for j in range(d):
            acc = 0.0
            for i in range(d):
                acc += TT[s, j, i] * (x[i] - TT[s, d, i])
            if acc != acc:
                nan = True
            bsum += acc
            if acc < bmin:
                bmin = acc
                jmin = j
        last = 1.0 - bsum
        if nan or last != last:
            return s, 2
        if last < bmin:
            bmin = last
            jmin = d
        if bmin > HINT_EPS:
            return s, 0
        sn = nbr[s, jmin]
        if sn < 0:
            return s, 1
        s = sn
    return s, 2


@njit(cache=True, inline="always")
def _clearly_outside(x, A, c, lim):
    """True when ``x`` is beyond some hull facet by more than ``lim``."""
    for f in range(A.shape[0]):
        acc = c[f]
        for i in range(x.shape[0]):
            acc += A[f, i] * x[i]
        if acc > lim:
            return True
    return False


@njit(cache=True, inline="always")
def _idw(out, dist, idx, n, V, f, cnt, hit_tol):
    """``out = sum_j w_j V[f, idx_j] / sum_j w_j`` with ``w = m / D^2``, or hits only (weighted by m)."""
    anyhit = False
    for j in range(n):
        if dist[j] <= hit_tol:
            anyhit = True
    for i in range(out.shape[0]):
        out[i] = 0.0
    wsum = 0.0
    for j in range(n):
        if anyhit:
            w = cnt[idx[j]] if dist[j] <= hit_tol else 0.0
        else:
            w = cnt[idx[j]] / (dist[j] * dist[j])
        wsum += w
        q = idx[j]
        for i in range(out.shape[0]):
            out[i] += w * V[f, q, i]
    for i in range(out.shape[0]):
        out[i] /= wsum


@njit(cache=True, inline="always")
def _listed_dist2(x, nc, a, m, d):
    """Squared distance from ``x`` (d,) to the ``m``-th listed point of anchor ``a`` (``nc`` (P, L, d))."""
    d2 = 0.0
    for i in range(d):
        c = nc[a, m, i] - x[i]
        d2 += c * c
    return d2


@njit(cache=True, inline="always")
def _farthest(bd, k):
    """Index of the largest of ``bd[:k]`` (the first one on ties)."""
    jm = 0
    for j in range(1, k):
        if bd[j] > bd[jm]:
            jm = j
    return jm


@njit(cache=True, inline="always")
def _knn_list(x, a, k, nl, nc, dl, Rend, eps, pu, bd, bi):
    """k nearest of x among the listed neighbours of training point ``a`` (into bd, bi; nearest first).

    The list holds the nearest training points of ``a`` (indices ``nl``,
    coordinates ``nc``, stored with the list so that the scan reads
    contiguous memory) by increasing distance ``dl``. Once a listed distance minus ``e = |x - a|`` exceeds the
    current k-th distance, no later point (listed or not) can enter the k
    nearest, so the scan stops there, certified. At the end of the list the
    same test with ``Rend`` (distance of the last listed point; ``inf`` when
    every point is listed) decides. Returns True when certified exact. The
    k are kept unsorted (the farthest is replaced; cheaper than keeping them
    sorted), with the nearest moved to the front.
    """
    d = x.shape[0]
    e2 = 0.0
    for i in range(d):
        c = x[i] - pu[a, i]
        e2 += c * c
    e = np.sqrt(e2)
    L = nl.shape[1]
    for m in range(k):  # k <= L: the first k listed points
        q = nl[a, m]
        d2 = _listed_dist2(x, nc, a, m, d)
        bd[m] = d2
        bi[m] = q
    jm = _farthest(bd, k)
    lim = np.sqrt(bd[jm]) * (1.0 + CERT_MARGIN) + eps
    ok = False
    m = k
    while m < L:
        if dl[a, m] - e > lim:
            ok = True
            break
        q = nl[a, m]
        d2 = _listed_dist2(x, nc, a, m, d)
        if d2 < bd[jm]:
            bd[jm] = d2
            bi[jm] = q
            jm = _farthest(bd, k)
            lim = np.sqrt(bd[jm]) * (1.0 + CERT_MARGIN) + eps
        m += 1
    if not ok:
        ok = Rend[a] - e > lim
    j0 = 0
    for j in range(1, k):
        if bd[j] < bd[j0]:
            j0 = j
    d2, q = bd[j0], bi[j0]
    bd[j0], bi[j0] = bd[0], bi[0]
    bd[0], bi[0] = d2, q
    for j in range(k):
        bd[j] = np.sqrt(bd[j])
    return ok


@njit(cache=True)
def _knn_brute(x, k, pu, bd, bi):
    """Exact k nearest of x over all training points (sorted into bd, bi)."""
    d = x.shape[0]
    for j in range(k):
        bd[j] = np.inf
        bi[j] = -1
    for q in range(pu.shape[0]):
        d2 = 0.0
        for i in range(d):
            e = pu[q, i] - x[i]
            d2 += e * e
        if d2 < bd[k - 1]:  # insert into the sorted top k (inline: a call per point costs more than the work)
            j = k - 1
            while j > 0 and bd[j - 1] > d2:
                bd[j] = bd[j - 1]
                bi[j] = bi[j - 1]
                j -= 1
            bd[j] = d2
            bi[j] = q
    for j in range(k):
        bd[j] = np.sqrt(bd[j])


@njit(cache=True)
def _advance_path(p, X, pts, fb, t, s, anchor, status, steps, which, meth, kf, V, pu, cnt, hit_tol,
                  TT, simp, nbr, hullA, hullc, hull_lim, nl, nc, dl, Rend, eps, brute, max_walk):
    """Advance path p from step ``t[p]`` until it is finished or needs Python (``status[p] = 1``)."""
    d = X.shape[1]
    f = which[p]
    k = kf[f]
    bd = np.empty(max(k, d + 1))
    bi = np.empty(max(k, d + 1), np.int64)
    v = np.empty(d)
    x = X[p]
    status[p] = 0
    while t[p] < steps:
        for i in range(d):
            if not np.isfinite(x[i]):
                status[p] = 1
                return
        use_knn = meth[f] == 0
        isfb = False
        if not use_knn:
            code = 3
            sn = -1
            if s[p] >= 0:
                sn, code = _locate(x, s[p], TT, nbr, max_walk)
                s[p] = sn
            if code == 0:
                for j in range(d + 1):
                    q = simp[sn, j]
                    d2 = 0.0
                    for i in range(d):
                        e = pu[q, i] - x[i]
                        d2 += e * e
                    bd[j] = np.sqrt(d2)
                    bi[j] = q
                _idw(v, bd, bi, d + 1, V, f, cnt, hit_tol)
            elif code != 2 and _clearly_outside(x, hullA, hullc, hull_lim):
                use_knn = True
                isfb = True
            else:
                status[p] = 1
                return
        if use_knn:
            ok = False
            a = anchor[p]
            for _ in range(8):  # move the anchor to the nearest point found while that helps
                if a < 0:
                    break
                ok = _knn_list(x, a, k, nl, nc, dl, Rend, eps, pu, bd, bi)
                if ok or bi[0] == a:
                    break
                a = bi[0]
            if not ok:
                if not brute:
                    status[p] = 1
                    return
                _knn_brute(x, k, pu, bd, bi)
            anchor[p] = bi[0]
            _idw(v, bd, bi, k, V, f, cnt, hit_tol)
        tt = t[p]
        for i in range(d):
            x[i] += v[i]
            pts[tt + 1, p, i] = x[i]
        fb[tt, p] = isfb
        t[p] = tt + 1


@njit(cache=True)
def advance_serial(X, pts, fb, t, s, anchor, status, steps, which, meth, kf, V, pu, cnt, hit_tol,
                   TT, simp, nbr, hullA, hullc, hull_lim, nl, nc, dl, Rend, eps, brute, max_walk):
    """Advance every path until it is finished or needs Python, one path after the other (few paths).

    Parameters (P paths, d dimensions, F fields, u training points, S simplices, L listed neighbours)
    ----------
    X : float (P, d), current points (updated)
    pts : float (steps+1, P, d), path points (row 0 = starts; filled)
    fb : bool (steps, P), fallback flags (filled)
    t : int (P,), next step of every path (updated)
    s : int (P,), last simplex of every path, -1 none (updated)
    anchor : int (P,), k-NN anchor (training point) of every path, -1 none (updated)
    status : int (P,), 0 finished / 1 the step ``t[p]`` needs the reference (written)
    steps : int
    which : int (P,), field of every path
    meth : int (F,), 0 k-NN / 1 Delaunay (1/D^2)
    kf : int (F,), k of every field (also its outside-hull fallback)
    V : float (F, u, d), vectors; pu : float (u, d), points; cnt : float (u,), multiplicities
    hit_tol : float
    TT : float (S, d+1, d), barycentric transforms; simp, nbr : int (S, d+1), vertices, neighbours
    hullA : float (h, d), hullc : float (h,), hull facets ``A x + c <= 0``; hull_lim : float
    nl : int (u, L), nc : float (u, L, d), dl : float (u, L), Rend : float (u,), eps : float
        Neighbour lists of the training points (see the module docstring).
    brute : bool, max_walk : int
    """
    for p in range(X.shape[0]):
        if t[p] < steps:
            _advance_path(p, X, pts, fb, t, s, anchor, status, steps, which, meth, kf, V, pu, cnt, hit_tol,
                          TT, simp, nbr, hullA, hullc, hull_lim, nl, nc, dl, Rend, eps, brute, max_walk)
        else:
            status[p] = 0


@njit(cache=True, parallel=True)
def advance_parallel(X, pts, fb, t, s, anchor, status, steps, which, meth, kf, V, pu, cnt, hit_tol,
                     TT, simp, nbr, hullA, hullc, hull_lim, nl, nc, dl, Rend, eps, brute, max_walk):
    """:func:`advance_serial` with the paths spread over numba's threads (many paths)."""
    for p in prange(X.shape[0]):
        if t[p] < steps:
            _advance_path(p, X, pts, fb, t, s, anchor, status, steps, which, meth, kf, V, pu, cnt, hit_tol,
                          TT, simp, nbr, hullA, hullc, hull_lim, nl, nc, dl, Rend, eps, brute, max_walk)
        else:
            status[p] = 0
