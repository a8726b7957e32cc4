"""Table assembly: Gauch & Peters' Table II in the paper's layout, in every unit, over the ensemble of starts,
and per fold, from the fold and member rows of :mod:`~animsynth.simplicial.folds`.

The published values (``paper``) come from :func:`animsynth.simplicial.settings.read_paper_table2`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .stats import member_medians, spread, stability

#: Columns of the wide all-units table (per method).
TABLE2_METRICS = ("error_a", "error_f", "error_a_norm", "error_f_norm", "error_a_pose", "error_f_pose")

#: Table II metrics: the paper's Error A and Error F (ours: normalised by the latent bbox diagonal).
PAPER_METRICS = ("error_a", "error_f")


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
                r[f"{m}_median"], r[f"{m}_q25"], r[f"{m}_q75"] = spread(x)
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
                r[f"{m}_median"], r[f"{m}_q25"], r[f"{m}_q75"] = spread(xs[m])
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


__all__ = ["PAPER_METRICS", "TABLE2_METRICS", "fold_ensemble", "table2", "table2_ensemble", "table2_units"]
