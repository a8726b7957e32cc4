"""The side-by-side claims, decided over clips and seeds, in the common verdict format (:mod:`animsynth.verdicts`).

Every claim compares two generators (or a group of them) on one metric, clip by clip and seed by seed
(seed ``i`` of a clip is the same seed for every generator). A pair in which the claim holds counts for
it, one in which the opposite holds against it, a tie (equal values, e.g. no skating in either) for
neither. The seeds of one clip are not independent cases (the replayed capture is the same for every
seed, and the field followers' seeds only jitter their start), so the **clip** is the unit of the test:
each clip's outcome is the majority over its seeds (a tie of seeds: no outcome), and the verdict is
decided over clips:

* ``reproduced`` -- at least ``compare.verdicts.share`` of the untied clips agree and a two-sided
  sign test over clips gives p below ``compare.verdicts.alpha``;
* ``contradicted`` -- the same for the opposite;
* ``partly`` -- anything between overall, but the claim holds on every untied clip of some groups
  (subsets of at least two untied clips) and its opposite on every untied clip of others;
* ``within noise`` -- anything between (the evidence gives the share and p);
* ``not reproduced`` -- no pair can be compared (a generator did not run: the evidence says why).

The evidence gives the clip counts, the clip x seed pair counts and the counts within each group, so a
claim that holds on some clips and not on others shows where. This rule is stricter than the shared
vocabulary's "on every nudge" only in allowing a share below one; the share is always printed.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import verdicts as V
from .generators import REFERENCES
from .jobs import METRICS

__all__ = ["decide", "by_group", "per_clip", "pair_outcomes", "build"]

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
    """``partly`` instead of ``within noise`` when the claim holds on every untied clip of some groups
    (subsets or re-sequencing clips) and its opposite on every untied clip of others; else ``verdict``.
    A group decides only with at least two untied clips (a re-sequencing clip is a group of one).

    ``groups`` and ``outcome`` are per clip (see :func:`per_clip`). Returns ``(verdict, {group: holds |
    opposite | mixed | one clip | no clip})``.
    """
    per = {}
    for g in (order if order is not None else dict.fromkeys(groups)):
        o = outcome[groups == g]
        o = o[o != 0]
        if len(o) < 2:  # one clip is no evidence that a group behaves one way
            per[g] = "no clip" if not len(o) else "one clip"
        else:
            per[g] = "holds" if (o > 0).all() else "opposite" if (o < 0).all() else "mixed"
    words = set(per.values())
    if verdict == "within noise" and {"holds", "opposite"} <= words:
        return "partly", per
    return verdict, per


def per_clip(j: pd.DataFrame) -> pd.DataFrame:
    """Clip x seed outcomes (columns ``clip, group, outcome``) -> one row per clip: ``clip, group,
    outcome`` (+1 when the claim holds on more of the clip's seeds than its opposite, -1 for the reverse,
    0 for a tie) and the seed counts ``seeds_for, seeds_against``."""
    g = j.groupby("clip", sort=False)
    out = pd.DataFrame({"group": g["group"].first(), "seeds_for": g["outcome"].apply(lambda o: int((o > 0).sum())),
                        "seeds_against": g["outcome"].apply(lambda o: int((o < 0).sum()))})
    out["outcome"] = np.sign(out["seeds_for"] - out["seeds_against"]).astype(int)
    return out.reset_index()


def _decide_clips(j: pd.DataFrame, vc: dict, order) -> tuple[str, str]:
    """Verdict and evidence text from clip x seed outcomes ``j`` (``clip, group, outcome``), decided over clips."""
    c = per_clip(j)
    holds, fails, ties = int((c["outcome"] > 0).sum()), int((c["outcome"] < 0).sum()), int((c["outcome"] == 0).sum())
    verdict, share, p = decide(holds, fails, float(vc["share"]), float(vc["alpha"]))
    verdict, per = by_group(c["group"], c["outcome"], verdict, float(vc["share"]), float(vc["alpha"]), order)
    ph, pf = int((j["outcome"] > 0).sum()), int((j["outcome"] < 0).sum())
    text = (f"holds in {holds} of {holds + fails} untied clips (share {V.fmt(share)}, {ties} tied; each clip the "
            f"majority of its seeds), sign test over clips p = {V.fmt(p, 2)}; clip x seed pairs: {ph} of {ph + pf} "
            f"untied; " + _per_group(c["group"], c["outcome"], order) + _partly(verdict, per))
    return verdict, text


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
        parts.append(f"{g} {int((o > 0).sum())}/{n}" if n else f"{g} no clip")
    return "per group (clips holding / untied): " + ", ".join(parts)


def _partly(verdict: str, per: dict) -> str:
    if verdict != "partly":
        return ""
    holds = [g for g, v in per.items() if v == "holds"]
    opposite = [g for g, v in per.items() if v == "opposite"]
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
    order = dict.fromkeys(metrics["group"])
    verdict, text = _decide_clips(j, vc, order)
    unit = _UNITS[metric]
    ours = f"{metric} ({unit}) median {a} {_spread(metrics, a, metric)} vs {b} {_spread(metrics, b, metric)}"
    evidence = f"{a} {'lower' if better == 'lower' else 'higher'}: " + text
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
    j = pd.DataFrame({"clip": [c for c, _s in ok.index], "group": groups.to_numpy(),
                      "outcome": np.where(ok.to_numpy(), 1, -1)})
    verdict, text = _decide_clips(j, vc, dict.fromkeys(metrics["group"]))
    ours = "; ".join(f"{g} novelty median {_spread(metrics, g, 'novelty_median_m')} m" for g in copiers + makers)
    evidence = f"every re-sequencer at most {V.fmt(tol)} m from the database and every field follower farther: " + text
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
        c = per_clip(part)
        h, f = int((c["outcome"] > 0).sum()), int((c["outcome"] < 0).sum())
        per[g] = decide(h, f, float(vc["share"]), float(vc["alpha"]))[0]
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
    not_held = [g for g, v in per.items() if v != "reproduced"]
    evidence = ("decided generator by generator over clips (each clip the majority of its seeds; share and sign "
                f"test as for the other claims); per generator (clips where replay skates less / untied clips): "
                f"{', '.join(texts)}"
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

    def pair(claim, a, b, metric, better="lower", paper_value="", caveat=""):
        if {a, b} <= configured:
            row = _pair_row(metrics, claim, a, b, metric, better, vc, data, paper_value, left_out)
            if caveat and row["verdict"] != "not reproduced":
                row["evidence"] += "; " + caveat
            rows.append(row)

    pair("the classic motion graph skates less than ST-Isomap re-sequencing", "motion_graph", "stisomap",
         "skate_share")
    if {"isomap", "stisomap", "delaunay", "knn"} & configured:
        rows.append(_copy_row(metrics, vc, data, left_out))
    pair("our motion graph's transitions skate less than fairmotion's", "motion_graph", "fairmotion",
         "transition_skate_share",
         caveat="fairmotion 0.0.4 as released on PyPI, fed the working rate: away from 60 fps its walk cuts pieces "
                "at 60 fps frame counts and blends from a held pose (animsynth.compare.fairmotion_peer), so much of "
                "its skating is those defects, not the method")
    pair("the motion graph's blended transitions jump less than random concatenation's seams", "motion_graph",
         "concat", "velocity_jump")
    pair("ST-Isomap re-sequencing jumps less at its seams than Isomap re-sequencing", "stisomap", "isomap",
         "velocity_jump", paper_value="ST-Isomap re-sequences more smoothly than Isomap (the re-sequencing paper)")
    pair("Delaunay field following stays closer to the held-out continuation than k-NN field following (L2P)",
         "delaunay", "knn", "l2p", paper_value="Delaunay gives lower Error A/F than k-NN (Gauch & Peters Table II)")
    if "replay" in configured:
        rows.append(_capture_row(metrics, vc, data))
    return V.table(rows)
