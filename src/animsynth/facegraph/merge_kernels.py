"""The compiled merge of sample graphs into a region graph (numba), with numpy's exact arithmetic.

The loop over one sample's visits (:func:`merge_sample`: each decision changes the state the next one sees) and
the undo of a trial merge (:func:`undo_merge`) work on the state arrays of :class:`.merging.Merger`; ``st`` is
``[n, ne, trial, n0, ne0, n_undo_nodes, n_undo_vins, stamp]``. They round as numpy does, with the helpers and
conventions of :mod:`.kernels` (its docstring says how), compiled with ``numba.njit(cache=True)``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .kernels import fma, pw_sum, py_hypot


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
def _open_undo_log(st, trial):
    """Start a merge's undo log in ``st`` (a trial merge: the node and edge counts before it, a new stamp)."""
    if trial:
        st[2] = 1
        st[3] = st[0]
        st[4] = st[1]
        st[5] = 0
        st[6] = 0
        st[7] += 1
    else:
        st[2] = 0


@njit(cache=True)
def _posed_displacement(g, has_R, R, tr, M, ndisp, qd):
    """``qd`` = node ``g``'s mean displacement ``(Lf, 2)`` carried by the sample's alignment so far (``R``, ``tr``;
    none yet when ``has_R`` is false), rounded as numpy's ``(M + d) @ R.T + t - M``."""
    if has_R:
        for l in range(M.shape[0]):
            a0 = M[l, 0] + ndisp[g, l, 0]
            a1 = M[l, 1] + ndisp[g, l, 1]
            qd[l, 0] = ((fma(a1, R[0, 1], a0 * R[0, 0])) + tr[0]) - M[l, 0]
            qd[l, 1] = ((fma(a1, R[1, 1], a0 * R[1, 0])) + tr[1]) - M[l, 1]
    else:
        qd[:, :] = ndisp[g]


@njit(cache=True)
def _best_final_node(n, T, lam, eps, qd, qv, red, Dred, head, vin_next, vin_mean, vin_nrm, qdr, qn, cdist, prod):
    """The final node (of the first ``n``) a sample node with displacement ``qd`` and entering velocity ``qv``
    joins, or -1: within the threshold ``T`` by its reduced-landmark distance sum, then the lowest eq. 3 score
    over the node's entering velocities (at most ``T``). ``qdr``, ``qn``, ``cdist``, ``prod`` are scratch."""
    Lr = red.shape[0]
    for l in range(Lr):
        qdr[l, 0] = qd[red[l], 0]
        qdr[l, 1] = qd[red[l], 1]
    best = -1
    bsc = np.inf
    for l in range(Lr):
        qn[l] = math.sqrt(qv[l, 0] * qv[l, 0] + qv[l, 1] * qv[l, 1])
    lim = T * T * (1.0 + 1e-9) + 1e-12
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
    return best


@njit(cache=True)
def _procrustes_fit(M, Dmean, f, qd, a, ma, mb, buf, Ra, ta):
    """The rigid 2-D fit (``Ra``, ``ta``) of the pose ``M + qd`` onto final node ``f``'s mean pose ``M + Dmean[f]``
    (``_rigid2d``'s arithmetic: means, then the rotation's cosine and sine from the summed dot and cross products);
    ``a`` holds the pose ``M + qd`` afterwards. ``ma``, ``mb``, ``buf`` are scratch."""
    Lf = M.shape[0]
    ma[0] = 0.0
    ma[1] = 0.0
    mb[0] = 0.0
    mb[1] = 0.0
    for l in range(Lf):
        a[l, 0] = M[l, 0] + qd[l, 0]
        a[l, 1] = M[l, 1] + qd[l, 1]
        ma[0] += a[l, 0]
        ma[1] += a[l, 1]
        mb[0] += M[l, 0] + Dmean[f, l, 0]
        mb[1] += M[l, 1] + Dmean[f, l, 1]
    ma[0] /= Lf
    ma[1] /= Lf
    mb[0] /= Lf
    mb[1] /= Lf
    for l in range(Lf):
        buf[2 * l] = (a[l, 0] - ma[0]) * ((M[l, 0] + Dmean[f, l, 0]) - mb[0])
        buf[2 * l + 1] = (a[l, 1] - ma[1]) * ((M[l, 1] + Dmean[f, l, 1]) - mb[1])
    dot = pw_sum(buf, 2 * Lf)
    for l in range(Lf):
        buf[l] = ((a[l, 0] - ma[0]) * ((M[l, 1] + Dmean[f, l, 1]) - mb[1])
                  - (a[l, 1] - ma[1]) * ((M[l, 0] + Dmean[f, l, 0]) - mb[0]))
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


@njit(cache=True)
def _align_to(M, Dmean, f, qd, qv, qvt, has_R, R, tr, a, ma, mb, buf, Ra, ta, tmp):
    """Align the sample node (displacement ``qd``, entering velocity ``qv``, both changed in place) to final node
    ``f``'s mean (:func:`_procrustes_fit`) and compose that fit onto the sample's alignment ``R``,
    ``tr``. Returns True (the sample now has an alignment)."""
    _procrustes_fit(M, Dmean, f, qd, a, ma, mb, buf, Ra, ta)
    for l in range(M.shape[0]):
        a0 = a[l, 0]
        a1 = a[l, 1]
        qd[l, 0] = ((fma(a1, Ra[0, 1], a0 * Ra[0, 0])) + ta[0]) - M[l, 0]
        qd[l, 1] = ((fma(a1, Ra[1, 1], a0 * Ra[1, 0])) + ta[1]) - M[l, 1]
    _rotate_rows(qv, Ra, qvt, qv.shape[0])
    if not has_R:
        R[:, :] = Ra
        tr[0] = ta[0]
        tr[1] = ta[1]
    else:
        for i in range(2):
            for j in range(2):
                tmp[i, j] = fma(Ra[i, 1], R[1, j], Ra[i, 0] * R[0, j])
        t0 = fma(Ra[0, 0], tr[0], Ra[0, 1] * tr[1]) + ta[0]
        t1 = fma(Ra[1, 0], tr[0], Ra[1, 1] * tr[1]) + ta[1]
        R[:, :] = tmp
        tr[0] = t0
        tr[1] = t1
    return True


@njit(cache=True)
def _add_to_node(f, new, c, qd, red, trial, n0, stamp, st, Dsum, Dmean, Dred, cnt, head, tail,
                 node_stamp, u_node, u_Dsum, u_cnt):
    """Add a sample node of ``c`` poses with displacement ``qd`` to final node ``f`` (``new``: a node opened for
    it), logging an old node's state for a trial merge's undo, and refresh the node's mean (``Dmean``, ``Dred``)."""
    if not new:
        if trial and f < n0 and node_stamp[f] != stamp:
            node_stamp[f] = stamp
            k = st[5]
            u_node[k] = f
            u_Dsum[k] = Dsum[f]
            u_cnt[k] = cnt[f]
            st[5] = k + 1
        for l in range(qd.shape[0]):
            Dsum[f, l, 0] += c * qd[l, 0]
            Dsum[f, l, 1] += c * qd[l, 1]
        cnt[f] += c
    else:
        for l in range(qd.shape[0]):
            Dsum[f, l, 0] = c * qd[l, 0]
            Dsum[f, l, 1] = c * qd[l, 1]
        cnt[f] = c
        head[f] = -1
        tail[f] = -1
    for l in range(qd.shape[0]):
        Dmean[f, l, 0] = Dsum[f, l, 0] / cnt[f]
        Dmean[f, l, 1] = Dsum[f, l, 1] / cnt[f]
    for l in range(red.shape[0]):
        Dred[f, 2 * l] = Dmean[f, red[l], 0]
        Dred[f, 2 * l + 1] = Dmean[f, red[l], 1]


@njit(cache=True)
def _new_edge(f, prev, e, qv, vin_sum, vin_mean, vin_nrm, vin_cnt, vin_owner, vin_prev, vin_next, vin_oldtail, head,
              tail):
    """Open edge record ``e``: final node ``f``'s incoming edge from ``prev``, with the entering velocity ``qv``
    as its first (appended to ``f``'s list of incoming edges)."""
    vin_owner[e] = f
    vin_prev[e] = prev
    vin_cnt[e] = 1.0
    for l in range(qv.shape[0]):
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


@njit(cache=True)
def _log_edge(e, st, vin_sum, vin_mean, vin_nrm, vin_cnt, u_vin, u_vsum, u_vcnt, u_vmean, u_vnrm):
    """Keep edge ``e``'s state in the undo log of a trial merge."""
    k = st[6]
    u_vin[k] = e
    u_vsum[k] = vin_sum[e]
    u_vcnt[k] = vin_cnt[e]
    u_vmean[k] = vin_mean[e]
    u_vnrm[k] = vin_nrm[e]
    st[6] = k + 1


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
    (:func:`undo_merge`). The steps of one visit: the node's displacement in the
    sample's alignment (:func:`_posed_displacement`), the final node it joins
    (:func:`_best_final_node`), the alignment to that node (:func:`_align_to`), the
    node's new mean (:func:`_add_to_node`) and the entering velocity added to the edge it came by (a new edge:
    :func:`_new_edge`).
    """
    Lf = M.shape[0]
    Lr = red.shape[0]
    _open_undo_log(st, trial)
    n, ne, n0, stamp = st[0], st[1], st[0], st[7]
    R, tr, Ra, ta, tmp = np.empty((2, 2)), np.empty(2), np.empty((2, 2)), np.empty(2), np.empty((2, 2))
    has_R = False
    qd, a, buf = np.empty((Lf, 2)), np.empty((Lf, 2)), np.empty(2 * Lf)
    qv, qvt, qdr = np.empty((Lr, 2)), np.empty((Lr, 2)), np.empty((Lr, 2))
    cdist, qn, prod = np.empty(Lr), np.empty(Lr), np.empty(Lr)
    ma, mb = np.empty(2), np.empty(2)
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
            _posed_displacement(g, has_R, R, tr, M, ndisp, qd)
            best = _best_final_node(n, T, lam, eps, qd, qv, red, Dred, head, vin_next, vin_mean, vin_nrm,
                                    qdr, qn, cdist, prod)
            if best >= 0 and procrustes:
                has_R = _align_to(M, Dmean, best, qd, qv, qvt, has_R, R, tr, a, ma, mb, buf, Ra, ta, tmp)
            new = best < 0
            f = n if new else best
            if new:
                n += 1
            _add_to_node(f, new, ncount[g], qd, red, trial, n0, stamp, st, Dsum, Dmean, Dred, cnt, head, tail,
                         node_stamp, u_node, u_Dsum, u_cnt)
            node_map[g] = f
        e = head[f]  # the entering velocity joins the incoming edge (f, prev)
        while e >= 0 and vin_prev[e] != prev:
            e = vin_next[e]
        if e < 0:
            _new_edge(f, prev, ne, qv, vin_sum, vin_mean, vin_nrm, vin_cnt, vin_owner, vin_prev, vin_next,
                      vin_oldtail, head, tail)
            ne += 1
        else:
            if trial and e < st[4] and vin_stamp[e] != stamp:
                vin_stamp[e] = stamp
                _log_edge(e, st, vin_sum, vin_mean, vin_nrm, vin_cnt, u_vin, u_vsum, u_vcnt, u_vmean, u_vnrm)
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
