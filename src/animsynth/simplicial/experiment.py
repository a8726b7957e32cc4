"""Leave-one-sequence-out experiments of Gauch & Peters and their extensions.

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
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from sklearn.decomposition import PCA

from .field import DERIVATIVES, VectorField, training_vectors
from .geometry import SafeDelaunay, bbox_diagonal
from .graph import MotionGraph
from .metrics import error_a, error_f
from .path import GeneratedPath, TargetPlanner, follow_batch, follow_field

log = logging.getLogger("animsynth.simplicial.experiment")

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

#: Columns of the wide all-units table (per method).
TABLE2_METRICS = ("error_a", "error_f", "error_a_norm", "error_f_norm", "error_a_pose", "error_f_pose")


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


def fit_pca(train: list, latent_dim: int) -> PCA:
    """PCA on the concatenated training frames (never the held-out one)."""
    X = np.vstack([np.asarray(t, float) for t in train])
    if not np.all(np.isfinite(X)):
        raise ValueError("training joint angles contain NaN/inf")
    max_dim = min(X.shape[0], X.shape[1])
    if latent_dim > max_dim:
        raise ValueError(f"config key 'simplicial.latent_dim': {latent_dim} exceeds what {X.shape[0]} frames x "
                         f"{X.shape[1]} angles allow ({max_dim})")
    return PCA(n_components=latent_dim, svd_solver="full").fit(X)


@dataclass
class FoldContext:
    """What every variant of one fold at one latent dimension shares."""

    pca: PCA
    clips: list
    X: np.ndarray
    lengths: list
    T: np.ndarray
    test: np.ndarray
    tri: SafeDelaunay
    diag: float
    floor: float
    vectors: dict = field(default_factory=dict)


def prepare_fold(train: list, test, latent_dim: int, dup_tol: float = 1e-9, rank_tol: float = 1e-9,
                 held_out: str = "") -> FoldContext:
    """PCA on the training trials, latent clips, held-out latent path and the shared triangulation."""
    test = np.asarray(test, float)
    if test.ndim != 2 or test.shape[0] < 2:
        raise ValueError(f"held-out trial {held_out!r} needs at least 2 frames")
    pca = fit_pca(train, latent_dim)
    clips = [pca.transform(np.asarray(t, float)) for t in train]
    X = np.vstack(clips)
    T = pca.transform(test)
    tri = SafeDelaunay(dup_tol, rank_tol).fit(X)
    floor = error_a(test, pca.inverse_transform(T))[0]  # Error A of the perfect latent path (PCA loss alone)
    return FoldContext(pca, clips, X, [len(c) for c in clips], T, test, tri, bbox_diagonal(X), floor)


def _variant_objects(ctx: FoldContext, variant: Variant, dup_tol: float, rank_tol: float):
    if variant.derivative not in ctx.vectors:
        ctx.vectors[variant.derivative] = training_vectors(ctx.clips, variant.derivative)
    V = ctx.vectors[variant.derivative]
    graph = MotionGraph(variant.method, variant.k, dup_tol, rank_tol).fit(ctx.X, V, ctx.lengths, triangulation=ctx.tri)
    fld = VectorField(variant.method, variant.k, variant.weights, dup_tol, rank_tol).fit(ctx.X, V, triangulation=ctx.tri)
    return V, graph, fld


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
    V, graph, fld = _variant_objects(ctx, variant, dup_tol, rank_tol)
    extra = {}
    if variant.generation == "field":
        path = follow_field(fld, ctx.T[0], steps_for(steps, len(ctx.T)))
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
    return FoldResult(row, ctx.pca, ctx.clips, ctx.T, path, graph, fld, V, extra)


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
        M = starts.shape[0]
        objs = [_variant_objects(ctx, v, dup_tol, rank_tol) for v in group]
        fld_idx = [i for i, v in enumerate(group) if v.generation == "field"]
        paths: dict[int, list] = {}
        if fld_idx:
            n = steps_for(steps, len(ctx.T))
            which = np.repeat(np.arange(len(fld_idx)), M)
            bp = follow_batch([objs[i][2] for i in fld_idx], np.tile(starts, (len(fld_idx), 1)), n, which)
            for j, i in enumerate(fld_idx):
                paths[i] = [(bp.path(j * M + m), "") for m in range(M)]
        for i, v in enumerate(group):
            if v.generation == "target":
                planner = TargetPlanner(max_all_pairs).fit(objs[i][1])
                paths[i] = []
                for m in range(M):
                    pth, info = planner.plan(starts[m], ctx.T[-1])
                    paths[i].append((pth, bool(info["reached"])))
        norm = ctx.diag if ctx.diag > 0 else np.nan
        for i, v in enumerate(group):
            p0 = paths[i][0][0].points
            vm = []
            for m, (pth, _) in enumerate(paths[i]):
                a = error_a(ctx.T, pth.points)[0]
                f = error_f(ctx.T, pth.points)
                if m == 0 or member_pose is True or (not isinstance(member_pose, bool) and v.name in member_pose):
                    gp = ctx.pca.inverse_transform(pth.points)
                    ap, fp = error_a(ctx.test, gp)[0], error_f(ctx.test, gp)
                else:
                    ap = fp = np.nan
                L = min(len(p0), len(pth.points))
                sep = np.linalg.norm(pth.points[:L] - p0[:L], axis=1) / norm
                vm.append({"dataset": dataset, "held_out": held_out, "fold": int(fold), "variant": v.name,
                           "method": v.method, "k": int(v.k), "latent_dim": int(v.latent_dim),
                           "derivative": v.derivative, "weights": v.weights, "generation": v.generation,
                           "member": m, "steps": pth.steps, "fallback_steps": pth.fallback_steps,
                           "error_a_norm": a / norm, "error_f_norm": f / norm, "error_a_pose": ap, "error_f_pose": fp,
                           "sep_initial_rel": float(sep[0]), "sep_final_rel": float(sep[-1]),
                           "sep_max_rel": float(sep.max())})
            vm = pd.DataFrame(vm, columns=MEMBER_COLUMNS)
            row = _fold_row(ctx, v, paths[i][0][0], objs[i][1], paths[i][0][1], dataset=dataset, held_out=held_out,
                            fold=fold)
            rows.append(_ensemble_columns(row, vm))
            mrows.append(vm)
    return rows, pd.concat(mrows, ignore_index=True)


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
# Table II (the paper's layout), its ensemble spread, and the paired comparison
# ----------------------------------------------------------------------------
#: Table II metrics: the paper's Error A and Error F (ours: normalised by the latent bbox diagonal).
PAPER_METRICS = ("error_a", "error_f")


def stability(share: float) -> str:
    """``stable`` when an ordering holds in every ensemble member (share 0 or 1), else the share."""
    if share is None or not np.isfinite(share):
        return "no ensemble"
    if share in (0.0, 1.0):
        return "stable"
    return f"within start-noise (share {100 * share:.0f} %)"


def table2(folds: pd.DataFrame, datasets, methods=("delaunay", "knn"), paper: pd.DataFrame | None = None,
           col: str = "{metric}_norm") -> pd.DataFrame:
    """Medians over the folds laid out as the paper's Table II.

    One row per metric (``error_a``, ``error_f``) x method; columns the
    subsets and ``all`` with our medians (``col``: bounding-box-normalised by
    default), then ``paper_<subset>`` with the published value (empty when
    ``paper`` is None or lacks the cell), then ``<subset>_minus_paper``
    (ours - paper, empty without the published value).

    Parameters
    ----------
    folds : fold rows (member 0 = the held-out start)
    paper : DataFrame with ``metric, method`` and one column per subset, optional
    """
    cols = list(datasets) + ["all"]
    pap = None
    if paper is not None and len(paper):
        pap = paper.set_index(["metric", "method"])
    rows = []
    for met in PAPER_METRICS:
        c = col.format(metric=met)
        for m in methods:
            r = {"metric": met, "method": m}
            fm = folds[folds["method"] == m]
            for d in cols:
                s = fm if d == "all" else fm[fm["dataset"] == d]
                r[d] = float(s[c].median()) if len(s) else np.nan
            for d in cols:
                val = np.nan
                if pap is not None and (met, m) in pap.index and d in pap.columns:
                    val = float(pap.loc[(met, m), d])
                r[f"paper_{d}"] = val
            for d in cols:
                r[f"{d}_minus_paper"] = r[d] - r[f"paper_{d}"]
            rows.append(r)
    return pd.DataFrame(rows, columns=["metric", "method"] + cols + [f"paper_{d}" for d in cols]
                        + [f"{d}_minus_paper" for d in cols])


def table2_units(folds: pd.DataFrame, datasets, methods=("delaunay", "knn")) -> pd.DataFrame:
    """Table II in every unit: one row per subset (+ ``all``), per method the median of each metric."""
    rows = []
    for name in list(datasets) + ["all"]:
        sub = folds if name == "all" else folds[folds["dataset"] == name]
        r = {"dataset": name, "folds": int(sub["fold"].count() // max(len(methods), 1))}
        for m in methods:
            s = sub[sub["method"] == m]
            for met in TABLE2_METRICS:
                r[f"{m}_{met}"] = float(s[met].median()) if len(s) else np.nan
            r[f"{m}_fallback_share"] = float(s["fallback_steps"].sum() / s["steps"].sum()) if len(s) else np.nan
        rows.append(r)
    return pd.DataFrame(rows)


def member_medians(members: pd.DataFrame, datasets, key: str, values, metric: str) -> dict:
    """Per ensemble member: the median over folds of ``metric`` per (value of ``key``, subset or ``all``).

    Returns
    -------
    dict (value, subset) -> ndarray (n_members,)
    """
    out = {}
    for v in values:
        mv = members[members[key] == v]
        for d in list(datasets) + ["all"]:
            s = mv if d == "all" else mv[mv["dataset"] == d]
            out[(v, d)] = s.groupby("member")[metric].median().sort_index().to_numpy(float)
    return out


def _spread(x):
    if len(x) == 0:
        return np.nan, np.nan, np.nan
    q25, q50, q75 = np.quantile(x, [0.25, 0.5, 0.75])
    return float(q50), float(q25), float(q75)


def table2_ensemble(members: pd.DataFrame, datasets, methods=("delaunay", "knn"),
                    paper: pd.DataFrame | None = None) -> pd.DataFrame:
    """Table II over the ensemble of starts: per metric x subset, each member's Table II cell.

    For every member j the cell is the median over the subset's folds (as in
    the paper); the row gives the median and IQR of that cell over members for
    both methods, the share of members in which the first method is lower
    (``a_lower_share``), whether that ordering is stable, the paper's ordering
    and the share of members that agree with it, and the fallback share of the
    first method (steps outside the hull, all members).
    """
    a, b = methods
    pap = paper.set_index(["metric", "method"]) if paper is not None and len(paper) else None
    rows = []
    for met in PAPER_METRICS:
        mm = member_medians(members, datasets, "method", methods, f"{met}_norm")
        for d in list(datasets) + ["all"]:
            xa, xb = mm[(a, d)], mm[(b, d)]
            r = {"metric": met, "dataset": d, "n_members": int(min(len(xa), len(xb)))}
            for m, x in ((a, xa), (b, xb)):
                r[f"{m}_median"], r[f"{m}_q25"], r[f"{m}_q75"] = _spread(x)
            n = r["n_members"]
            share = float(np.mean(xa[:n] < xb[:n])) if n else np.nan
            r["a_lower_share"] = share
            r["ordering"] = (f"{a}<{b}" if share > 0.5 else f"{b}<{a}" if share < 0.5 else "tie") if n else ""
            r["stability"] = stability(share)
            pa = pb = np.nan
            if pap is not None and (met, a) in pap.index and (met, b) in pap.index and d in pap.columns:
                pa, pb = float(pap.loc[(met, a), d]), float(pap.loc[(met, b), d])
            r[f"paper_{a}"], r[f"paper_{b}"] = pa, pb
            r[f"{a}_median_minus_paper"] = r[f"{a}_median"] - pa
            r[f"{b}_median_minus_paper"] = r[f"{b}_median"] - pb
            if np.isfinite(pa) and np.isfinite(pb) and n:
                r["paper_ordering"] = f"{a}<{b}" if pa < pb else f"{b}<{a}" if pb < pa else "tie"
                r["agree_share"] = share if pa < pb else (1.0 - share if pb < pa else np.nan)
            else:
                r["paper_ordering"], r["agree_share"] = "", np.nan
            s = members[(members["method"] == a) & ((members["dataset"] == d) | (d == "all"))]
            r[f"{a}_fallback_share"] = float(s["fallback_steps"].sum() / s["steps"].sum()) if len(s) else np.nan
            rows.append(r)
    return pd.DataFrame(rows)


def fold_ensemble(members: pd.DataFrame, datasets, methods=("delaunay", "knn")) -> pd.DataFrame:
    """Per fold and metric: median and IQR over members per method, share of members with the first method lower,
    and each method's fallback share (held-out start, and over all members)."""
    a, b = methods
    rows = []
    for (d, fold), s in members.groupby(["dataset", "fold"], sort=False):
        for met in PAPER_METRICS:
            c = f"{met}_norm"
            r = {"dataset": d, "fold": int(fold), "held_out": s["held_out"].iloc[0], "metric": met}
            xs = {}
            for m in methods:
                sm = s[s["method"] == m].sort_values("member")
                xs[m] = sm[c].to_numpy(float)
                r[f"{m}_start"] = float(sm.loc[sm["member"] == 0, c].iloc[0]) if (sm["member"] == 0).any() else np.nan
                r[f"{m}_median"], r[f"{m}_q25"], r[f"{m}_q75"] = _spread(xs[m])
            n = min(len(xs[a]), len(xs[b]))
            share = float(np.mean(xs[a][:n] < xs[b][:n])) if n else np.nan
            r["a_lower_share"], r["stability"] = share, stability(share)
            for m in methods:
                sm = s[s["method"] == m]
                z = sm[sm["member"] == 0]
                r[f"{m}_fallback_share_start"] = float(z["fallback_steps"].sum() / max(z["steps"].sum(), 1))
                r[f"{m}_fallback_share_members"] = float(sm["fallback_steps"].sum() / max(sm["steps"].sum(), 1))
            rows.append(r)
    out = pd.DataFrame(rows)
    order = {d: i for i, d in enumerate(datasets)}
    return out.assign(_d=out["dataset"].map(order)).sort_values(["_d", "fold", "metric"], kind="stable").drop(
        columns="_d").reset_index(drop=True)


def paired_comparison(folds: pd.DataFrame, a: str = "delaunay", b: str = "knn",
                      metrics=("error_a_norm", "error_f_norm", "error_a_pose", "error_f_pose"),
                      n_boot: int = 2000, seed: int = 0, alpha: float = 0.05, key: str = "method") -> pd.DataFrame:
    """Paired Wilcoxon signed-rank test and bootstrap CI of ``a - b`` over folds.

    Folds are paired on (dataset, held_out). ``median_diff`` < 0 means ``a``
    has the lower error. The bootstrap resamples folds (paired) and reports
    the percentile CI of the median difference.
    """
    rng = np.random.default_rng(seed)
    A = folds[folds[key] == a].set_index(["dataset", "held_out"])
    B = folds[folds[key] == b].set_index(["dataset", "held_out"])
    common = A.index.intersection(B.index)
    rows = []
    for met in metrics:
        x = A.loc[common, met].to_numpy(float)
        y = B.loc[common, met].to_numpy(float)
        d = x - y
        n = int(d.size)
        r = {"metric": met, "a": a, "b": b, "n_pairs": n,
             "median_a": float(np.median(x)) if n else np.nan, "median_b": float(np.median(y)) if n else np.nan,
             "median_diff": float(np.median(d)) if n else np.nan, "a_better_folds": int(np.sum(d < 0)),
             "b_better_folds": int(np.sum(d > 0))}
        if n >= 2 and np.any(d != 0):
            from scipy import stats  # here, not at import: scipy.stats costs a fold job a third of a second

            w = stats.wilcoxon(x, y, zero_method="wilcox", alternative="two-sided")
            r["wilcoxon_stat"], r["p_value"] = float(w.statistic), float(w.pvalue)
        else:
            r["wilcoxon_stat"], r["p_value"] = np.nan, np.nan
        if n >= 2:
            idx = rng.integers(0, n, size=(n_boot, n))
            meds = np.median(d[idx], axis=1)
            r["ci_low"], r["ci_high"] = (float(v) for v in np.quantile(meds, [alpha / 2, 1 - alpha / 2]))
        else:
            r["ci_low"] = r["ci_high"] = np.nan
        r["verdict"] = comparison_verdict(r, alpha)
        rows.append(r)
    return pd.DataFrame(rows)


def comparison_verdict(r: dict, alpha: float = 0.05) -> str:
    """``a_better``/``b_better`` when Wilcoxon p < alpha, else ``no_significant_difference``."""
    p = r.get("p_value")
    if p is None or not np.isfinite(p) or p >= alpha:
        return "no_significant_difference"
    return f"{r['a']}_better" if r["median_diff"] < 0 else f"{r['b']}_better"


# ----------------------------------------------------------------------------
# Variant grids
# ----------------------------------------------------------------------------
def derivative_variants(derivatives, methods, k: int, latent_dim: int, weights: str = "idw") -> list[Variant]:
    return [Variant(f"{m}_{d}", method=m, k=k, latent_dim=latent_dim, derivative=d, weights=weights).check()
            for d in derivatives for m in methods]


def beyond_variants(cfg: dict, base_k: int, derivative: str) -> list[Variant]:
    """The beyond-the-paper grid (see ``docs/config_simplicial.md``).

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
        if cfg.get("barycentric", True):
            add(Variant(f"delaunay_bary_d{d}", "delaunay", base_k, d, derivative, "barycentric"))
        add(Variant(f"knn{base_k}_d{d}", "knn", base_k, d, derivative))
        if cfg.get("kdelaunay", True):
            add(Variant(f"kdelaunay{base_k}_d{d}", "kdelaunay", base_k, d, derivative))
    for k in cfg["k_values"]:
        add(Variant(f"knn{k}_d{d0}", "knn", int(k), d0, derivative))
        if cfg.get("kdelaunay", True):
            add(Variant(f"kdelaunay{k}_d{d0}", "kdelaunay", int(k), d0, derivative))
    if cfg.get("target_directed", True):
        add(Variant(f"target_delaunay_d{d0}", "delaunay", base_k, d0, derivative, "idw", "target"))
        add(Variant(f"target_knn{base_k}_d{d0}", "knn", base_k, d0, derivative, "idw", "target"))
    return list(out.values())


def summarise_variants(folds: pd.DataFrame, baseline: str, datasets,
                       metrics=("error_a_pose", "error_f_pose", "error_a_norm", "error_f_norm"),
                       n_boot: int = 2000, seed: int = 0, members: pd.DataFrame | None = None) -> pd.DataFrame:
    """One row per variant: medians over all folds (held-out start), per-subset median of the first metric,
    the paired comparison with ``baseline`` on the first metric, and with ``members`` the share of ensemble
    members in which the variant's all-fold median is below the baseline's (``lower_share_vs_baseline``)."""
    first = metrics[0]
    mm = members if members is not None and len(members) else None
    rows = []
    for name, s in folds.groupby("variant", sort=False):
        r = {"variant": name}
        for c in ("method", "k", "latent_dim", "derivative", "weights", "generation"):
            r[c] = s[c].iloc[0]
        r["folds"] = int(len(s))
        for met in metrics:
            r[met] = float(s[met].median())
        for d in datasets:
            r[f"{first}_{d}"] = float(s.loc[s["dataset"] == d, first].median()) if (s["dataset"] == d).any() else np.nan
        r["pose_floor"] = float(s["pose_floor"].median())
        r["fallback_steps"] = float(s["fallback_steps"].median())
        r["fallback_share"] = float(s["fallback_steps"].sum() / max(s["steps"].sum(), 1))
        r["length_ratio"] = float(s["length_ratio"].median())
        r["sep_growth_log10"] = float(s["sep_growth_log10"].median())
        if name != baseline:
            pc = paired_comparison(folds, name, baseline, metrics=(first,), n_boot=n_boot, seed=seed, key="variant")
            pr = pc.iloc[0]
            r["rel_change_vs_baseline"] = (r[first] / float(folds.loc[folds["variant"] == baseline, first].median())) - 1.0
            r["p_vs_baseline"] = pr["p_value"]
            r["better_folds_vs_baseline"] = int(pr["a_better_folds"])
        else:
            r["rel_change_vs_baseline"] = 0.0
            r["p_vs_baseline"] = np.nan
            r["better_folds_vs_baseline"] = 0
        r["lower_share_vs_baseline"] = np.nan
        r["share_metric"] = ""
        r["members"] = int(members[members["variant"] == name]["member"].nunique()) if mm is not None else 0
        if mm is not None and name != baseline:
            from .verdicts import member_share

            same_dim = int(r["latent_dim"]) == int(folds.loc[folds["variant"] == baseline, "latent_dim"].iloc[0])
            for met in (first, "error_a_norm") if same_dim else (first,):
                sh = member_share(members, name, baseline, met)
                if np.isfinite(sh):
                    r["lower_share_vs_baseline"], r["share_metric"] = sh, met
                    break
        rows.append(r)
    out = pd.DataFrame(rows)
    return out.sort_values([first, "variant"], kind="stable").reset_index(drop=True)


def derivative_summary(folds: pd.DataFrame, methods=("delaunay", "knn"), claim: str = "delaunay_better",
                       n_boot: int = 2000, seed: int = 0, members: pd.DataFrame | None = None) -> pd.DataFrame:
    """Per derivative: medians per method (held-out start), the Delaunay-vs-k-NN ordering, whether it matches
    ``claim``, and with ``members`` its share over the ensemble of starts and each method's separation growth."""
    a, b = methods
    rows = []
    for d, s in folds.groupby("derivative", sort=False):
        r = {"derivative": d, "folds": int(len(s) // 2)}
        for m in methods:
            sm = s[s["method"] == m]
            for met in ("error_a_norm", "error_f_norm", "error_a_pose", "length_ratio", "fallback_steps",
                        "sep_growth_log10", "sep_final_rel"):
                r[f"{m}_{met}"] = float(sm[met].median())
        pc = paired_comparison(s, a, b, metrics=("error_a_norm", "error_f_norm"), n_boot=n_boot, seed=seed)
        for _, p in pc.iterrows():
            tag = "a" if p["metric"] == "error_a_norm" else "f"
            r[f"p_value_{tag}"] = p["p_value"]
            r[f"{a}_lower_{tag}"] = bool(p["median_a"] < p["median_b"])
        r["ordering"] = ordering(r[f"{a}_lower_a"], r[f"{a}_lower_f"], a, b)
        r["reproduces_claim"] = claim_matches(claim, r[f"{a}_lower_a"], r[f"{a}_lower_f"])
        for tag, met in (("a", "error_a_norm"), ("f", "error_f_norm")):
            share = np.nan
            if members is not None and len(members):
                md = members[members["derivative"] == d]
                mm = member_medians(md, [], "method", methods, met)
                x, y = mm[(a, "all")], mm[(b, "all")]
                n = min(len(x), len(y))
                share = float(np.mean(x[:n] < y[:n])) if n else np.nan
            r[f"{a}_lower_share_{tag}"] = share
            r[f"stability_{tag}"] = stability(share)
        rows.append(r)
    return pd.DataFrame(rows)


def ordering(a_lower_a: bool, a_lower_f: bool, a: str, b: str) -> str:
    if a_lower_a and a_lower_f:
        return f"{a}<{b} (A and F)"
    if not a_lower_a and not a_lower_f:
        return f"{b}<{a} (A and F)"
    return "mixed: " + (f"{a}<{b} on A" if a_lower_a else f"{b}<{a} on A") + (
        f", {a}<{b} on F" if a_lower_f else f", {b}<{a} on F")


def claim_matches(claim: str, a_lower_a: bool, a_lower_f: bool) -> str:
    """``yes``/``no``/``partly``/``unknown`` against the configured paper claim."""
    if claim == "unknown":
        return "unknown"
    want = claim == "delaunay_better"
    hits = [a_lower_a == want, a_lower_f == want]
    return "yes" if all(hits) else ("no" if not any(hits) else "partly")


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
    "FOLD_COLUMNS", "MEMBER_COLUMNS", "FoldResult", "Variant", "beyond_variants", "derivative_summary",
    "derivative_variants", "fit_pca", "fold_ensemble", "jittered_starts", "member_medians", "order_folds",
    "paired_comparison", "prepare_fold", "run_fold", "run_fold_ensemble", "run_subset", "stability", "steps_for",
    "summarise_variants", "table2", "table2_ensemble", "table2_units", "to_jsonable",
]
