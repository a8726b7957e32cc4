"""The side-by-side claims, decided over clips and seeds, in the common verdict format (:mod:`animsynth.verdicts`).

Every claim compares two generators (or a group of them) on one metric, clip by clip and seed by seed
(seed ``i`` of a clip is the same seed for every generator). A pair in which the claim holds counts for
it, one in which the opposite holds against it, a tie (equal values, e.g. no skating in either) for
neither. The verdict:

* ``reproduced`` -- at least ``compare.verdicts.share`` of the untied pairs agree and a two-sided
  sign test gives p below ``compare.verdicts.alpha``;
* ``contradicted`` -- the same for the opposite;
* ``partly`` -- anything between overall, but the claim holds (as above) within some groups (subsets or
  re-sequencing clips) and its opposite within others;
* ``within noise`` -- anything between (the evidence gives the share and p);
* ``not reproduced`` -- no pair can be compared (a generator did not run: the evidence says why).

The evidence also gives the share within each group (subset or re-sequencing clip), so a claim that
holds on some clips and not on others shows where.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import verdicts as V
from .generators import REFERENCES
from .jobs import METRICS

__all__ = ["decide", "by_group", "pair_outcomes", "build"]

_UNITS = {m: u for m, u, _b in METRICS}


def decide(holds: int, fails: int, share: float, alpha: float) -> tuple[str, float, float]:
    """``(verdict, share of untied pairs holding, sign-test p)`` for ``holds`` pairs for and ``fails`` against."""
    from scipy.stats import binomtest

    n = int(holds) + int(fails)
    if n == 0:
        return "not reproduced", float("nan"), float("nan")
    s = holds / n
    p = float(binomtest(int(holds), n, 0.5).pvalue)
    if s >= share and p < alpha:
        return "reproduced", s, p
    if s <= 1.0 - share and p < alpha:
        return "contradicted", s, p
    return "within noise", s, p


def by_group(groups: pd.Series, outcome: pd.Series, verdict: str, share: float, alpha: float, order=None):
    """``partly`` instead of ``within noise`` when the claim holds stably in some groups (subsets or clips)
    and its opposite holds stably in others (each group decided as a whole claim); else ``verdict``.
    Returns ``(verdict, {group: its verdict})``."""
    per = {}
    for g in (order if order is not None else dict.fromkeys(groups)):
        o = outcome[groups == g]
        per[g] = decide(int((o > 0).sum()), int((o < 0).sum()), share, alpha)[0]
    words = set(per.values())
    if verdict == "within noise" and {"reproduced", "contradicted"} <= words:
        return "partly", per
    return verdict, per


def pair_outcomes(metrics: pd.DataFrame, a: str, b: str, metric: str, better: str = "lower") -> pd.DataFrame:
    """Per clip x seed where both ``a`` and ``b`` have a finite ``metric``: ``group``, ``a``, ``b`` and
    ``outcome`` (+1: ``a`` better, -1: ``b`` better, 0: tie)."""
    key = ["clip", "seed"]
    A = metrics[metrics["generator"] == a].set_index(key)[["group", metric]]
    B = metrics[metrics["generator"] == b].set_index(key)[metric]
    j = A.join(B.rename("b"), how="inner").rename(columns={metric: "a"})
    j["a"] = pd.to_numeric(j["a"], errors="coerce")
    j["b"] = pd.to_numeric(j["b"], errors="coerce")
    j = j[np.isfinite(j["a"]) & np.isfinite(j["b"])]
    d = j["a"] - j["b"]
    j["outcome"] = np.sign(-d if better == "lower" else d).astype(int)
    return j.reset_index()


def _per_group(groups: pd.Series, outcome: pd.Series, order=None) -> str:
    parts = []
    for g in (order if order is not None else dict.fromkeys(groups)):
        o = outcome[groups == g]
        n = int((o != 0).sum())
        parts.append(f"{g} {int((o > 0).sum())}/{n}" if n else f"{g} no pair")
    return "per group (holds/untied): " + ", ".join(parts)


def _partly(verdict: str, per: dict) -> str:
    if verdict != "partly":
        return ""
    holds = [g for g, v in per.items() if v == "reproduced"]
    opposite = [g for g, v in per.items() if v == "contradicted"]
    return f"; holds in {' '.join(holds)}, the opposite holds in {' '.join(opposite)}"


def _median(metrics: pd.DataFrame, g: str, metric: str) -> float:
    x = pd.to_numeric(metrics.loc[metrics["generator"] == g, metric], errors="coerce")
    x = x[np.isfinite(x)]
    return float(x.median()) if len(x) else float("nan")


def _spread(metrics: pd.DataFrame, g: str, metric: str) -> str:
    x = pd.to_numeric(metrics.loc[metrics["generator"] == g, metric], errors="coerce")
    x = x[np.isfinite(x)].to_numpy(float)
    if not x.size:
        return "no value"
    q = np.percentile(x, [25, 50, 75])
    return f"{V.fmt(q[1])} (IQR {V.fmt(q[0])}-{V.fmt(q[2])})"


def _pair_row(metrics, claim, a, b, metric, better, vc, data, paper_value="", left_out=None):
    left_out = left_out or {}
    missing = [g for g in (a, b) if g not in set(metrics["generator"])]
    if missing:
        why = "; ".join(f"{g}: {left_out.get(g, 'not in this run')}" for g in missing)
        return V.row(claim, "not reproduced", f"no pair to compare ({why})", paper_value=paper_value,
                     ours="", data=data, source="compare/metrics.csv")
    j = pair_outcomes(metrics, a, b, metric, better)
    holds, fails, ties = int((j["outcome"] > 0).sum()), int((j["outcome"] < 0).sum()), int((j["outcome"] == 0).sum())
    verdict, share, p = decide(holds, fails, float(vc["share"]), float(vc["alpha"]))
    order = dict.fromkeys(metrics["group"])
    verdict, per = by_group(j["group"], j["outcome"], verdict, float(vc["share"]), float(vc["alpha"]), order)
    unit = _UNITS[metric]
    ours = f"{metric} ({unit}) median {a} {_spread(metrics, a, metric)} vs {b} {_spread(metrics, b, metric)}"
    evidence = (f"{a} {'lower' if better == 'lower' else 'higher'} in {holds} of {holds + fails} untied clip x seed "
                f"pairs (share {V.fmt(share)}, {ties} ties), sign test p = {V.fmt(p, 2)}; "
                + _per_group(j["group"], j["outcome"], order) + _partly(verdict, per))
    return V.row(claim, verdict, evidence, paper_value=paper_value, ours=ours, data=data, source="compare/metrics.csv")


def _copy_row(metrics, vc, data, left_out=None):
    claim = "re-sequencers copy database frames (novelty ~ 0) while field followers synthesise new poses"
    copiers = [g for g in ("isomap", "stisomap") if g in set(metrics["generator"])]
    makers = [g for g in ("delaunay", "knn") if g in set(metrics["generator"])]
    tol = float(vc["novelty_copy_m"])
    if not copiers or not makers:
        return V.row(claim, "not reproduced", "no pair to compare (a re-sequencer or a field follower did not run)",
                     data=data, source="compare/metrics.csv")
    wide = metrics[metrics["generator"].isin(copiers + makers)].pivot_table(
        index=["clip", "seed"], columns="generator", values="novelty_median_m", aggfunc="first")
    groups = metrics.drop_duplicates(["clip", "seed"]).set_index(["clip", "seed"])["group"].reindex(wide.index)
    wide = wide.dropna()
    groups = groups.reindex(wide.index)
    ok = (wide[copiers].max(axis=1) <= tol) & (wide[makers].min(axis=1) > tol)
    holds, fails = int(ok.sum()), int((~ok).sum())
    verdict, share, p = decide(holds, fails, float(vc["share"]), float(vc["alpha"]))
    order = dict.fromkeys(metrics["group"])
    outcome = pd.Series(np.where(ok, 1, -1), index=ok.index)
    verdict, per = by_group(groups, outcome, verdict, float(vc["share"]), float(vc["alpha"]), order)
    ours = "; ".join(f"{g} novelty median {_spread(metrics, g, 'novelty_median_m')} m" for g in copiers + makers)
    evidence = (f"every re-sequencer at most {V.fmt(tol)} m from the database and every field follower farther in "
                f"{holds} of {holds + fails} clip x seed pairs (share {V.fmt(share)}), sign test p = {V.fmt(p, 2)}; "
                + _per_group(groups, outcome, order) + _partly(verdict, per))
    return V.row(claim, verdict, evidence, ours=ours, data=data, source="compare/metrics.csv")


def _capture_row(metrics, vc, data):
    claim = "the held-out capture skates less than every generator (the realism upper bound holds for this metric)"
    gens = [g for g in dict.fromkeys(metrics["generator"]) if g not in REFERENCES]
    if "replay" not in set(metrics["generator"]) or not gens:
        return V.row(claim, "not reproduced", "no pair to compare (replay or every generator missing)", data=data,
                     source="compare/metrics.csv")
    parts = [pair_outcomes(metrics, "replay", g, "skate_share", "lower") for g in gens]
    # "every generator": decided generator by generator, each over its clip x seed pairs
    per, texts = {}, []
    for g, part in zip(gens, parts):
        h, f = int((part["outcome"] > 0).sum()), int((part["outcome"] < 0).sum())
        per[g], sh, _p = decide(h, f, float(vc["share"]), float(vc["alpha"]))
        texts.append(f"{g} {h}/{h + f}")
    words = set(per.values())
    if words == {"reproduced"}:
        verdict = "reproduced"
    elif words == {"contradicted"}:
        verdict = "contradicted"
    elif "reproduced" in words:
        verdict = "partly"
    else:
        verdict = "within noise"
    j = pd.concat(parts, ignore_index=True)
    holds, fails, ties = int((j["outcome"] > 0).sum()), int((j["outcome"] < 0).sum()), int((j["outcome"] == 0).sum())
    not_held = [g for g, v in per.items() if v != "reproduced"]
    evidence = (f"replay lower in {holds} of {holds + fails} untied clip x seed x generator triples ({ties} ties); "
                f"per generator (replay lower / untied pairs): {', '.join(texts)}"
                + (f"; not stably lower than: {', '.join(f'{g} ({per[g]})' for g in not_held)}" if not_held else ""))
    ours = f"skate share median replay {_spread(metrics, 'replay', 'skate_share')}"
    return V.row(claim, verdict, evidence, ours=ours, data=data, source="compare/metrics.csv")


def build(metrics: pd.DataFrame, vc: dict, data: str, left_out: dict | None = None) -> pd.DataFrame:
    """The verdict table of the comparison.

    Parameters
    ----------
    metrics : DataFrame, ``compare/metrics.csv``
    vc : the ``compare.verdicts`` block (``share``, ``alpha``, ``novelty_copy_m``)
    data : what the numbers ran on (e.g. "CMU: 19 held-out clips x 5 seeds")
    left_out : {generator: why it did not run}
    """
    rows = []
    present = set(metrics["generator"])
    configured = present | set(left_out or {})

    def pair(claim, a, b, metric, better="lower", paper_value=""):
        if {a, b} <= configured:
            rows.append(_pair_row(metrics, claim, a, b, metric, better, vc, data, paper_value, left_out))

    pair("the classic motion graph skates less than ST-Isomap re-sequencing", "motion_graph", "stisomap",
         "skate_share")
    if {"isomap", "stisomap", "delaunay", "knn"} & configured:
        rows.append(_copy_row(metrics, vc, data, left_out))
    pair("our motion graph's transitions skate less than fairmotion's", "motion_graph", "fairmotion",
         "transition_skate_share")
    pair("the motion graph's blended transitions jump less than random concatenation's seams", "motion_graph",
         "concat", "velocity_jump")
    pair("ST-Isomap re-sequencing jumps less at its seams than Isomap re-sequencing", "stisomap", "isomap",
         "velocity_jump", paper_value="ST-Isomap re-sequences more smoothly than Isomap (the re-sequencing paper)")
    pair("Delaunay field following stays closer to the held-out continuation than k-NN field following (L2P)",
         "delaunay", "knn", "l2p", paper_value="Delaunay gives lower Error A/F than k-NN (Gauch & Peters Table II)")
    if "replay" in configured:
        rows.append(_capture_row(metrics, vc, data))
    return V.table(rows)
