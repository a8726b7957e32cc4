"""The 18-joint skeleton, its forward kinematics, linear blend skinning and
automatic skinning weights.

Conventions (the same as :mod:`animsynth.skeleton`, with the ASF local frame
``C`` = identity):

* joint ``j`` starts at ``starts[j]`` in the rest pose and its segment ends at
  ``ends[j]``; ``offset_j = starts[j] - starts[parent]``;
* a pose is a root translation ``root_t`` (F, 3) (world position of the root
  start) and per-joint Euler angles ``angles`` (F, 18, 3) in **radians**, the
  local rotation being the *extrinsic* ``xyz`` rotation ``L = Rz Ry Rx`` (the
  Acclaim ``rx ry rz`` convention);
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
from scipy.spatial.transform import Rotation

from ..skeleton import Joint, Skeleton

#: The 18 joints, parents before children.
JOINTS = (
    "hips", "spine", "spine1", "chest", "neck", "head",
    "l_upperarm", "l_forearm", "l_hand", "r_upperarm", "r_forearm", "r_hand",
    "l_thigh", "l_shin", "l_foot", "r_thigh", "r_shin", "r_foot",
)
PARENTS = (-1, 0, 1, 2, 3, 4, 3, 6, 7, 3, 9, 10, 0, 12, 13, 0, 15, 16)
#: Which CMU (ASF) bone drives each of the 18 joints.
CMU_MAP = {
    "hips": "root", "spine": "lowerback", "spine1": "upperback", "chest": "thorax",
    "neck": "lowerneck", "head": "head",
    "l_upperarm": "lhumerus", "l_forearm": "lradius", "l_hand": "lwrist",
    "r_upperarm": "rhumerus", "r_forearm": "rradius", "r_hand": "rwrist",
    "l_thigh": "lfemur", "l_shin": "ltibia", "l_foot": "lfoot",
    "r_thigh": "rfemur", "r_shin": "rtibia", "r_foot": "rfoot",
}
N_JOINTS = len(JOINTS)


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
def euler_to_matrix(angles: np.ndarray) -> np.ndarray:
    """Extrinsic-xyz Euler angles (..., 3) radians -> rotation matrices (..., 3, 3) ``Rz Ry Rx``."""
    a = np.asarray(angles, float)
    return Rotation.from_euler("xyz", a.reshape(-1, 3)).as_matrix().reshape(a.shape[:-1] + (3, 3))


def matrix_to_euler(R: np.ndarray) -> np.ndarray:
    """Inverse of :func:`euler_to_matrix` (principal branch)."""
    R = np.asarray(R, float)
    return Rotation.from_matrix(R.reshape(-1, 3, 3)).as_euler("xyz").reshape(R.shape[:-2] + (3,))


def forward(rig: Rig, root_t: np.ndarray, angles: np.ndarray):
    """World rotations and joint starts for every frame.

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
        L = euler_to_matrix(L)
    F, J = L.shape[:2]
    off = rig.offsets
    W = np.empty((F, J, 3, 3))
    S = np.empty((F, J, 3))
    for j, p in enumerate(rig.parents):
        if p < 0:
            W[:, j] = L[:, j]
            S[:, j] = root_t
        else:
            W[:, j] = W[:, p] @ L[:, j]
            S[:, j] = S[:, p] + W[:, p] @ off[j]
    return W, S


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
    from ..kinematics import forward_kinematics

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
    from ..kinematics import forward_kinematics

    sk = motion.skeleton
    rig = rig or rig_from_cmu(sk)
    starts, Wc = forward_kinematics(sk, motion.values, ends=False, world_rotations=True)
    idx = [sk.index(CMU_MAP[n]) for n in JOINTS]
    Wm = np.stack([Wc[i].as_matrix() for i in idx], axis=1)  # (F, 18, 3, 3)
    L = np.empty_like(Wm)
    for j, p in enumerate(rig.parents):
        L[:, j] = Wm[:, j] if p < 0 else np.swapaxes(Wm[:, p], -1, -2) @ Wm[:, j]
    angles = np.unwrap(matrix_to_euler(L), axis=0)
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
    L = np.empty_like(Wn)
    for j, p in enumerate(rig.parents):
        L[:, j] = Wn[:, j] if p < 0 else np.swapaxes(Wn[:, p], -1, -2) @ Wn[:, j]
    return np.unwrap(matrix_to_euler(L), axis=0)
