"""Fine detail: control meshes, RBF reconstruction, detail frames and
differential (Laplacian) coordinates.

* **Control mesh** (:class:`ControlMesh`): the paper's decimation — quadric
  edge collapses of the first frame, recorded and replayed on every frame
  (``fast-simplification``) — or, as a labelled variant, a farthest-point
  vertex subset of the first frame. Both are the same for all frames.
* **Reconstruction** (:class:`RBFUpsampler`): the full mesh's detail is the
  thin-plate RBF interpolant of the control detail (the local interpolant of
  :class:`scipy.interpolate.RBFInterpolator`), precomputed once as a sparse
  ``(V, C)`` map, so each frame costs one sparse product.
* **Detail frames**: detail ``d = p - p_skinned`` is stored in the rotating frame
  of each control vertex's dominant joint (``R_dom(t)^T d``), so it is a
  function of the joint angles and not of the global orientation.
* **Laplacian coordinates** (:class:`LaplacianCoder`) on the control mesh's
  triangles (cotangent Laplacian), decoded with one sparse factorisation
  reused for every frame.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu
from scipy.spatial import cKDTree


def farthest_point_order(points: np.ndarray, n: int, start: int = 0) -> np.ndarray:
    """Indices of ``n`` points chosen greedily, each farthest from those already chosen."""
    P = np.asarray(points, float)
    n = int(min(n, len(P)))
    order = np.empty(n, dtype=np.int64)
    d = np.full(len(P), np.inf)
    cur = int(start)
    for k in range(n):
        order[k] = cur
        d = np.minimum(d, np.sum((P - P[cur]) ** 2, axis=1))
        cur = int(np.argmax(d))
    return order


def level_indices(order: np.ndarray, n_vertices: int, percent: float) -> np.ndarray:
    """Control vertex indices of a resolution level (percent of all vertices), sorted."""
    if not 0 < percent <= 100:
        raise ValueError(f"resolution level must be in (0, 100], got {percent}")
    if percent >= 100:
        return np.arange(n_vertices)
    n = max(4, int(round(n_vertices * percent / 100.0)))
    if n > len(order):
        raise ValueError(f"level {percent}% needs {n} samples, only {len(order)} were ordered")
    return np.sort(order[:n])


def mesh_edges(faces: np.ndarray) -> np.ndarray:
    f = np.asarray(faces, np.int64)
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    e.sort(axis=1)
    return np.unique(e, axis=0)


def uniform_laplacian(edges: np.ndarray, n: int) -> sparse.csr_matrix:
    """``L = I - D^-1 A`` (uniform weights); isolated vertices get a zero row."""
    i, j = edges[:, 0], edges[:, 1]
    A = sparse.coo_matrix((np.ones(2 * len(i)), (np.r_[i, j], np.r_[j, i])), shape=(n, n)).tocsr()
    A.data[:] = 1.0
    deg = np.asarray(A.sum(axis=1)).ravel()
    inv = np.where(deg > 0, 1.0 / np.maximum(deg, 1), 0.0)
    return (sparse.diags((deg > 0).astype(float)) - sparse.diags(inv) @ A).tocsr()


def to_local(d_world: np.ndarray, R: np.ndarray) -> np.ndarray:
    """World vectors (F, V, 3) -> frames of rotations R (F, V, 3, 3): R^T d."""
    return np.einsum("fvba,fvb->fva", R, d_world, optimize=True)


def to_world(d_local: np.ndarray, R: np.ndarray) -> np.ndarray:
    return np.einsum("fvab,fvb->fva", R, d_local, optimize=True)


class LaplacianCoder:
    """Differential (Laplacian) coordinates of a displacement field on the control mesh.

    With triangles (the control mesh of replayed edge collapses) the operator
    is the cotangent Laplacian of the rest control mesh (``robust_laplacian``;
    its "intrinsic Delaunay" version stays well-behaved on decimated
    triangles); without (a farthest-point vertex subset) it is the uniform
    Laplacian of a k-nearest-neighbour graph. The code of a field ``d`` (C, 3)
    is ``[L d ; mean_c(d)]``: the Laplacian coordinates plus the mean of every
    connected component (the Laplacian's null space), so decoding
    ``argmin |M p - code|²`` (``M = [L ; component means]``) is exact for an
    exact code and spreads errors smoothly otherwise. ``M^T M`` is factorised
    once (sparse LU) and reused for every frame.

    Parameters
    ----------
    rest : (C, 3) rest positions; faces : (T, 3) or None; k : neighbours of the k-NN graph.

    Attributes
    ----------
    n_extra : number of component-mean rows appended to the C Laplacian rows.
    """

    def __init__(self, rest: np.ndarray, faces: np.ndarray | None = None, k: int = 6):
        from scipy.sparse.csgraph import connected_components

        rest = np.asarray(rest, float)
        n = len(rest)
        if faces is not None:
            import robust_laplacian

            edges = mesh_edges(faces)
            self.L = robust_laplacian.mesh_laplacian(rest, np.asarray(faces, np.int64))[0].tocsr()
        else:
            k = max(1, min(k, n - 1))
            _, nb = cKDTree(rest).query(rest, k + 1)
            edges = np.unique(np.sort(np.stack([np.repeat(np.arange(n), k), nb[:, 1:].ravel()], axis=1), axis=1),
                              axis=0)
            self.L = uniform_laplacian(edges, n)
        A = sparse.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
        n_comp, lab = connected_components(A, directed=False)
        Cm = sparse.coo_matrix((1.0 / np.bincount(lab)[lab], (lab, np.arange(n))), shape=(n_comp, n))
        self.M = sparse.vstack([self.L, Cm]).tocsr()
        self.n_extra = int(n_comp)
        self._lu = splu((self.M.T @ self.M).tocsc())

    def encode(self, disp: np.ndarray) -> np.ndarray:
        """Displacement field (F, C, 3) -> code (F, C + n_extra, 3)."""
        F, C = disp.shape[:2]
        out = self.M @ np.moveaxis(disp, 0, 1).reshape(C, -1)
        return np.moveaxis(out.reshape(-1, F, 3), 1, 0)

    def decode(self, code: np.ndarray) -> np.ndarray:
        """Code (F, C + n_extra, 3) -> least-squares displacement field (F, C, 3)."""
        F = code.shape[0]
        C = self.M.shape[1]
        rhs = self.M.T @ np.moveaxis(code, 0, 1).reshape(code.shape[1], -1)
        out = self._lu.solve(rhs)
        return np.moveaxis(out.reshape(C, F, 3), 1, 0)


# --------------------------------------------------------------------------- control meshes
class ControlMesh:
    """A control mesh of the rest mesh, consistent over all frames.

    Parameters
    ----------
    rest : (V, 3) rest (first-frame) mesh; faces : (T, 3)
    percent : float
        Size in percent of the vertices (100: the mesh itself).
    method : {"collapse", "farthest"}
        ``collapse`` (the paper's): quadric edge collapses of the rest mesh
        (:func:`fast_simplification.simplify` with ``return_collapses=True``)
        recorded once; replaying them
        (:func:`fast_simplification.replay_simplification`) gives the map from
        every vertex to the control vertex it collapsed into, and a control
        vertex's position in any frame is the centroid of its vertices in
        that frame (a fixed sparse averaging, linear and exact under rigid
        motion). The replayed quadric-optimal positions themselves
        (:meth:`replay`) are not used for the detail: where the optimum is
        ill-conditioned (flat or cylindrical patches) they jump between
        frames — up to 0.3 m on the synthetic character.
        ``farthest``: a farthest-point vertex subset of the rest mesh (no
        connectivity; Laplacian coordinates then use a k-NN graph).
    order : optional precomputed farthest-point order (for nested subsets).

    Attributes
    ----------
    rest_ : (C, 3) control positions in the rest frame
    faces_ : (T', 3) control-mesh triangles, or None
    source_ : (C,) an original vertex represented by each control vertex
        (nearest absorbed vertex; used for its dominant joint)
    collapses_ : (K, 2) recorded collapses; mapping_ : (V,) control vertex of
        every vertex; average_ : sparse (C, V) centroid map (collapse only)
    """

    def __init__(self, rest, faces, percent: float, method: str = "collapse", order=None):
        rest = np.asarray(rest, float)
        faces = np.asarray(faces, np.int64)
        if method not in ("collapse", "farthest"):
            raise ValueError(f"decimation must be collapse or farthest, got {method!r}")
        self.method = method
        self.percent = float(percent)
        self.n_vertices = len(rest)
        self.collapses_ = None
        if percent >= 100:
            self.rest_, self.faces_, self.source_ = rest, faces, np.arange(len(rest))
            self.identity = True
            return
        self.identity = False
        if method == "farthest":
            order = farthest_point_order(rest, int(np.ceil(len(rest) * percent / 100.0)) + 1) if order is None else order
            self.source_ = level_indices(order, len(rest), percent)
            self.rest_, self.faces_ = rest[self.source_], None
            return
        import fast_simplification

        target = max(4, int(round(2 * len(rest) * percent / 100.0)))
        _, fc, col = fast_simplification.simplify(rest, faces, target_count=target, return_collapses=True)
        self.collapses_ = np.asarray(col)
        self.faces_ = np.asarray(fc, np.int64)
        _, _, mapping = fast_simplification.replay_simplification(rest, faces, self.collapses_)
        self.mapping_ = np.asarray(mapping, np.int64)
        ok = np.flatnonzero(self.mapping_ >= 0)
        C = int(self.mapping_.max()) + 1
        counts = np.bincount(self.mapping_[ok], minlength=C).astype(float)
        self.average_ = sparse.csr_matrix((1.0 / counts[self.mapping_[ok]], (self.mapping_[ok], ok)),
                                          shape=(C, len(rest)))
        self.rest_ = self.average_ @ rest
        d = np.linalg.norm(rest[ok] - self.rest_[self.mapping_[ok]], axis=1)
        order = np.lexsort((d, self.mapping_[ok]))  # per control vertex, its nearest absorbed vertex first
        first = np.r_[True, np.diff(self.mapping_[ok][order]) != 0]
        self.source_ = ok[order][first]

    def replay(self, frames: np.ndarray, faces: np.ndarray) -> np.ndarray:
        """The recorded collapses replayed on each frame: quadric-optimal control positions (F, C, 3)."""
        import fast_simplification

        return np.stack([np.asarray(fast_simplification.replay_simplification(f, np.asarray(faces, np.int64),
                                                                             self.collapses_)[0], float)
                         for f in np.asarray(frames, float)])

    @property
    def n_control(self) -> int:
        return len(self.rest_)

    def positions(self, frames: np.ndarray, faces: np.ndarray) -> np.ndarray:
        """Control positions (F, C, 3) of full-mesh frames (F, V, 3)."""
        frames = np.asarray(frames, float)
        if self.identity:
            return frames
        if self.method == "farthest":
            return frames[:, self.source_]
        F, V = frames.shape[:2]
        out = self.average_ @ np.moveaxis(frames, 0, 1).reshape(V, -1)
        return np.moveaxis(out.reshape(-1, F, 3), 1, 0)


class RBFUpsampler:
    """Control values -> full mesh by radial basis functions, as one precomputed sparse map.

    The value at a fine vertex is the thin-plate-spline RBF interpolant (with
    a linear polynomial) of its ``neighbors`` nearest control vertices in the
    rest pose — the interpolant of :class:`scipy.interpolate.RBFInterpolator`
    with ``kernel="thin_plate_spline", degree=1, neighbors=k`` (the tests check
    they agree). That class does not expose its interpolation weights, which
    are linear in the data; they are computed here once (one batched small
    solve per fine vertex) into a sparse ``(V, C)`` matrix so that every frame
    is reconstructed with one sparse product ("factor once, reuse"). Where a
    neighbourhood is degenerate (coplanar control points: the linear part is
    undetermined and the local system singular) the minimum-norm solution is
    used for all vertices.

    Parameters
    ----------
    control_rest : (C, 3); fine_rest : (V, 3); neighbors : int
    """

    def __init__(self, control_rest: np.ndarray, fine_rest: np.ndarray, neighbors: int = 24):
        Y = np.asarray(control_rest, float)
        X = np.asarray(fine_rest, float)
        C, V = len(Y), len(X)
        k = int(min(neighbors, C))
        self.shape = (V, C)
        _, nb = cKDTree(Y).query(X, k)
        nb = nb.reshape(V, k)
        Yl = Y[nb] - X[:, None]  # local coordinates, centred at the query (shift invariance)
        s = np.maximum(np.linalg.norm(Yl, axis=-1).max(axis=1), 1e-12)[:, None, None]
        Yl = Yl / s  # and scaled (TPS with a linear polynomial is scale invariant)

        def tps(r):
            with np.errstate(divide="ignore", invalid="ignore"):
                return np.where(r > 0, r * r * np.log(np.where(r > 0, r, 1.0)), 0.0)

        A = np.zeros((V, k + 4, k + 4))
        A[:, :k, :k] = tps(np.linalg.norm(Yl[:, :, None] - Yl[:, None], axis=-1))
        A[:, :k, k] = A[:, k, :k] = 1.0
        A[:, :k, k + 1:] = Yl
        A[:, k + 1:, :k] = np.swapaxes(Yl, 1, 2)
        b = np.zeros((V, k + 4))
        b[:, :k] = tps(np.linalg.norm(Yl, axis=-1))
        b[:, k] = 1.0  # query at the local origin: linear terms 0
        try:
            w = np.linalg.solve(A, b[..., None])[..., 0][:, :k]
        except np.linalg.LinAlgError:
            # some neighbourhoods are degenerate (e.g. coplanar control points on a flat patch leave the
            # linear polynomial undetermined): minimum-norm solutions, which still interpolate
            w = (np.linalg.pinv(A, rcond=1e-12, hermitian=True) @ b[..., None])[..., 0][:, :k]
        self.B = sparse.csr_matrix((w.ravel(), nb.ravel(), np.arange(0, V * k + 1, k)), shape=(V, C))

    def __call__(self, values: np.ndarray) -> np.ndarray:
        """Interpolate (..., C, d) control values to (..., V, d)."""
        v = np.moveaxis(np.asarray(values, float), -2, 0)
        C = v.shape[0]
        out = self.B @ v.reshape(C, -1)
        return np.moveaxis(out.reshape((self.shape[0],) + v.shape[1:]), 0, -2)
