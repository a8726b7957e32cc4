"""The hybrid mesh model (skinned skeleton + learned detail) and its baselines.

:class:`MeshContext` holds what every model of one mesh sequence shares: the
rest mesh, rig, skinning weights, the farthest-point order used for
decimation and the cached up-samplers.

:class:`HybridModel` is one configurable model:

* ``regressor="gp"`` — the paper's method: a shared GPLVM with GPDM dynamics
  on ``[Y_S, Y_M]`` (latent dimension 4, X initialised from the PCA of ``Y_S``),
  then a GP regression ``Y_S -> X``; reconstruction is
  ``skinned pose + f_M(f_S^-1(y_S))``;
* ``regressor="ridge"`` — the linear detail baseline (pose-space-deformation
  family): ridge regression from standardised ``y_S`` to the detail;
* ``regressor="none"`` — LBS only;
* ``target="full"`` — the GP learns the *full* deformation (vertex positions in
  the root's frame) instead of the detail only (the paper's Fig. 5a baseline).

``joint_param`` chooses the skeleton features (Euler angles, quaternions,
exponential maps; ``y_S = [θ_t, θ_{t-1}]`` without the root) and ``detail``
the detail encoding (``xyz`` displacements or ``laplacian`` differential
coordinates on the control mesh), both in each vertex's dominant-joint frame.
"""

from __future__ import annotations

import logging
import time

import numpy as np
from scipy import sparse
from scipy.spatial.transform import Rotation

from .detail import LaplacianCoder, Upsampler, farthest_point_order, level_indices, to_local, to_world
from .gp import GPRegression, SharedGPDM
from .rig import Rig, euler_to_matrix, forward, joint_transforms, lbs

log = logging.getLogger("animsynth.meshdetail.models")

JOINT_PARAMS = ("euler", "quaternion", "expmap")
DETAILS = ("xyz", "laplacian")


def joint_features(angles: np.ndarray, param: str = "euler") -> np.ndarray:
    """Per-frame joint parameters without the root: (F, 17*3) or (F, 17*4)."""
    a = np.asarray(angles, float)[:, 1:]
    F = a.shape[0]
    if param == "euler":
        return a.reshape(F, -1)
    R = Rotation.from_euler("xyz", a.reshape(-1, 3))
    if param == "expmap":
        return R.as_rotvec().reshape(F, -1)
    if param == "quaternion":
        q = R.as_quat().reshape(F, -1, 4)
        q *= np.where(q[..., 3:4] < 0, -1.0, 1.0)  # w >= 0 hemisphere ...
        for t in range(1, F):  # ... and temporal continuity
            flip = np.sum(q[t] * q[t - 1], axis=-1) < 0
            q[t, flip] *= -1
        return q.reshape(F, -1)
    raise ValueError(f"joint parameterisation must be one of {JOINT_PARAMS}, got {param!r}")


def pose_features(angles: np.ndarray, param: str = "euler", prev_angles: np.ndarray | None = None) -> np.ndarray:
    """``y_S = [θ_t, θ_{t-1}]`` without the root.

    ``θ_{t-1}`` is the previous row; for the first row it is ``prev_angles``
    (the frame before the block) when given, else the first frame itself.
    """
    f = joint_features(angles, param)
    first = joint_features(prev_angles[-1:], param) if prev_angles is not None else f[:1]
    prev = np.vstack([first, f[:-1]])
    return np.concatenate([f, prev], axis=1)


class MeshContext:
    """Shared, precomputed pieces of one mesh sequence.

    Parameters
    ----------
    rest : (V, 3) rest mesh (the first frame); faces : (T, 3); rig : Rig; weights : (V, J)
    max_level : float
        Largest decimation level (percent) that will be asked for below 100.
    """

    def __init__(self, rest, faces, rig: Rig, weights, max_level: float = 75.0):
        self.rest = np.asarray(rest, float)
        self.faces = np.asarray(faces, np.int64)
        self.rig = rig
        self.weights = sparse.csr_matrix(weights)
        self.dom = np.asarray(self.weights.argmax(axis=1)).ravel()
        V = len(self.rest)
        n = int(np.ceil(V * min(max_level, 99.999) / 100.0)) + 1
        self.order = farthest_point_order(self.rest, n)
        self._ups: dict = {}
        self._lap: dict = {}

    @property
    def n_vertices(self) -> int:
        return len(self.rest)

    def control(self, level: float) -> np.ndarray:
        return level_indices(self.order, self.n_vertices, level)

    def upsampler(self, level: float) -> Upsampler:
        if level not in self._ups:
            self._ups[level] = Upsampler(self.faces, self.n_vertices, self.control(level))
        return self._ups[level]

    def laplacian(self, level: float) -> LaplacianCoder:
        if level not in self._lap:
            self._lap[level] = LaplacianCoder(self.rest[self.control(level)])
        return self._lap[level]

    def skin(self, root_t, angles):
        """Skinned vertices (F, V, 3), world rotations (F, J, 3, 3) and joint starts (F, J, 3)."""
        W, S = forward(self.rig, root_t, angles)
        return lbs(self.weights, self.rest, joint_transforms(self.rig, W, S)), W, S


class HybridModel:
    """Skinned skeleton plus learned fine detail (see the module docstring).

    Parameters
    ----------
    level : float
        Control-mesh resolution in percent of the vertices (paper: 5).
    regressor : {"gp", "ridge", "none"}
    target : {"detail", "full"}
    joint_param : {"euler", "quaternion", "expmap"}
    detail : {"xyz", "laplacian"}
    latent_dim, iterations, dynamics_weight : SharedGPDM settings.
    ridge_alpha : float
        Ridge penalty of the linear baseline (on standardised features).

    Attributes
    ----------
    train_seconds_ : wall time of :meth:`fit` (model learning only, not the pose fit).
    """

    def __init__(self, level: float = 5.0, regressor: str = "gp", target: str = "detail",
                 joint_param: str = "euler", detail: str = "xyz", latent_dim: int = 4,
                 iterations: int = 100, dynamics_weight: float = 1.0, ridge_alpha: float = 1.0):
        if regressor not in ("gp", "ridge", "none"):
            raise ValueError(f"regressor must be gp, ridge or none, got {regressor!r}")
        if target not in ("detail", "full"):
            raise ValueError(f"target must be detail or full, got {target!r}")
        if detail not in DETAILS:
            raise ValueError(f"detail must be one of {DETAILS}, got {detail!r}")
        if joint_param not in JOINT_PARAMS:
            raise ValueError(f"joint_param must be one of {JOINT_PARAMS}, got {joint_param!r}")
        self.level = float(level)
        self.regressor = regressor
        self.target = target
        self.joint_param = joint_param
        self.detail = detail
        self.latent_dim = int(latent_dim)
        self.iterations = int(iterations)
        self.dynamics_weight = float(dynamics_weight)
        self.ridge_alpha = float(ridge_alpha)

    # -- encoding of the mesh part ----------------------------------------
    def _encode(self, ctx: MeshContext, P, Ps, W, S):
        idx = self.control_
        if self.target == "full":
            return np.einsum("fba,fvb->fva", W[:, 0], P[:, idx] - S[:, 0, None]).reshape(len(P), -1)
        d = P[:, idx] - Ps[:, idx]
        if self.detail == "laplacian":
            d = ctx.laplacian(self.level).encode(d)
        return to_local(d, self._frames(ctx, W)).reshape(len(P), -1)

    def _frames(self, ctx, W):
        R = W[:, ctx.dom[self.control_]]
        if self.detail == "laplacian":  # component-mean rows live in the root frame
            n = ctx.laplacian(self.level).n_extra
            R = np.concatenate([R, np.repeat(W[:, :1], n, axis=1)], axis=1)
        return R

    def _decode(self, ctx: MeshContext, Ym, Ps, W, S):
        idx = self.control_
        F = len(Ps)
        ups = ctx.upsampler(self.level)
        if self.target == "full":
            q = Ym.reshape(F, len(idx), 3)
            u = q - (ctx.rest[idx] - ctx.rig.starts[0])
            local = ctx.rest - ctx.rig.starts[0] + ups(u)
            return np.einsum("fab,fvb->fva", W[:, 0], local) + S[:, 0, None]
        d = to_world(Ym.reshape(F, -1, 3), self._frames(ctx, W))
        if self.detail == "laplacian":
            d = ctx.laplacian(self.level).decode(d)
        return Ps + ups(d)

    def fit(self, ctx: MeshContext, frames: np.ndarray, root_t: np.ndarray, angles: np.ndarray) -> "HybridModel":
        """Learn from consecutive training frames (F, V, 3) and their fitted poses."""
        t0 = time.perf_counter()
        self.control_ = ctx.control(self.level)
        self.n_train_ = len(frames)
        if self.regressor != "none":
            Ps, W, S = ctx.skin(root_t, angles)
            Ym = self._encode(ctx, np.asarray(frames, float), Ps, W, S)
            Ys = pose_features(angles, self.joint_param)
            if self.regressor == "gp":
                self.gp_ = SharedGPDM(self.latent_dim, self.iterations, dynamics=True,
                                      dynamics_weight=self.dynamics_weight).fit([Ys, Ym])
                self.inv_ = GPRegression(self.iterations).fit(Ys, self.gp_.X_)
            else:
                from sklearn.linear_model import Ridge

                self.ys_mean_, self.ys_sd_ = Ys.mean(axis=0), Ys.std(axis=0) + 1e-8
                self.ridge_ = Ridge(alpha=self.ridge_alpha).fit((Ys - self.ys_mean_) / self.ys_sd_, Ym)
        ctx.upsampler(self.level)  # precompute (part of training)
        self.train_seconds_ = time.perf_counter() - t0
        return self

    def predict_mesh_part(self, angles: np.ndarray, prev_angles=None) -> np.ndarray | None:
        Ys = pose_features(angles, self.joint_param, prev_angles)
        if self.regressor == "gp":
            return self.gp_.predict(self.inv_.predict(Ys), 1)
        if self.regressor == "ridge":
            return self.ridge_.predict((Ys - self.ys_mean_) / self.ys_sd_)
        return None

    def predict(self, ctx: MeshContext, root_t: np.ndarray, angles: np.ndarray, prev_angles=None) -> np.ndarray:
        """Reconstructed meshes (F, V, 3) for poses (root_t (F, 3), angles (F, J, 3)).

        ``prev_angles``: pose of the frame before the block (for ``θ_{t-1}`` of its first frame).
        """
        Ps, W, S = ctx.skin(root_t, angles)
        Ym = self.predict_mesh_part(angles, prev_angles)
        if Ym is None:
            return Ps
        return self._decode(ctx, Ym, Ps, W, S)

    def stored_floats(self, ctx: MeshContext, n_frames: int) -> int:
        """Numbers needed to store the animation with this model (see :func:`compressed_size`)."""
        J = ctx.rig.n_joints
        base = ctx.rest.size + 2 * ctx.weights.nnz + 6 * J + n_frames * (3 + 3 * J) + len(self.control_)
        if self.regressor == "gp":
            N = self.n_train_
            D_m = self.gp_.alpha_[1].shape[1]
            # latent points, alpha for the mesh mapping, the inverse map's alpha, hyperparameters, normalisers
            base += N * self.latent_dim + N * D_m + N * self.latent_dim + 20 + 2 * D_m
        elif self.regressor == "ridge":
            base += self.ridge_.coef_.size + self.ridge_.intercept_.size + 2 * self.ys_mean_.size
        return int(base)


def mean_vertex_error(pred: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per-frame mean Euclidean vertex distance (same units as the input)."""
    return np.linalg.norm(np.asarray(pred) - np.asarray(truth), axis=-1).mean(axis=-1)


def reconstruction_seconds_per_frame(model: HybridModel, ctx: MeshContext, root_t, angles, repeat: int = 1) -> float:
    """Wall time per frame when frames are reconstructed one at a time (interactive editing).

    Frame t is reconstructed alone from its pose and the previous frame's angles.
    """
    F = len(root_t)
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        for t in range(1, F):
            model.predict(ctx, root_t[t: t + 1], angles[t: t + 1], prev_angles=angles[t - 1: t])
        best = min(best, (time.perf_counter() - t0) / max(F - 1, 1))
    return best


def angles_from_matrices(L: np.ndarray) -> np.ndarray:
    from .rig import matrix_to_euler

    return np.unwrap(matrix_to_euler(L), axis=0)


__all__ = ["HybridModel", "MeshContext", "pose_features", "joint_features", "mean_vertex_error",
           "reconstruction_seconds_per_frame", "euler_to_matrix"]
