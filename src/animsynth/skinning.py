"""The 18-joint skeleton, its forward kinematics, linear blend skinning and
automatic skinning weights.

Conventions (the same as :mod:`animsynth.skeleton`, with the ASF local frame
``C`` = identity):

* joint ``j`` starts at ``starts[j]`` in the rest pose and its segment ends at
  ``ends[j]``; ``offset_j = starts[j] - starts[parent]``;
* a pose is a root translation ``root_t`` (F, 3) (world position of the root
  start) and per-joint Euler angles ``angles`` (F, 18, 3) in **radians**, the
  local rotation being the *extrinsic* ``xyz`` rotation ``L = Rz Ry Rx`` (the
  Acclaim ``rx ry rz`` convention; :func:`animsynth.kinematics.xyz_euler_to_matrix`);
* world rotation ``W_j = W_parent L_j``, world start ``s_j = s_parent + W_parent offset_j``;
* LBS: ``p_i = sum_j w_ij (W_j (v_i - starts[j]) + s_j)``.

:meth:`Rig.to_skeleton` gives the equivalent :class:`animsynth.skeleton.Skeleton`
(root DOF ``tx ty tz rx ry rz``, three rotational DOF per other joint), so
:func:`animsynth.kinematics.forward_kinematics` and the AMC writer apply.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
from scipy import sparse

from .kinematics import forward_kinematics, matrix_to_xyz_euler, tree_forward, tree_local, xyz_euler_to_matrix
from .rig_layout import CMU_MAP, JOINTS, PARENTS
from .skeleton import Joint, Skeleton


@dataclass
class Rig:
    """Rest-pose embedding of the 18-joint skeleton.

    Attributes
    ----------
    starts : ndarray (18, 3)
        Rest-pose world position where each joint (its segment) starts.
    ends : ndarray (18, 3)
        Rest-pose world position where each segment ends (used for weights and drawing).
    names, parents : the fixed 18-joint structure.
    """

    starts: np.ndarray
    ends: np.ndarray
    names: tuple = JOINTS
    parents: tuple = PARENTS

    def __post_init__(self):
        self.starts = np.asarray(self.starts, float).reshape(-1, 3)
        self.ends = np.asarray(self.ends, float).reshape(-1, 3)
        if self.starts.shape != (len(self.names), 3) or self.ends.shape != self.starts.shape:
            raise ValueError(f"rig needs {len(self.names)} joint starts and ends, got {self.starts.shape} / {self.ends.shape}")
        if not (np.all(np.isfinite(self.starts)) and np.all(np.isfinite(self.ends))):
            raise ValueError("rig joint positions must be finite")

    @property
    def n_joints(self) -> int:
        return len(self.names)

    @property
    def offsets(self) -> np.ndarray:
        off = self.starts.copy()
        for j, p in enumerate(self.parents):
            if p >= 0:
                off[j] = self.starts[j] - self.starts[p]
        return off

    def to_json(self) -> str:
        return json.dumps({"starts": self.starts.tolist(), "ends": self.ends.tolist(), "names": list(self.names),
                           "parents": list(self.parents)})

    @classmethod
    def from_json(cls, s: str) -> "Rig":
        d = json.loads(s)
        return cls(np.array(d["starts"]), np.array(d["ends"]), tuple(d["names"]), tuple(d["parents"]))

    def to_skeleton(self, name: str = "rig18") -> Skeleton:
        """The equivalent generic :class:`Skeleton` (metres, degrees)."""
        off = self.offsets
        joints = []
        for j, (n, p) in enumerate(zip(self.names, self.parents)):
            dofs = ["tx", "ty", "tz", "rx", "ry", "rz"] if p < 0 else ["rx", "ry", "rz"]
            joints.append(Joint(name="root" if p < 0 else n, parent=p, offset=off[j] if p >= 0 else self.starts[j].copy(),
                                tail=self.ends[j] - self.starts[j], dofs=dofs))
        return Skeleton(joints, 1.0, "deg", name)

    def motion_values(self, root_t: np.ndarray, angles: np.ndarray) -> np.ndarray:
        """Pose -> DOF values (F, 6 + 3*17) in the :meth:`to_skeleton` column order (degrees)."""
        F = len(root_t)
        deg = np.rad2deg(angles)
        return np.concatenate([root_t - self.starts[0], deg[:, 0], deg[:, 1:].reshape(F, -1)], axis=1)


def default_rig(height: float = 1.72) -> Rig:
    """A hand-made T-pose rig (metres, Y up, facing +Z, left = +X), scaled to ``height``."""
    s = height / 1.72
    st, en = {}, {}
    st["hips"], en["hips"] = (0, 0.95, 0), (0, 1.02, 0)
    st["spine"], en["spine"] = (0, 1.02, 0), (0, 1.15, 0)
    st["spine1"], en["spine1"] = (0, 1.15, 0), (0, 1.28, 0)
    st["chest"], en["chest"] = (0, 1.28, 0), (0, 1.42, 0)
    st["neck"], en["neck"] = (0, 1.42, 0), (0, 1.51, 0)
    st["head"], en["head"] = (0, 1.51, 0), (0, 1.72, 0)
    for side, sx in (("l", 1.0), ("r", -1.0)):
        st[f"{side}_upperarm"], en[f"{side}_upperarm"] = (0.18 * sx, 1.40, 0), (0.46 * sx, 1.40, 0)
        st[f"{side}_forearm"], en[f"{side}_forearm"] = (0.46 * sx, 1.40, 0), (0.71 * sx, 1.40, 0)
        st[f"{side}_hand"], en[f"{side}_hand"] = (0.71 * sx, 1.40, 0), (0.87 * sx, 1.40, 0)
        st[f"{side}_thigh"], en[f"{side}_thigh"] = (0.09 * sx, 0.92, 0), (0.09 * sx, 0.50, 0)
        st[f"{side}_shin"], en[f"{side}_shin"] = (0.09 * sx, 0.50, 0), (0.09 * sx, 0.09, 0)
        st[f"{side}_foot"], en[f"{side}_foot"] = (0.09 * sx, 0.09, 0), (0.09 * sx, 0.03, 0.17)
    return Rig(np.array([st[n] for n in JOINTS]) * s, np.array([en[n] for n in JOINTS]) * s)


# --------------------------------------------------------------------------- kinematics
def forward(rig: Rig, root_t: np.ndarray, angles: np.ndarray):
    """World rotations and joint starts for every frame: :func:`animsynth.kinematics.tree_forward` on rotation
    matrices (the rig's offsets the same in every frame).

    Parameters
    ----------
    root_t : (F, 3)
    angles : (F, J, 3) Euler radians (or rotation matrices (F, J, 3, 3))

    Returns
    -------
    W : (F, J, 3, 3) world rotations
    S : (F, J, 3) world joint starts
    """
    root_t = np.atleast_2d(np.asarray(root_t, float))
    L = np.asarray(angles, float)
    if L.shape[-1] == 3 and L.ndim == 3:
        L = xyz_euler_to_matrix(L)
    F, J = L.shape[:2]
    off = rig.offsets
    T = [np.broadcast_to(root_t, (F, 3)) if p < 0 else off[j] for j, p in enumerate(rig.parents)]
    W, S = tree_forward(rig.parents, [L[:, j] for j in range(J)], T)
    return np.stack(W, axis=1), np.stack(S, axis=1)


def joint_transforms(rig: Rig, W: np.ndarray, S: np.ndarray) -> np.ndarray:
    """Affine skinning transforms (F, J, 3, 4): ``x -> W_j x + (S_j - W_j starts_j)``."""
    t = S - np.einsum("fjab,jb->fja", W, rig.starts)
    return np.concatenate([W, t[..., None]], axis=-1)


def lbs(weights, rest: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Linear blend skinning.

    Parameters
    ----------
    weights : (V, J) sparse or dense, rows sum to 1
    rest : (V, 3) rest-pose vertices
    T : (F, J, 3, 4) joint transforms from :func:`joint_transforms` (or (J, 3, 4))

    Returns
    -------
    (F, V, 3) skinned vertices (or (V, 3))
    """
    single = T.ndim == 3
    T = T[None] if single else T
    F, J = T.shape[:2]
    Tm = np.moveaxis(T.reshape(F, J, 12), 0, 1).reshape(J, F * 12)
    M = (weights @ Tm).reshape(-1, F, 3, 4)  # (V, F, 3, 4)
    out = np.einsum("vfab,vb->fva", M[..., :3], rest) + np.moveaxis(M[..., 3], 0, 1)
    return out[0] if single else out


def pose_vertices(rig: Rig, weights, rest, root_t, angles) -> np.ndarray:
    """Skinned vertices (F, V, 3) of a pose sequence."""
    W, S = forward(rig, root_t, angles)
    return lbs(weights, rest, joint_transforms(rig, W, S))


# --------------------------------------------------------------------------- weights
def _point_segment_distance(P: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Distances (V, J) from points P (V, 3) to segments A[j]-B[j]."""
    AB = B - A
    L2 = np.maximum(np.sum(AB * AB, axis=1), 1e-12)
    AP = P[:, None, :] - A[None]
    u = np.clip(np.einsum("vjk,jk->vj", AP, AB) / L2, 0.0, 1.0)
    closest = A[None] + u[..., None] * AB[None]
    return np.linalg.norm(P[:, None, :] - closest, axis=-1)


def skinning_weights(rest: np.ndarray, rig: Rig, power: float = 4.0, max_influences: int = 4,
                     falloff: float = 2.0) -> sparse.csr_matrix:
    """Automatic skinning weights by a smooth distance falloff to the bone segments.

    ``w_ij ∝ (d_i,min / d_ij)^power`` for the ``max_influences`` nearest
    segments whose distance is below ``falloff * d_i,min + 1 cm``, rows
    normalised to 1. Close to each bone a vertex follows that bone rigidly,
    and it blends between bones near joints.

    Returns
    -------
    scipy.sparse.csr_matrix (V, J)
    """
    rest = np.asarray(rest, float)
    D = np.maximum(_point_segment_distance(rest, rig.starts, rig.ends), 1e-6)
    dmin = D.min(axis=1, keepdims=True)
    w = (dmin / D) ** power
    w[D > falloff * dmin + 0.01] = 0.0
    k = min(max_influences, D.shape[1])
    if k < D.shape[1]:
        cut = np.argsort(-w, axis=1)[:, k:]
        np.put_along_axis(w, cut, 0.0, axis=1)
    w /= w.sum(axis=1, keepdims=True)
    return sparse.csr_matrix(w)


def dominant_joint(weights) -> np.ndarray:
    W = weights.toarray() if sparse.issparse(weights) else np.asarray(weights)
    return np.argmax(W, axis=1)


# --------------------------------------------------------------------------- CMU mapping
def rig_from_cmu(skeleton: Skeleton) -> Rig:
    """An 18-joint rig from a CMU (ASF) skeleton's rest pose, in metres."""


    zero = np.zeros((1, skeleton.n_dof))
    starts = forward_kinematics(skeleton, zero, ends=False)[0] * skeleton.length_to_m
    ends = forward_kinematics(skeleton, zero, ends=True)[0] * skeleton.length_to_m
    st = np.array([starts[skeleton.index(CMU_MAP[n])] for n in JOINTS])
    en = np.array([ends[skeleton.index(CMU_MAP[n])] for n in JOINTS])
    # The CMU root has no segment; give it one up to the spine start so it gets weights.
    en[0] = st[1] if np.linalg.norm(st[1] - st[0]) > 1e-6 else st[0] + np.array([0, 0.07, 0])
    # Arms of the 18-joint rig hang from the chest (clavicles folded in); heads/necks keep their ASF starts.
    return Rig(st, en)


def cmu_motion_to_rig(motion, rig: Rig | None = None):
    """Map a CMU-skeleton :class:`~animsynth.motion.Motion` onto the 18-joint rig.

    Each rig joint takes the *world* rotation of its CMU bone; local angles are
    ``W_parent^-1 W_j`` (so dropped bones such as the clavicles are folded into
    their children). Root translation is converted to metres.

    Returns
    -------
    rig, root_t (F, 3) metres, angles (F, 18, 3) radians
    """


    sk = motion.skeleton
    rig = rig or rig_from_cmu(sk)
    starts, Wc = forward_kinematics(sk, motion.values, ends=False, world_rotations=True)
    idx = [sk.index(CMU_MAP[n]) for n in JOINTS]
    Wm = np.stack([Wc[i].as_matrix() for i in idx], axis=1)  # (F, 18, 3, 3)
    angles = np.unwrap(matrix_to_xyz_euler(tree_local(rig.parents, Wm)), axis=0)
    root_t = starts[:, idx[0]] * sk.length_to_m
    return rig, root_t, angles


def rebase(rig: Rig, root_t0: np.ndarray, angles0: np.ndarray) -> Rig:
    """The rig placed in a posed frame: joint starts/ends where pose (root_t0, angles0) puts them.

    Used to place a known skeleton "in the first-frame mesh": angles relative
    to the new rig are then relative to that frame's pose (see :func:`rebase_pose`).
    """
    W, S = forward(rig, np.atleast_2d(root_t0), np.asarray(angles0)[None])
    ends = S[0] + np.einsum("jab,jb->ja", W[0], rig.ends - rig.starts)
    return Rig(S[0], ends, rig.names, rig.parents)


def rebase_pose(rig: Rig, root_t: np.ndarray, angles: np.ndarray, angles0: np.ndarray) -> np.ndarray:
    """Angles of a pose sequence relative to the rig rebased at pose ``angles0`` (same world motion)."""
    W, _ = forward(rig, root_t, angles)
    W0, _ = forward(rig, np.zeros((1, 3)), np.asarray(angles0)[None])
    Wn = W @ np.swapaxes(W0, -1, -2)  # new world rotations: W_j(t) W_j(0)^T
    return np.unwrap(matrix_to_xyz_euler(tree_local(rig.parents, Wn)), axis=0)


# --------------------------------------------------------------------------- inside test
def winding_number(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray, chunk: int = 32) -> np.ndarray:
    """Generalised winding number of query points with respect to a triangle mesh.

    ``w(q) = sum_f Ω_f(q) / 4π`` with the signed solid angle ``Ω_f`` of each
    triangle (Van Oosterom & Strackee 1983). For a closed, consistently
    oriented mesh ``w`` is 1 inside and 0 outside (-1 inside for inward
    normals); for meshes with small holes it degrades gracefully (values in
    between). Written with numpy because it is a dozen lines for a handful of
    query points (the joint centres), while the library versions need extra
    dependencies (libigl) or a ray-casting backend (trimesh with embree/rtree).

    Parameters
    ----------
    points : (Q, 3) query points
    vertices : (V, 3), faces : (T, 3) the mesh

    Returns
    -------
    (Q,) winding numbers
    """
    P = np.atleast_2d(np.asarray(points, float))
    tri = np.asarray(vertices, float)[np.asarray(faces, np.int64)]  # (T, 3, 3)
    out = np.empty(len(P))
    for q0 in range(0, len(P), chunk):
        R = tri[None] - P[q0:q0 + chunk, None, None, :]  # (q, T, 3, 3)
        a, b, c = R[:, :, 0], R[:, :, 1], R[:, :, 2]
        la, lb, lc = (np.linalg.norm(x, axis=-1) for x in (a, b, c))
        det = np.einsum("qti,qti->qt", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("qti,qti->qt", a, b) * lc + np.einsum("qti,qti->qt", b, c) * la
               + np.einsum("qti,qti->qt", c, a) * lb)
        out[q0:q0 + chunk] = np.sum(2.0 * np.arctan2(det, den), axis=1) / (4.0 * np.pi)
    return out


def inside_mesh(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Boolean (Q,): is each point inside the closed mesh (``|winding number| > 0.5``)."""
    return np.abs(winding_number(points, vertices, faces)) > 0.5


# --------------------------------------------------------------------------- bone heat
def _closest_on_segments(P: np.ndarray, A: np.ndarray, B: np.ndarray):
    """Closest points (V, J, 3) on segments A[j]-B[j] to points P (V, 3), and their distances (V, J)."""
    AB = B - A
    L2 = np.maximum(np.sum(AB * AB, axis=1), 1e-12)
    u = np.clip(np.einsum("vjk,jk->vj", P[:, None, :] - A[None], AB) / L2, 0.0, 1.0)
    C = A[None] + u[..., None] * AB[None]
    return C, np.linalg.norm(P[:, None, :] - C, axis=-1)


def _segments_hit_mesh(origins: np.ndarray, targets: np.ndarray, origin_ids: np.ndarray, vertices: np.ndarray,
                       faces: np.ndarray, eps: float = 1e-6) -> np.ndarray:
    """Does the open segment origin->target cross a mesh triangle not incident to the origin vertex?

    Möller-Trumbore intersection against the triangles near each segment
    (triangles whose centroid lies within their radius of the segment,
    found with k-d trees).
    """
    from scipy.spatial import cKDTree

    tri = vertices[faces]
    cen = tri.mean(axis=1)
    rad = np.max(np.linalg.norm(tri - cen[:, None], axis=-1), axis=1)  # (T,) each triangle's radius
    # Candidates: triangles whose centroid lies within their radius of the segment (a triangle that meets the
    # segment has every point within its largest vertex distance of its centroid). Triangles are searched in
    # two groups (radius up to twice the median, and the larger rest), each with a k-d tree of centroids
    # queried along the segment by balls of that group's largest radius plus half a piece (pieces no
    # longer than twice that radius); a triangle found by several balls is tested more than once.
    length = np.linalg.norm(targets - origins, axis=1)
    cut = 2.0 * float(np.median(rad))
    segs, fs = [], []
    for group in (np.flatnonzero(rad <= cut), np.flatnonzero(rad > cut)):
        if not len(group):
            continue
        r = float(rad[group].max())
        pieces = np.maximum(1, np.ceil(0.5 * length / max(r, 1e-12))).astype(np.int64)
        owner = np.repeat(np.arange(len(origins)), pieces)
        frac = (np.arange(len(owner)) - np.repeat(np.cumsum(pieces) - pieces, pieces) + 0.5) / pieces[owner]
        mid = origins[owner] + frac[:, None] * (targets - origins)[owner]
        cand = cKDTree(cen[group]).query_ball_point(mid, 0.5 * length[owner] / pieces[owner] + r)
        segs.append(np.repeat(owner, [len(c) for c in cand]))
        fs.append(group[np.concatenate([np.asarray(c, np.int64) for c in cand])] if len(segs[-1]) else
                  np.zeros(0, np.int64))
    seg, f = np.concatenate(segs), np.concatenate(fs)
    if len(seg) == 0:
        return np.zeros(len(origins), bool)
    keep = ~np.any(faces[f] == origin_ids[seg, None], axis=1)
    seg, f = seg[keep], f[keep]
    o, d = origins[seg], targets[seg] - origins[seg]
    s = np.clip(np.einsum("ij,ij->i", cen[f] - o, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    gap = cen[f] - o - s[:, None] * d
    near = np.einsum("ij,ij->i", gap, gap) <= (rad[f] * (1 + 1e-9)) ** 2
    seg, f = seg[near], f[near]
    o, d = origins[seg], targets[seg] - origins[seg]
    v0, e1, e2 = tri[f, 0], tri[f, 1] - tri[f, 0], tri[f, 2] - tri[f, 0]
    pv = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, pv)
    ok = np.abs(det) > 1e-15
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    tv = o - v0
    u = np.einsum("ij,ij->i", tv, pv) * inv
    qv = np.cross(tv, e1)
    v = np.einsum("ij,ij->i", d, qv) * inv
    t = np.einsum("ij,ij->i", e2, qv) * inv
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > eps) & (t < 1 - eps)
    out = np.zeros(len(origins), bool)
    out[seg[hit]] = True
    return out


def bone_heat_weights(vertices: np.ndarray, faces: np.ndarray, rig: Rig, c: float = 1.0, max_influences: int = 4,
                      visibility_candidates: int = 4, min_weight: float = 0.01) -> sparse.csr_matrix:
    """Skinning weights by bone heat diffusion (Baran & Popović 2007, "Pinocchio").

    For every bone ``i`` solve ``(-Δ + H) w_i = H p_i`` on the surface, where
    ``Δ`` is the cotangent Laplace-Beltrami operator (``-Δ = M^-1 L`` with the
    stiffness ``L`` and lumped mass ``M`` from :mod:`robust_laplacian`, which
    stays well-behaved on imperfect meshes), ``p_ij = 1`` if bone ``i`` is the
    nearest bone *visible* from vertex ``j`` (the segment to its closest bone
    point crosses no other part of the surface; the ``visibility_candidates``
    nearest bones are tried in order), and ``H_jj = c / d_j²`` with ``d_j`` the
    distance to that bone (``H_jj = 0`` if none is visible). Multiplied by
    ``M`` the system ``(L + M H) w_i = M H p_i`` is symmetric positive
    definite; it is factorised once and solved for all bones. Rows sum to one
    by construction (``L 1 = 0``); weights below ``min_weight`` are dropped,
    each vertex keeps its ``max_influences`` largest, and rows are renormalised.

    Parameters
    ----------
    vertices : (V, 3), faces : (T, 3) the rest (first-frame) mesh
    rig : Rig (segments ``starts[j]``-``ends[j]``)
    c : float
        Heat-source strength (the paper's ``c = 1``).

    Returns
    -------
    scipy.sparse.csr_matrix (V, J)
    """
    import robust_laplacian
    from scipy.sparse.linalg import splu

    Vx = np.asarray(vertices, float)
    Fc = np.asarray(faces, np.int64)
    J = rig.n_joints
    C, D = _closest_on_segments(Vx, rig.starts, rig.ends)
    order = np.argsort(D, axis=1)[:, :max(1, min(visibility_candidates, J))]
    nearest = np.full(len(Vx), -1)
    todo = np.arange(len(Vx))
    for k in range(order.shape[1]):
        b = order[todo, k]
        blocked = _segments_hit_mesh(Vx[todo], C[todo, b], todo, Vx, Fc)
        nearest[todo[~blocked]] = b[~blocked]
        todo = todo[blocked]
        if not len(todo):
            break
    has = nearest >= 0
    d = np.where(has, D[np.arange(len(Vx)), np.maximum(nearest, 0)], np.inf)
    h = np.where(has, c / np.maximum(d, 1e-4) ** 2, 0.0)
    L, M = robust_laplacian.mesh_laplacian(Vx, Fc)
    MH = sparse.diags(M.diagonal() * h)
    lu = splu((L + MH).tocsc())
    rhs = np.zeros((len(Vx), J))
    rhs[np.flatnonzero(has), nearest[has]] = (M.diagonal() * h)[has]
    w = lu.solve(rhs)
    w[w < min_weight] = 0.0
    k = min(max_influences, J)
    if k < J:
        cut = np.argsort(-w, axis=1)[:, k:]
        np.put_along_axis(w, cut, 0.0, axis=1)
    s = w.sum(axis=1, keepdims=True)
    empty = s[:, 0] <= 0
    if np.any(empty):  # unreachable parts: nearest bone
        w[empty] = 0.0
        w[empty, np.argmin(D[empty], axis=1)] = 1.0
        s = w.sum(axis=1, keepdims=True)
    return sparse.csr_matrix(w / s)


def refit_weights(weights, rest: np.ndarray, T: np.ndarray, frames: np.ndarray, parents=None,
                  max_influences: int = 4) -> sparse.csr_matrix:
    """Per-vertex non-negative, sum-to-one skinning weights fitted to posed frames.

    For vertex ``i`` the candidate bones are those with a nonzero weight in
    ``weights`` (plus their parents and children when ``parents`` is given);
    its new weights minimise ``sum_t |sum_j w_j T_j(t) v_i - p_i(t)|²`` subject to
    ``w >= 0`` and ``sum w = 1`` (:func:`scipy.optimize.nnls` with the
    sum-to-one row appended with a large weight, then renormalised); if more
    than ``max_influences`` come out nonzero, the largest are refitted alone.
    Pass the **training** frames only.

    Parameters
    ----------
    weights : (V, J) initial weights (their support)
    rest : (V, 3); T : (F, J, 3, 4) joint transforms of the frames; frames : (F, V, 3)
    parents : sequence of J parent indices (-1 for the root), optional

    Returns
    -------
    scipy.sparse.csr_matrix (V, J)
    """
    from scipy.optimize import nnls

    W0 = weights.toarray() if sparse.issparse(weights) else np.asarray(weights, float)
    V, J = W0.shape
    nb = [np.array([j], int) for j in range(J)]
    if parents is not None:
        for j, p in enumerate(parents):
            if p >= 0:
                nb[j] = np.append(nb[j], p)
                nb[p] = np.append(nb[p], j)
    T = np.asarray(T, float)
    frames = np.asarray(frames, float)
    F = len(T)
    Y = frames.transpose(1, 0, 2).reshape(V, F * 3)
    big = 1e3 * np.sqrt(F)
    out = np.zeros_like(W0)
    for i in range(V):
        sup = np.unique(np.concatenate([nb[j] for j in np.flatnonzero(W0[i] > 0)]))
        Ts = T[:, sup]
        X = (np.einsum("fjab,b->jfa", Ts[..., :3], rest[i]) + Ts[..., 3].transpose(1, 0, 2)).reshape(len(sup), -1)
        b = np.concatenate([Y[i], [big]])
        w, _ = nnls(np.vstack([X.T, np.full((1, len(sup)), big)]), b)
        if np.count_nonzero(w) > max_influences:
            keep = np.argsort(-w)[:max_influences]
            sup, X = sup[keep], X[keep]
            w, _ = nnls(np.vstack([X.T, np.full((1, len(sup)), big)]), b)
        s = w.sum()
        out[i, sup] = w / s if s > 0 else W0[i, sup] / max(W0[i, sup].sum(), 1e-12)
    return sparse.csr_matrix(out)
