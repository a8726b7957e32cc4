"""Path generation: field following and target-directed graph search.

:func:`follow_field` starts at a latent point and repeatedly samples the vector
field and steps by it (explicit Euler with unit step, as in the paper).
:func:`follow_batch` advances many paths at once (an ensemble of starts, and
several fields on the same training points): every step is one vectorised
field evaluation for all current points (:class:`FieldStack`), so following
P paths costs far less than P single paths; each path gets exactly the steps
:func:`follow_field` would give it (to float rounding).

:class:`TargetPlanner` is the "beyond the paper" alternative: shortest paths
in G' (edge weights = latent edge lengths, all pairs computed once with
Dijkstra) from the training frame nearest the start to the training frame
nearest a target point (e.g. the held-out final frame). The generated path is
``[start, nodes on the shortest path...]``. When the target node is not
reachable from the start node, the planner goes to the reachable node closest
to the target and says so (``reached=False``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse.csgraph import shortest_path
from scipy.spatial import cKDTree

from .field import FieldStack
from .graph import MotionGraph


@dataclass
class GeneratedPath:
    """A generated latent path.

    Attributes
    ----------
    points : ndarray (steps+1, d)
    fallback : ndarray (steps,) of bool
        Steps whose field sample fell back to k-NN (outside the hull).
    """

    points: np.ndarray
    fallback: np.ndarray

    @property
    def steps(self) -> int:
        return int(self.points.shape[0] - 1)

    @property
    def fallback_steps(self) -> int:
        return int(np.count_nonzero(self.fallback))


def follow_field(field, start, steps: int) -> GeneratedPath:
    """Follow ``field`` for ``steps`` unit Euler steps from ``start``."""
    steps = int(steps)
    if steps < 0:
        raise ValueError(f"steps must be >= 0, got {steps}")
    x = np.asarray(start, float).copy()
    if not np.all(np.isfinite(x)):
        raise ValueError("follow_field: start point is not finite")
    pts = np.empty((steps + 1, x.size))
    fb = np.zeros(steps, bool)
    pts[0] = x
    for t in range(steps):
        v, fb[t] = field(x)
        x = x + v
        pts[t + 1] = x
    if not np.all(np.isfinite(pts)):
        raise FloatingPointError("follow_field produced a non-finite point")
    return GeneratedPath(pts, fb)


@dataclass
class BatchPaths:
    """Many generated latent paths of equal length.

    Attributes
    ----------
    points : ndarray (steps+1, P, d)
    fallback : ndarray (steps, P) of bool
    """

    points: np.ndarray
    fallback: np.ndarray

    def path(self, j: int) -> GeneratedPath:
        """Path ``j`` as a :class:`GeneratedPath`."""
        return GeneratedPath(self.points[:, j, :].copy(), self.fallback[:, j].copy())


def follow_batch(fields, starts, steps: int, which=None) -> BatchPaths:
    """Follow several paths together, one vectorised field evaluation per step.

    Parameters
    ----------
    fields : VectorField, list of VectorField (sharing one triangulation), or FieldStack
    starts : array (P, d)
        Start point of every path.
    steps : int
    which : array (P,) of int, optional
        Field of every path (index into ``fields``); default all 0.

    Returns
    -------
    BatchPaths
    """
    steps = int(steps)
    if steps < 0:
        raise ValueError(f"steps must be >= 0, got {steps}")
    stack = fields if isinstance(fields, FieldStack) else FieldStack(
        fields if isinstance(fields, (list, tuple)) else [fields])
    x = np.array(np.atleast_2d(starts), float)
    P = x.shape[0]
    if not np.all(np.isfinite(x)):
        raise ValueError("follow_batch: a start point is not finite")
    which = np.zeros(P, int) if which is None else np.asarray(which, int)
    if which.shape != (P,) or (P and (which.min() < 0 or which.max() >= len(stack.fields))):
        raise ValueError(f"follow_batch: 'which' must be {P} indices into {len(stack.fields)} fields")
    if P == 1 and _SinglePath.supports(stack):
        if getattr(stack, "_single", None) is None:  # scalar tables, built once per stack
            stack._single = _SinglePath(stack)
        return stack._single.follow(x[0], steps)
    if P > 1 and _SinglePath.supports(stack) and stack.fields[0].method == "delaunay":
        return _follow_delaunay_many(stack, x, steps)
    pts = np.empty((steps + 1, P, x.shape[1]))
    fb = np.zeros((steps, P), bool)
    pts[0] = x
    hint = np.full(P, -1)
    for t in range(steps):
        v, fb[t] = stack.evaluate(x, which, hint)
        x = x + v
        pts[t + 1] = x
    if not np.all(np.isfinite(pts)):
        raise FloatingPointError("follow_batch produced a non-finite point")
    return BatchPaths(pts, fb)


def _follow_delaunay_many(stack: FieldStack, x, steps: int) -> BatchPaths:
    """Many paths through one Delaunay field (1/D^2 weights, full-rank triangulation), lean vectorised steps.

    Each point is walked from the simplex it was in one step earlier (as in
    :meth:`SafeDelaunay.find` with a hint) and weighted with ``m / D^2`` over
    that simplex's vertices, with a handful of array operations per step.
    Points not found strictly inside a simplex within a few face crossings,
    and exact hits on a training point, take the general route
    (:meth:`FieldStack.evaluate`), so every path gets the steps
    :func:`follow_field` would give it (to float rounding).
    """
    from .geometry import HINT_EPS, HINT_WALK

    f = stack.fields[0]
    tri = f.triangulation_
    TT = tri._barycentric_transform()
    nbr = tri._tri.neighbors
    simp = tri.simplices_
    pts_u, vec, cnt = f.points_, f.vectors_, f.counts_
    r = pts_u.shape[1]
    P = x.shape[0]
    pts = np.empty((steps + 1, P, r))
    fb = np.zeros((steps, P), bool)
    pts[0] = x
    s = np.full(P, -1)
    zero = np.zeros(P, int)
    v = np.empty_like(x)
    for t in range(steps):
        ok = np.zeros(P, bool)
        idx = np.flatnonzero(s >= 0)
        for _ in range(HINT_WALK):
            if not idx.size:
                break
            T = TT[s[idx]]
            b = np.einsum("mij,mj->mi", T[:, :r, :], x[idx] - T[:, r, :])
            full = np.concatenate([b, 1.0 - b.sum(axis=1, keepdims=True)], axis=1)
            bmin = full.min(axis=1)
            good = bmin > HINT_EPS
            ok[idx[good]] = True
            rest = ~good & np.isfinite(bmin)
            idx = idx[rest]
            s[idx] = nbr[s[idx], np.argmin(full[rest], axis=1)]
            idx = idx[s[idx] >= 0]
        oi = np.flatnonzero(ok)
        if oi.size:
            verts = simp[s[oi]]
            diff = pts_u[verts] - x[oi, None, :]
            d2 = np.einsum("mkd,mkd->mk", diff, diff)
            hit = (d2 <= f.hit_tol_ ** 2).any(axis=1)
            if hit.any():
                ok[oi[hit]] = False
                oi, verts, d2 = oi[~hit], verts[~hit], d2[~hit]
            w = cnt[verts] / d2
            v[oi] = np.einsum("mk,mkd->md", w, vec[verts]) / w.sum(axis=1, keepdims=True)
        bad = np.flatnonzero(~ok)
        if bad.size:
            hb = np.full(bad.size, -1)
            v[bad], fb[t, bad] = stack.evaluate(x[bad], zero[:bad.size], hb)
            s[bad] = hb
        x = x + v
        pts[t + 1] = x
    if not np.all(np.isfinite(pts)):
        raise FloatingPointError("follow_batch produced a non-finite point")
    return BatchPaths(pts, fb)


class _SinglePath:
    """One path through one field, with per-step costs of a few microseconds.

    With a single path, numpy's per-call overhead dominates a vectorised
    step, so this follows it with scalar arithmetic instead, giving the same
    answer as :func:`follow_field` (to float rounding):

    * Delaunay (1/D^2 weights, full-rank triangulation): the point is first
      tried in the simplex it was in one step earlier, then walked across the
      face opposite its most negative barycentric coordinate (a few steps at
      most). Only a point found *strictly* inside a simplex is accepted that
      way (then that simplex is the only one containing it); anything else
      (faces, vertices, outside the hull) goes to :meth:`VectorField.__call__`,
      the reference. scipy has no warm-started point location, hence the walk
      by hand.
    * k-NN: one ``cKDTree.query`` per step through :meth:`VectorField.__call__`
      (a cached candidate set bounded by the triangle inequality was tried
      and was no faster than the query itself at k = 16).
    """

    MAX_WALK = 32

    @staticmethod
    def supports(stack: FieldStack) -> bool:
        if len(stack.fields) != 1:
            return False
        f = stack.fields[0]
        if f.method == "knn":
            return True
        tri = f.triangulation_
        return (f.method == "delaunay" and f.weights == "idw" and tri._tri is not None and tri.basis_ is None)

    def __init__(self, stack: FieldStack):
        f = stack.fields[0]
        self.f = f
        self.d = f.points_.shape[1]
        self.hit2 = f.hit_tol_ ** 2
        if f.method == "delaunay":
            tri = f.triangulation_
            self.T = tri._barycentric_transform().tolist()
            self.simp = tri.simplices_.tolist()
            self.nbr = tri._tri.neighbors.tolist()
            self.P = f.points_.tolist()
            self.V = f.vectors_.tolist()
            self.m = f.counts_.tolist()

    def follow(self, x0, steps: int) -> BatchPaths:
        pts = np.empty((steps + 1, 1, self.d))
        fb = np.zeros((steps, 1), bool)
        pts[0, 0] = x0
        if self.f.method == "delaunay" and self.d == 2:
            return self._follow_delaunay_2d(x0, steps, pts, fb)
        step = self._delaunay_step if self.f.method == "delaunay" else self._knn_step
        x = np.array(x0, float)
        self.s = -1
        for t in range(steps):
            v, fb[t, 0] = step(x)
            x = x + v
            pts[t + 1, 0] = x
        if not np.all(np.isfinite(pts)):
            raise FloatingPointError("follow_batch produced a non-finite point")
        return BatchPaths(pts, fb)

    def _follow_delaunay_2d(self, x0, steps, pts, fb):
        """The Delaunay step unrolled for the paper's 2-D latent space (same arithmetic as the general step)."""
        from .geometry import HINT_EPS

        if getattr(self, "_packed", None) is None:
            # per simplex: transform, centre, neighbours and vertices; per vertex: position, multiplier, vector
            self._packed = (
                [(a00, a01, a10, a11, c0, c1, n[0], n[1], n[2], v[0], v[1], v[2])
                 for ((a00, a01), (a10, a11), (c0, c1)), n, v in zip(self.T, self.nbr, self.simp)],
                [(p[0], p[1], m, w[0], w[1]) for p, m, w in zip(self.P, self.m, self.V)])
        TS, PV = self._packed
        hit2, max_walk = self.hit2, self.MAX_WALK
        x0_, x1_ = float(x0[0]), float(x0[1])
        s = -1
        xs = [(x0_, x1_)]
        for t in range(steps):
            found = False
            if s >= 0:
                for _ in range(max_walk):
                    a00, a01, a10, a11, c0, c1, n0, n1, n2, i0, i1, i2 = TS[s]
                    y0, y1 = x0_ - c0, x1_ - c1
                    b0 = a00 * y0 + a01 * y1
                    b1 = a10 * y0 + a11 * y1
                    b2 = 1.0 - (b0 + b1)
                    bm = min(b0, b1, b2)
                    if bm > HINT_EPS:
                        found = True
                        break
                    if bm != bm:
                        break
                    s = n0 if bm == b0 else (n1 if bm == b1 else n2)
                    if s < 0:
                        break
            if found:
                p0, p1, m0, u0, w0 = PV[i0]
                q0, q1, m1, u1, w1 = PV[i1]
                r0, r1, m2, u2, w2 = PV[i2]
                e0, e1 = p0 - x0_, p1 - x1_
                da = e0 * e0 + e1 * e1
                e0, e1 = q0 - x0_, q1 - x1_
                db = e0 * e0 + e1 * e1
                e0, e1 = r0 - x0_, r1 - x1_
                dc = e0 * e0 + e1 * e1
                found = da > hit2 and db > hit2 and dc > hit2
            if found:
                wa, wb, wc = m0 / da, m1 / db, m2 / dc
                wsum = wa + wb + wc
                v0 = (wa * u0 + wb * u1 + wc * u2) / wsum
                v1 = (wa * w0 + wb * w1 + wc * w2) / wsum
            else:
                x = np.array((x0_, x1_))
                s = self.f.triangulation_.find_one(x)
                v, fb[t, 0] = self.f(x)
                v0, v1 = float(v[0]), float(v[1])
            x0_, x1_ = x0_ + v0, x1_ + v1
            xs.append((x0_, x1_))
        pts[:, 0, :] = xs
        if not np.all(np.isfinite(pts)):
            raise FloatingPointError("follow_batch produced a non-finite point")
        return BatchPaths(pts, fb)

    def _bary(self, s, x):
        Ts = self.T[s]
        c = Ts[self.d]
        y = [x[j] - c[j] for j in range(self.d)]
        b = [sum(row[j] * y[j] for j in range(self.d)) for row in Ts[:self.d]]
        b.append(1.0 - sum(b))
        return b

    def _delaunay_step(self, x):
        from .geometry import HINT_EPS

        xl = x.tolist()
        s = self.s
        found = False
        for _ in range(self.MAX_WALK if s >= 0 else 0):
            b = self._bary(s, xl)
            if b != b or min(b) > HINT_EPS:  # NaN (degenerate simplex) fails the next test too
                found = min(b) > HINT_EPS
                break
            j = b.index(min(b))
            s = self.nbr[s][j]
            if s < 0:
                break
        if not found:
            self.s = self.f.triangulation_.find_one(x)
            v, fb = self.f(x)
            return v, fb
        self.s = s
        verts = self.simp[s]
        acc = [0.0] * self.d
        wsum = 0.0
        for vi in verts:
            p = self.P[vi]
            d2 = sum((p[j] - xl[j]) ** 2 for j in range(self.d))
            if d2 <= self.hit2:
                return self.f(x)
            w = self.m[vi] / d2
            wsum += w
            vv = self.V[vi]
            for j in range(self.d):
                acc[j] += w * vv[j]
        return np.array(acc) / wsum, False

    def _knn_step(self, x):
        return self.f(x)


class TargetPlanner:
    """All-pairs shortest paths on G' toward a target point.

    Parameters
    ----------
    max_all_pairs : int
        Above this many vertices only the rows needed are computed (single
        source Dijkstra) to bound memory; results are identical.

    Attributes
    ----------
    dist_, pred_ : ndarray (n, n) or None
        All-pairs distances and predecessors (when n <= max_all_pairs).
    """

    def __init__(self, max_all_pairs: int = 4000):
        self.max_all_pairs = max_all_pairs

    def fit(self, graph: MotionGraph) -> "TargetPlanner":
        self.graph_ = graph
        self.points_ = graph.points_
        self.tree_ = cKDTree(self.points_)
        self.adj_ = graph.adjacency(weighted=True)
        self.dist_ = self.pred_ = None
        if graph.n_ <= self.max_all_pairs:
            self.dist_, self.pred_ = shortest_path(self.adj_, method="D", directed=True, return_predecessors=True)
        return self

    def _row(self, s: int):
        if self.dist_ is not None:
            return self.dist_[s], self.pred_[s]
        d, p = shortest_path(self.adj_, method="D", directed=True, indices=[s], return_predecessors=True)
        return d[0], p[0]

    def plan(self, start, target):
        """Path from ``start`` toward ``target`` (latent points).

        Returns
        -------
        path : GeneratedPath (``fallback`` all False)
        info : dict with ``source``, ``target_node``, ``reached`` and ``graph_length``
        """
        start = np.asarray(start, float)
        target = np.asarray(target, float)
        s = int(self.tree_.query(start)[1])
        t = int(self.tree_.query(target)[1])
        dist, pred = self._row(s)
        reached = bool(np.isfinite(dist[t]))
        if not reached:
            ok = np.flatnonzero(np.isfinite(dist))
            t = int(ok[np.argmin(np.linalg.norm(self.points_[ok] - target, axis=1))])
        nodes = [t]
        while nodes[-1] != s:
            nodes.append(int(pred[nodes[-1]]))
        nodes = nodes[::-1]
        pts = np.vstack([start[None, :], self.points_[nodes]])
        info = {"source": s, "target_node": t, "reached": reached, "graph_length": float(dist[t]),
                "nodes": len(nodes)}
        return GeneratedPath(pts, np.zeros(len(pts) - 1, bool)), info
