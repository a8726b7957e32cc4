"""Path generation: field following and target-directed graph search.

:func:`follow_field` starts at a latent point and repeatedly samples the vector
field and steps by it (explicit Euler with unit step, as in the paper).
:func:`follow_batch` advances many paths at once (an ensemble of starts, and
several fields on the same training points): k-NN and Delaunay (1/D^2) paths
run all their steps in one compiled loop (:mod:`animsynth.simplicial.kernels`),
the other field kinds take one vectorised field evaluation for all current
points per step (:class:`FieldStack`); each path gets exactly the steps
:func:`follow_field` would give it alone (to float rounding).

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

from .field import FieldStack, VectorField
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


def follow_field(field, start, steps: int, compiled: bool = True) -> GeneratedPath:
    """Follow ``field`` for ``steps`` unit Euler steps from ``start``.

    Parameters
    ----------
    field : VectorField, or any callable ``x (d,) -> (vector (d,), fallback bool)``
    start : array (d,)
    steps : int
    compiled : bool
        For a :class:`VectorField`, take the compiled route of
        :func:`follow_batch` (same steps to float rounding). ``False`` (or any
        other callable) calls ``field(x)`` step by step: the reference.
    """
    steps = int(steps)
    if steps < 0:
        raise ValueError(f"steps must be >= 0, got {steps}")
    x = np.asarray(start, float).copy()
    if not np.all(np.isfinite(x)):
        raise ValueError("follow_field: start point is not finite")
    if compiled and isinstance(field, VectorField):
        return follow_batch(field, x[None, :], steps).path(0)
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


def follow_batch(fields, starts, steps: int, which=None, compiled: bool = True) -> BatchPaths:
    """Follow several paths together.

    Paths whose field is k-NN, or Delaunay with 1/D^2 weights on a full-rank
    triangulation, run in the compiled loop (:mod:`animsynth.simplicial.kernels`:
    warm-started simplex walks, certified k-NN candidate caches, all steps of
    all paths in one call, on numba's threads from ``PARALLEL_MIN_PATHS``
    paths); the few steps it cannot settle exactly go to
    :meth:`FieldStack.evaluate`, batched over paths. The other paths
    (k-Delaunay, barycentric weights, reduced-rank triangulations), and all
    paths with ``compiled=False``, take one vectorised
    :meth:`FieldStack.evaluate` per step (the reference). Every path gets the
    steps :func:`follow_field` would give it alone (to float rounding).

    Parameters
    ----------
    fields : VectorField, list of VectorField (sharing one triangulation), or FieldStack
    starts : array (P, d)
        Start point of every path.
    steps : int
    which : array (P,) of int, optional
        Field of every path (index into ``fields``); default all 0.
    compiled : bool
        ``False``: the per-step numpy reference for every path.

    Returns
    -------
    BatchPaths
    """
    steps = int(steps)
    if steps < 0:
        raise ValueError(f"steps must be >= 0, got {steps}")
    if isinstance(fields, FieldStack):
        stack = fields
    elif isinstance(fields, VectorField):
        if fields._stack is None:  # kept on the field, with its compiled-loop tables
            fields._stack = FieldStack([fields])
        stack = fields._stack
    else:
        stack = FieldStack(list(fields))
    x = np.array(np.atleast_2d(starts), float)
    P = x.shape[0]
    if not np.all(np.isfinite(x)):
        raise ValueError("follow_batch: a start point is not finite")
    which = np.zeros(P, int) if which is None else np.asarray(which, int)
    if which.shape != (P,) or (P and (which.min() < 0 or which.max() >= len(stack.fields))):
        raise ValueError(f"follow_batch: 'which' must be {P} indices into {len(stack.fields)} fields")
    pts = np.empty((steps + 1, P, x.shape[1]))
    fb = np.zeros((steps, P), bool)
    pts[0] = x
    fast = _compiled_fields(stack)[which] if compiled else np.zeros(P, bool)
    if fast.all():
        pts, fb = _follow_compiled(stack, x, steps, which)
    elif fast.any():
        sel = np.flatnonzero(fast)
        pts[:, sel], fb[:, sel] = _follow_compiled(stack, x[sel], steps, which[sel])
    rest = np.flatnonzero(~fast)
    if rest.size:
        xr, wr = x[rest], which[rest]
        hint = np.full(rest.size, -1)
        for t in range(steps):
            v, fb[t, rest] = stack.evaluate(xr, wr, hint)
            xr = xr + v
            pts[t + 1, rest] = xr
    if not np.all(np.isfinite(pts)):
        raise FloatingPointError("follow_batch produced a non-finite point")
    return BatchPaths(pts, fb)


#: the compiled loop finds exact k nearest neighbours by brute force when the certified lists fail,
#: up to this many training points (above it such steps go to the reference, one batched cKDTree query)
BRUTE_MAX_POINTS = 20000
#: neighbours listed per training point for the certified k-NN: CACHE_FACTOR * k (at most all points)
CACHE_FACTOR = 16
#: the compiled loop runs on numba's threads from this many paths on, in chunks of PARALLEL_CHUNK paths
PARALLEL_MIN_PATHS = 64
PARALLEL_CHUNK = 16
#: faces a simplex walk may cross in one step before the step goes to the reference
MAX_WALK = 32


def _compiled_fields(stack: FieldStack) -> np.ndarray:
    """Which fields of ``stack`` the compiled loop handles exactly (bool per field)."""
    ok = getattr(stack, "_compiled_ok", None)
    if ok is None:
        tri = stack.tri_
        full = tri._tri is not None and tri.basis_ is None and tri.simplices_.shape[0] > 0
        ok = np.array([f.method == "knn" or (f.method == "delaunay" and f.weights == "idw" and full)
                       for f in stack.fields])
        stack._compiled_ok = ok
    return ok


def _kernel_tables(stack: FieldStack) -> dict:
    """Contiguous arrays for :mod:`kernels`, built once per stack (triangulation parts once per triangulation).

    ``nl`` (u, L) lists the L nearest training points of every training
    point (itself first) by increasing distance ``dl`` (u, L), with their
    coordinates ``nc`` (u, L, d); ``Rend`` (u,)
    is the distance of the L-th (``inf`` when that is every point): the
    certified candidate lists of the k-NN.
    """
    tab = getattr(stack, "_kernel", None)
    if tab is not None:
        return tab
    tri = stack.tri_
    d = stack.dim_
    geo = getattr(tri, "_kernel_geometry", None)
    if geo is None:
        if tri._tri is not None and tri.basis_ is None and tri.simplices_.shape[0] > 0:
            TT = np.ascontiguousarray(tri._barycentric_transform(), float)
            simp = np.ascontiguousarray(tri.simplices_, np.int64)
            nbr = np.ascontiguousarray(tri._tri.neighbors, np.int64)
        else:  # never used: such stacks have no compiled Delaunay field
            TT, simp, nbr = np.zeros((1, d + 1, d)), np.zeros((1, d + 1), np.int64), np.full((1, d + 1), -1, np.int64)
        if tri._hull_eq is not None:
            A, c = (np.ascontiguousarray(a, float) for a in tri._hull_eq)
        else:  # no facets: nothing is "clearly outside", such steps go to the reference
            A, c = np.zeros((0, d)), np.zeros(0)
        # outside by clearly more than the tolerance of SafeDelaunay.find (rounding of the dot products)
        lim = float(tri.tol_) * (1.0 + 1e-6) + 1e-12 * float(tri.scale_)
        geo = tri._kernel_geometry = (TT, simp, nbr, A, c, lim)
    pu = np.ascontiguousarray(stack.points_, float)
    u = pu.shape[0]
    kf = np.asarray(stack.k_, np.int64)
    L = int(min(u, CACHE_FACTOR * kf.max()))
    dl, nl = stack.tree_.query(pu, k=L)
    nl = np.ascontiguousarray(np.reshape(nl, (u, L)), np.int64)
    dl = np.ascontiguousarray(np.reshape(dl, (u, L)), float)
    Rend = np.full(u, np.inf) if L >= u else dl[:, -1].copy()
    tab = stack._kernel = {
        "geo": geo, "meth": np.array([0 if f.method == "knn" else 1 for f in stack.fields], np.int64),
        "kf": kf, "V": np.ascontiguousarray(stack.vectors_, float), "pu": pu,
        "cnt": np.ascontiguousarray(stack.counts_, float), "hit_tol": float(stack.hit_tol_), "nl": nl, "nc": pu[nl], "dl": dl,
        "Rend": Rend, "eps": 1e-12 * float(tri.scale_)}
    return tab


def _follow_compiled(stack: FieldStack, x, steps: int, which, brute: bool | None = None):
    """Paths through compiled-capable fields: ``(points (steps+1, P, d), fallback (steps, P))``.

    Runs :func:`kernels.advance_serial` / :func:`kernels.advance_parallel`
    until every path is finished; in between, the steps they hand back are
    evaluated with :meth:`FieldStack.evaluate`, batched over paths. ``brute``
    (default: at most ``BRUTE_MAX_POINTS`` training points) lets the compiled
    loop settle uncertified k-NN steps itself.
    """
    import numba

    from . import kernels

    tab = _kernel_tables(stack)
    TT, simp, nbr, A, c, lim = tab["geo"]
    meth, kf, V, pu, cnt, hit_tol = (tab[n] for n in ("meth", "kf", "V", "pu", "cnt", "hit_tol"))
    nl, nc, dl, Rend, eps = tab["nl"], tab["nc"], tab["dl"], tab["Rend"], tab["eps"]
    if brute is None:
        brute = pu.shape[0] <= BRUTE_MAX_POINTS
    X = np.array(x, float, order="C")
    P, d = X.shape
    which = np.ascontiguousarray(which, np.int64)
    pts = np.empty((steps + 1, P, d))
    pts[0] = X
    fb = np.zeros((steps, P), bool)
    t = np.zeros(P, np.int64)
    s = np.full(P, -1, np.int64)
    anchor = np.full(P, -1, np.int64)
    status = np.zeros(P, np.int64)
    kern = kernels.advance_parallel if P >= PARALLEL_MIN_PATHS else kernels.advance_serial
    while P:
        # small chunks handed out dynamically: on a shared machine one descheduled thread does not hold up the rest
        old = numba.set_parallel_chunksize(PARALLEL_CHUNK)
        try:
            kern(X, pts, fb, t, s, anchor, status, steps, which, meth, kf, V, pu, cnt, hit_tol,
                 TT, simp, nbr, A, c, lim, nl, nc, dl, Rend, eps, bool(brute), MAX_WALK)
        finally:
            numba.set_parallel_chunksize(old)
        ref = np.flatnonzero(status == 1)
        if not ref.size:
            break
        h = s[ref].copy()
        v, fbv = stack.evaluate(X[ref], which[ref], h)
        s[ref] = h
        anchor[ref] = np.reshape(stack.tree_.query(X[ref], k=1, workers=-1)[1], -1)  # a start for the lists
        X[ref] += v
        tr = t[ref]
        pts[tr + 1, ref] = X[ref]
        fb[tr, ref] = fbv
        t[ref] += 1
    return pts, fb


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
