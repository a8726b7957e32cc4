"""Face-graph baseline (Zhang et al. 2004, "Spacetime faces", keyframe animation).

Every database pose (pre-processed forward frames, displacement form) is a node
connected to every other node; an edge weighs the L2 distance of the two poses
raised to ``power``; an animation between two key poses is the Dijkstra
shortest path, one pose per frame.

With ``power = 1`` (plain L2) the triangle inequality makes the direct edge a
shortest path in a complete graph, so the "animation" jumps from the first key
pose to the second (2 frames); ``power = 2`` (squared L2) favours many small
steps. Both are reported. ``per_region=True`` builds one such graph per facial
region and assembles the regions as the region graphs do (resampled to the mean
length of the regions whose path moves).
"""

from __future__ import annotations

import time

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial.distance import cdist

from .regiongraph import EDGE_EPS
from .preprocess import FaceDatabase
from .regions import REGION_NAMES
from .synthesis import resample


class FaceGraphBaseline:
    """Complete pose graph(s) with L2**power weights.

    Parameters
    ----------
    power : float
        Exponent of the L2 distance used as edge weight (1: plain L2).
    per_region : bool
        One graph per region instead of one holistic graph.

    Attributes
    ----------
    graphs_ : dict part -> csr_matrix (N x N)
    parts_ : dict part -> landmark ids
    n_nodes_ : int
    """

    def __init__(self, power: float = 1.0, per_region: bool = False):
        self.power = power
        self.per_region = per_region

    def fit(self, db: FaceDatabase) -> "FaceGraphBaseline":
        if self.power <= 0:
            raise ValueError("power must be > 0")
        self.poses_ = np.asarray(db.disp, float)
        self.offsets_ = db.offsets
        self.parts_ = ({r: np.asarray(db.regions[r], int) for r in REGION_NAMES} if self.per_region
                       else {"face": np.arange(68)})
        self.graphs_ = {}
        for name, idx in self.parts_.items():
            X = self.poses_[:, idx].reshape(len(self.poses_), -1)
            W = cdist(X, X) ** self.power + EDGE_EPS
            np.fill_diagonal(W, 0.0)
            self.graphs_[name] = csr_matrix(W)
        self.n_nodes_ = int(len(self.poses_))
        return self

    def nbytes(self) -> int:
        """Memory of the graph(s) as float32 weights (N^2 each) plus the poses (float32)."""
        n = self.n_nodes_
        return int(4 * (len(self.graphs_) * n * n + n * 68 * 2))

    @property
    def n_edges(self) -> int:
        return int(sum(g.nnz for g in self.graphs_.values()))

    def synthesize(self, src: int, dst: int) -> tuple[np.ndarray, float, dict]:
        """Animation between database frames ``src`` and ``dst`` (global frame indices).

        Returns (displacements (frames, 68, 2), path-finding seconds, paths per part).
        """
        paths, secs = {}, 0.0
        for name, A in self.graphs_.items():
            t0 = time.perf_counter()
            dist, pred = dijkstra(A, directed=True, indices=src, return_predecessors=True)
            secs += time.perf_counter() - t0
            if not np.isfinite(dist[dst]):
                raise RuntimeError(f"face graph {name!r}: frame {dst} unreachable from {src}")
            p = [int(dst)]
            while p[-1] != src:
                p.append(int(pred[p[-1]]))
            paths[name] = np.array(p[::-1], int)
        moving = [len(p) for p in paths.values() if len(p) > 1] or [len(p) for p in paths.values()]
        n = max(1, int(np.rint(np.mean(moving))))
        out = np.zeros((n, 68, 2))
        for name, p in paths.items():
            idx = self.parts_[name]
            out[:, idx] = resample(self.poses_[p][:, idx], n)
        return out, secs, paths
