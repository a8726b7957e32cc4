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
