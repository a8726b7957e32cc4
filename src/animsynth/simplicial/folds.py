"""Fold running: the leave-one-sequence-out folds of Gauch & Peters, ensembles of starts, variant grids.

One *fold* holds one trial of a subset out, fits PCA on the other trials'
joint angles (56 columns, root removed), builds the vector field and the
motion graph G' on their latent points, follows the field from the held-out
trial's first latent frame (or plans a shortest path in G' toward its last
frame) and scores the generated path with Error A and Error F.

Every fold gives one row (:data:`FOLD_COLUMNS`, fixed order). Errors are
reported

* in latent units (``error_a``, ``error_f``),
* normalised by the diagonal of the fold's latent bounding box of the
  training points (``*_norm``; compares subsets, not latent dimensions), and
* in joint-angle space (``*_pose``, degrees): the generated latent path is
  reprojected with the inverse PCA and compared with the held-out trial's
  real 56 joint angles. Only this one compares different latent dimensions.
  ``pose_floor`` is the pose-space Error A of the *perfect* latent path (the
  held-out trial projected and reprojected): the part of ``error_a_pose``
  that is PCA reconstruction loss, not generation error.

The method itself (PCA, training vectors, vector field, Euler steps, inverse PCA) is
:class:`~animsynth.simplicial.generator.FieldFollower`, the estimator the CLI and the side-by-side comparison
call too: a fold fits its latent space once per latent dimension (:func:`prepare_fold`) and one field per
variant on it (:func:`variant_follower`). The motion graph G' of target-directed generation and the scores
are the paper pipeline's own.

``length_ratio`` is the arc length of the generated latent path over that of
the held-out latent path (about 0.5 means the walk covered half the motion).

Ensembles of starts
-------------------
Field following is chaotic for some training vectors: moving the start by
1e-9 of the latent diagonal can flip which method wins a fold. Every fold is
therefore also run from an *ensemble*: member 0 starts at the held-out
trial's first latent frame (the paper's start), members 1..N at seeded
copies moved by ``jitter`` x the latent bounding-box diagonal in a random
direction. All members of all variants of a fold that share the latent
space are followed together (:func:`~animsynth.simplicial.path.follow_batch`).
Member 0 gives the fold row; the members give the spread (IQR), the share of
members in which one method beats another, and the separation growth
``|x_j(T) - x_0(T)| / |x_j(0) - x_0(0)|`` (how fast nearby paths separate).

The tables built from these rows are in :mod:`~animsynth.simplicial.tables`, the statistics over them
(paired tests, shares over the ensemble, variant summaries) in :mod:`~animsynth.simplicial.stats`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from .field import DERIVATIVES, VectorField
from .generator import FieldFollower, fit_pca
from .geometry import SafeDelaunay
from .graph import MotionGraph
from .metrics import error_a, error_f
from .path import GeneratedPath, TargetPlanner, follow_batch

if TYPE_CHECKING:  # the fitted PCA comes from generator.fit_pca, which imports scikit-learn when it fits
    from sklearn.decomposition import PCA

GENERATIONS = ("field", "target")

FOLD_COLUMNS = [
    "dataset", "held_out", "fold", "variant", "method", "k", "latent_dim", "derivative", "weights", "generation",
    "n_train_frames", "n_test_frames", "explained_var", "bbox_diag",
    "steps", "fallback_steps", "error_a", "error_a_norm", "error_f", "error_f_norm",
    "error_a_pose", "error_f_pose", "pose_floor", "error_a_true_to_gen", "error_a_gen_to_true", "length_ratio",
    "components", "largest_component_frac", "undirected_connected", "h_connected",
    "n_edges", "n_clip_edges", "n_added_pairs", "n_tie_edges",
    "tri_status", "n_duplicates", "target_reached",
    "fallback_share", "n_members", "ens_error_a_norm_median", "ens_error_a_norm_q25", "ens_error_a_norm_q75",
    "ens_error_f_norm_median", "ens_error_f_norm_q25", "ens_error_f_norm_q75", "ens_fallback_share",
    "sep_growth_log10", "sep_final_rel",
]

#: One row per ensemble member and variant of a fold.
MEMBER_COLUMNS = [
    "dataset", "held_out", "fold", "variant", "method", "k", "latent_dim", "derivative", "weights", "generation",
    "member", "steps", "fallback_steps", "error_a_norm", "error_f_norm", "error_a_pose", "error_f_pose",
    "sep_initial_rel", "sep_final_rel", "sep_max_rel",
]


@dataclass(frozen=True)
class Variant:
    """One method configuration.

    Attributes
    ----------
    name : str
    method : {"delaunay", "knn", "kdelaunay"}
    k : int
        k-NN neighbours (for ``delaunay``: the outside-hull fallback k).
    latent_dim : int
    derivative : {"half", "forward", "central"}
    weights : {"idw", "barycentric"}
    generation : {"field", "target"}
    """

    name: str
    method: str = "delaunay"
    k: int = 16
    latent_dim: int = 2
    derivative: str = "half"
    weights: str = "idw"
    generation: str = "field"

    def check(self) -> "Variant":
        if self.derivative not in DERIVATIVES:
            raise ValueError(f"variant {self.name!r}: derivative must be one of {DERIVATIVES}")
        if self.generation not in GENERATIONS:
            raise ValueError(f"variant {self.name!r}: generation must be one of {GENERATIONS}")
        if self.latent_dim < 1:
            raise ValueError(f"variant {self.name!r}: latent_dim must be >= 1")
        return self


@dataclass
class FoldResult:
    """Everything one fold computed (for tables and figures)."""

    row: dict
    pca: PCA
    train_latent: list
    test_latent: np.ndarray
    path: GeneratedPath
    graph: MotionGraph
    field: VectorField
    vectors: np.ndarray
    extra: dict = field(default_factory=dict)


def steps_for(steps, n_frames: int) -> int:
    """Number of path steps: ``"held_out"`` -> the held-out trial's frame count, or an int."""
    if steps in (None, "held_out"):
        return int(n_frames)
    s = int(steps)
    if s < 1:
        raise ValueError(f"config key 'simplicial.steps': must be 'held_out' or an integer >= 1, got {steps!r}")
    return s


def arc_length(points) -> float:
    p = np.asarray(points, float)
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) if len(p) > 1 else 0.0


@dataclass
class FoldContext:
    """What every variant of one fold at one latent dimension shares: the latent space (``space``, a
    :class:`~.generator.FieldFollower` fitted by :meth:`~.generator.FieldFollower.fit_latent` on the training
    trials; ``pca``, ``clips``, ``X`` and ``diag`` read its ``pca_``, ``latent_clips_``, ``latent_`` and
    ``scale_``), the held-out trial in it and the triangulation."""

    space: FieldFollower
    lengths: list
    T: np.ndarray
    test: np.ndarray
    tri: SafeDelaunay
    floor: float

    @property
    def pca(self) -> PCA:
        return self.space.pca_

    @property
    def clips(self) -> list:
        return self.space.latent_clips_

    @property
    def X(self) -> np.ndarray:
        return self.space.latent_

    @property
    def diag(self) -> float:
        return self.space.scale_


def prepare_fold(train: list, test, latent_dim: int, dup_tol: float = 1e-9, rank_tol: float = 1e-9,
                 held_out: str = "") -> FoldContext:
    """PCA on the training trials, latent clips, held-out latent path and the shared triangulation."""
    test = np.asarray(test, float)
    if test.ndim != 2 or test.shape[0] < 2:
        raise ValueError(f"held-out trial {held_out!r} needs at least 2 frames")
    space = FieldFollower(latent_dim=latent_dim, dup_tol=dup_tol, rank_tol=rank_tol).fit_latent(train)
    X = space.latent_
    T = space.encode(test)
    tri = SafeDelaunay(dup_tol, rank_tol).fit(X)
    floor = error_a(test, space.decode(T))[0]  # Error A of the perfect latent path (PCA loss alone)
    return FoldContext(space, [len(c) for c in space.latent_clips_], T, test, tri, floor)


def variant_follower(ctx: FoldContext, variant: Variant, dup_tol: float = 1e-9,
                     rank_tol: float = 1e-9) -> FieldFollower:
    """The variant's :class:`~.generator.FieldFollower` on the fold's shared latent space and triangulation."""
    return FieldFollower(variant.method, variant.latent_dim, variant.k, variant.derivative, weights=variant.weights,
                         dup_tol=dup_tol, rank_tol=rank_tol).fit_field(space=ctx.space, triangulation=ctx.tri)


def _variant_objects(ctx: FoldContext, variant: Variant, dup_tol: float, rank_tol: float):
    """The variant's field follower and the motion graph G' on its training vectors (target-directed
    generation; the paper's graph, not part of field following)."""
    est = variant_follower(ctx, variant, dup_tol, rank_tol)
    graph = MotionGraph(variant.method, variant.k, dup_tol, rank_tol).fit(ctx.X, est.vectors_, ctx.lengths,
                                                                          triangulation=ctx.tri)
    return est, graph


def _fold_row(ctx: FoldContext, variant: Variant, path: GeneratedPath, graph: MotionGraph, reached, *,
              dataset: str, held_out: str, fold: int) -> dict:
    T, X, pca, test, tri, diag = ctx.T, ctx.X, ctx.pca, ctx.test, ctx.tri, ctx.diag
    a, t2g, g2t = error_a(T, path.points)
    f = error_f(T, path.points)
    gen_pose = pca.inverse_transform(path.points)
    a_pose = error_a(test, gen_pose)[0]
    f_pose = error_f(test, gen_pose)
    conn = graph.connectivity()
    norm = diag if diag > 0 else np.nan
    return {
        "dataset": dataset, "held_out": held_out, "fold": int(fold), "variant": variant.name,
        "method": variant.method, "k": int(variant.k), "latent_dim": int(variant.latent_dim),
        "derivative": variant.derivative, "weights": variant.weights, "generation": variant.generation,
        "n_train_frames": int(X.shape[0]), "n_test_frames": int(len(T)),
        "explained_var": float(np.sum(pca.explained_variance_ratio_)), "bbox_diag": diag,
        "steps": path.steps, "fallback_steps": path.fallback_steps,
        "error_a": a, "error_a_norm": a / norm, "error_f": f, "error_f_norm": f / norm,
        "error_a_pose": a_pose, "error_f_pose": f_pose, "pose_floor": ctx.floor,
        "error_a_true_to_gen": t2g, "error_a_gen_to_true": g2t,
        "length_ratio": arc_length(path.points) / max(arc_length(T), 1e-300),
        "components": conn["scc"], "largest_component_frac": conn["largest_scc_frac"],
        "undirected_connected": conn["undirected_connected"], "h_connected": conn["h_connected"],
        "n_edges": conn["n_edges"], "n_clip_edges": conn["n_clip_edges"], "n_added_pairs": conn["n_added_pairs"],
        "n_tie_edges": conn["n_tie_edges"], "tri_status": tri.status_, "n_duplicates": tri.n_duplicates_,
        "target_reached": reached,
        "fallback_share": path.fallback_steps / path.steps if path.steps else 0.0,
    }


def _ensemble_columns(row: dict, members: pd.DataFrame) -> dict:
    """Fill the ensemble columns of a fold row from its member rows."""
    out = dict(row)
    out["n_members"] = int(len(members))
    for met in ("error_a_norm", "error_f_norm"):
        v = members[met].to_numpy(float)
        q25, q50, q75 = np.quantile(v, [0.25, 0.5, 0.75])
        out[f"ens_{met}_median"], out[f"ens_{met}_q25"], out[f"ens_{met}_q75"] = float(q50), float(q25), float(q75)
    st = members["steps"].to_numpy(float)
    out["ens_fallback_share"] = float(members["fallback_steps"].sum() / st.sum()) if st.sum() else 0.0
    jit = members[members["member"] > 0]
    with np.errstate(divide="ignore", invalid="ignore"):  # jitter 0: no separation to grow
        growth = jit["sep_final_rel"].to_numpy(float) / jit["sep_initial_rel"].to_numpy(float)
    growth = growth[np.isfinite(growth) & (growth > 0)]
    out["sep_growth_log10"] = float(np.median(np.log10(growth))) if growth.size else np.nan
    out["sep_final_rel"] = float(jit["sep_final_rel"].median()) if len(jit) else np.nan
    assert list(out) == FOLD_COLUMNS
    return out


def run_fold(train: list, test, variant: Variant, *, dataset: str = "", held_out: str = "", fold: int = 0,
             steps="held_out", dup_tol: float = 1e-9, rank_tol: float = 1e-9,
             max_all_pairs: int = 4000) -> FoldResult:
    """Run one leave-one-sequence-out fold from the held-out start alone (one path).

    Parameters
    ----------
    train : list of arrays (n_i, 56)
        Joint angles of the training trials (root removed).
    test : array (n, 56)
        The held-out trial.
    variant : Variant
    steps : "held_out" or int
        Path length for field following.
    """
    variant.check()
    ctx = prepare_fold(train, test, variant.latent_dim, dup_tol, rank_tol, held_out)
    est, graph = _variant_objects(ctx, variant, dup_tol, rank_tol)
    extra = {}
    if variant.generation == "field":
        path = est.follow(ctx.T[0], steps_for(steps, len(ctx.T)))
        reached = ""
    else:
        planner = TargetPlanner(max_all_pairs).fit(graph)
        path, info = planner.plan(ctx.T[0], ctx.T[-1])
        extra["plan"] = info
        reached = bool(info["reached"])
    row = _fold_row(ctx, variant, path, graph, reached, dataset=dataset, held_out=held_out, fold=fold)
    one = pd.DataFrame([{"member": 0, "steps": path.steps, "fallback_steps": path.fallback_steps,
                         "error_a_norm": row["error_a_norm"], "error_f_norm": row["error_f_norm"],
                         "sep_initial_rel": 0.0, "sep_final_rel": 0.0}])
    row = _ensemble_columns(row, one)
    return FoldResult(row, ctx.pca, ctx.clips, ctx.T, path, graph, est.field_, est.vectors_, extra)


def jittered_starts(start, n_starts: int, jitter: float, scale: float, seed: int) -> np.ndarray:
    """The held-out start and ``n_starts`` copies moved by ``jitter * scale`` in seeded random directions.

    Returns
    -------
    ndarray (n_starts + 1, d); row 0 is ``start`` itself. A jitter of 0 gives identical rows.
    """
    start = np.asarray(start, float)
    if int(n_starts) < 0 or not np.isfinite(jitter) or jitter < 0:
        raise ValueError(f"config key 'simplicial.ensemble': n_starts must be >= 0 and jitter >= 0, "
                         f"got {n_starts!r}, {jitter!r}")
    u = np.random.default_rng(seed).normal(size=(int(n_starts), start.size))
    u /= np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-300)
    return np.vstack([start[None, :], start[None, :] + float(jitter) * float(scale) * u])


def run_fold_ensemble(train: list, test, variants, *, n_starts: int = 16, jitter: float = 1e-6, seed: int = 0,
                      dataset: str = "", held_out: str = "", fold: int = 0, steps="held_out",
                      dup_tol: float = 1e-9, rank_tol: float = 1e-9, max_all_pairs: int = 4000,
                      member_pose=False) -> tuple[list, pd.DataFrame]:
    """One fold for several variants, each from the same ensemble of starts.

    Variants that share a latent dimension share the PCA and the
    triangulation; all their field-following paths (members x variants) are
    advanced together (:func:`~animsynth.simplicial.path.follow_batch`). The jitter
    directions are seeded by ``seed`` and the latent dimension only, so every
    variant (and every job) of a fold uses the same starts: member j of
    Delaunay pairs with member j of k-NN.

    Parameters
    ----------
    n_starts : int
        Jittered copies besides the held-out start (members 1..n_starts).
    jitter : float
        Start displacement relative to the latent bounding-box diagonal.
    member_pose : bool or collection of variant names
        Also compute the pose-space errors of every member (of all variants, or of
        the named ones); otherwise only member 0 has them (NaN for the others).

    Returns
    -------
    rows : list of dict
        One :data:`FOLD_COLUMNS` row per variant (member 0 plus ensemble columns).
    members : DataFrame (:data:`MEMBER_COLUMNS`)
    """
    variants = [v.check() for v in variants]
    rows, mrows = [], []
    for dim in dict.fromkeys(v.latent_dim for v in variants):
        group = [v for v in variants if v.latent_dim == dim]
        ctx = prepare_fold(train, test, dim, dup_tol, rank_tol, held_out)
        starts = jittered_starts(ctx.T[0], n_starts, jitter, ctx.diag, seed)
        objs = [_variant_objects(ctx, v, dup_tol, rank_tol) for v in group]
        paths = _ensemble_paths(ctx, group, objs, starts, steps, max_all_pairs)
        for i, v in enumerate(group):
            pose = member_pose is True or (not isinstance(member_pose, bool) and v.name in member_pose)
            vm = _member_rows(ctx, v, paths[i], pose, dict(dataset=dataset, held_out=held_out, fold=int(fold)))
            row = _fold_row(ctx, v, paths[i][0][0], objs[i][1], paths[i][0][1], dataset=dataset, held_out=held_out,
                            fold=fold)
            rows.append(_ensemble_columns(row, vm))
            mrows.append(vm)
    return rows, pd.concat(mrows, ignore_index=True)


def _ensemble_paths(ctx, group: list, objs: list, starts: np.ndarray, steps, max_all_pairs: int) -> dict:
    """``{variant index: [(path, reached), ...]}``, one path per start: every field variant's members followed at
    once (``reached`` ""), every target variant's planned to the held-out end (``reached`` True or False)."""
    M = starts.shape[0]
    fld_idx = [i for i, v in enumerate(group) if v.generation == "field"]
    paths: dict[int, list] = {}
    if fld_idx:
        n = steps_for(steps, len(ctx.T))
        which = np.repeat(np.arange(len(fld_idx)), M)
        # every member of every variant at once: the batched form of FieldFollower.follow (follow_field is
        # follow_batch of one path), one step loop over the variants' fields
        bp = follow_batch([objs[i][0].field_ for i in fld_idx], np.tile(starts, (len(fld_idx), 1)), n, which)
        for j, i in enumerate(fld_idx):
            paths[i] = [(bp.path(j * M + m), "") for m in range(M)]
    for i, v in enumerate(group):
        if v.generation == "target":
            planner = TargetPlanner(max_all_pairs).fit(objs[i][1])
            paths[i] = []
            for m in range(M):
                pth, info = planner.plan(starts[m], ctx.T[-1])
                paths[i].append((pth, bool(info["reached"])))
    return paths


def _member_rows(ctx, v, paths: list, pose: bool, where: dict) -> pd.DataFrame:
    """One :data:`MEMBER_COLUMNS` row per member path of variant ``v``: latent errors, pose errors (member 0
    always, the others when ``pose``) and the separation from member 0; ``where``: dataset, held_out, fold."""
    norm = ctx.diag if ctx.diag > 0 else np.nan
    p0 = paths[0][0].points
    vm = []
    for m, (pth, _) in enumerate(paths):
        a = error_a(ctx.T, pth.points)[0]
        f = error_f(ctx.T, pth.points)
        if m == 0 or pose:
            gp = ctx.pca.inverse_transform(pth.points)
            ap, fp = error_a(ctx.test, gp)[0], error_f(ctx.test, gp)
        else:
            ap = fp = np.nan
        L = min(len(p0), len(pth.points))
        sep = np.linalg.norm(pth.points[:L] - p0[:L], axis=1) / norm
        vm.append({**where, "variant": v.name,
                   "method": v.method, "k": int(v.k), "latent_dim": int(v.latent_dim),
                   "derivative": v.derivative, "weights": v.weights, "generation": v.generation,
                   "member": m, "steps": pth.steps, "fallback_steps": pth.fallback_steps,
                   "error_a_norm": a / norm, "error_f_norm": f / norm, "error_a_pose": ap, "error_f_pose": fp,
                   "sep_initial_rel": float(sep[0]), "sep_final_rel": float(sep[-1]),
                   "sep_max_rel": float(sep.max())})
    return pd.DataFrame(vm, columns=MEMBER_COLUMNS)


def run_subset(trials: dict, variants, *, dataset: str, steps="held_out", dup_tol=1e-9, rank_tol=1e-9,
               max_all_pairs: int = 4000, ensemble: dict | None = None, seed: int = 0,
               member_pose=False):
    """All leave-one-out folds of one subset for every variant.

    Parameters
    ----------
    trials : dict trial id -> array (n, 56), in subset order (fold i holds trial i out)
    variants : iterable of Variant
    ensemble : dict with ``n_starts`` and ``jitter``, optional
        Without it every fold is one path from the held-out start (no members returned).
    seed : int
        Seeds the jitter (mixed with the held-out trial id).

    Returns
    -------
    folds : DataFrame (:data:`FOLD_COLUMNS`), and with ``ensemble`` also members (:data:`MEMBER_COLUMNS`)
    """
    from ..config import derive_seed

    ids = list(trials)
    variants = list(variants)
    rows, members = [], []
    if ensemble is None:
        for v in variants:
            for i, tid in enumerate(ids):
                train = [trials[t] for t in ids if t != tid]
                res = run_fold(train, trials[tid], v, dataset=dataset, held_out=tid, fold=i, steps=steps,
                               dup_tol=dup_tol, rank_tol=rank_tol, max_all_pairs=max_all_pairs)
                rows.append(res.row)
        return pd.DataFrame(rows, columns=FOLD_COLUMNS)
    for i, tid in enumerate(ids):
        train = [trials[t] for t in ids if t != tid]
        r, m = run_fold_ensemble(train, trials[tid], variants, n_starts=int(ensemble["n_starts"]),
                                 jitter=float(ensemble["jitter"]), seed=derive_seed(seed, dataset, tid),
                                 dataset=dataset, held_out=tid, fold=i, steps=steps, dup_tol=dup_tol,
                                 rank_tol=rank_tol, max_all_pairs=max_all_pairs, member_pose=member_pose)
        rows += r
        members.append(m)
    folds = pd.DataFrame(rows, columns=FOLD_COLUMNS)
    return folds, pd.concat(members, ignore_index=True)[MEMBER_COLUMNS]


def order_folds(df: pd.DataFrame, datasets) -> pd.DataFrame:
    """Fixed row order: datasets in config order, then variant, then fold (then member)."""
    order = {d: i for i, d in enumerate(datasets)}
    keys = ["_d", "variant", "fold"] + (["member"] if "member" in df.columns else [])
    cols = MEMBER_COLUMNS if "member" in df.columns else FOLD_COLUMNS
    df = df.assign(_d=df["dataset"].map(order)).sort_values(keys, kind="stable")
    return df.drop(columns="_d").reset_index(drop=True)[cols]


# ----------------------------------------------------------------------------
# Variant grids
# ----------------------------------------------------------------------------
def derivative_variants(derivatives, methods, k: int, latent_dim: int, weights: str = "idw") -> list[Variant]:
    return [Variant(f"{m}_{d}", method=m, k=k, latent_dim=latent_dim, derivative=d, weights=weights).check()
            for d in derivatives for m in methods]


def beyond_variants(cfg: dict, base_k: int, derivative: str) -> list[Variant]:
    """The beyond-the-paper grid (see ``docs/config_simplicial.md``).

    ``cfg`` holds the keys of config ``simplicial.beyond`` used here: ``latent_dims``, ``k_values``,
    ``barycentric``, ``kdelaunay`` and ``target_directed`` (all required; the schema fills them).

    * latent dimension in ``latent_dims`` for Delaunay (1/D^2), Delaunay
      (barycentric), k-NN and k-Delaunay (k = ``base_k``);
    * k in ``k_values`` for k-NN and k-Delaunay at the first latent dimension;
    * target-directed generation (shortest paths in G') for Delaunay and k-NN
      at the first latent dimension, beside plain field following.
    """
    dims = list(cfg["latent_dims"])
    d0 = dims[0]
    out: dict[str, Variant] = {}

    def add(v: Variant):
        out.setdefault(v.name, v.check())

    for d in dims:
        add(Variant(f"delaunay_idw_d{d}", "delaunay", base_k, d, derivative, "idw"))
        if cfg["barycentric"]:
            add(Variant(f"delaunay_bary_d{d}", "delaunay", base_k, d, derivative, "barycentric"))
        add(Variant(f"knn{base_k}_d{d}", "knn", base_k, d, derivative))
        if cfg["kdelaunay"]:
            add(Variant(f"kdelaunay{base_k}_d{d}", "kdelaunay", base_k, d, derivative))
    for k in cfg["k_values"]:
        add(Variant(f"knn{k}_d{d0}", "knn", int(k), d0, derivative))
        if cfg["kdelaunay"]:
            add(Variant(f"kdelaunay{k}_d{d0}", "kdelaunay", int(k), d0, derivative))
    if cfg["target_directed"]:
        add(Variant(f"target_delaunay_d{d0}", "delaunay", base_k, d0, derivative, "idw", "target"))
        add(Variant(f"target_knn{base_k}_d{d0}", "knn", base_k, d0, derivative, "idw", "target"))
    return list(out.values())


def to_jsonable(row: dict) -> dict:
    """Plain-Python copy of a fold row (numpy scalars -> float/int/bool, NaN -> None)."""
    out = {}
    for k, v in row.items():
        if isinstance(v, (np.bool_, bool)):
            out[k] = bool(v)
        elif isinstance(v, (np.integer,)):
            out[k] = int(v)
        elif isinstance(v, (float, np.floating)):
            out[k] = None if not np.isfinite(v) else float(v)
        else:
            out[k] = v
    return out


__all__ = [
    "FOLD_COLUMNS", "GENERATIONS", "MEMBER_COLUMNS", "FoldContext", "FoldResult", "Variant", "arc_length",
    "beyond_variants", "derivative_variants", "fit_pca", "jittered_starts", "order_folds", "prepare_fold",
    "run_fold", "run_fold_ensemble", "run_subset", "steps_for", "to_jsonable", "variant_follower",
]
