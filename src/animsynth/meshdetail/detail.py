"""Fine detail: decimation to a control mesh, smooth up-sampling, detail frames and
differential (Laplacian) coordinates.

* **Decimation** is a vertex subset chosen once on the rest (first-frame) mesh
  by farthest-point sampling, so it is consistent across all frames and the
  levels are nested (the 5 % set is inside the 10 % set ...).
* **Up-sampling** (control mesh -> fine mesh) interpolates a per-vertex field
  (detail displacements) with the *biharmonic* interpolant on the mesh graph:
  the fine values minimise ``|L f|²`` (uniform graph Laplacian ``L``) subject to
  the control values. It is an RBF-like smooth interpolant (the biharmonic
  equation's Green's function is the thin-plate RBF) measured *along the
  surface*, so detail does not leak across gaps between surfaces that are close
  in space (skirt hem and legs). The map is a precomputed dense
  ``(V, C)`` matrix: reconstruction is one matrix product per frame.
* **Detail frames**: detail ``d = p - p_skinned`` is stored in the rotating frame
  of each vertex's dominant joint (``R_dom(t)^T d``), so it is a function of the
  joint angles and not of the global orientation.
* **Laplacian coordinates** ``δ = L p`` on a k-nearest-neighbour graph of the
  control vertices; decoding solves ``min |L p - (L p_s + δ)|² + eps |p - p_s|²``.
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


class Upsampler:
    """Biharmonic interpolation from control vertices to the whole mesh.

    Parameters
    ----------
    faces : (T, 3) mesh connectivity; n_vertices : int; control : control vertex indices.
    reg : float
        Tiny Tikhonov term so that parts without any control vertex get zero
        (instead of a singular system).

    The free-vertex system ``Q_ff f = -Q_fc c`` (``Q = L^T L``) is factorised
    once (sparse LU). When the dense map ``B = -Q_ff^-1 Q_fc`` has at most (default 0:
    never; measured slower) ``dense_max`` entries it is precomputed (one matrix product per call);
    otherwise each call is one sparse product and one triangular solve for all
    frames and coordinates at once.
    """

    def __init__(self, faces, n_vertices: int, control: np.ndarray, reg: float = 1e-8, dense_max: float = 0):
        control = np.asarray(control, np.int64)
        V = int(n_vertices)
        self.control = control
        self.n_vertices = V
        self.free = None
        if len(control) == V:
            return
        L = uniform_laplacian(mesh_edges(faces), V)
        Q = (L.T @ L).tocsr()
        self.free = np.setdiff1d(np.arange(V), control)
        Qff = Q[self.free][:, self.free] + reg * sparse.eye(len(self.free))
        self._Qfc = Q[self.free][:, control].tocsr()
        self._lu = splu(Qff.tocsc())
        self._B = None
        if len(self.free) * len(control) <= dense_max:
            self._B = -self._lu.solve(self._Qfc.toarray())

    def __call__(self, values: np.ndarray) -> np.ndarray:
        """Interpolate (..., C, k) control values to (..., V, k)."""
        if self.free is None:
            return values
        v = np.moveaxis(np.asarray(values, float), -2, 0)  # (C, ..., k)
        C = v.shape[0]
        flat = v.reshape(C, -1)
        f = self._B @ flat if self._B is not None else self._lu.solve(-(self._Qfc @ flat))
        out = np.empty((self.n_vertices, flat.shape[1]))
        out[self.control] = flat
        out[self.free] = f
        return np.moveaxis(out.reshape((self.n_vertices,) + v.shape[1:]), 0, -2)


def dominant_rotations(W: np.ndarray, dom: np.ndarray) -> np.ndarray:
    """Per-vertex rotation (F, V, 3, 3) of each vertex's dominant joint."""
    return W[:, dom]


def to_local(d_world: np.ndarray, R: np.ndarray) -> np.ndarray:
    """World vectors (F, V, 3) -> frames of rotations R (F, V, 3, 3): R^T d."""
    return np.einsum("fvba,fvb->fva", R, d_world, optimize=True)


def to_world(d_local: np.ndarray, R: np.ndarray) -> np.ndarray:
    return np.einsum("fvab,fvb->fva", R, d_local, optimize=True)


class LaplacianCoder:
    """Differential coordinates on a k-NN graph of (control) vertices.

    The code of a displacement field ``d`` (C, 3) is ``[L d ; mean_c(d)]``: the
    uniform-Laplacian coordinates plus the mean displacement of every connected
    component ``c`` of the graph (the Laplacian's null space), so decoding
    ``argmin |M p - code|²`` with ``M = [L ; component means]`` is exact for an
    exact code and spreads errors smoothly otherwise.

    Parameters
    ----------
    rest : (C, 3) rest positions of the vertices; k : neighbours.

    Attributes
    ----------
    n_extra : number of component-mean rows appended to the C Laplacian rows.
    """

    def __init__(self, rest: np.ndarray, k: int = 6):
        from scipy.sparse.csgraph import connected_components

        rest = np.asarray(rest, float)
        n = len(rest)
        k = max(1, min(k, n - 1))
        _, nb = cKDTree(rest).query(rest, k + 1)
        edges = np.unique(np.sort(np.stack([np.repeat(np.arange(n), k), nb[:, 1:].ravel()], axis=1), axis=1), axis=0)
        self.L = uniform_laplacian(edges, n)
        A = sparse.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
        n_comp, lab = connected_components(A, directed=False)
        Cm = sparse.coo_matrix((1.0 / np.bincount(lab)[lab], (lab, np.arange(n))), shape=(n_comp, n))
        self.M = sparse.vstack([self.L, Cm]).tocsr()
        self.n_extra = int(n_comp)
        self._Md = self.M.toarray()
        self._lu = splu((self.M.T @ self.M).tocsc())

    def encode(self, disp: np.ndarray) -> np.ndarray:
        """Displacement field (F, C, 3) -> code (F, C + n_extra, 3)."""
        return np.einsum("ij,fjk->fik", self._Md, disp, optimize=True)

    def decode(self, code: np.ndarray) -> np.ndarray:
        """Code (F, C + n_extra, 3) -> least-squares displacement field (F, C, 3)."""
        F = code.shape[0]
        C = self._Md.shape[1]
        rhs = np.einsum("ji,fjk->fik", self._Md, code, optimize=True)
        out = self._lu.solve(np.moveaxis(rhs, 0, 1).reshape(C, -1))
        return np.moveaxis(out.reshape(C, F, 3), 1, 0)
