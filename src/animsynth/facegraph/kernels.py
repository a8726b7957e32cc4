"""Compiled inner loops of graph creation (numba), with numpy's exact arithmetic.

Algorithm 1 (a walk pose by pose), the merge of sample graphs (node by node,
each decision changing the state the next one sees) and the threshold searches
around them are sequential; numpy can only vectorise them across samples,
which costs many small array operations per step. No library offers these
loops, so they are written here once, compiled with ``numba.njit(cache=True)``
(the first process compiles and caches them; later processes load the cache).

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
    for l in range(L):
        mean[0, l, 0] = X[0, l, 0]
        mean[0, l, 1] = X[0, l, 1]
        ent_u[0, 0, l, 0] = U[0, l, 0]
        ent_u[0, 0, l, 1] = U[0, l, 1]
        ent_ok[0, 0, l] = OK[0, l]
    cnt[0] = 1.0
    ent_n[0] = 1
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
# merging (state arrays of merging.Merger; ``st`` = [n, ne, trial, n0, ne0, n_undo_nodes, n_undo_vins, stamp])
@njit(cache=True)
def _rotate_rows(qv, R, qvt, n):
    """``qv[:n] = qv[:n] @ R.T`` in place (rows are 2-D vectors), rounded as numpy's
    ``(n, 2) @ (2, 2)`` product does (module docstring); ``qvt`` is scratch."""
    for l in range(n):
        x0 = qv[l, 0]
        x1 = qv[l, 1]
        qvt[l, 0] = fma(x1, R[0, 1], x0 * R[0, 0])
        qvt[l, 1] = fma(x1, R[1, 1], x0 * R[1, 0])
    qv[:n, :] = qvt[:n, :]


@njit(cache=True)
def merge_sample(s, T, trial, lam, eps, procrustes, st,
                 visit_node, visit_vel, visit_first, ndisp, ncount, first, red, M,
                 Dsum, Dmean, Dred, cnt, node_map, visit_map,
                 vin_sum, vin_mean, vin_nrm, vin_cnt, vin_owner, vin_prev, vin_next, vin_oldtail, head, tail,
                 u_node, u_Dsum, u_cnt, node_stamp, u_vin, u_vsum, u_vcnt, u_vmean, u_vnrm, vin_stamp):
    """:meth:`merging.Merger.merge` of sample ``s`` -> its merge compression (%).

    Candidate final nodes are those whose reduced-landmark Frobenius distance
    (computed from differences, so without cancellation) is within the
    threshold; among them the distance sum and then eq. 3 decide, with
    numpy's arithmetic (module docs). ``trial`` keeps an undo log
    (:func:`undo_merge`).
    """
    Lf = M.shape[0]
    Lr = red.shape[0]
    T2 = T * T
    n = st[0]
    ne = st[1]
    n0 = n
    if trial:
        st[2] = 1
        st[3] = n
        st[4] = ne
        st[5] = 0
        st[6] = 0
        st[7] += 1
    else:
        st[2] = 0
    stamp = st[7]
    R = np.empty((2, 2))
    tr = np.empty(2)
    Ra = np.empty((2, 2))
    ta = np.empty(2)
    tmp = np.empty((2, 2))
    has_R = False
    qd = np.empty((Lf, 2))
    a = np.empty((Lf, 2))
    qv = np.empty((Lr, 2))
    qvt = np.empty((Lr, 2))
    qdr = np.empty((Lr, 2))
    cdist = np.empty(Lr)
    qn = np.empty(Lr)
    prod = np.empty(Lr)
    buf = np.empty(2 * Lf)
    ma = np.empty(2)
    mb = np.empty(2)
    prev = -1
    for vi_ in range(visit_first[s], visit_first[s + 1]):
        g = visit_node[vi_]
        for l in range(Lr):
            qv[l, 0] = visit_vel[vi_, l, 0]
            qv[l, 1] = visit_vel[vi_, l, 1]
        if has_R:
            _rotate_rows(qv, R, qvt, Lr)
        f = node_map[g]
        if f < 0:
            if has_R:
                for l in range(Lf):
                    a0 = M[l, 0] + ndisp[g, l, 0]
                    a1 = M[l, 1] + ndisp[g, l, 1]
                    qd[l, 0] = ((fma(a1, R[0, 1], a0 * R[0, 0])) + tr[0]) - M[l, 0]
                    qd[l, 1] = ((fma(a1, R[1, 1], a0 * R[1, 0])) + tr[1]) - M[l, 1]
            else:
                qd[:, :] = ndisp[g]
            for l in range(Lr):
                qdr[l, 0] = qd[red[l], 0]
                qdr[l, 1] = qd[red[l], 1]
            best = -1
            bsc = np.inf
            for l in range(Lr):
                qn[l] = math.sqrt(qv[l, 0] * qv[l, 0] + qv[l, 1] * qv[l, 1])
            lim = T2 * (1.0 + 1e-9) + 1e-12
            for j in range(n):
                d2 = 0.0
                for l in range(Lr):
                    e0 = Dred[j, 2 * l] - qdr[l, 0]
                    e1 = Dred[j, 2 * l + 1] - qdr[l, 1]
                    d2 += e0 * e0 + e1 * e1
                if d2 > lim:
                    continue
                for l in range(Lr):
                    e0 = Dred[j, 2 * l] - qdr[l, 0]
                    e1 = Dred[j, 2 * l + 1] - qdr[l, 1]
                    cdist[l] = math.sqrt(e0 * e0 + e1 * e1)
                if not (pw_sum(cdist, Lr) <= T):
                    continue
                e = head[j]
                while e >= 0:
                    for l in range(Lr):
                        nb = vin_nrm[e, l]
                        if qn[l] > eps and nb > eps:
                            c = (qv[l, 0] * vin_mean[e, l, 0] + qv[l, 1] * vin_mean[e, l, 1]) / (qn[l] * nb)
                        else:
                            c = 1.0
                        vi = 1.0 - min(abs(c), 1.0)
                        prod[l] = cdist[l] * (1.0 + lam * vi)
                    v = pw_sum(prod, Lr)
                    if v < bsc:
                        bsc = v
                        best = j
                    e = vin_next[e]
            if not (bsc <= T):
                best = -1
            c = ncount[g]
            if best >= 0:
                if procrustes:
                    ma[0] = 0.0
                    ma[1] = 0.0
                    mb[0] = 0.0
                    mb[1] = 0.0
                    for l in range(Lf):
                        a[l, 0] = M[l, 0] + qd[l, 0]
                        a[l, 1] = M[l, 1] + qd[l, 1]
                        ma[0] += a[l, 0]
                        ma[1] += a[l, 1]
                        mb[0] += M[l, 0] + Dmean[best, l, 0]
                        mb[1] += M[l, 1] + Dmean[best, l, 1]
                    ma[0] /= Lf
                    ma[1] /= Lf
                    mb[0] /= Lf
                    mb[1] /= Lf
                    for l in range(Lf):
                        buf[2 * l] = (a[l, 0] - ma[0]) * ((M[l, 0] + Dmean[best, l, 0]) - mb[0])
                        buf[2 * l + 1] = (a[l, 1] - ma[1]) * ((M[l, 1] + Dmean[best, l, 1]) - mb[1])
                    dot = pw_sum(buf, 2 * Lf)
                    for l in range(Lf):
                        buf[l] = ((a[l, 0] - ma[0]) * ((M[l, 1] + Dmean[best, l, 1]) - mb[1])
                                  - (a[l, 1] - ma[1]) * ((M[l, 0] + Dmean[best, l, 0]) - mb[0]))
                    cross = pw_sum(buf, Lf)
                    h = py_hypot(dot, cross)
                    if h > 0:
                        cs = dot / h
                        sn = cross / h
                    else:
                        cs = 1.0
                        sn = 0.0
                    Ra[0, 0] = cs
                    Ra[0, 1] = -sn
                    Ra[1, 0] = sn
                    Ra[1, 1] = cs
                    ta[0] = mb[0] - fma(Ra[0, 0], ma[0], Ra[0, 1] * ma[1])
                    ta[1] = mb[1] - fma(Ra[1, 0], ma[0], Ra[1, 1] * ma[1])
                    for l in range(Lf):
                        a0 = a[l, 0]
                        a1 = a[l, 1]
                        qd[l, 0] = ((fma(a1, Ra[0, 1], a0 * Ra[0, 0])) + ta[0]) - M[l, 0]
                        qd[l, 1] = ((fma(a1, Ra[1, 1], a0 * Ra[1, 0])) + ta[1]) - M[l, 1]
                    _rotate_rows(qv, Ra, qvt, Lr)
                    if not has_R:
                        R[:, :] = Ra
                        tr[0] = ta[0]
                        tr[1] = ta[1]
                        has_R = True
                    else:
                        for i in range(2):
                            for j in range(2):
                                tmp[i, j] = fma(Ra[i, 1], R[1, j], Ra[i, 0] * R[0, j])
                        t0 = fma(Ra[0, 0], tr[0], Ra[0, 1] * tr[1]) + ta[0]
                        t1 = fma(Ra[1, 0], tr[0], Ra[1, 1] * tr[1]) + ta[1]
                        R[:, :] = tmp
                        tr[0] = t0
                        tr[1] = t1
                f = best
                if trial and f < n0 and node_stamp[f] != stamp:
                    node_stamp[f] = stamp
                    k = st[5]
                    u_node[k] = f
                    u_Dsum[k] = Dsum[f]
                    u_cnt[k] = cnt[f]
                    st[5] = k + 1
                for l in range(Lf):
                    Dsum[f, l, 0] += c * qd[l, 0]
                    Dsum[f, l, 1] += c * qd[l, 1]
                cnt[f] += c
            else:
                f = n
                n += 1
                for l in range(Lf):
                    Dsum[f, l, 0] = c * qd[l, 0]
                    Dsum[f, l, 1] = c * qd[l, 1]
                cnt[f] = c
                head[f] = -1
                tail[f] = -1
            for l in range(Lf):
                Dmean[f, l, 0] = Dsum[f, l, 0] / cnt[f]
                Dmean[f, l, 1] = Dsum[f, l, 1] / cnt[f]
            for l in range(Lr):
                Dred[f, 2 * l] = Dmean[f, red[l], 0]
                Dred[f, 2 * l + 1] = Dmean[f, red[l], 1]
            node_map[g] = f
        # incoming-edge velocity of (f, prev)
        e = head[f]
        while e >= 0 and vin_prev[e] != prev:
            e = vin_next[e]
        if e < 0:
            e = ne
            ne += 1
            vin_owner[e] = f
            vin_prev[e] = prev
            vin_cnt[e] = 1.0
            for l in range(Lr):
                vin_sum[e, l, 0] = qv[l, 0]
                vin_sum[e, l, 1] = qv[l, 1]
                vin_mean[e, l, 0] = qv[l, 0]
                vin_mean[e, l, 1] = qv[l, 1]
                vin_nrm[e, l] = math.sqrt(qv[l, 0] * qv[l, 0] + qv[l, 1] * qv[l, 1])
            vin_next[e] = -1
            vin_oldtail[e] = tail[f]
            if tail[f] >= 0:
                vin_next[tail[f]] = e
            else:
                head[f] = e
            tail[f] = e
        else:
            if trial and e < st[4] and vin_stamp[e] != stamp:
                vin_stamp[e] = stamp
                k = st[6]
                u_vin[k] = e
                u_vsum[k] = vin_sum[e]
                u_vcnt[k] = vin_cnt[e]
                u_vmean[k] = vin_mean[e]
                u_vnrm[k] = vin_nrm[e]
                st[6] = k + 1
            vin_cnt[e] += 1.0
            for l in range(Lr):
                vin_sum[e, l, 0] += qv[l, 0]
                vin_sum[e, l, 1] += qv[l, 1]
                m0 = vin_sum[e, l, 0] / vin_cnt[e]
                m1 = vin_sum[e, l, 1] / vin_cnt[e]
                vin_mean[e, l, 0] = m0
                vin_mean[e, l, 1] = m1
                vin_nrm[e, l] = math.sqrt(m0 * m0 + m1 * m1)
        visit_map[vi_] = f
        prev = f
    st[0] = n
    st[1] = ne
    k = first[s + 1] - first[s]
    return 100.0 * (1.0 - (n - n0) / max(k, 1))


@njit(cache=True)
def undo_merge(s, st, first, red, Dsum, Dmean, Dred, cnt, node_map,
               vin_sum, vin_mean, vin_nrm, vin_cnt, vin_owner, vin_next, vin_oldtail, tail,
               u_node, u_Dsum, u_cnt, u_vin, u_vsum, u_vcnt, u_vmean, u_vnrm):
    """Revert the last trial :func:`merge_sample` of sample ``s``."""
    n0, ne0 = st[3], st[4]
    Lf = Dsum.shape[1]
    for k in range(st[5]):
        f = u_node[k]
        Dsum[f] = u_Dsum[k]
        cnt[f] = u_cnt[k]
        for l in range(Lf):
            Dmean[f, l, 0] = Dsum[f, l, 0] / cnt[f]
            Dmean[f, l, 1] = Dsum[f, l, 1] / cnt[f]
        for l in range(red.shape[0]):
            Dred[f, 2 * l] = Dmean[f, red[l], 0]
            Dred[f, 2 * l + 1] = Dmean[f, red[l], 1]
    for k in range(st[6]):
        e = u_vin[k]
        vin_sum[e] = u_vsum[k]
        vin_cnt[e] = u_vcnt[k]
        vin_mean[e] = u_vmean[k]
        vin_nrm[e] = u_vnrm[k]
    for e in range(st[1] - 1, ne0 - 1, -1):
        f = vin_owner[e]
        if f < n0:
            t = vin_oldtail[e]
            tail[f] = t
            vin_next[t] = -1
    for g in range(first[s], first[s + 1]):
        node_map[g] = -1
    st[0] = n0
    st[1] = ne0
    st[2] = 0


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
