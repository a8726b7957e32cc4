"""Training vectors and the interpolated vector field.

Training vectors (one per training frame, clip by clip), ``derivative``:

``half`` (the paper as printed)
    ``v_i = (x_{i+1} - x_i) / 2``, and ``v_i = (x_i - x_{i-1}) / 2`` at a
    clip's last frame.
``forward``
    The same without the 1/2: ``v_i = x_{i+1} - x_i`` (``x_i - x_{i-1}`` at the end).
``central``
    ``v_i = (x_{i+1} - x_{i-1}) / 2``; one-sided full differences at the
    first and last frame.

A field that moves half a frame per step (``half``) traverses the data at half
speed, so with as many steps as the held-out clip has frames it covers about
half of it; ``forward`` and ``central`` move one frame per step.

The field at a query point ``q`` interpolates the training vectors of a
neighbourhood N(q):

* ``delaunay``: the vertices of the simplex containing q;
* ``knn``: the k nearest training points;
* ``kdelaunay``: the union of both ("k-Delaunay").

Weights are ``1 / D^2`` (D = distance from q), normalised to sum 1; a query
that coincides with a training point (D <= ``hit_tol``) takes that point's
vector (averaged if several coincide). ``weights="barycentric"`` uses the
barycentric coordinates of q in its simplex instead (a continuous,
piecewise-linear field; Delaunay only). Outside the convex hull of the
training points (no containing simplex) ``delaunay``, ``kdelaunay`` and
``barycentric`` fall back to k-NN with 1/D^2 weights; every such evaluation
is flagged so that callers can count fallback steps.

Duplicate training points are merged (see
:mod:`animsynth.simplicial.geometry`); a merged point carries the mean of its
members' vectors.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.spatial import cKDTree

from .geometry import SafeDelaunay, bbox_diagonal

log = logging.getLogger("animsynth.simplicial.field")

DERIVATIVES = ("half", "forward", "central")
FIELD_METHODS = ("delaunay", "knn", "kdelaunay")
WEIGHTS = ("idw", "barycentric")


def training_vectors(clips, derivative: str = "half") -> np.ndarray:
    """Per-frame training vectors of a list of latent clips (concatenated).

    Parameters
    ----------
    clips : list of ndarray (n_i, d)
        Each clip needs at least 2 frames.
    derivative : {"half", "forward", "central"}

    Returns
    -------
    ndarray (sum n_i, d)
    """
    if derivative not in DERIVATIVES:
        raise ValueError(f"simplicial derivative must be one of {DERIVATIVES}, got {derivative!r}")
    out = []
    for c, x in enumerate(clips):
        x = np.asarray(x, float)
        if x.ndim != 2 or x.shape[0] < 2:
            raise ValueError(f"training clip {c} needs at least 2 frames, has shape {x.shape}")
        v = np.empty_like(x)
        if derivative == "central":
            v[1:-1] = 0.5 * (x[2:] - x[:-2])
            v[0] = x[1] - x[0]
            v[-1] = x[-1] - x[-2]
        else:
            f = 0.5 if derivative == "half" else 1.0
            v[:-1] = f * (x[1:] - x[:-1])
            v[-1] = f * (x[-1] - x[-2])
        out.append(v)
    return np.concatenate(out, axis=0)


def idw_weights(dist, hit_tol: float = 0.0) -> np.ndarray:
    """Row-normalised 1/D^2 weights; a row with a hit (D <= hit_tol) weights only its hits.

    Parameters
    ----------
    dist : array (m, k) of distances (``inf`` marks an unused slot)
    """
    d = np.asarray(dist, float)
    hit = d <= hit_tol
    with np.errstate(divide="ignore"):
        w = 1.0 / (d * d)
    w[~np.isfinite(d)] = 0.0
    any_hit = hit.any(axis=1)
    if any_hit.any():
        w[any_hit] = hit[any_hit].astype(float)
    s = w.sum(axis=1, keepdims=True)
    return w / s


class VectorField:
    """Interpolated vector field over latent training points.

    Parameters
    ----------
    method : {"delaunay", "knn", "kdelaunay"}
    k : int
        Neighbours for ``knn``/``kdelaunay`` and for the outside-hull fallback.
    weights : {"idw", "barycentric"}
        ``barycentric`` needs ``method="delaunay"``.
    dup_tol, rank_tol : float
        Relative tolerances (see :class:`SafeDelaunay`); ``dup_tol`` times the
        bounding-box diagonal is also the exact-hit tolerance.

    Attributes
    ----------
    points_, vectors_ : ndarray (u, d)
        Unique training points and their (group-averaged) vectors.
    triangulation_ : SafeDelaunay or None
    hit_tol_ : float
    """

    def __init__(self, method: str = "delaunay", k: int = 16, weights: str = "idw",
                 dup_tol: float = 1e-9, rank_tol: float = 1e-9):
        self.method = method
        self.k = k
        self.weights = weights
        self.dup_tol = dup_tol
        self.rank_tol = rank_tol

    def fit(self, points, vectors, triangulation: SafeDelaunay | None = None) -> "VectorField":
        if self.method not in FIELD_METHODS:
            raise ValueError(f"simplicial method must be one of {FIELD_METHODS}, got {self.method!r}")
        if self.weights not in WEIGHTS:
            raise ValueError(f"simplicial weights must be one of {WEIGHTS}, got {self.weights!r}")
        if self.weights == "barycentric" and self.method != "delaunay":
            raise ValueError("weights='barycentric' needs method='delaunay'")
        if int(self.k) < 1:
            raise ValueError(f"simplicial k must be >= 1, got {self.k}")
        x = np.asarray(points, float)
        v = np.asarray(vectors, float)
        if x.shape != v.shape or x.ndim != 2:
            raise ValueError(f"points {x.shape} and vectors {v.shape} must both be (n, d)")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            raise ValueError("VectorField: points or vectors contain NaN/inf")
        tri = triangulation if triangulation is not None else SafeDelaunay(self.dup_tol, self.rank_tol).fit(x)
        self.triangulation_ = tri
        u = tri.unique_points_.shape[0]
        vsum = np.zeros((u, x.shape[1]))
        np.add.at(vsum, tri.rep_, v)
        self.points_ = tri.unique_points_
        self.vectors_ = vsum / np.bincount(tri.rep_, minlength=u)[:, None]
        self.tree_ = cKDTree(self.points_)
        self.k_eff_ = int(min(self.k, u))
        self.hit_tol_ = tri.tol_
        self.dim_ = x.shape[1]
        self.scale_ = bbox_diagonal(x)
        self._uses_tri = self.method in ("delaunay", "kdelaunay")
        if self._uses_tri and tri.simplices_.shape[0] == 0:
            log.warning("VectorField(%s): no simplices (%s); every evaluation falls back to k-NN",
                        self.method, tri.status_)
        return self

    # ------------------------------------------------------------------
    def _knn(self, q):
        d, i = self.tree_.query(q, k=self.k_eff_)
        return np.asarray(d, float).reshape(len(q), -1), np.asarray(i, int).reshape(len(q), -1)

    def evaluate(self, q):
        """Field at many points (vectorised).

        Parameters
        ----------
        q : array (m, d)

        Returns
        -------
        vectors : ndarray (m, d)
        fallback : ndarray (m,) of bool
            True where a simplex-based method had no containing simplex and
            used k-NN instead (always False for ``knn``).
        """
        q = np.atleast_2d(np.asarray(q, float))
        m = q.shape[0]
        out = np.empty((m, self.dim_))
        fallback = np.zeros(m, bool)
        if not self._uses_tri:
            d, i = self._knn(q)
            w = idw_weights(d, self.hit_tol_)
            return np.einsum("mk,mkd->md", w, self.vectors_[i]), fallback
        tri = self.triangulation_
        s, bary = tri.find(q)
        inside = s >= 0
        fallback = ~inside
        if fallback.any():
            d, i = self._knn(q[fallback])
            out[fallback] = np.einsum("mk,mkd->md", idw_weights(d, self.hit_tol_), self.vectors_[i])
        if inside.any():
            verts = tri.simplices_[s[inside]]  # unique-point indices
            qi = q[inside]
            if self.weights == "barycentric":
                w = np.clip(bary[inside], 0.0, None)
                w /= w.sum(axis=1, keepdims=True)
            else:
                if self.method == "kdelaunay":
                    _, ki = self._knn(qi)
                    verts = np.concatenate([verts, ki], axis=1)
                    srt = np.sort(verts, axis=1)
                    dup = np.zeros_like(srt, bool)
                    dup[:, 1:] = srt[:, 1:] == srt[:, :-1]
                    verts = srt
                dist = np.linalg.norm(self.points_[verts] - qi[:, None, :], axis=2)
                if self.method == "kdelaunay":
                    dist[dup] = np.inf
                w = idw_weights(dist, self.hit_tol_)
            out[inside] = np.einsum("mk,mkd->md", w, self.vectors_[verts])
        return out, fallback

    def __call__(self, q):
        """Field at one point: ``(vector (d,), fallback bool)`` (low-overhead path)."""
        q = np.asarray(q, float)
        if not self._uses_tri:
            d, i = self.tree_.query(q, k=self.k_eff_)
            return self._idw1(np.atleast_1d(d), np.atleast_1d(i)), False
        tri = self.triangulation_
        if tri.basis_ is not None or tri._tri is None or self.weights == "barycentric" or self.method == "kdelaunay":
            v, fb = self.evaluate(q[None, :])
            return v[0], bool(fb[0])
        j = tri.find_one(q)
        if j < 0:
            d, i = self.tree_.query(q, k=self.k_eff_)
            return self._idw1(np.atleast_1d(d), np.atleast_1d(i)), True
        verts = tri.simplices_[j]
        diff = self.points_[verts] - q
        return self._idw1(np.sqrt(np.einsum("kd,kd->k", diff, diff)), verts), False

    def _idw1(self, d, idx):
        hit = d <= self.hit_tol_
        if hit.any():
            return self.vectors_[idx[hit]].mean(axis=0)
        w = 1.0 / (d * d)
        return (w / w.sum()) @ self.vectors_[idx]
