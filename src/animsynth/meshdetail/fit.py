"""Per-frame skeleton pose fitting against a mesh sequence, and joint refinement.

:class:`PoseFitter` estimates, for every frame, the root translation and
three angles per joint so that the linear-blend-skinned rest mesh matches the
frame in the least-squares sense. It works root-to-leaves, vectorised over
frames:

1. **initial pass** — each joint's world rotation is the weighted orthogonal
   Procrustes (Kabsch) solution that maps its vertices (weight ``w_ij²``) from
   the rest pose to the frame about the joint's start, which the already
   fitted parent fixes (the root also solves its translation);
2. **Levenberg-Marquardt** on the full LBS residual
   ``sum_i c_i |sum_k w_ik T_k v_i - p_i|²`` over the root translation and
   all joint rotations jointly, with the analytic Jacobian (a small world-frame
   rotation ``w`` of joint ``k`` moves vertex ``i`` by ``w x y_ik`` with
   ``y_ik = sum_{j in subtree(k)} w_ij (x_ij - s_k)``);
3. **robust reweighting** — after each iteration, vertices with large residuals
   (loose clothing the skeleton cannot explain) are down-weighted
   (Cauchy weights, scale ``2.5 x`` the median residual, at least 5 mm).

Angles are the extrinsic-xyz Euler angles of the local rotations,
unwrapped over time.

:func:`refine_joints_from_motion` moves joint centres to the points that
move most rigidly with both adjacent body parts over the sequence (the
classic rotation-centre least squares), for embeddings that were only
roughly placed.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy import sparse
from threadpoolctl import threadpool_limits

from ..kinematics import matrix_to_xyz_euler, tree_local
from ..skinning import Rig, inside_mesh, joint_transforms, lbs, winding_number

log = logging.getLogger("animsynth.meshdetail.fit")


def _kabsch(a: np.ndarray, b: np.ndarray, c: np.ndarray, translate: bool):
    """Weighted Kabsch, batched over frames.

    a : (n, 3) rest-side points; b : (F, n, 3) targets; c : (F, n) or (n,) weights.
    Returns R (F, 3, 3) (and t (F, 3) if translate) minimising sum c |R a + t - b|².
    """
    F = b.shape[0]
    c = np.broadcast_to(c, (F, a.shape[0]))
    cs = np.maximum(c.sum(axis=1), 1e-12)
    if translate:
        ca = np.einsum("fn,nk->fk", c, a) / cs[:, None]
        cb = np.einsum("fn,fnk->fk", c, b) / cs[:, None]
        A = a[None] - ca[:, None]
        B = b - cb[:, None]
        H = np.einsum("fn,fni,fnj->fij", c, A, B)
    else:
        H = np.einsum("fn,ni,fnj->fij", c, a, b)
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(np.swapaxes(Vt, -1, -2) @ np.swapaxes(U, -1, -2)))
    Dm = np.zeros((F, 3, 3))
    Dm[:, 0, 0] = 1
    Dm[:, 1, 1] = 1
    Dm[:, 2, 2] = d
    R = np.swapaxes(Vt, -1, -2) @ Dm @ np.swapaxes(U, -1, -2)
    if translate:
        t = cb - np.einsum("fij,fj->fi", R, ca)
        return R, t
    return R


def _fk_from_world(rig: Rig, W: np.ndarray, root_t: np.ndarray) -> np.ndarray:
    off = rig.offsets
    S = np.empty(W.shape[:2] + (3,))
    for j, p in enumerate(rig.parents):
        S[:, j] = root_t if p < 0 else S[:, p] + W[:, p] @ off[j]
    return S


def _world_from_local(rig: Rig, L: np.ndarray) -> np.ndarray:
    W = np.empty_like(L)
    for j, p in enumerate(rig.parents):
        W[:, j] = L[:, j] if p < 0 else W[:, p] @ L[:, j]
    return W


def _skew(v):
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1), np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


class PoseFitter:
    """Fit root translation and per-joint Euler angles to every frame of a mesh sequence.

    Parameters
    ----------
    iterations : int
        Levenberg-Marquardt iterations on the full LBS residual after the initial pass.
    robust : bool
        Down-weight vertices with large residuals (loose clothing).
    min_weight : float
        Vertices with a skinning weight below this do not inform a joint.
    max_vertices : int
        The Levenberg-Marquardt stage uses at most this many vertices (an even
        stride through the vertex list); the initial pass uses all.
    tol : float
        Stop when no frame's cost improves by more than this relative amount.

    Attributes
    ----------
    root_t_ : (F, 3), angles_ : (F, J, 3) radians, W_ : (F, J, 3, 3) world rotations,
    residual_ : (F,) mean vertex distance of the LBS fit.
    """

    def __init__(self, iterations: int = 8, robust: bool = True, min_weight: float = 0.05,
                 max_vertices: int = 2500, tol: float = 1e-5):
        self.iterations = int(iterations)
        self.max_vertices = int(max_vertices)
        self.tol = float(tol)
        self.robust = bool(robust)
        self.min_weight = float(min_weight)

    def fit(self, rig: Rig, weights, rest: np.ndarray, frames: np.ndarray) -> "PoseFitter":
        frames = np.asarray(frames, float)
        if frames.ndim == 2:
            frames = frames[None]
        if frames.shape[1:] != rest.shape:
            raise ValueError(f"frames have shape {frames.shape[1:]}, rest mesh {rest.shape}")
        if not np.all(np.isfinite(frames)):
            raise ValueError("mesh frames contain non-finite coordinates")
        Wt = weights.toarray() if sparse.issparse(weights) else np.asarray(weights, float)
        Wsp = sparse.csr_matrix(Wt)
        F, V = frames.shape[:2]
        J = rig.n_joints
        sets = [np.flatnonzero(Wt[:, j] >= self.min_weight) for j in range(J)]
        # 1. initial pass: dominant vertices, Kabsch about the joint start
        W = np.tile(np.eye(3), (F, J, 1, 1))
        S = np.zeros((F, J, 3))
        dom = np.argmax(Wt, axis=1)
        root_t = None
        for j, p in enumerate(rig.parents):
            idx = np.flatnonzero((dom == j) & (Wt[:, j] >= 0.5))
            if len(idx) < 3:
                idx = sets[j]
            if len(idx) < 3:
                W[:, j] = W[:, p] if p >= 0 else np.eye(3)
                S[:, j] = S[:, p] + W[:, p] @ rig.offsets[j] if p >= 0 else frames.mean(axis=1)
                continue
            a = rest[idx] - rig.starts[j]
            c = Wt[idx, j] ** 2
            if p < 0:
                R, t = _kabsch(a, frames[:, idx], c, translate=True)
                W[:, j], S[:, j] = R, t
                root_t = t
            else:
                S[:, j] = S[:, p] + W[:, p] @ rig.offsets[j]
                W[:, j] = _kabsch(a, frames[:, idx] - S[:, j, None], c, translate=False)
        # 2. Levenberg-Marquardt on the full LBS residual, chunks of frames, robust weights
        desc = np.zeros((J, J))
        for k in range(J):
            j = k
            while j >= 0:
                desc[k, j] = 1.0  # k is in the subtree of j
                j = rig.parents[j]
        L = tree_local(rig.parents, W)
        sub = np.unique(np.linspace(0, V - 1, min(V, self.max_vertices)).round().astype(int))
        chunk = max(1, int(4e6 // (len(sub) * J * 3)))
        for f0 in range(0, F, chunk):
            sl = slice(f0, min(F, f0 + chunk))
            with threadpool_limits(limits=1, user_api="blas"):
                L[sl], root_t[sl] = self._lm(rig, Wt[sub], desc, rest[sub], frames[sl][:, sub], L[sl], root_t[sl])
        W = _world_from_local(rig, L)
        S = _fk_from_world(rig, W, root_t)
        self.W_ = W
        self.root_t_ = root_t
        self.angles_ = np.unwrap(matrix_to_xyz_euler(tree_local(rig.parents, W)), axis=0)
        self.residual_ = np.linalg.norm(lbs(Wsp, rest, joint_transforms(rig, W, S)) - frames, axis=-1).mean(axis=1)
        return self

    def _lm(self, rig, Wt, desc, rest, P, L, root_t):
        """Levenberg-Marquardt iterations for a chunk of frames (F, V, 3)."""
        from scipy.spatial.transform import Rotation

        F, V = P.shape[:2]
        J = rig.n_joints
        K = int(min(J, max(1, np.max(np.sum(Wt > 0, axis=1)))))
        jk = np.argsort(-Wt, axis=1)[:, :K]  # (V, K) influencing joints
        wk = np.take_along_axis(Wt, jk, axis=1)  # (V, K)
        A = rest[:, None, :] - rig.starts[jk]  # (V, K, 3)
        descK = desc[jk]  # (V, K, J): is influence k inside the subtree of joint j
        m = Wt @ desc  # (V, J): weight mass in each joint's subtree
        c = np.ones((F, V))
        lam = np.full(F, 1e-3)

        def evaluate(L, root_t):
            W = _world_from_local(rig, L)
            S = _fk_from_world(rig, W, root_t)
            X = np.einsum("fvkab,vkb->fvka", W[:, jk], A, optimize=True) + S[:, jk]  # (F, V, K, 3)
            pred = np.einsum("vk,fvka->fva", wk, X, optimize=True)
            return W, S, X, pred

        W, S, X, pred = evaluate(L, root_t)
        for it in range(self.iterations):
            r = pred - P
            res = np.linalg.norm(r, axis=-1)
            if self.robust:
                scale = np.maximum(2.5 * np.median(res, axis=1, keepdims=True), 0.005)
                c = 1.0 / (1.0 + (res / scale) ** 2)
            cost = np.sum(c * res**2, axis=1)
            wx = wk[None, :, :, None] * X  # (F, V, K, 3)
            Y = np.einsum("fvka,vkj->fvja", wx, descK, optimize=True) - m[None, :, :, None] * S[:, None]  # (F, V, J, 3)
            sc = np.sqrt(c)
            Yc = np.ascontiguousarray(Y * sc[..., None, None]).reshape(F, V, 3 * J)
            G = np.stack([Yc[f].T @ Yc[f] for f in range(F)]).reshape(F, J, 3, J, 3)
            tr = np.einsum("fkala->fkl", G)
            H = np.zeros((F, 3 + 3 * J, 3 + 3 * J))
            blk = tr[:, :, None, :, None] * np.eye(3)[None, None, :, None, :] - np.swapaxes(G, 2, 4)
            H[:, 3:, 3:] = blk.reshape(F, 3 * J, 3 * J)
            sy = np.matmul(sc[:, None, :], Yc)[:, 0].reshape(F, J, 3)  # sum_v c Y
            cross = -_skew(sy)  # (F, J, 3, 3): d t-residual / d w_k
            H[:, :3, 3:] = np.moveaxis(cross, 1, 2).reshape(F, 3, 3 * J)
            H[:, 3:, :3] = np.swapaxes(H[:, :3, 3:], 1, 2)
            H[:, :3, :3] = c.sum(axis=1)[:, None, None] * np.eye(3)
            g = np.zeros((F, 3 + 3 * J))
            g[:, :3] = np.einsum("fv,fva->fa", c, r)
            # sum_v c (Y x r), from the products M[f, (k, b), e] = sum_v c Y[f, v, k, b] r[f, v, e] (one batched
            # matrix product instead of a cross product of every vertex and joint)
            M = np.matmul(np.swapaxes(Yc, 1, 2), sc[..., None] * r).reshape(F, J, 3, 3)
            g[:, 3:] = np.stack([M[..., 1, 2] - M[..., 2, 1], M[..., 2, 0] - M[..., 0, 2],
                                 M[..., 0, 1] - M[..., 1, 0]], axis=-1).reshape(F, 3 * J)
            diag = np.einsum("fii->fi", H)
            Hd = H + (lam[:, None] * np.maximum(diag, 1e-9))[:, :, None] * np.eye(3 + 3 * J)[None]
            step = -np.linalg.solve(Hd, g[..., None])[..., 0]
            dt, w = step[:, :3], step[:, 3:].reshape(F, J, 3)
            Rw = Rotation.from_rotvec(w.reshape(-1, 3)).as_matrix().reshape(F, J, 3, 3)
            Lnew = np.empty_like(L)
            for j, p in enumerate(rig.parents):
                Wp = np.eye(3)[None] if p < 0 else W[:, p]
                Lnew[:, j] = np.swapaxes(Wp, -1, -2) @ Rw[:, j] @ Wp @ L[:, j]
            # the root rotation pivots about the root start: translation unchanged by it
            tnew = root_t + dt
            W2, S2, X2, pred2 = evaluate(Lnew, tnew)
            cost2 = np.sum(c * np.sum((pred2 - P) ** 2, axis=-1), axis=1)
            ok = cost2 <= cost
            lam = np.where(ok, lam * 0.3, lam * 10.0)
            L = np.where(ok[:, None, None, None], Lnew, L)
            root_t = np.where(ok[:, None], tnew, root_t)
            # each frame is evaluated alone: the accepted frames' evaluation is the candidate's
            W = np.where(ok[:, None, None, None], W2, W)
            S = np.where(ok[:, None, None], S2, S)
            X = np.where(ok[:, None, None, None], X2, X)
            pred = np.where(ok[:, None, None], pred2, pred)
            if np.all(np.abs(cost2 - cost) <= self.tol * np.maximum(cost, 1e-30)):
                break
        log.info("pose fit LM: mean residual %.3f mm", 1000 * np.linalg.norm(pred - P, axis=-1).mean())
        return L, root_t


def refine_joints_from_motion(rig: Rig, weights, rest: np.ndarray, frames: np.ndarray,
                              min_weight: float = 0.5, return_status: bool = False):
    """Move every non-root joint start to its least-squares rotation centre.

    Each body part (the vertices a joint dominates, with weight >= ``min_weight``)
    gets a free rigid transform per frame (Kabsch). The joint between part
    ``p`` (parent) and part ``j`` is the rest-pose point ``c`` minimising
    ``sum_t |T_p(t) c - T_j(t) c|²`` — the point that both parts carry along
    identically — solved as one linear least-squares problem (with a small
    pull towards the initial position for directions the motion leaves
    undetermined, e.g. along a hinge axis). Segment ends move with the
    joint starts of the children they point at.

    Returns the refined Rig (and, with ``return_status``, a list with one
    status per joint: ``"moved"``, ``"root"``, ``"too few rigid vertices"``
    or ``"moved too far"``).
    """
    Wt = weights.toarray() if sparse.issparse(weights) else np.asarray(weights, float)
    frames = np.asarray(frames, float)
    J = rig.n_joints
    T = [None] * J
    dom = np.argmax(Wt, axis=1)
    for j in range(J):
        idx = np.flatnonzero((dom == j) & (Wt[:, j] >= min_weight))
        if len(idx) >= 4:
            R, t = _kabsch(rest[idx], frames[:, idx], np.ones(len(idx)), translate=True)
            T[j] = (R, t)
    starts = rig.starts.copy()
    ends = rig.ends.copy()
    scale = np.linalg.norm(rest.max(0) - rest.min(0))
    status = ["root" if p < 0 else "too few rigid vertices" for p in rig.parents]
    for j, p in enumerate(rig.parents):
        if p < 0 or T[j] is None or T[p] is None:
            continue
        Rp, tp = T[p]
        Rj, tj = T[j]
        A = (Rp - Rj).reshape(-1, 3)
        b = (tj - tp).reshape(-1)
        lam = 1e-3 * len(Rp)
        c0 = rig.starts[j]
        c = np.linalg.solve(A.T @ A + lam * np.eye(3), A.T @ b + lam * c0)
        if np.linalg.norm(c - c0) < 0.1 * scale:
            starts[j] = c
            status[j] = "moved"
        else:
            status[j] = "moved too far"
            log.warning("joint %s: motion-based centre moved %.3f, kept the initial position", rig.names[j],
                        np.linalg.norm(c - c0))
    for j, p in enumerate(rig.parents):
        kids = [k for k, q in enumerate(rig.parents) if q == j]
        if len(kids) == 1:
            ends[j] = starts[kids[0]]
        else:
            ends[j] = ends[j] + (starts[j] - rig.starts[j])
    out = Rig(starts, ends, rig.names, rig.parents)
    return (out, status) if return_status else out


def nearest_interior_point(point: np.ndarray, vertices: np.ndarray, faces: np.ndarray, radius: float = 0.08,
                           step: float = 0.02) -> np.ndarray | None:
    """The interior point near ``point`` that is deep and close: on a grid of spacing ``step`` within
    ``radius``, among points inside the closed mesh (winding number), the one maximising
    ``clearance - distance to point`` (clearance = distance to the nearest mesh vertex). ``None`` if
    no grid point is inside."""
    from scipy.spatial import cKDTree

    g = np.arange(-radius, radius + 1e-9, step)
    G = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    G = G[np.linalg.norm(G, axis=1) <= radius] + point
    ins = inside_mesh(G, vertices, faces)
    if not ins.any():
        return None
    G = G[ins]
    clear = cKDTree(vertices).query(G)[0]
    return G[np.argmax(clear - np.linalg.norm(G - point, axis=1))]


def place_joints(rig: Rig, weights, rest: np.ndarray, faces: np.ndarray, frames: np.ndarray | None,
                 max_move: float = 0.08, cache: dict | None = None):
    """Joint centres from the mesh motion, checked to lie inside the first-frame mesh.

    Every non-root joint first gets its least-squares rotation centre
    (:func:`refine_joints_from_motion`, on ``frames``, pass the training frames;
    ``None`` skips it). A motion-based centre is kept only if it lies inside
    the closed rest mesh (generalised winding number) and moved at most
    ``max_move``; otherwise the initial position is kept if it is inside, and a
    joint that is still outside goes to :func:`nearest_interior_point`. Segment
    ends follow the child joints.

    ``cache`` (optional dict, kept by the caller between calls with the same ``rig``, ``rest`` and
    ``faces``, e.g. the folds of a cross-validation): the winding numbers of the initial starts and
    the interior points found for them are computed once and reused (they depend on neither
    ``weights`` nor ``frames``).

    Returns
    -------
    rig : the placed Rig
    table : pandas.DataFrame, one row per joint (initial/motion/final position,
        winding number of the final centre, ``inside``, ``placement``, ``moved_mm``)
    """
    import pandas as pd

    faces = np.asarray(faces, np.int64)
    if frames is None:  # report only
        wn = winding_number(rig.starts, rest, faces)
        return rig, pd.DataFrame({"joint": list(rig.names), **{a: np.round(rig.starts[:, i], 4) for i, a in enumerate("xyz")},
                                  "moved_mm": 0.0, "winding_number": np.round(wn, 3), "inside": np.abs(wn) > 0.5,
                                  "placement": "given"})
    moved, status = refine_joints_from_motion(rig, weights, rest, frames, return_status=True)
    cache = {} if cache is None else cache
    if "initial_winding" not in cache:
        cache["initial_winding"] = winding_number(rig.starts, rest, faces)
    wn0 = cache["initial_winding"]
    wn1 = winding_number(moved.starts, rest, faces)
    starts = rig.starts.copy()
    how = []
    for j in range(rig.n_joints):
        d = np.linalg.norm(moved.starts[j] - rig.starts[j])
        if d > 1e-9 and abs(wn1[j]) > 0.5 and d <= max_move:
            starts[j], h = moved.starts[j], "rotation centre from motion"
        elif abs(wn0[j]) > 0.5:
            h = "initial (motion-based centre " + ("outside the mesh" if d > 1e-9 and abs(wn1[j]) <= 0.5 else
                                                  f"moved > {1000 * max_move:.0f} mm" if d > max_move else
                                                  {"root": "n/a: root", "moved too far": "moved too far",
                                                   "too few rigid vertices": "n/a: < 4 dominated vertices with weight "
                                                   ">= 0.5 on a part"}.get(status[j], status[j])) + ")"
        else:
            key = ("nearest_interior", j)
            if key not in cache:
                cache[key] = nearest_interior_point(rig.starts[j], rest, faces)
            p = cache[key]
            if p is None:
                h = "initial, outside the mesh (no interior point within 8 cm)"
                log.warning("joint %s lies outside the first-frame mesh", rig.names[j])
            else:
                starts[j], h = p, "nearest interior point (initial position outside the mesh)"
        how.append(h)
    ends = rig.ends.copy()
    for j in range(rig.n_joints):
        kids = [k for k, q in enumerate(rig.parents) if q == j]
        ends[j] = starts[kids[0]] if len(kids) == 1 else rig.ends[j] + (starts[j] - rig.starts[j])
    out = Rig(starts, ends, rig.names, rig.parents)
    wn = winding_number(out.starts, rest, faces)
    table = pd.DataFrame({
        "joint": list(rig.names),
        **{a: np.round(out.starts[:, i], 4) for i, a in enumerate("xyz")},
        "moved_mm": np.round(1000 * np.linalg.norm(out.starts - rig.starts, axis=1), 1),
        "winding_number": np.round(wn, 3), "inside": np.abs(wn) > 0.5, "placement": how})
    return out, table
