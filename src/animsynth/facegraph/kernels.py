"""Compiled inner loops of graph creation (numba), with numpy's exact arithmetic.

Algorithm 1 (a walk pose by pose), the merge of sample graphs (node by node,
each decision changing the state the next one sees) and the threshold searches
around them are sequential; numpy can only vectorise them across samples,
which costs many small array operations per step. No library offers these
loops, so they are written here once (the merge loop in :mod:`.merge_kernels`),
compiled with ``numba.njit(cache=True)`` (the first process compiles and caches
them; later processes load the cache).

**Same results, bit for bit.** The loops reproduce the floating-point
operations of the numpy code they replace, in the same order:

* ``np.add.reduce`` along a contiguous axis is numpy's pairwise summation
  (:func:`pw_sum`: eight accumulators from eight elements on, added from a
  zero start); along a strided axis it adds element by element;
* a ``(n, 2) @ (2, 2)`` product (BLAS ``gemm``, OpenBLAS Haswell kernel) is
  ``fma(a1, b1, a0 * b0)``; a ``(2, 2) @ (2,)`` product (``gemv``) is
  ``fma(a0, b0, a1 * b1)`` (:func:`fma`, the LLVM intrinsic); these were
  checked against numpy's results on this build and are covered by
  ``tests/test_facegraph_compiled.py`` (compiled kernels against a numpy
  route in the same process; another BLAS kernel could round differently);
* ``math.hypot`` is CPython's correctly rounded algorithm (:func:`py_hypot`),
  not the C library's.

Products and sums are never contracted into fused operations by numba unless
``fastmath`` is set (it is not).
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit
from numba.core import cgutils, types
from numba.extending import intrinsic


@intrinsic
def _fma_intrinsic(typingctx, a, b, c):
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.DoubleType(), [ir.DoubleType()] * 3)
        fn = cgutils.get_or_insert_function(builder.module, fnty, "llvm.fma.f64")
        return builder.call(fn, args)

    return sig, codegen


@njit(cache=True)
def fma(a, b, c):
    """``a * b + c`` with one rounding."""
    return _fma_intrinsic(a, b, c)


#: Most elements :func:`pw_sum` adds (three levels of numpy's block halving above 128).
MAX_SUM = 480
#: Most landmarks of one region (a 2-D dot product sums 2 values per landmark).
MAX_REGION_LANDMARKS = MAX_SUM // 2


@njit(cache=True)
def pw_sum(a, n):
    """``np.add.reduce(a[:n])`` of a contiguous float64 array, in numpy's order.

    Parameters
    ----------
    a : ndarray (>= n,)
    n : int, at most 480 (three levels of numpy's halving of blocks above 128)
    """
    if n <= 128:
        return 0.0 + _pw_block(a, 0, n)
    return 0.0 + _pw_split1(a, 0, n)


@njit(cache=True)
def _pw_block(a, lo, n):
    """numpy's pairwise_sum for n <= 128 (no recursion)."""
    if n < 8:
        res = -0.0
        for i in range(n):
            res += a[lo + i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    stop = n - (n % 8)
    while i < stop:
        r0 += a[lo + i]
        r1 += a[lo + i + 1]
        r2 += a[lo + i + 2]
        r3 += a[lo + i + 3]
        r4 += a[lo + i + 4]
        r5 += a[lo + i + 5]
        r6 += a[lo + i + 6]
        r7 += a[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True)
def _pw_split2(a, lo, n):
    if n <= 128:
        return _pw_block(a, lo, n)
    n2 = n // 2
    n2 -= n2 % 8
    return _pw_block(a, lo, n2) + _pw_block(a, lo + n2, n - n2)


@njit(cache=True)
def _pw_split1(a, lo, n):
    if n > MAX_SUM:
        raise ValueError("pw_sum: more than 480 elements")
    n2 = n // 2
    n2 -= n2 % 8
    return _pw_split2(a, lo, n2) + _pw_split2(a, lo + n2, n - n2)


@njit(cache=True)
def py_hypot(x, y):
    """``math.hypot(x, y)`` of CPython (>= 3.10): correctly rounded, unlike libm's.

    Scaled squares are summed exactly (products split with an fma, compensated
    sums), the square root is corrected by one Newton step.
    """
    x, y = abs(x), abs(y)
    mx = max(x, y)
    if math.isinf(mx):
        return mx
    if math.isnan(x) or math.isnan(y):
        return math.nan
    if mx == 0.0:
        return mx
    m, e = math.frexp(mx)
    if e < -1023:  # subnormal: rescale (never happens for the poses here)
        d = 2.2250738585072014e-308
        return d * py_hypot(x / d, y / d)
    scale = math.ldexp(1.0, -e)
    csum, frac1, frac2 = 1.0, 0.0, 0.0
    for k in range(2):
        v = (x if k == 0 else y) * scale
        hi = v * v
        lo = fma(v, v, -hi)
        s = csum + hi
        frac2 += (csum - s) + hi
        csum = s
        frac1 += lo
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    hi = -h * h
    lo = fma(-h, h, -hi)
    s = csum + hi
    frac2 += (csum - s) + hi
    csum = s
    frac1 += lo
    v = csum - 1.0 + (frac1 + frac2)
    h += v / (2.0 * h)
    return h / scale


# ---------------------------------------------------------------------------
# Algorithm 1
@njit(cache=True)
def _first_node(X, U, OK, mean, cnt, ent_u, ent_ok, ent_n):
    """Node 0 of a walk: the first pose, with its velocity as the one entering velocity."""
    for l in range(X.shape[1]):
        mean[0, l, 0] = X[0, l, 0]
        mean[0, l, 1] = X[0, l, 1]
        ent_u[0, 0, l, 0] = U[0, l, 0]
        ent_u[0, 0, l, 1] = U[0, l, 1]
        ent_ok[0, 0, l] = OK[0, l]
    cnt[0] = 1.0
    ent_n[0] = 1


@njit(cache=True)
def alg1_walk(X, U, OK, n, thr, lam, Q, out, mean, cnt, ent_u, ent_ok, ent_n, sc, dist, prod):
    """Algorithm 1 for one sample of one region; node indices written to ``out``.

    Parameters
    ----------
    X, U : ndarray (T, L, 2)
        Poses and unit velocities (reduced landmarks, zero-padded to ``L``).
    OK : ndarray (T, L)
        1.0 where the velocity has a direction.
    n : int
        Poses of the sample.
    thr, lam : float
        Creation threshold, lambda of eq. 3.
    Q : int
        Entering velocities kept per node.
    out : int ndarray (>= n,)
    mean, cnt, ent_u, ent_ok, ent_n, sc, dist, prod : work arrays
        (T, L, 2), (T,), (T, Q, L, 2), (T, Q, L), (T,), (T,), (L,), (L,).

    Every node is scored (eq. 3, minimum over its entering velocities); the
    current node wins ties, then the lowest index. This is the result of the
    pruned vectorised walk it replaces (which scores the nearest nodes and
    falls back to all of them when a farther node could win).
    """
    L = X.shape[1]
    _first_node(X, U, OK, mean, cnt, ent_u, ent_ok, ent_n)
    nn = 1
    cur = 0
    out[0] = 0
    for t in range(1, n):
        for k in range(nn):
            for l in range(L):
                d0 = X[t, l, 0] - mean[k, l, 0]
                d1 = X[t, l, 1] - mean[k, l, 1]
                dist[l] = math.sqrt(d0 * d0 + d1 * d1)
            sd = pw_sum(dist, L)
            best = np.inf
            for q in range(ent_n[k]):
                for l in range(L):
                    c = abs(U[t, l, 0] * ent_u[k, q, l, 0] + U[t, l, 1] * ent_u[k, q, l, 1])
                    vi = (1.0 - min(c, 1.0)) * ent_ok[k, q, l] * OK[t, l]
                    prod[l] = dist[l] * vi
                v = sd + lam * pw_sum(prod, L)
                if v < best:
                    best = v
            sc[k] = best
        bj = cur
        bs = sc[cur]
        for k in range(nn):
            if sc[k] < bs:
                bs = sc[k]
                bj = k
        if bs <= thr:
            tgt = bj
        else:
            tgt = nn
            nn += 1
            cnt[tgt] = 0.0
            ent_n[tgt] = 0
            for l in range(L):
                mean[tgt, l, 0] = 0.0
                mean[tgt, l, 1] = 0.0
        c = cnt[tgt] + 1.0
        for l in range(L):
            for j in range(2):
                mean[tgt, l, j] = mean[tgt, l, j] + (X[t, l, j] - mean[tgt, l, j]) / c
        cnt[tgt] = c
        if tgt != cur and ent_n[tgt] < Q:
            q = ent_n[tgt]
            for l in range(L):
                ent_u[tgt, q, l, 0] = U[t, l, 0]
                ent_u[tgt, q, l, 1] = U[t, l, 1]
                ent_ok[tgt, q, l] = OK[t, l]
            ent_n[tgt] = q + 1
        cur = tgt
        out[t] = tgt
    return nn


@njit(cache=True)
def alg1_all(X, U, OK, lengths, thr, lam, Q, out):
    """Algorithm 1 for every candidate set, region and sample.

    Parameters
    ----------
    X, U : ndarray (R, S, T, L, 2); OK : ndarray (R, S, T, L)
    lengths : int ndarray (S,)
    thr : ndarray (B, R, S)
    out : int ndarray (B, R, S, T), filled with -1 beyond each sample's end
    """
    B, R, S = thr.shape
    T, L = X.shape[2], X.shape[3]
    mean = np.zeros((T, L, 2))
    cnt = np.zeros(T)
    ent_u = np.zeros((T, Q, L, 2))
    ent_ok = np.zeros((T, Q, L))
    ent_n = np.zeros(T, np.int64)
    sc = np.zeros(T)
    dist = np.zeros(L)
    prod = np.zeros(L)
    for b in range(B):
        for r in range(R):
            for s in range(S):
                n = lengths[s]
                for t in range(n, T):
                    out[b, r, s, t] = -1
                if n > 0:
                    alg1_walk(X[r, s], U[r, s], OK[r, s], n, thr[b, r, s], lam, Q, out[b, r, s],
                              mean, cnt, ent_u, ent_ok, ent_n, sc, dist, prod)


# ---------------------------------------------------------------------------
# node-to-node similarities
@njit(cache=True)
def edge_weights(edges, Dred, vin_mean, order, lo, hi, lam, eps):
    """Node-to-node eq. 3 of every edge: minimum over the incoming-velocity pairs.

    Parameters
    ----------
    edges : int ndarray (E, 2)
    Dred : ndarray (N, Lr, 2), mean reduced displacements
    vin_mean : ndarray (V, Lr, 2), incoming-edge velocities
    order, lo, hi : int ndarrays
        ``order[lo[f]:hi[f]]`` are the incoming edges of node ``f``.

    Returns
    -------
    ndarray (E,)
    """
    E = edges.shape[0]
    Lr = Dred.shape[1]
    dist = np.empty(Lr)
    prod = np.empty(Lr)
    w = np.full(E, np.inf)
    for k in range(E):
        a, b = edges[k, 0], edges[k, 1]
        for l in range(Lr):
            d0 = Dred[a, l, 0] - Dred[b, l, 0]
            d1 = Dred[a, l, 1] - Dred[b, l, 1]
            dist[l] = math.sqrt(d0 * d0 + d1 * d1)
        for i in range(lo[a], hi[a]):
            ia = order[i]
            for j in range(lo[b], hi[b]):
                ib = order[j]
                for l in range(Lr):
                    va0, va1 = vin_mean[ia, l, 0], vin_mean[ia, l, 1]
                    vb0, vb1 = vin_mean[ib, l, 0], vin_mean[ib, l, 1]
                    na = math.sqrt(va0 * va0 + va1 * va1)
                    nb = math.sqrt(vb0 * vb0 + vb1 * vb1)
                    if na > eps and nb > eps:
                        c = (va0 * vb0 + va1 * vb1) / (na * nb)
                    else:
                        c = 1.0
                    prod[l] = dist[l] * (1.0 + lam * (1.0 - min(abs(c), 1.0)))
                v = pw_sum(prod, Lr)
                if v < w[k]:
                    w[k] = v
    return w


@njit(cache=True)
def nearest_other_sample(D, sample, q):
    """For each query node, the smallest landmark-distance sum to a node of another sample.

    Parameters
    ----------
    D : ndarray (G, L, 2), reduced node displacements
    sample : int ndarray (G,)
    q : int ndarray (k,), query nodes

    Returns
    -------
    ndarray (k,), ``inf`` where no other sample has nodes. The sum runs over
    landmarks in order (as the pruned numpy search it replaces did).
    """
    G, L = D.shape[0], D.shape[1]
    out = np.full(q.shape[0], np.inf)
    for i in range(q.shape[0]):
        a = q[i]
        best = np.inf
        for j in range(G):
            if sample[j] == sample[a]:
                continue
            tot = 0.0
            for l in range(L):
                d0 = D[j, l, 0] - D[a, l, 0]
                d1 = D[j, l, 1] - D[a, l, 1]
                dl = math.sqrt(d0 * d0 + d1 * d1)
                tot = dl if l == 0 else tot + dl
                if tot > best:
                    break
            if tot < best:
                best = tot
        out[i] = best
    return out
