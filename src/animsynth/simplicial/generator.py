"""Gauch & Peters field following as one estimator: :class:`FieldFollower`.

The method, once: PCA of the training joint angles (:func:`fit_pca`), the training vectors of the latent clips
(:func:`~.field.training_vectors`), the interpolated vector field (:class:`~.field.VectorField`), Euler steps
along it from a latent start (:func:`~.path.follow_field`) and the inverse PCA back to joint angles. Every route
calls it:

* the paper's leave-one-sequence-out folds (:mod:`.folds`) fit the latent space on the training trials
  (:meth:`FieldFollower.fit_latent`), one field per variant on it (:meth:`FieldFollower.fit_field`) and follow
  it (:meth:`FieldFollower.follow`; the ensembles of starts advance the fitted fields together with
  :func:`~.path.follow_batch`, the batched form of the same steps);
* the one-call user route (:func:`.generate.generate_from_trials`, the CLI ``animsynth generate``) fits on
  joint-angle clips (:meth:`FieldFollower.fit_angles`), follows from the encoded start and decodes the path;
* the side-by-side comparison's ``delaunay`` and ``knn`` rows (:mod:`animsynth.compare.generators.registry`) fit on a
  database of motions (:meth:`FieldFollower.fit`) and generate poses (:meth:`FieldFollower.generate`).
"""

from __future__ import annotations

import numpy as np

from ..generator import Database, Generator
from ..motion import Motion

__all__ = ["FieldFollower", "fit_pca"]


def fit_pca(train: list, latent_dim: int, what: str = "config key 'simplicial.latent_dim'"):
    """PCA on the concatenated training frames (never the held-out one).

    Parameters
    ----------
    train : list of array-like (n_i, D), the training trials' joint angles
    latent_dim : int, principal components kept (at most ``min(sum n_i, D)``)
    what : str, names the setting in the error of a ``latent_dim`` the frames do not allow

    Returns
    -------
    sklearn.decomposition.PCA, fitted (``svd_solver="full"``) on the stacked ``(sum n_i, D)`` frames:
    ``components_`` ``(latent_dim, D)``, ``mean_`` ``(D,)``

    Raises
    ------
    ValueError if the frames hold NaN/inf or ``latent_dim`` exceeds ``min(sum n_i, D)``.
    """
    from sklearn.decomposition import PCA

    X = np.vstack([np.asarray(t, float) for t in train])
    if not np.all(np.isfinite(X)):
        raise ValueError("training joint angles contain NaN/inf")
    max_dim = min(X.shape[0], X.shape[1])
    if latent_dim > max_dim:
        raise ValueError(f"{what}: {latent_dim} exceeds what {X.shape[0]} frames x "
                         f"{X.shape[1]} angles allow ({max_dim})")
    return PCA(n_components=latent_dim, svd_solver="full").fit(X)


class FieldFollower(Generator):
    """Gauch & Peters field following: PCA latent space, vector field, Euler steps, decoded to poses.

    As a :class:`~animsynth.generator.Generator` (``fit(database)`` / ``generate``) the root comes from the
    database frame nearest in latent space (an extension: the paper has no root), integrated from the start
    (:meth:`animsynth.generator.Database.play`).

    Parameters
    ----------
    method : {"delaunay", "knn", "kdelaunay"}
    latent_dim : int, PCA dimension of the joint angles (paper: 2)
    k : int, k-NN neighbours (and Delaunay's outside-hull fallback; paper: 16)
    derivative : {"half", "forward", "central"}, training vectors; ``half`` moves half a frame per
        step, so :meth:`generate` takes two steps per output frame, the others one step per frame
    jitter : float, :meth:`generate` moves the start's latent point by this fraction of the latent
        bounding-box diagonal in a seeded random direction (the field is deterministic: seeds differ by this)
    weights : {"idw", "barycentric"}, the field's interpolation weights (:class:`~.field.VectorField`)
    dup_tol, rank_tol : float, the triangulation's relative tolerances (:class:`~.geometry.SafeDelaunay`)

    Attributes
    ----------
    pca_ : sklearn PCA of the training joint angles
    latent_clips_ : list of ndarray (n_i, latent_dim), the training clips in latent space
    latent_ : ndarray (N, latent_dim), the same stacked
    scale_ : float, latent bounding-box diagonal
    vectors_ : ndarray (N, latent_dim), the training vectors
    field_ : :class:`~.field.VectorField`
    db_ : :class:`~animsynth.generator.Database` (:meth:`fit` only)
    tree_ : cKDTree of ``latent_`` (:meth:`fit` only)
    steps_per_frame_ : int (:meth:`fit` only)
    """

    lazy_imports = Generator.lazy_imports + (
        "scipy.spatial", "sklearn.decomposition", "numba", "animsynth.retarget", "animsynth.simplicial.field",
        "animsynth.simplicial.geometry", "animsynth.simplicial.path", "animsynth.simplicial.kernels")

    def __init__(self, method: str = "delaunay", latent_dim: int = 2, k: int = 16, derivative: str = "half",
                 jitter: float = 0.01, weights: str = "idw", dup_tol: float = 1e-9, rank_tol: float = 1e-9):
        self.method = method
        self.latent_dim = latent_dim
        self.k = k
        self.derivative = derivative
        self.jitter = jitter
        self.weights = weights
        self.dup_tol = dup_tol
        self.rank_tol = rank_tol
        self.name = method

    # ------------------------------------------------------------------ the method's steps
    def fit_latent(self, clips, what: str = "config key 'simplicial.latent_dim'") -> "FieldFollower":
        """PCA of joint-angle clips (list of ``(n_i, D)``, root removed) and the clips in latent space."""
        d = int(self.latent_dim)
        if d < 1:
            raise ValueError(f"{what}: {d} is not >= 1")
        clips = [np.asarray(c, float) for c in clips]
        if not clips:
            raise ValueError("FieldFollower: no training clips")
        self.pca_ = fit_pca(clips, d, what)
        self.latent_clips_ = [self.pca_.transform(c) for c in clips]
        self.latent_ = np.vstack(self.latent_clips_)
        from .geometry import bbox_diagonal

        self.scale_ = float(bbox_diagonal(self.latent_))
        return self

    def fit_field(self, space: "FieldFollower | None" = None, triangulation=None) -> "FieldFollower":
        """Training vectors and vector field on the latent clips.

        Parameters
        ----------
        space : FieldFollower, optional
            A fitted estimator of the same ``latent_dim`` whose latent space (PCA and latent clips) this one
            shares instead of its own :meth:`fit_latent`: the folds fit PCA once per fold and latent
            dimension for all their variants (the same numbers as fitting it again, without the repeat).
        triangulation : SafeDelaunay of ``latent_``, optional
            Shared by the variants of a fold (:meth:`.field.VectorField.fit`).
        """
        from .field import VectorField, training_vectors

        if space is not None:
            if int(space.latent_dim) != int(self.latent_dim):
                raise ValueError(f"FieldFollower: latent_dim {self.latent_dim} but the shared space has "
                                 f"{space.latent_dim}")
            self.pca_, self.latent_clips_ = space.pca_, space.latent_clips_
            self.latent_, self.scale_ = space.latent_, space.scale_
        self.vectors_ = training_vectors(self.latent_clips_, self.derivative)
        self.field_ = VectorField(self.method, self.k, self.weights, self.dup_tol, self.rank_tol).fit(
            self.latent_, self.vectors_, triangulation=triangulation)
        return self

    def fit_angles(self, clips) -> "FieldFollower":
        """Fit on joint-angle clips (root removed): :meth:`fit_latent`, then :meth:`fit_field`."""
        return self.fit_latent(clips).fit_field()

    def encode(self, angles) -> np.ndarray:
        """Joint angles ``(n, D)`` -> latent points ``(n, latent_dim)``."""
        return self.pca_.transform(angles)

    def decode(self, points) -> np.ndarray:
        """Latent points ``(n, latent_dim)`` -> joint angles ``(n, D)`` (inverse PCA)."""
        return self.pca_.inverse_transform(points)

    def follow(self, x0, steps: int):
        """``steps`` Euler steps along the field from the latent point ``x0``
        (:class:`~.path.GeneratedPath`: ``steps + 1`` points and the steps that fell back to k-NN)."""
        from .path import follow_field

        return follow_field(self.field_, x0, steps)

    # ------------------------------------------------------------------ the generator interface
    #: the field methods and weights whose path kernel this process has run (:meth:`warm_up`: once each)
    _warmed: set = set()

    def warm_up(self) -> None:
        """Import what fit and generate import on first use (:meth:`animsynth.generator.Generator.warm_up`), then,
        once per process, field method and weights, follow a small field for 3 steps: numba loads its compiled kernels (from
        its cache) at their first call, which would otherwise be the first generation's time."""
        super().warm_up()
        if (self.method, self.weights) in FieldFollower._warmed:
            return
        from .field import VectorField
        from .path import follow_field

        d = max(int(self.latent_dim), 2)
        pts = np.random.default_rng(0).standard_normal((max(12, d + 2), d))  # enough points for a d-simplex
        follow_field(VectorField(self.method, min(int(self.k), 4), self.weights, self.dup_tol, self.rank_tol).fit(
            pts, -pts), pts[0] * 0.1, 3)
        FieldFollower._warmed.add((self.method, self.weights))

    def fit(self, database, native_clips=None) -> "FieldFollower":
        """Fit on a database of motions (list of Motion; ``native_clips``: ignored, it runs at the working rate,
        :class:`animsynth.generator.Generator`): the joint angles of every clip, root removed, each clip
        on the angle branch of the first clip's (:func:`animsynth.retarget.align_angle_branches`; the
        comparison's clips already are, and stay as they are). The clips are expected continuous along time
        (:func:`animsynth.retarget.unwrap_angles`, which :func:`animsynth.data.load_trial` and the
        comparison's clips apply at the capture's own rate)."""
        from scipy.spatial import cKDTree

        from ..retarget import align_angle_branches

        self.db_ = db = Database(database)
        clips = [align_angle_branches(c, db.clips[0]) for c in db.clips]
        self.branch_ref_ = clips[0]
        self.fit_latent([np.asarray(c.values, float)[:, db.n_root:] for c in clips], what="latent_dim")
        self.fit_field()
        self.tree_ = cKDTree(self.latent_)
        self.steps_per_frame_ = 2 if self.derivative == "half" else 1
        return self

    def generate(self, start: Motion, length: int, seed: int, native_start: Motion | None = None) -> Motion:
        """Follow the field from the start's last pose and decode the path to poses.

        Parameters
        ----------
        start : Motion, ``(>= 2, n_dof)`` values of the database's skeleton; its last frame's joint angles (put on
            the database's angle branch) are encoded, the latent point moved by the seeded
            ``jitter``
        length : int, output frames; the path takes ``length * steps_per_frame_`` Euler steps
        seed : int, the jitter's random direction
        native_start : ignored (it runs at the working rate)

        Returns
        -------
        Motion, ``(length, n_dof)`` values: joint angles decoded from every ``steps_per_frame_``-th path point,
        the root played from the database frames nearest in latent space (integrated from the start's last
        frame); ``meta``: ``seams`` (empty, int64), ``source_frames`` ``(length, 2)`` int64 of -1 (decoded poses
        have no source frame), ``fallback_share`` (float, the share of steps that fell back to k-NN)
        """
        from ..retarget import align_angle_branches

        self._check_start(start, length)
        db, spf, length = self.db_, self.steps_per_frame_, int(length)
        start_values = align_angle_branches(start, self.branch_ref_).values  # on the database's branch
        x0 = self.encode(np.asarray(start_values, float)[-1:, db.n_root:])[0]
        u = np.random.default_rng(seed).normal(size=x0.size)
        x0 = x0 + float(self.jitter) * self.scale_ * u / max(float(np.linalg.norm(u)), 1e-300)
        path = self.follow(x0, length * spf)
        pts = path.points[spf::spf]
        _, near = self.tree_.query(np.vstack([x0[None, :], pts]))
        values = db.play(near, start.values[-1])[1:]
        values[:, db.n_root:] = self.decode(pts)
        return self._motion(values, length, [], np.full((length, 2), -1),
                            fallback_share=float(path.fallback.mean()) if path.fallback.size else 0.0)
