"""Isomap / ST-Isomap re-sequencing as one estimator: :class:`Resequencer`.

The method, once: frame features of the database (:func:`.features.motion_features`), the method's
neighbourhood graph (Isomap: the k nearest frames; ST-Isomap: the spatio-temporally adjusted distances with the
adjacent temporal neighbours always in), Dijkstra paths between frames on it (:meth:`Resequencer.path`) and
chains of such paths to seeded targets played as motion (:meth:`Resequencer.generate`). Every route calls it:

* the one-call route (:func:`.quick.resequence_motion`, the CLI ``animsynth resequence``): the dense graph of one
  capture, a path between two frames;
* the paper study's paths (:func:`.jobs.resequence`): the dense graph of a configuration (metric, global DOF,
  sign mode, the config's ST-Isomap block) at the configuration's k, the measured paths between frame pairs;
* the side-by-side comparison's ``isomap`` and ``stisomap`` rows (:mod:`animsynth.compare.generators.registry`): the sparse
  graph of a database of clips, :meth:`Resequencer.generate`.

The frame distances of the dense graph (:func:`frame_distances`) and the method's adjustment of them
(:func:`method_matrix`) are also what the study's minimum-k and embedding steps (:func:`.jobs.analyse`,
:func:`.jobs.explain`) read: those steps fit embeddings and scan k, which no generator does, and stay in
:mod:`.jobs`.
"""

from __future__ import annotations

import numpy as np

from ..generator import Database, Generator
from ..motion import Motion
from .settings import METHODS, METRICS

__all__ = ["NEIGHBOURS", "Resequencer", "frame_distances", "method_matrix"]

#: how the neighbourhood graph is built: from candidate lists of a spatial index (a database of clips), or
#: from the full distance matrix of one capture (the paper's study: both metrics, global DOF)
NEIGHBOURS = ("sparse", "dense")


def frame_distances(features, metric: str, include_global: bool = False, sign_mode: str = "continuous",
                    translation_scale: float = 1.0, lee: dict | None = None) -> np.ndarray:
    """The full frame distance matrix of one capture under ``metric``.

    ``l2``: between the linearised features (:meth:`.features.MotionFeatures.linearised`, ``sign_mode`` and
    ``translation_scale`` applied); ``lee``: :func:`.distances.lee_distances` with ``translation_scale`` and the
    keyword arguments ``lee`` (``weights``, ``nu``, ``sqrt``; a ``translation_scale`` there wins).

    Parameters
    ----------
    features : MotionFeatures, the capture's ``N`` frames (:func:`.features.motion_features`)
    metric : {"l2", "lee"}
    include_global : bool, the root's orientation and position in the distances
    sign_mode : str, quaternion linearisation of the L2 features (:func:`.features.linearize_quaternions`)
    translation_scale : float, root translation with ``include_global``: radians per metre
    lee : dict, optional, keyword arguments of :func:`.distances.lee_distances`

    Returns
    -------
    ndarray (N, N) float64, symmetric, zero diagonal
    """
    from .distances import l2_distances, lee_distances

    if metric == "l2":
        return l2_distances(features.linearised(include_global, sign_mode, translation_scale))
    if metric == "lee":
        kw = {"translation_scale": translation_scale, **(lee or {})}
        return lee_distances(features, include_global=include_global, **kw)
    raise ValueError(f"unknown metric {metric!r} (expected one of {METRICS})")


def method_matrix(D: np.ndarray, method: str, st: dict | None = None):
    """The matrix a method builds its k-NN graph on, the edges it always keeps and its
    common-temporal-neighbour matrix.

    Isomap: ``(D, None, None)``. ST-Isomap: :func:`.embedding.spatio_temporal_distances` with the keyword
    arguments ``st`` (frames; its defaults where absent).

    Parameters
    ----------
    D : ndarray (N, N), the frame distances (:func:`frame_distances`)
    method : {"isomap", "stisomap"}
    st : dict, optional, ST-Isomap's parameters in frames

    Returns
    -------
    Dm : ndarray (N, N), the (adjusted) distances the k-NN graph is built on
    always : ndarray (N, N) of bool or None, the adjacent temporal neighbours kept whatever k (ST-Isomap)
    ctn : ndarray (N, N) of bool or None, the common temporal neighbours (ST-Isomap)
    """
    from .embedding import spatio_temporal_distances

    if method == "isomap":
        return D, None, None
    if method == "stisomap":
        return spatio_temporal_distances(D, **(st or {}))
    raise ValueError(f"unknown method {method!r} (expected one of {METHODS})")


class Resequencer(Generator):
    """Isomap / ST-Isomap re-sequencing: Dijkstra paths on the neighbourhood graph of the database's frames.

    Parameters
    ----------
    method : {"isomap", "stisomap"}
    n_candidates : int, neighbours listed per frame (``neighbours="sparse"``; doubled until the smallest
        connecting k fits)
    k : int or None, neighbours of the graph. ``sparse``: None or smaller than the smallest k that connects the
        graph gives that k (as the re-sequencing study). ``dense``: None gives the smallest connecting k, an int
        is used as given and must connect the graph (:class:`~.embedding.DisconnectedGraphError` otherwise)
    min_target_gap_s : float, :meth:`generate`'s random target lies at least this far (seconds of database)
        from the current frame in the same clip
    stisomap : dict, the re-sequencing study's ``stisomap`` block (seconds, read at the database's frame rate by
        :func:`.settings.st_parameters`); ST-Isomap needs it with ``sparse``
    neighbours : {"sparse", "dense"}, see :data:`NEIGHBOURS`; ``dense`` takes a database of one clip
    metric : {"l2", "lee"}, the frame distance (``lee``: ``dense`` only)
    global_dof : bool, the root's orientation and position in the features
    sign_mode : str, quaternion linearisation of the L2 features (:func:`.features.linearize_quaternions`)
    translation_scale : float, root translation with the global DOF: radians per metre
    lee : dict, optional, keyword arguments of :func:`.distances.lee_distances` (``weights``, ``nu``, ``sqrt``,
        ``translation_scale``)
    st : dict, optional, keyword arguments of the ST-Isomap adjustment in frames (``dense``, without
        ``stisomap``; the adjustment's defaults where absent)

    Attributes
    ----------
    db_ : Database
    graph_ : scipy.sparse csr matrix (N, N), the weighted neighbourhood graph
    k_ : int, neighbours used
    min_k_ : int, the smallest connecting k (None for ``dense`` with ``k`` given: not computed)
    features_ : ndarray (N, dims), the frames' linearised features (what :meth:`generate` matches the start in)
    tree_ : cKDTree of ``features_``
    """

    @property
    def lazy_imports(self) -> tuple[str, ...]:
        """The modules :meth:`fit` and :meth:`generate` import on first use (the sparse route's neighbour search
        too when ``neighbours`` is not dense): :meth:`animsynth.generator.Generator.warm_up`."""
        mods = Generator.lazy_imports + (
            "scipy.spatial", "animsynth.resequencing.distances", "animsynth.resequencing.embedding",
            "animsynth.resequencing.features", "animsynth.resequencing.paths", "animsynth.resequencing.settings")
        return mods + (() if self.neighbours == "dense" else ("animsynth.resequencing.sparse", "sklearn.neighbors"))

    def __init__(self, method: str = "isomap", n_candidates: int = 20, k=None, min_target_gap_s: float = 0.5,
                 stisomap: dict | None = None, neighbours: str = "sparse", metric: str = "l2",
                 global_dof: bool = False, sign_mode: str = "continuous", translation_scale: float = 1.0,
                 lee: dict | None = None, st: dict | None = None):
        self.method = method
        self.n_candidates = n_candidates
        self.k = k
        self.min_target_gap_s = min_target_gap_s
        self.stisomap = stisomap
        self.neighbours = neighbours
        self.metric = metric
        self.global_dof = global_dof
        self.sign_mode = sign_mode
        self.translation_scale = translation_scale
        self.lee = lee
        self.st = st
        self.name = method

    # ------------------------------------------------------------------ fitting
    def _st(self, fps: float) -> dict:
        from .settings import st_parameters

        if self.stisomap and self.st:
            raise ValueError("Resequencer: give the ST-Isomap parameters as stisomap (seconds) or st (frames), "
                             "not both")
        return st_parameters(self.stisomap, fps) if self.stisomap else dict(self.st or {})

    def fit(self, database, native_clips=None) -> "Resequencer":
        """Build the neighbourhood graph of the database's frames (list of Motion; ``native_clips``: ignored, it runs
        at the working rate)."""
        from scipy.spatial import cKDTree

        from .features import motion_features

        if self.method not in METHODS:
            raise ValueError(f"unknown method {self.method!r} (expected one of {METHODS})")
        if self.neighbours not in NEIGHBOURS:
            raise ValueError(f"re-sequencing neighbours must be one of {NEIGHBOURS}, got {self.neighbours!r}")
        if self.metric not in METRICS:
            raise ValueError(f"unknown metric {self.metric!r} (expected one of {METRICS})")
        self.db_ = db = Database(database)
        feats = [motion_features(c) for c in db.clips]
        if self.neighbours == "dense":
            self._fit_dense(feats)
        else:
            self._fit_sparse(feats)
        self.tree_ = cKDTree(self.features_)
        return self

    def _linearised(self, feats) -> np.ndarray:
        return feats.linearised(self.global_dof, self.sign_mode, self.translation_scale)

    def _fit_dense(self, feats) -> None:
        from .embedding import checked_graph, min_connected_k

        if len(feats) != 1:
            raise ValueError(f"dense re-sequencing graphs are of one capture; the database has {len(feats)} clips")
        f = feats[0]
        D = frame_distances(f, self.metric, self.global_dof, self.sign_mode, self.translation_scale, self.lee)
        Dm, always, _ = method_matrix(D, self.method, self._st(self.db_.fps) if self.method == "stisomap" else None)
        self.min_k_ = None
        if self.k is None:
            self.min_k_ = int(min_connected_k(Dm, always=always))
        self.k_ = int(self.min_k_ if self.k is None else self.k)
        self.graph_ = checked_graph(Dm, self.k_, always, f"{self.method}/{self.metric}")
        self.features_ = self._linearised(f)

    def _fit_sparse(self, feats) -> None:
        from . import sparse as sp

        if self.metric != "l2":
            raise ValueError(f"sparse re-sequencing graphs use the l2 metric, got {self.metric!r} "
                             "(the lee metric: neighbours='dense')")
        if self.method == "stisomap" and not self.stisomap:
            raise ValueError("stisomap needs its parameters (the re-sequencing study's stisomap block)")
        feats, seq = sp.concat_features(feats)
        X = np.vstack([self._linearised(f) for f in feats])

        def pair(i, j):
            return np.linalg.norm(X[i] - X[j], axis=1)

        g = sp.sparse_graph(lambda m: (*sp.l2_neighbours(X, m), pair), seq, self.method, self.n_candidates,
                            self.k, st=self._st(self.db_.fps) if self.method == "stisomap" else None)
        self.min_k_, self.k_, self.graph_ = g.min_k, g.k, g.graph
        self.features_ = X

    # ------------------------------------------------------------------ paths and generation
    def path(self, start: int, end: int, return_cost: bool = False):
        """The Dijkstra shortest-cost path of database frames from ``start`` to ``end`` on the graph
        (:func:`.paths.shortest_path_frames`).

        Parameters
        ----------
        start, end : int, database frame indices (``0 <= i < N``)
        return_cost : bool, also return the path's cost

        Returns
        -------
        path : ndarray (m,) int64, the frames from ``start`` to ``end`` inclusive
        cost : float, the sum of the path's edge weights (only with ``return_cost``)

        Raises
        ------
        :class:`~.embedding.DisconnectedGraphError` if ``end`` is unreachable from ``start``.
        """
        from .paths import shortest_path_frames

        path, cost = shortest_path_frames(self.graph_, start, end)
        return (path, cost) if return_cost else path

    def generate(self, start: Motion, length: int, seed: int, native_start: Motion | None = None) -> Motion:
        """Paths from the database frame nearest the start's last frame to seeded random targets, chained until
        ``length`` frames, played with the root integrated (:meth:`animsynth.generator.Database.play`;
        ``native_start``: ignored, it runs at the working rate)."""
        from .features import motion_features

        self._check_start(start, length)
        db, length = self.db_, int(length)
        x = self._linearised(motion_features(start))[-1]
        path = [int(self.tree_.query(x)[1])]
        rng = np.random.default_rng(seed)
        gap = max(1, int(round(float(self.min_target_gap_s) * db.fps)))
        n = db.n_frames
        while len(path) < length + 1:
            cur = path[-1]
            far = (db.clip != db.clip[cur]) | (np.abs(db.frame - db.frame[cur]) >= gap)
            choices = np.flatnonzero(far)
            target = int(rng.choice(choices)) if choices.size else int((cur + 1 + rng.integers(n - 1)) % n)
            p = self.path(cur, target)
            path.extend(int(f) for f in p[1:])
        path = np.asarray(path[:length + 1], np.int64)
        values = db.play(path, start.values[-1])[1:]
        seams = db.seams(path)  # positions in path; output frame t = path position t + 1
        seams = seams[seams >= 2] - 1
        return self._motion(values, length, seams, db.sources(path[1:]))
