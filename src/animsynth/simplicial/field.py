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

Weights are ``m / D^2`` (D = distance from q, m = number of training points
merged into that point, 1 without duplicates), normalised to sum 1; a query
that coincides with a training point (D <= ``hit_tol``) takes that point's
vector (averaged, weighted by m, if several coincide). ``weights="barycentric"`` uses the
barycentric coordinates of q in its simplex instead (a continuous,
piecewise-linear field; Delaunay only). Outside the convex hull of the
training points (no containing simplex) ``delaunay``, ``kdelaunay`` and
``barycentric`` fall back to k-NN with 1/D^2 weights; every such evaluation
is flagged so that callers can count fallback steps.

Duplicate training points are merged (see
:mod:`animsynth.simplicial.geometry`); a merged point carries the mean of its
members' vectors and the weight ``m / D^2`` of its ``m`` members, which is
exactly what ``1 / D^2`` over the original (unmerged) points gives. k-NN picks
the k nearest *merged* points, so a duplicated frame does not crowd other
neighbours out of the neighbourhood.

Many query points, and many fields that share one set of training points
(e.g. the same fold with different derivatives or methods), are evaluated
together by :meth:`FieldStack.evaluate`: one point location and one k-NN query
for all points, vectorised weights, per-point fallback. :meth:`VectorField.evaluate`
is that method with a single field, so batched and one-at-a-time results
agree to float rounding. :meth:`VectorField.__call__` (one point) is the
reference that field following is tested against; following itself runs in
compiled loops (:mod:`animsynth.simplicial.kernels`).
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


def idw_weights(dist, hit_tol: float = 0.0, mult=None) -> np.ndarray:
    """Row-normalised ``m/D^2`` weights; a row with a hit (D <= hit_tol) weights only its hits (by m).

    Parameters
    ----------
    dist : array (m, k) of distances (``inf`` marks an unused slot)
    hit_tol : float
    mult : array (m, k), optional
        Multiplicity of every neighbour (points merged into it); default 1.

    Returns
    -------
    ndarray (m, k), rows summing to 1
    """
    d = np.asarray(dist, float)
    hit = d <= hit_tol
    with np.errstate(divide="ignore"):
        w = 1.0 / (d * d)
    w[~np.isfinite(d)] = 0.0
    any_hit = hit.any(axis=1)
    if any_hit.any():
        w[any_hit] = hit[any_hit].astype(float)
    if mult is not None:
        w = w * mult
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
    counts_ : ndarray (u,)
        Number of training points merged into every unique point (its weight multiplier).
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
        """Fit on training points (n, d) and their vectors (n, d); ``triangulation`` may be shared."""
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
        self.counts_ = np.bincount(tri.rep_, minlength=u).astype(float)
        self.vectors_ = vsum / self.counts_[:, None]
        self.tree_ = getattr(tri, "_field_tree", None)
        if self.tree_ is None:  # one k-d tree per triangulation, shared by every field built on it
            self.tree_ = tri._field_tree = cKDTree(self.points_)
        self.k_eff_ = int(min(self.k, u))
        if self.k_eff_ < self.k:  # documented fallback: merged duplicates leave fewer distinct points than k
            log.warning("VectorField: k = %d but only %d distinct points after merging duplicates; using k = %d",
                        self.k, u, self.k_eff_)
        self.hit_tol_ = tri.tol_
        self.dim_ = x.shape[1]
        self.scale_ = bbox_diagonal(x)
        self._uses_tri = self.method in ("delaunay", "kdelaunay")
        self._stack = None
        if self._uses_tri and tri.simplices_.shape[0] == 0:
            log.warning("VectorField(%s): no simplices (%s); every evaluation falls back to k-NN",
                        self.method, tri.status_)
        return self

    # ------------------------------------------------------------------
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
        if self._stack is None:
            self._stack = FieldStack([self])
        q = np.atleast_2d(np.asarray(q, float))
        return self._stack.evaluate(q, np.zeros(q.shape[0], int))

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
        m = self.counts_[idx]
        if hit.any():
            w = m * hit
        else:
            w = m / (d * d)
        return (w / w.sum()) @ self.vectors_[idx]


class FieldStack:
    """Several fields on the same training points, evaluated together.

    All fields must have been fitted on one :class:`SafeDelaunay` object
    (same points, possibly different vectors, methods, weights or k). One call
    locates every query point that needs a simplex (one ``find``) and runs one
    k-NN query per distinct k for every point that needs neighbours (k-NN
    fields, outside-hull fallbacks, k-Delaunay), then combines the weights
    point by point. ``hint`` (the simplex each point was in at the previous
    step) lets :meth:`SafeDelaunay.find` skip the search for points still
    strictly inside it.

    Parameters
    ----------
    fields : list of fitted VectorField

    Attributes
    ----------
    vectors_ : ndarray (F, u, d)
    """

    def __init__(self, fields):
        fields = list(fields)
        if not fields:
            raise ValueError("FieldStack needs at least one field")
        tri = fields[0].triangulation_
        for f in fields:
            if f.triangulation_ is not tri:
                raise ValueError("FieldStack: every field must be fitted on the same triangulation object")
        self.fields = fields
        self.tri_ = tri
        f0 = fields[0]
        self.points_, self.counts_, self.tree_, self.hit_tol_ = f0.points_, f0.counts_, f0.tree_, f0.hit_tol_
        self.dim_ = f0.dim_
        self.vectors_ = np.stack([f.vectors_ for f in fields])
        code = {"knn": 0, "delaunay": 1, "kdelaunay": 2}
        self.method_ = np.array([code[f.method] for f in fields])
        self.bary_ = np.array([f.weights == "barycentric" for f in fields])
        self.k_ = np.array([f.k_eff_ for f in fields])

    def _knn(self, q, k):
        d, i = self.tree_.query(q, k=int(k))
        return np.asarray(d, float).reshape(len(q), -1), np.asarray(i, int).reshape(len(q), -1)

    def _idw(self, which, dist, idx):
        w = idw_weights(dist, self.hit_tol_, self.counts_[idx])
        return np.einsum("mk,mkd->md", w, self.vectors_[which[:, None], idx])

    def evaluate(self, q, which, hint=None):
        """Field ``which[i]`` at point ``q[i]``.

        Parameters
        ----------
        q : array (m, d)
        which : array (m,) of int
            Index into ``fields`` for every point.
        hint : array (m,) of int, optional
            Previous simplex of every point (-1 = none); updated in place.

        Returns
        -------
        vectors : ndarray (m, d)
        fallback : ndarray (m,) of bool
        """
        m = q.shape[0]
        out = np.empty((m, self.dim_))
        fallback = np.zeros(m, bool)
        meth = self.method_[which]
        uses_tri = meth > 0
        need_knn = ~uses_tri
        s = np.full(m, -1)
        bary = None
        if uses_tri.any():
            ti = np.flatnonzero(uses_tri)
            st, bt = self.tri_.find(q[ti], hint=None if hint is None else hint[ti])
            s[ti] = st
            if hint is not None:
                hint[ti] = st
            bary = np.full((m, bt.shape[1]), np.nan)
            bary[ti] = bt
            fallback = uses_tri & (s < 0)
            need_knn = need_knn | fallback | ((meth == 2) & (s >= 0))
        knn_d = knn_i = None
        if need_knn.any():
            ni = np.flatnonzero(need_knn)
            ks = self.k_[which[ni]]
            kmax = int(ks.max())
            knn_d = np.full((m, kmax), np.inf)
            knn_i = np.zeros((m, kmax), int)
            for k in np.unique(ks):
                sel = ni[ks == k]
                d, i = self._knn(q[sel], k)
                knn_d[sel, :k], knn_i[sel, :k] = d, i
            plain = np.flatnonzero(need_knn & ((meth == 0) | fallback))
            if plain.size:
                out[plain] = self._idw(which[plain], knn_d[plain], knn_i[plain])
        inside = np.flatnonzero(uses_tri & (s >= 0))
        if inside.size:
            verts = self.tri_.simplices_[s[inside]]
            wi = which[inside]
            isb = self.bary_[wi]
            if isb.any():
                b = inside[isb]
                w = np.clip(bary[b], 0.0, None)
                w /= w.sum(axis=1, keepdims=True)
                out[b] = np.einsum("mk,mkd->md", w, self.vectors_[which[b][:, None], verts[isb]])
            kd = (meth[inside] == 2) & ~isb
            if kd.any():
                kk = inside[kd]
                v = np.concatenate([verts[kd], knn_i[kk]], axis=1)
                slot = np.concatenate([np.zeros_like(verts[kd], bool), ~np.isfinite(knn_d[kk])], axis=1)
                v = np.where(slot, -1, v)
                v = np.sort(v, axis=1)
                dup = np.zeros_like(v, bool)
                dup[:, 1:] = v[:, 1:] == v[:, :-1]
                dup |= v < 0
                v = np.where(v < 0, 0, v)
                dist = np.linalg.norm(self.points_[v] - q[kk][:, None, :], axis=2)
                dist[dup] = np.inf
                out[kk] = self._idw(which[kk], dist, v)
            pl = ~isb & ~kd
            if pl.any():
                p = inside[pl]
                vp = verts[pl]
                dist = np.linalg.norm(self.points_[vp] - q[p][:, None, :], axis=2)
                out[p] = self._idw(which[p], dist, vp)
        return out, fallback
