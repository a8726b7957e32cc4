"""Statistics over the fold and member rows of :mod:`~animsynth.simplicial.folds`.

* :func:`stability` -- whether an ordering holds in every member of the ensemble of starts;
* :func:`member_medians`, :func:`member_share` -- per ensemble member, the median over folds, and the share of
  members in which one variant's median is below another's;
* :func:`paired_comparison` -- paired Wilcoxon signed-rank test and bootstrap CI of a difference over folds;
* :func:`derivative_summary`, :func:`summarise_variants` -- the derivative-variant and beyond-the-paper summaries.

Nothing here reads a file or builds a verdict row (:mod:`~animsynth.simplicial.verdicts` does).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..verdicts import share_outcome


def stability(share: float) -> str:
    """``stable`` when an ordering holds in every ensemble member (share 0 or 1), else the share."""
    if share is None or not np.isfinite(share):
        return "no ensemble"
    if share in (0.0, 1.0):
        return "stable"
    return f"within start-noise (share {100 * share:.0f} %)"


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


def spread(x):
    """Median, 25th and 75th percentile of ``x`` (NaN each when empty)."""
    if len(x) == 0:
        return np.nan, np.nan, np.nan
    q25, q50, q75 = np.quantile(x, [0.25, 0.5, 0.75])
    return float(q50), float(q25), float(q75)


def member_share(members: pd.DataFrame | None, var: str, ref: str, metric: str) -> float:
    """Share of ensemble members in which ``var``'s all-fold median ``metric`` is below ``ref``'s (NaN if unknown)."""
    if members is None or not len(members):
        return np.nan
    med = {}
    for v in (var, ref):
        s = members[members["variant"] == v]
        if not len(s) or s[metric].isna().any():
            return np.nan
        med[v] = s.groupby("member")[metric].median().sort_index().to_numpy(float)
    n = min(len(med[var]), len(med[ref]))
    return float(np.mean(med[var][:n] < med[ref][:n])) if n else np.nan


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
    """``a_better``/``b_better`` when Wilcoxon p < alpha, else ``no_significant_difference``.

    The outcome of one test, shown in ``paired.csv``; not a word of the verdict vocabulary
    (:data:`animsynth.verdicts.VOCABULARY`) and never copied into a verdict table.
    """
    p = r.get("p_value")
    if p is None or not np.isfinite(p) or p >= alpha:
        return "no_significant_difference"
    return f"{r['a']}_better" if r["median_diff"] < 0 else f"{r['b']}_better"


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
    """``yes``/``no``/``partly``/``unknown``: whether the held-out-start ordering on A and F matches ``claim``.

    The ``reproduces_claim`` column of ``derivative.csv`` (one start only); not a verdict: the verdict on each
    derivative variant is decided over the ensemble of starts by
    :func:`animsynth.simplicial.verdicts.build_verdicts`, in the vocabulary of :mod:`animsynth.verdicts`.
    """
    if claim == "unknown":
        return "unknown"
    want = claim == "delaunay_better"
    hits = [a_lower_a == want, a_lower_f == want]
    return {"all": "yes", "some": "partly", "none": "no"}[share_outcome(hits)]


__all__ = [
    "claim_matches", "comparison_verdict", "derivative_summary", "member_medians", "member_share", "ordering",
    "paired_comparison", "spread", "stability", "summarise_variants",
]
