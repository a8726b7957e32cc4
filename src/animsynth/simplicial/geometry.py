"""Robust Delaunay triangulation of latent points (never crashes inside Qhull).

Gauch & Peters build a simplicial complex by Delaunay-triangulating the latent
(PCA) training points. Real data breaks a plain ``scipy.spatial.Delaunay``
call in three ways, each handled here with a documented, logged treatment:

Duplicate points
    Points closer than ``dup_tol * scale`` (``scale`` = diagonal of the
    points' bounding box) are merged into one *unique point* (union-find over
    ``cKDTree.query_pairs``); its representative is the lowest index of the
    group. Qhull only ever sees unique points. Callers (the vector field)
    average the training vectors of a group and weigh the group by its size
    m (``m / D^2``), which is exactly what 1/D^2 weights over the original
    points give (all members are at the same distance).
Rank-deficient input (collinear / coplanar points, fewer than d+1 points)
    The affine rank ``r`` of the unique points is measured with an SVD
    (singular values below ``rank_tol * s_max`` count as zero). When
    ``r < d`` the points are triangulated inside their own ``r``-dimensional
    affine hull: ``r >= 2`` with Qhull in the ``r`` principal coordinates,
    ``r == 1`` by sorting along the line (simplices = consecutive segments),
    ``r == 0`` (a single distinct point) has no simplex at all. A query point
    farther than ``dup_tol * scale`` from that affine hull is *outside*.
Qhull failure or lost points
    A ``QhullError`` is retried once with joggled input (``QJ``); if that also
    fails the triangulation is empty (status ``failed``) and every query is
    *outside*, so callers fall back to k-NN. Points that Qhull leaves out of
    every simplex (``Delaunay.coplanar``) are reported and joined to their
    nearest vertex by an edge.

Point location guards against ``find_simplex`` returning -1 for points that
are inside the hull (scipy issue 21279): such points are retried with
``bruteforce=True`` and then by an exact barycentric test against every
simplex; only points that fail all three are *outside*.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, Delaunay, QhullError, cKDTree

log = logging.getLogger("animsynth.simplicial.geometry")

#: barycentric slack (relative) below which a coordinate still counts as inside
BARY_EPS = 1e-10
#: a point counts as strictly inside its hint simplex when every barycentric coordinate exceeds this
HINT_EPS = 1e-9
#: face-crossing steps tried from the hint simplex before a full search
HINT_WALK = 4


def unique_pairs(pairs, n: int | None = None) -> np.ndarray:
    """Sorted unique rows of an (E, 2) int array (fast: rows encoded as one int64)."""
    e = np.asarray(pairs, np.int64).reshape(-1, 2)
    if e.shape[0] == 0:
        return np.zeros((0, 2), int)
    n = int(e.max()) + 1 if n is None else int(n)
    code = np.unique(e[:, 0] * n + e[:, 1])
    return np.stack([code // n, code % n], axis=1).astype(int)


def bbox_diagonal(points) -> float:
    """Length of the diagonal of the axis-aligned bounding box of ``points``."""
    p = np.atleast_2d(np.asarray(points, float))
    if p.shape[0] == 0:
        return 0.0
    return float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))


def merge_duplicates(points, tol: float):
    """Group points closer than ``tol`` (absolute) together.

    Returns
    -------
    rep : ndarray (n,) of int
        For every point, the index (into the unique array) of its group.
    unique_index : ndarray (u,) of int
        Lowest original index of every group (groups in order of that index).
    """
    p = np.asarray(points, float)
    n = p.shape[0]
    if n == 0:
        return np.zeros(0, int), np.zeros(0, int)
    pairs = cKDTree(p).query_pairs(r=tol, output_type="ndarray") if tol > 0 else np.zeros((0, 2), int)
    if tol <= 0:
        # exact duplicates only
        _, first, inv = np.unique(p, axis=0, return_index=True, return_inverse=True)
        order = np.argsort(first, kind="stable")
        remap = np.empty_like(order)
        remap[order] = np.arange(order.size)
        return remap[inv.ravel()], np.sort(first)
    if len(pairs) == 0:
        return np.arange(n), np.arange(n)
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(g, directed=False)
    # number groups by their lowest member
    first = np.full(labels.max() + 1, n)
    np.minimum.at(first, labels, np.arange(n))
    order = np.argsort(first, kind="stable")
    remap = np.empty_like(order)
    remap[order] = np.arange(order.size)
    return remap[labels], first[order]


class SafeDelaunay:
    """Delaunay triangulation of points in R^d with the guards described above.

    Parameters
    ----------
    dup_tol : float
        Merge tolerance relative to the bounding-box diagonal.
    rank_tol : float
        Relative singular-value threshold for the affine rank.

    Attributes
    ----------
    points_ : ndarray (n, d)
        The input points.
    rep_ : ndarray (n,)
        Unique-point index of every input point.
    unique_index_ : ndarray (u,)
        Input index of every unique point's representative.
    unique_points_ : ndarray (u, d)
    rank_ : int
        Affine rank of the unique points.
    simplices_ : ndarray (m, rank_+1)
        Simplices as unique-point indices (empty when ``rank_ == 0`` or failed).
    status_ : str
        ``ok``, ``reduced_rank``, ``joggled``, ``single_point`` or ``failed``.
    notes_ : list of str
        Human-readable description of every treatment applied (also logged).
    n_duplicates_ : int
        Input points merged into another point.
    n_lost_ : int
        Unique points Qhull left out of every simplex.
    """

    def __init__(self, dup_tol: float = 1e-9, rank_tol: float = 1e-9):
        self.dup_tol = dup_tol
        self.rank_tol = rank_tol

    # ------------------------------------------------------------------
    def fit(self, points) -> "SafeDelaunay":
        p = np.asarray(points, float)
        if p.ndim != 2 or p.shape[0] == 0:
            raise ValueError(f"SafeDelaunay needs a non-empty (n, d) array, got shape {p.shape}")
        if not np.all(np.isfinite(p)):
            raise ValueError("SafeDelaunay: points contain NaN or inf")
        n, d = p.shape
        # caches of an earlier fit (barycentric transforms, the compiled route's tables) describe other points
        self._transform = None
        self._kernel_geometry = None
        self.points_ = p
        self.notes_: list[str] = []
        scale = bbox_diagonal(p)
        self.scale_ = scale if scale > 0 else 1.0
        self.tol_ = self.dup_tol * self.scale_
        self.rep_, self.unique_index_ = merge_duplicates(p, self.tol_)
        self.unique_points_ = p[self.unique_index_]
        u = self.unique_points_.shape[0]
        self.n_duplicates_ = n - u
        if self.n_duplicates_:
            self._note(f"merged {self.n_duplicates_} duplicate point(s) (within {self.tol_:.3g}) into {u} unique points")
        # affine rank
        self.origin_ = self.unique_points_.mean(axis=0)
        centred = self.unique_points_ - self.origin_
        if u > 1:
            _, s, vt = np.linalg.svd(centred, full_matrices=False)
            r = int(np.sum(s > self.rank_tol * s[0])) if s[0] > 0 else 0
        else:
            s, vt, r = np.zeros(1), np.eye(d), 0
        self.rank_ = r
        self.n_lost_ = 0
        self.status_ = "ok"
        self._tri = None
        self._hull_eq = None
        self._order = None
        if r == d:
            self.basis_ = None  # full rank: work in the original coordinates
            coords = self.unique_points_
        else:
            self.basis_ = vt[:r].T  # (d, r)
            coords = centred @ self.basis_
            if r == 0:
                self.status_ = "single_point"
                self._note(f"all {n} point(s) coincide: no simplex; every query falls back to k-NN")
            else:
                self.status_ = "reduced_rank"
                why = f"only {u} distinct point(s)" if u < d + 1 else "points are affinely dependent (collinear/coplanar)"
                self._note(f"{why}: affine rank {r} < {d}; triangulating inside the {r}-D affine hull")
        self.coords_ = coords
        if r == 1:
            order = np.argsort(coords[:, 0], kind="stable")
            self._order = order
            self._sorted = coords[order, 0]
            self.simplices_ = np.stack([order[:-1], order[1:]], axis=1)
        elif r >= 2:
            self.simplices_ = self._qhull(coords)
        else:
            self.simplices_ = np.zeros((0, 1), int)
        return self

    def _note(self, msg: str) -> None:
        self.notes_.append(msg)
        log.warning("SafeDelaunay: %s", msg)

    def _qhull(self, coords):
        try:
            tri = Delaunay(coords)
        except (QhullError, ValueError) as exc:
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            self._note(f"Qhull failed ({first}); retrying with joggled input (QJ)")
            try:
                tri = Delaunay(coords, qhull_options="QJ Qbb Qc")  # no Qz: its point at infinity leaks into simplices with QJ
                self.status_ = "joggled"
            except (QhullError, ValueError) as exc2:
                first2 = str(exc2).strip().splitlines()[0] if str(exc2).strip() else type(exc2).__name__
                self._note(f"Qhull failed again ({first2}); no triangulation, every query falls back to k-NN")
                self.status_ = "failed"
                return np.zeros((0, coords.shape[1] + 1), int)
        if np.any(tri.simplices >= coords.shape[0]):  # defensive: never index past the input points
            self._note("Qhull returned simplices with an extra vertex; no triangulation, falling back to k-NN")
            self.status_ = "failed"
            return np.zeros((0, coords.shape[1] + 1), int)
        self._tri = tri
        try:  # hull facets, to tell "outside" from scipy issue 21279 misses cheaply
            eq = ConvexHull(coords).equations
            self._hull_eq = (eq[:, :-1], eq[:, -1])
        except (QhullError, ValueError):
            self._hull_eq = None
        used = np.zeros(coords.shape[0], bool)
        used[tri.simplices.ravel()] = True
        self.n_lost_ = int((~used).sum())
        self._lost_links = np.zeros((0, 2), int)
        if self.n_lost_:
            links = []
            cop = np.asarray(tri.coplanar)
            for i in np.flatnonzero(~used):
                hit = cop[cop[:, 0] == i]
                if len(hit):
                    links.append((i, int(hit[0, 2])))
                else:  # nearest used vertex
                    cand = np.flatnonzero(used)
                    j = cand[np.argmin(np.linalg.norm(coords[cand] - coords[i], axis=1))]
                    links.append((i, int(j)))
            self._lost_links = np.array(links, int)
            self._note(f"Qhull left {self.n_lost_} point(s) out of every simplex; each joined to its nearest vertex")
        return np.asarray(tri.simplices, int)

    # ------------------------------------------------------------------
    def _to_coords(self, q):
        """Coordinates in the triangulated space and the off-hull residual."""
        q = np.atleast_2d(np.asarray(q, float))
        if self.basis_ is None:
            return q, np.zeros(q.shape[0])
        c = q - self.origin_
        y = c @ self.basis_
        resid = np.linalg.norm(c - y @ self.basis_.T, axis=1)
        return y, resid

    def find(self, q, hint=None):
        """Locate query points.

        Parameters
        ----------
        q : array (m, d)
        hint : array (m,) of int, optional
            A simplex to try first for every point (-1 = none), e.g. where the
            point was one step earlier. A point *strictly* inside its hint
            simplex (every barycentric coordinate > ``HINT_EPS``) is located
            there without a search; that is the only simplex containing it, so
            the answer is the same as without the hint. scipy's
            ``find_simplex`` has no warm start, hence this check by hand.

        Returns
        -------
        simplex : ndarray (m,) of int
            Row of :attr:`simplices_` containing each point, -1 when outside.
        bary : ndarray (m, rank_+1)
            Barycentric coordinates in that simplex (NaN rows when outside).
        """
        y, resid = self._to_coords(q)
        m = y.shape[0]
        r = self.rank_
        s = np.full(m, -1, int)
        bary = np.full((m, r + 1), np.nan)
        if r == 0 or self.simplices_.shape[0] == 0:
            return s, bary
        on_hull = resid <= self.tol_
        if r == 1:
            return self._find_on_line(y[:, 0], on_hull, s, bary)
        s_all = np.full(m, -1, int)
        todo = np.arange(m) if hint is None else self._find_from_hints(y, hint, on_hull, s_all)
        self._search(y, todo, on_hull, s_all)
        s_all[~on_hull] = -1
        ok = s_all >= 0
        s[ok] = s_all[ok]
        if ok.any():
            T = self._barycentric_transform()[s[ok]]  # (mk, r+1, r)
            b = np.einsum("mij,mj->mi", T[:, :r, :], y[ok] - T[:, r, :])
            bary[ok, :r] = b
            bary[ok, r] = 1.0 - b.sum(axis=1)
            if m > 1:
                self._relocate_on_faces(q, y, ok, s, bary)
        return s, bary

    def _find_on_line(self, x, on_hull, s, bary):
        """:meth:`find` on a one-dimensional complex: the segment between sorted vertices holding each ``x``."""
        lo, hi = self._sorted[0], self._sorted[-1]
        inside = on_hull & (x >= lo - self.tol_) & (x <= hi + self.tol_)
        k = np.clip(np.searchsorted(self._sorted, x, side="right") - 1, 0, len(self._sorted) - 2)
        a, b = self._sorted[k], self._sorted[k + 1]
        t = np.clip((x - a) / np.where(b > a, b - a, 1.0), 0.0, 1.0)
        s[inside] = k[inside]
        bary[inside, 0] = 1.0 - t[inside]
        bary[inside, 1] = t[inside]
        return s, bary

    def _find_from_hints(self, y, hint, on_hull, s_all) -> np.ndarray:
        """The warm start: the hint simplex, then up to :data:`HINT_WALK` steps across the face opposite the most
        negative barycentric coordinate (scipy's directed walk, vectorised over points). Points found strictly
        inside a simplex get it in ``s_all``; returns the points still to search."""
        r, m = self.rank_, y.shape[0]
        h = np.asarray(hint, int).copy()
        cand = np.flatnonzero((h >= 0) & on_hull)
        TT = self._barycentric_transform()
        nbr = self._tri.neighbors
        done = np.zeros(m, bool)
        for _ in range(HINT_WALK):
            if not cand.size:
                break
            T = TT[h[cand]]
            b = np.einsum("mij,mj->mi", T[:, :r, :], y[cand] - T[:, r, :])
            full = np.concatenate([b, 1.0 - b.sum(axis=1, keepdims=True)], axis=1)
            bmin = full.min(axis=1)
            keep = bmin > HINT_EPS
            s_all[cand[keep]] = h[cand[keep]]
            done[cand[keep]] = True
            rest = ~keep & np.isfinite(bmin)
            cand, full = cand[rest], full[rest]
            h[cand] = nbr[h[cand], np.argmin(full, axis=1)]
            cand = cand[h[cand] >= 0]
        return np.flatnonzero(~done)

    def _search(self, y, todo, on_hull, s_all) -> None:
        """scipy's ``find_simplex`` for the points ``todo`` (into ``s_all``), after leaving out those outside a hull
        facet, and again by brute force and then exactly for points on the hull it missed."""
        tri, m = self._tri, y.shape[0]
        if todo.size and self._hull_eq is not None:
            # scipy's find_simplex is slow for points outside the hull (about 0.4 ms each in scipy 1.17):
            # points outside a hull facet by more than the tolerance are outside, without a search
            A, c = self._hull_eq
            out_h = np.any(y[todo] @ A.T + c > self.tol_, axis=1)
            todo = todo[~out_h]
        if todo.size == m:
            s_all[:] = tri.find_simplex(y)
        elif todo.size:
            s_all[todo] = tri.find_simplex(y[todo])
        bad = np.flatnonzero((s_all < 0) & on_hull)
        if bad.size and self._hull_eq is not None:
            A, c = self._hull_eq
            in_hull = np.all(y[bad] @ A.T + c <= self.tol_, axis=1)
            bad = bad[in_hull]
        if bad.size:  # scipy issue 21279: directed walk can miss inside points
            s_all[bad] = tri.find_simplex(y[bad], bruteforce=True)
            still = bad[s_all[bad] < 0]
            for i in still:
                s_all[i] = self._exact_locate(y[i])

    def _relocate_on_faces(self, q, y, ok, s, bary) -> None:
        """A point on a shared face lies in several simplices, and scipy's walk (which starts where the previous
        point of the batch ended) may pick any of them. Such points are located again one by one, so the answer
        never depends on the other points of a batch."""
        r = self.rank_
        edge = np.flatnonzero(ok)[bary[ok].min(axis=1) <= HINT_EPS]
        for i in edge:
            j = self.find_one(q[i] if np.ndim(q) == 2 else q)
            s[i] = j
            if j >= 0:
                Tj = self._barycentric_transform()[j]
                bj = Tj[:r, :] @ (y[i] - Tj[r, :])
                bary[i, :r], bary[i, r] = bj, 1.0 - bj.sum()

    def _barycentric_transform(self) -> np.ndarray:
        """scipy's ``Delaunay.transform`` (r+1, r per simplex), computed once with one stacked inverse.

        scipy computes it simplex by simplex on first use (over a second for
        2,500 triangles on a busy machine); ``np.linalg.inv`` on the stacked
        (m, r, r) matrices gives the same array in milliseconds. Degenerate
        simplices get NaN rows, as in scipy.
        """
        T = getattr(self, "_transform", None)
        if T is None:
            pts = self._tri.points
            simp = self._tri.simplices
            r = pts.shape[1]
            last = pts[simp[:, r]]
            M = np.transpose(pts[simp[:, :r]] - last[:, None, :], (0, 2, 1))  # columns = edge vectors
            T = np.full((simp.shape[0], r + 1, r), np.nan)
            det = np.linalg.det(M)
            ok = np.isfinite(det) & (np.abs(det) > 0)
            T[ok, :r, :] = np.linalg.inv(M[ok])
            T[:, r, :] = last
            self._transform = T
        return T

    def _exact_locate(self, y) -> int:
        """Simplex with the largest minimum barycentric coordinate, if >= -eps."""
        T = self._barycentric_transform()
        r = self.rank_
        b = np.einsum("mij,mj->mi", T[:, :r, :], y[None, :] - T[:, r, :])
        full = np.concatenate([b, 1.0 - b.sum(axis=1, keepdims=True)], axis=1)
        worst = full.min(axis=1)
        worst[~np.all(np.isfinite(full), axis=1)] = -np.inf
        j = int(np.argmax(worst))
        return j if worst[j] >= -BARY_EPS else -1

    def find_one(self, q) -> int:
        """Simplex containing one query point, or -1 (outside); low-overhead path.

        Calls scipy's ``find_simplex`` with a (1, d) array (in scipy 1.17 we
        measured a 1-D query of scattered points at milliseconds against a few
        microseconds for the (1, d) form). A -1 goes through the
        guards of :meth:`find` only when the point is inside the hull facets
        (scipy issue 21279), so outside points stay cheap.
        """
        if self._tri is None or self.basis_ is not None:
            return int(self.find(np.reshape(q, (1, -1)))[0][0])
        y = np.reshape(np.asarray(q, float), (1, -1))
        j = int(self._tri.find_simplex(y)[0])
        if j >= 0:
            return j
        if self._hull_eq is not None:
            A, c = self._hull_eq
            if np.any(A @ y[0] + c > self.tol_):
                return -1
        return int(self.find(y)[0][0])

    # ------------------------------------------------------------------
    def unique_edges(self) -> np.ndarray:
        """Undirected edges (u_i < u_j) between unique points sharing a simplex."""
        simp = self.simplices_
        if simp.shape[0] == 0:
            return np.zeros((0, 2), int)
        k = simp.shape[1]
        ii, jj = np.triu_indices(k, 1)
        e = np.concatenate([simp[:, ii].reshape(-1, 1), simp[:, jj].reshape(-1, 1)], axis=1)
        if getattr(self, "_lost_links", None) is not None and len(self._lost_links):
            e = np.concatenate([e, self._lost_links], axis=0)
        e = np.sort(e, axis=1)
        e = e[e[:, 0] != e[:, 1]]
        return unique_pairs(e)

    def edges(self) -> np.ndarray:
        """Undirected edges between *input* points (i < j).

        Every edge between unique points is expanded to all pairs of their
        group members, and the members of a duplicate group are joined to each
        other.
        """
        ue = self.unique_edges()
        groups = [[] for _ in range(self.unique_points_.shape[0])]
        for i, g in enumerate(self.rep_):
            groups[g].append(i)
        if self.n_duplicates_ == 0:
            out = self.unique_index_[ue]
        else:
            rows = []
            for a, b in ue:
                ga, gb = groups[a], groups[b]
                rows.append(np.array(np.meshgrid(ga, gb, indexing="ij")).reshape(2, -1).T)
            for g in groups:
                if len(g) > 1:
                    ii, jj = np.triu_indices(len(g), 1)
                    rows.append(np.stack([np.array(g)[ii], np.array(g)[jj]], axis=1))
            out = np.concatenate(rows, axis=0) if rows else np.zeros((0, 2), int)
        if out.size == 0:
            return np.zeros((0, 2), int)
        out = np.sort(out, axis=1)
        return unique_pairs(out)
