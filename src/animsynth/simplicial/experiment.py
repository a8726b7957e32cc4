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
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import stats
from sklearn.decomposition import PCA

from .field import DERIVATIVES, VectorField, training_vectors
from .geometry import SafeDelaunay, bbox_diagonal
from .graph import MotionGraph
from .metrics import error_a, error_f
from .path import GeneratedPath, TargetPlanner, follow_field

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
]

#: Columns of the paper's Table II that we fill (per method).
TABLE2_METRICS = ("error_a", "error_f", "error_a_norm", "error_f_norm")


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


def run_fold(train: list, test, variant: Variant, *, dataset: str = "", held_out: str = "", fold: int = 0,
             steps="held_out", dup_tol: float = 1e-9, rank_tol: float = 1e-9,
             max_all_pairs: int = 4000) -> FoldResult:
    """Run one leave-one-sequence-out fold.

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
    test = np.asarray(test, float)
    if test.ndim != 2 or test.shape[0] < 2:
        raise ValueError(f"held-out trial {held_out!r} needs at least 2 frames")
    pca = fit_pca(train, variant.latent_dim)
    clips = [pca.transform(np.asarray(t, float)) for t in train]
    X = np.vstack(clips)
    lengths = [len(c) for c in clips]
    V = training_vectors(clips, variant.derivative)
    T = pca.transform(test)
    tri = SafeDelaunay(dup_tol, rank_tol).fit(X)
    graph_method = variant.method
    graph = MotionGraph(graph_method, variant.k, dup_tol, rank_tol).fit(X, V, lengths, triangulation=tri)
    fld = VectorField(variant.method, variant.k, variant.weights, dup_tol, rank_tol).fit(X, V, triangulation=tri)
    extra = {}
    if variant.generation == "field":
        path = follow_field(fld, T[0], steps_for(steps, len(T)))
        reached = ""
    else:
        planner = TargetPlanner(max_all_pairs).fit(graph)
        path, info = planner.plan(T[0], T[-1])
        extra["plan"] = info
        reached = bool(info["reached"])
    diag = bbox_diagonal(X)
    a, t2g, g2t = error_a(T, path.points)
    f = error_f(T, path.points)
    gen_pose = pca.inverse_transform(path.points)
    a_pose = error_a(test, gen_pose)[0]
    f_pose = error_f(test, gen_pose)
    floor = error_a(test, pca.inverse_transform(T))[0]  # Error A of the perfect latent path (PCA loss alone)
    conn = graph.connectivity()
    norm = diag if diag > 0 else np.nan
    row = {
        "dataset": dataset, "held_out": held_out, "fold": int(fold), "variant": variant.name,
        "method": variant.method, "k": int(variant.k), "latent_dim": int(variant.latent_dim),
        "derivative": variant.derivative, "weights": variant.weights, "generation": variant.generation,
        "n_train_frames": int(X.shape[0]), "n_test_frames": int(len(T)),
        "explained_var": float(np.sum(pca.explained_variance_ratio_)), "bbox_diag": diag,
        "steps": path.steps, "fallback_steps": path.fallback_steps,
        "error_a": a, "error_a_norm": a / norm, "error_f": f, "error_f_norm": f / norm,
        "error_a_pose": a_pose, "error_f_pose": f_pose, "pose_floor": floor,
        "error_a_true_to_gen": t2g, "error_a_gen_to_true": g2t,
        "length_ratio": arc_length(path.points) / max(arc_length(T), 1e-300),
        "components": conn["scc"], "largest_component_frac": conn["largest_scc_frac"],
        "undirected_connected": conn["undirected_connected"], "h_connected": conn["h_connected"],
        "n_edges": conn["n_edges"], "n_clip_edges": conn["n_clip_edges"], "n_added_pairs": conn["n_added_pairs"],
        "n_tie_edges": conn["n_tie_edges"], "tri_status": tri.status_, "n_duplicates": tri.n_duplicates_,
        "target_reached": reached,
    }
    assert list(row) == FOLD_COLUMNS
    return FoldResult(row, pca, clips, T, path, graph, fld, V, extra)


def run_subset(trials: dict, variants, *, dataset: str, steps="held_out", dup_tol=1e-9, rank_tol=1e-9,
               max_all_pairs: int = 4000) -> pd.DataFrame:
    """All leave-one-out folds of one subset for every variant.

    Parameters
    ----------
    trials : dict trial id -> array (n, 56), in subset order (fold i holds trial i out)
    variants : iterable of Variant
    """
    ids = list(trials)
    rows = []
    for v in variants:
        for i, tid in enumerate(ids):
            train = [trials[t] for t in ids if t != tid]
            res = run_fold(train, trials[tid], v, dataset=dataset, held_out=tid, fold=i, steps=steps,
                           dup_tol=dup_tol, rank_tol=rank_tol, max_all_pairs=max_all_pairs)
            rows.append(res.row)
    return pd.DataFrame(rows, columns=FOLD_COLUMNS)


def order_folds(df: pd.DataFrame, datasets) -> pd.DataFrame:
    """Fixed row order: datasets in config order, then variant, then fold."""
    order = {d: i for i, d in enumerate(datasets)}
    df = df.assign(_d=df["dataset"].map(order)).sort_values(["_d", "variant", "fold"], kind="stable")
    return df.drop(columns="_d").reset_index(drop=True)[FOLD_COLUMNS]


# ----------------------------------------------------------------------------
# Table II and the paired comparison
# ----------------------------------------------------------------------------
def table2(folds: pd.DataFrame, datasets, methods=("delaunay", "knn"), paper: dict | None = None) -> pd.DataFrame:
    """Medians per subset and over all folds, laid out like the paper's Table II.

    One row per subset plus ``all``; for every method the median Error A and
    Error F (latent units and normalised), the number of folds, and the
    paper's published value beside ours (``paper_<method>_error_a`` ...;
    empty when not supplied).
    """
    paper = paper or {}
    rows = []
    for name in list(datasets) + ["all"]:
        sub = folds if name == "all" else folds[folds["dataset"] == name]
        r = {"dataset": name, "folds": int(sub["fold"].count() // max(len(methods), 1))}
        for m in methods:
            s = sub[sub["method"] == m]
            for met in TABLE2_METRICS:
                r[f"{m}_{met}"] = float(s[met].median()) if len(s) else np.nan
        for m in methods:
            for met in ("error_a", "error_f"):
                val = (paper.get(name) or {}).get(f"{m}_{met}")
                r[f"paper_{m}_{met}"] = np.nan if val is None else float(val)
        rows.append(r)
    return pd.DataFrame(rows)


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
                       n_boot: int = 2000, seed: int = 0) -> pd.DataFrame:
    """One row per variant: medians over all folds, per-subset median of the first metric,
    and the paired comparison with ``baseline`` on the first metric."""
    first = metrics[0]
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
        r["length_ratio"] = float(s["length_ratio"].median())
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
        rows.append(r)
    out = pd.DataFrame(rows)
    return out.sort_values([first, "variant"], kind="stable").reset_index(drop=True)


def derivative_summary(folds: pd.DataFrame, methods=("delaunay", "knn"), claim: str = "delaunay_better",
                       n_boot: int = 2000, seed: int = 0) -> pd.DataFrame:
    """Per derivative: medians per method, the Delaunay-vs-k-NN ordering and whether it matches ``claim``."""
    a, b = methods
    rows = []
    for d, s in folds.groupby("derivative", sort=False):
        r = {"derivative": d, "folds": int(len(s) // 2)}
        for m in methods:
            sm = s[s["method"] == m]
            for met in ("error_a_norm", "error_f_norm", "error_a_pose", "length_ratio", "fallback_steps"):
                r[f"{m}_{met}"] = float(sm[met].median())
        pc = paired_comparison(s, a, b, metrics=("error_a_norm", "error_f_norm"), n_boot=n_boot, seed=seed)
        for _, p in pc.iterrows():
            tag = "a" if p["metric"] == "error_a_norm" else "f"
            r[f"p_value_{tag}"] = p["p_value"]
            r[f"{a}_lower_{tag}"] = bool(p["median_a"] < p["median_b"])
        r["ordering"] = ordering(r[f"{a}_lower_a"], r[f"{a}_lower_f"], a, b)
        r["reproduces_claim"] = claim_matches(claim, r[f"{a}_lower_a"], r[f"{a}_lower_f"])
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
    "FOLD_COLUMNS", "FoldResult", "Variant", "beyond_variants", "derivative_summary",
    "build_verdicts", "derivative_variants", "fit_pca", "order_folds", "paired_comparison", "run_fold", "run_subset",
    "steps_for", "summarise_variants", "table2", "to_jsonable",
]


# ----------------------------------------------------------------------------
# Verdicts: the claims this family checks, decided from the numbers
# ----------------------------------------------------------------------------
def _fmt(x, nd=3):
    return "nan" if x is None or not np.isfinite(x) else f"{x:.{nd}g}"


def build_verdicts(paired: pd.DataFrame, deriv: pd.DataFrame, folds: pd.DataFrame, beyond: pd.DataFrame | None,
                   beyond_folds: pd.DataFrame | None, *, claim: str, main_derivative: str, baseline: str,
                   alpha: float = 0.05) -> pd.DataFrame:
    """Rows ``claim, verdict, evidence`` generated from the result tables.

    Parameters
    ----------
    paired : output of :func:`paired_comparison` on the main folds
    deriv : output of :func:`derivative_summary`
    folds : main fold table (delaunay and knn, main derivative)
    beyond, beyond_folds : output of :func:`summarise_variants` and its fold rows (optional)
    claim : {"delaunay_better", "knn_better", "unknown"}
        The ordering the paper concludes (config ``simplicial.paper_claim``).
    """
    rows = []

    def add(c, v, e):
        rows.append({"claim": c, "verdict": v, "evidence": e})

    pa = paired.set_index("metric")
    claim_txt = {"delaunay_better": "Delaunay gives lower errors than k-NN",
                 "knn_better": "k-NN gives lower errors than Delaunay",
                 "unknown": "(paper ordering not configured)"}[claim]
    for met, lab in (("error_a_norm", "Error A"), ("error_f_norm", "Error F")):
        if met not in pa.index:
            continue
        r = pa.loc[met]
        a_lower = r["median_a"] < r["median_b"]
        if claim == "unknown":
            v = "unknown"
        else:
            match = a_lower == (claim == "delaunay_better")
            sig = np.isfinite(r["p_value"]) and r["p_value"] < alpha
            v = ("reproduced" if sig else "same direction, not significant") if match else (
                "contradicted" if sig else "opposite direction, not significant")
        add(f"Paper conclusion on {lab} ({claim_txt}), derivative '{main_derivative}', all folds",
            v, f"median {lab}/bbox diag: delaunay {_fmt(r['median_a'])}, knn {_fmt(r['median_b'])}; "
               f"Wilcoxon p={_fmt(r['p_value'])} over {int(r['n_pairs'])} paired folds; "
               f"95% bootstrap CI of median(delaunay-knn) [{_fmt(r['ci_low'])}, {_fmt(r['ci_high'])}]; "
               f"delaunay lower in {int(r['a_better_folds'])}/{int(r['n_pairs'])} folds")
    for met, lab in (("error_a_norm", "Error A"), ("error_f_norm", "Error F")):
        if met in pa.index:
            r = pa.loc[met]
            add(f"Delaunay and k-NN differ on {lab} (paired, alpha={alpha})",
                "yes" if (np.isfinite(r["p_value"]) and r["p_value"] < alpha) else "no",
                f"Wilcoxon signed-rank p={_fmt(r['p_value'])}, verdict {r['verdict']}")
    for _, r in deriv.iterrows():
        add(f"Derivative '{r['derivative']}' reproduces the paper's ordering ({claim_txt})",
            r["reproduces_claim"],
            f"ordering {r['ordering']}; median Error A/diag delaunay {_fmt(r['delaunay_error_a_norm'])} vs knn "
            f"{_fmt(r['knn_error_a_norm'])} (p={_fmt(r['p_value_a'])}); Error F/diag {_fmt(r['delaunay_error_f_norm'])} "
            f"vs {_fmt(r['knn_error_f_norm'])} (p={_fmt(r['p_value_f'])})")
    dd = deriv.set_index("derivative")
    if {"half", "forward"} <= set(dd.index):
        h = dd.loc["half", "delaunay_length_ratio"], dd.loc["half", "knn_length_ratio"]
        f = dd.loc["forward", "delaunay_length_ratio"], dd.loc["forward", "knn_length_ratio"]
        half_ok = all(0.35 <= x <= 0.65 for x in h)
        fwd_ok = all(0.75 <= x <= 1.33 for x in f)
        add("The printed 1/2 makes the field traverse the data at half speed (likely a typo)",
            "supported" if half_ok and fwd_ok else "not supported",
            f"median generated/held-out arc length: half {_fmt(h[0])} (delaunay), {_fmt(h[1])} (knn); "
            f"forward {_fmt(f[0])}, {_fmt(f[1])}; median Error A/diag half {_fmt(dd.loc['half', 'delaunay_error_a_norm'])}"
            f"/{_fmt(dd.loc['half', 'knn_error_a_norm'])} vs forward {_fmt(dd.loc['forward', 'delaunay_error_a_norm'])}"
            f"/{_fmt(dd.loc['forward', 'knn_error_a_norm'])} (delaunay/knn)")
        rep = [d for d, v in dd["reproduces_claim"].items() if v == "yes"]
        sig = [d for d in rep if min(dd.loc[d, "p_value_a"], dd.loc[d, "p_value_f"]) < alpha]
        add("Which derivative variant reproduces the paper's conclusion",
            ", ".join(rep) if rep else "none",
            "variants whose Delaunay-vs-k-NN ordering of median Error A and Error F both match the configured claim; "
            + (f"significant (Wilcoxon p < {alpha}) for: {', '.join(sig)}" if sig else
               f"none of these orderings is significant (Wilcoxon p >= {alpha}), so the ordering is within noise"))
    for m, s in folds.groupby("method", sort=False):
        one = int((s["components"] == 1).sum())
        add(f"G' ({m}) is strongly connected in every fold", "yes" if one == len(s) else "no",
            f"{one}/{len(s)} folds with one strongly connected component (max {int(s['components'].max())}); "
            f"undirected connected in {int(s['undirected_connected'].sum())}/{len(s)}; "
            f"H connected in {int(s['h_connected'].sum())}/{len(s)}")
    if beyond is not None and len(beyond):
        b = beyond.set_index("variant")
        metric = "error_a_pose"
        base = float(b.loc[baseline, metric]) if baseline in b.index else np.nan
        best = beyond.iloc[0]
        add("Best beyond-the-paper variant (median pose-space Error A)", str(best["variant"]),
            f"{_fmt(best[metric])} deg vs paper baseline {baseline} {_fmt(base)} deg "
            f"({_fmt(100 * best['rel_change_vs_baseline'])}% change, Wilcoxon p={_fmt(best['p_vs_baseline'])}, "
            f"lower in {int(best['better_folds_vs_baseline'])}/{int(best['folds'])} folds); PCA floor "
            f"{_fmt(best['pose_floor'])} vs {_fmt(float(b.loc[baseline, 'pose_floor']) if baseline in b.index else np.nan)} "
            f"deg, so most of a gain from a higher latent dimension is reconstruction, not generation")
        d0 = int(beyond["latent_dim"].min())
        for tgt, fld in ((f"target_delaunay_d{d0}", f"delaunay_idw_d{d0}"),):
            if tgt in b.index and fld in b.index:
                for met, lab in (("error_a_norm", "Error A"), ("error_f_norm", "Error F")):
                    t, f_ = float(b.loc[tgt, met]), float(b.loc[fld, met])
                    pc = paired_comparison(beyond_folds, tgt, fld, metrics=(met,), key="variant").iloc[0]
                    add(f"Target-directed shortest paths in G' beat field following on {lab} (Delaunay)",
                        "yes" if (t < f_ and pc["p_value"] < alpha) else "no",
                        f"median {met}: target {_fmt(t)} vs field {_fmt(f_)}, Wilcoxon p={_fmt(pc['p_value'])}")
        dims = sorted(beyond["latent_dim"].unique())
        if len(dims) > 1:
            per = beyond[(beyond["method"] == "delaunay") & (beyond["weights"] == "idw") & (beyond["generation"] == "field")]
            per = per.set_index("latent_dim")
            add("Higher latent dimension lowers pose-space Error A (Delaunay 1/D^2)",
                "yes" if per[metric].idxmin() != dims[0] else "no",
                "; ".join(f"d={int(d)}: {_fmt(r[metric])} deg (PCA floor {_fmt(r['pose_floor'])} deg)"
                          for d, r in per.sort_index().iterrows())
                + "; the floor is the error of a perfect latent path, i.e. PCA reconstruction loss")
        for var, ref, lab in ((f"delaunay_bary_d{d0}", f"delaunay_idw_d{d0}", "Barycentric weights beat 1/D^2 weights"),
                              (next((v for v in b.index if v.startswith("kdelaunay") and v.endswith(f"_d{d0}")
                                     and f"kdelaunay{int(b.loc[baseline, 'k']) if baseline in b.index else 16}_" in v), ""),
                               f"delaunay_idw_d{d0}", "k-Delaunay beats Delaunay")):
            if var in b.index and ref in b.index:
                pc = paired_comparison(beyond_folds, var, ref, metrics=("error_a_norm",), key="variant").iloc[0]
                add(f"{lab} (Error A, latent dim {d0})",
                    "yes" if (pc["median_a"] < pc["median_b"] and pc["p_value"] < alpha) else "no",
                    f"median Error A/diag {_fmt(pc['median_a'])} vs {_fmt(pc['median_b'])}, Wilcoxon p={_fmt(pc['p_value'])}")
    return pd.DataFrame(rows, columns=["claim", "verdict", "evidence"])
