"""The hybrid mesh model (skinned skeleton + learned detail) and its baselines.

:class:`MeshContext` holds what every model of one mesh sequence shares: the
rest mesh, rig, skinning weights, control meshes, RBF maps and Laplacian
coders (each built once).

:class:`HybridModel` is one configurable model:

* ``regressor="gp"`` — the paper's method: a shared GPLVM with GPDM dynamics
  on ``[Y_S, Y_M]`` (latent dimension 4, X initialised from the PCA of ``Y_S``),
  then a GP regression ``Y_S -> X``; reconstruction is
  ``skinned pose + f_M(f_S^-1(y_S))``;
* ``regressor="gp_regression"`` — plain GP regression ``y_S -> Y_M`` (no latent space);
* ``regressor="ridge_cv"`` — linear detail model (pose-space-deformation family):
  ridge regression with the penalty chosen by blocked CV inside the training frames;
* ``regressor="none"`` — LBS only;
* ``target="full"`` — the GP learns the *full* deformation (control positions in
  the root's frame) instead of the detail only (the paper's Fig. 5a baseline).

``joint_param`` chooses the skeleton features (exponential maps by default,
the paper's final choice; Euler angles, quaternions; ``y_S = [θ_t, θ_{t-1}]``
without the root) and ``detail`` the detail encoding (``xyz`` displacements
or ``laplacian`` differential coordinates on the control mesh), both in each
control vertex's dominant-joint frame.
"""

from __future__ import annotations

import copy

import logging
import time

import numpy as np
from scipy import sparse

from threadpoolctl import threadpool_limits

from .detail import ControlMesh, LaplacianCoder, RBFUpsampler, farthest_point_order, to_local, to_world
from .gp import GPRegression, SharedGPDM
from ..kinematics import xyz_euler_rotation
from ..skinning import Rig, forward, joint_transforms, lbs

log = logging.getLogger("animsynth.meshdetail.models")

JOINT_PARAMS = ("euler", "quaternion", "expmap")
DETAILS = ("xyz", "laplacian")


def joint_features(angles: np.ndarray, param: str = "euler") -> np.ndarray:
    """Per-frame joint parameters without the root: (F, 17*3) or (F, 17*4)."""
    a = np.asarray(angles, float)[:, 1:]
    F = a.shape[0]
    if param == "euler":
        return a.reshape(F, -1)
    R = xyz_euler_rotation(a)
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
        Largest decimation level (percent) that will be asked for below 100
        (length of the farthest-point order).
    decimation : {"collapse", "farthest"}
        How control meshes are made (:class:`~.detail.ControlMesh`).
    rbf_neighbors : int
        Control vertices per fine vertex in the RBF reconstruction.
    """

    def __init__(self, rest, faces, rig: Rig, weights, max_level: float = 75.0, decimation: str = "collapse",
                 rbf_neighbors: int = 24):
        self.rest = np.asarray(rest, float)
        self.faces = np.asarray(faces, np.int64)
        self.rig = rig
        self.weights = sparse.csr_matrix(weights)
        self.dom = np.asarray(self.weights.argmax(axis=1)).ravel()
        self.decimation = decimation
        self.rbf_neighbors = int(rbf_neighbors)
        self._max_level = max_level
        self._order = None
        self._ctl: dict = {}
        self._ups: dict = {}
        self._lap: dict = {}
        self._pos: dict = {}

    @property
    def n_vertices(self) -> int:
        return len(self.rest)

    @property
    def order(self) -> np.ndarray:
        if self._order is None:
            n = int(np.ceil(self.n_vertices * min(self._max_level, 99.999) / 100.0)) + 1
            self._order = farthest_point_order(self.rest, n)
        return self._order

    def control_mesh(self, level: float, method: str | None = None) -> ControlMesh:
        key = (float(level), method or self.decimation)
        if key not in self._ctl:
            m = key[1]
            self._ctl[key] = ControlMesh(self.rest, self.faces, level, m, self.order if m == "farthest" and level < 100
                                         else None)
        return self._ctl[key]

    def control(self, level: float, method: str | None = None) -> np.ndarray:
        """Original vertex represented by each control vertex."""
        return self.control_mesh(level, method).source_

    def upsampler(self, level: float, method: str | None = None) -> RBFUpsampler | None:
        key = (float(level), method or self.decimation)
        if key not in self._ups:
            c = self.control_mesh(level, method)
            self._ups[key] = None if c.identity else RBFUpsampler(c.rest_, self.rest, self.rbf_neighbors)
        return self._ups[key]

    def laplacian(self, level: float, method: str | None = None) -> LaplacianCoder:
        key = (float(level), method or self.decimation)
        if key not in self._lap:
            c = self.control_mesh(level, method)
            self._lap[key] = LaplacianCoder(c.rest_, c.faces_)
        return self._lap[key]

    def control_positions(self, level: float, frames: np.ndarray, method: str | None = None,
                          cache: str | None = None) -> np.ndarray:
        """Control positions (F, C, 3) of full-mesh frames; ``cache`` names a sequence to keep them for."""
        key = (float(level), method or self.decimation, cache)
        if cache is not None and key in self._pos:
            return self._pos[key]
        out = self.control_mesh(level, method).positions(frames, self.faces)
        if cache is not None:
            self._pos[key] = out
        return out

    def with_skin(self, rig: Rig, weights) -> "MeshContext":
        """The same mesh with another skeleton and skin (e.g. one cross-validation fold's).

        Shares what depends only on the mesh (control meshes, RBF upsamplers,
        Laplacian coders, the cached control positions of the captured frames);
        drops the cached positions of skinned frames, which depend on the skin.
        """
        new = copy.copy(self)
        new.rig = rig
        new.weights = sparse.csr_matrix(weights)
        new.dom = np.asarray(new.weights.argmax(axis=1)).ravel()
        new._pos = {k: v for k, v in self._pos.items() if k[2] == "frames"}
        return new

    def skin(self, root_t, angles):
        """Skinned vertices (F, V, 3), world rotations (F, J, 3, 3) and joint starts (F, J, 3)."""
        W, S = forward(self.rig, root_t, angles)
        return lbs(self.weights, self.rest, joint_transforms(self.rig, W, S)), W, S


REGRESSORS = ("gp", "gp_regression", "ridge_cv", "none")


class HybridModel:
    """Skinned skeleton plus learned fine detail (see the module docstring).

    Parameters
    ----------
    level : float
        Control-mesh resolution in percent of the vertices (paper: 5).
    regressor : {"gp", "gp_regression", "ridge_cv", "none"}
        ``gp``: the paper's SGPLVM+GPDM; ``gp_regression``: plain GP regression
        from pose to detail (scikit-learn :class:`GaussianProcessRegressor`, a
        constant x RBF + white-noise kernel fitted by marginal likelihood on
        standardised features); ``ridge_cv``: ridge regression with the
        penalty chosen from ``ridge_alphas`` by blocked (contiguous, unshuffled)
        5-fold cross-validation inside the training frames; ``none``: LBS only.
    target : {"detail", "full"}
    joint_param : {"euler", "quaternion", "expmap"}
    detail : {"xyz", "laplacian"}
    decimation : {"collapse", "farthest"} or None (the context's)
    latent_dim, iterations, dynamics_weight : SharedGPDM settings (dynamics_weight 0: no GPDM term).
    ridge_alphas : sequence of float

    Attributes
    ----------
    train_seconds_, train_cpu_seconds_ : wall and CPU time of :meth:`fit` (model learning only).
    """

    def __init__(self, level: float = 5.0, regressor: str = "gp", target: str = "detail",
                 joint_param: str = "expmap", detail: str = "xyz", latent_dim: int = 4,
                 iterations: int = 100, dynamics_weight: float = 1.0,
                 ridge_alphas=(0.01, 0.1, 1, 10, 100, 1000, 10000), decimation: str | None = None):
        if regressor not in REGRESSORS:
            raise ValueError(f"regressor must be one of {REGRESSORS}, got {regressor!r}")
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
        self.ridge_alphas = tuple(float(a) for a in ridge_alphas)
        self.decimation = decimation

    # -- encoding of the mesh part ----------------------------------------
    def _encode(self, ctx: MeshContext, Pc, Psc, W, S):
        """Control positions of the frames (Pc) and of their skinned meshes (Psc) -> Y_M (F, D)."""
        cm = ctx.control_mesh(self.level, self.decimation)
        if self.target == "full":
            return np.einsum("fba,fvb->fva", W[:, 0], Pc - S[:, 0, None]).reshape(len(Pc), -1)
        d = Pc - Psc
        if self.detail == "laplacian":
            d = ctx.laplacian(self.level, self.decimation).encode(d)
        return to_local(d, self._frames(ctx, W, cm)).reshape(len(Pc), -1)

    def _frames(self, ctx, W, cm):
        R = W[:, ctx.dom[cm.source_]]
        if self.detail == "laplacian":  # component-mean rows live in the root frame
            n = ctx.laplacian(self.level, self.decimation).n_extra
            R = np.concatenate([R, np.repeat(W[:, :1], n, axis=1)], axis=1)
        return R

    def _decode(self, ctx: MeshContext, Ym, Ps, W, S):
        cm = ctx.control_mesh(self.level, self.decimation)
        F = len(Ps)
        ups = ctx.upsampler(self.level, self.decimation)
        up = (lambda x: x) if ups is None else ups  # noqa: E731
        if self.target == "full":
            q = Ym.reshape(F, cm.n_control, 3)
            u = q - (cm.rest_ - ctx.rig.starts[0])
            local = ctx.rest - ctx.rig.starts[0] + up(u)
            return np.einsum("fab,fvb->fva", W[:, 0], local) + S[:, 0, None]
        d = to_world(Ym.reshape(F, -1, 3), self._frames(ctx, W, cm))
        if self.detail == "laplacian":
            d = ctx.laplacian(self.level, self.decimation).decode(d)
        return Ps + up(d)

    def fit(self, ctx: MeshContext, frames: np.ndarray, root_t: np.ndarray, angles: np.ndarray,
            features: np.ndarray | None = None, control: tuple | None = None) -> "HybridModel":
        """Learn from training frames (F, V, 3) and their fitted poses.

        ``features``: precomputed pose features ``y_S`` of these frames (when
        they are not consecutive, compute them on the whole sequence and index);
        ``control``: precomputed control positions (of the frames, of their
        skinned meshes), e.g. cached on the context for the whole sequence.
        """
        t0, c0 = time.perf_counter(), time.process_time()
        cm = ctx.control_mesh(self.level, self.decimation)
        self.control_ = cm.source_
        self.n_train_ = len(frames)
        if self.regressor != "none":
            Ps, W, S = ctx.skin(root_t, angles)
            if control is None:
                control = (ctx.control_positions(self.level, frames, self.decimation),
                           ctx.control_positions(self.level, Ps, self.decimation))
            Ym = self._encode(ctx, control[0], control[1], W, S)
            Ys = pose_features(angles, self.joint_param) if features is None else np.asarray(features)
            self.ys_mean_, self.ys_sd_ = Ys.mean(axis=0), Ys.std(axis=0) + 1e-8
            Z = (Ys - self.ys_mean_) / self.ys_sd_
            if self.regressor == "gp":
                self.gp_ = SharedGPDM(self.latent_dim, self.iterations, dynamics=self.dynamics_weight > 0,
                                      dynamics_weight=max(self.dynamics_weight, 1e-12)).fit([Ys, Ym])
                self.inv_ = GPRegression(self.iterations).fit(Ys, self.gp_.X_)
            elif self.regressor == "gp_regression":
                from sklearn.gaussian_process import GaussianProcessRegressor
                from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

                kernel = ConstantKernel() * RBF(length_scale=np.sqrt(Z.shape[1])) + WhiteKernel()
                with threadpool_limits(limits=1, user_api="blas"):
                    self.gpr_ = GaussianProcessRegressor(kernel=kernel, normalize_y=True).fit(Z, Ym)
            else:
                from sklearn.linear_model import RidgeCV
                from sklearn.model_selection import KFold

                cv = KFold(n_splits=min(5, len(Z)))  # unshuffled: contiguous blocks
                self.ridge_ = RidgeCV(alphas=self.ridge_alphas, cv=cv).fit(Z, Ym)
        ctx.upsampler(self.level, self.decimation)  # precompute (part of training)
        self.train_seconds_ = time.perf_counter() - t0
        self.train_cpu_seconds_ = time.process_time() - c0
        return self

    def predict_mesh_part(self, angles: np.ndarray, prev_angles=None) -> np.ndarray | None:
        Ys = pose_features(angles, self.joint_param, prev_angles)
        if self.regressor == "gp":
            return self.gp_.predict(self.inv_.predict(Ys), 1)
        if self.regressor == "gp_regression":
            return self.gpr_.predict((Ys - self.ys_mean_) / self.ys_sd_)
        if self.regressor == "ridge_cv":
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
        """Numbers needed to store the animation with this model (rest mesh, weights, poses, model)."""
        J = ctx.rig.n_joints
        cm = ctx.control_mesh(self.level, self.decimation)
        base = ctx.rest.size + 2 * ctx.weights.nnz + 6 * J + n_frames * (3 + 3 * J)
        base += 0 if cm.collapses_ is None else cm.collapses_.size
        base += len(self.control_) if cm.method == "farthest" else 0
        if self.regressor == "gp":
            N = self.n_train_
            D_m = self.gp_.alpha_[1].shape[1]
            base += N * self.latent_dim + N * D_m + N * self.latent_dim + 20 + 2 * D_m
        elif self.regressor == "gp_regression":
            base += self.gpr_.alpha_.size + self.gpr_.X_train_.size + 4
        elif self.regressor == "ridge_cv":
            base += self.ridge_.coef_.size + self.ridge_.intercept_.size + 2 * self.ys_mean_.size
        return int(base)


def mean_vertex_error(pred: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per-frame mean Euclidean vertex distance (same units as the input)."""
    return np.linalg.norm(np.asarray(pred) - np.asarray(truth), axis=-1).mean(axis=-1)


def reconstruction_seconds_per_frame(model: HybridModel, ctx: MeshContext, root_t, angles, repeat: int = 1):
    """Wall and CPU time per frame when frames are reconstructed one at a time (interactive editing).

    Frame t is reconstructed alone from its pose and the previous frame's angles. Returns the best
    of ``repeat`` runs as (wall seconds, CPU seconds) per frame.
    """
    F = len(root_t)
    best, best_cpu = np.inf, np.inf
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        for t in range(1, F):
            model.predict(ctx, root_t[t: t + 1], angles[t: t + 1], prev_angles=angles[t - 1: t])
        n = max(F - 1, 1)
        best, best_cpu = min(best, (time.perf_counter() - t0) / n), min(best_cpu, (time.process_time() - c0) / n)
    return best, best_cpu


__all__ = ["HybridModel", "MeshContext", "pose_features", "joint_features", "mean_vertex_error",
           "reconstruction_seconds_per_frame"]
