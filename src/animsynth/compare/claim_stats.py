"""The statistics of one comparison of two generators on one metric, over clips, seeds and groups.

* :func:`pair_outcomes`, :func:`per_clip`, :func:`group_outcomes` -- the effect of ``a`` against ``b`` per clip x
  seed, per clip (its seeds' median and majority) and per independent group (:mod:`animsynth.compare.groups`),
  with each group's vote (:func:`animsynth.verdicts.unit_votes`);
* :func:`t_interval` -- the t interval of the mean of the groups' effects;
* :func:`subject_tests` -- per group, the sign test of its clips' outcomes, Holm over the groups;
* :func:`metric_median`, :func:`spread`, :func:`floating_reason` -- one generator's values of a metric in words and
  whether its feet touch the floor (a skating comparison needs them to).

The sign-flip test of the mean and the statistics of a claim (:class:`animsynth.compare.verdicts.Stats`) use them.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import verdicts as V

__all__ = ["pair_outcomes", "per_clip", "group_outcomes", "t_interval", "subject_tests", "metric_median", "spread",
           "floating_reason"]


def pair_outcomes(metrics: pd.DataFrame, a: str, b: str, metric: str, better: str = "lower") -> pd.DataFrame:
    """Per clip x seed where both ``a`` and ``b`` have a finite ``metric``: ``group``, ``a``, ``b``, ``effect``
    (the difference signed so that positive favours ``a``, in the metric's units) and ``outcome`` (+1: ``a``
    better, -1: ``b`` better, 0: tie)."""
    key = ["clip", "seed"]
    A = metrics[metrics["generator"] == a].set_index(key)[["group", metric]]
    B = metrics[metrics["generator"] == b].set_index(key)[metric]
    j = A.join(B.rename("b"), how="inner").rename(columns={metric: "a"})
    j["a"] = pd.to_numeric(j["a"], errors="coerce")
    j["b"] = pd.to_numeric(j["b"], errors="coerce")
    j = j[np.isfinite(j["a"]) & np.isfinite(j["b"])]
    d = j["a"] - j["b"]
    j["effect"] = -d if better == "lower" else d
    j["outcome"] = np.sign(j["effect"]).astype(int)
    return j.reset_index()


def per_clip(j: pd.DataFrame) -> pd.DataFrame:
    """Clip x seed outcomes (``clip, outcome[, effect]``) -> one row per clip: ``clip``, ``outcome`` (+1 when
    the claim holds on more of its seeds than its opposite, -1 for the reverse, 0 for a tie), ``effect`` (the
    median over seeds) and the seed counts ``seeds_for, seeds_against``."""
    g = j.groupby("clip", sort=False)
    out = pd.DataFrame({"seeds_for": (j["outcome"] > 0).groupby(j["clip"], sort=False).sum().astype(int),
                        "seeds_against": (j["outcome"] < 0).groupby(j["clip"], sort=False).sum().astype(int)})
    out["effect"] = g["effect"].median() if "effect" in j else np.nan
    out["outcome"] = np.sign(out["seeds_for"] - out["seeds_against"]).astype(int)
    return out.reset_index()


def group_outcomes(j: pd.DataFrame, groups: dict, min_effect: float) -> pd.DataFrame:
    """Per group: ``clips_for``, ``clips_against`` (clip outcomes, :func:`per_clip`), ``effect`` (median of its
    clips' effects) and ``vote`` (:func:`animsynth.verdicts.unit_votes`): +1 (holds: more clips for than against
    and effect >= ``min_effect``), -1 (the opposite), 0 (within noise)."""
    c = per_clip(j)
    c["unit"] = c["clip"].map(groups).fillna(c["clip"])
    g = c.groupby("unit", sort=False)
    out = pd.DataFrame({"clips": g.size(), "clips_for": (c["outcome"] > 0).groupby(c["unit"], sort=False).sum().astype(int),
                        "clips_against": (c["outcome"] < 0).groupby(c["unit"], sort=False).sum().astype(int),
                        "effect": g["effect"].median()})
    out["vote"] = V.unit_votes(out["clips_for"] - out["clips_against"], out["effect"], min_effect)
    return out


def t_interval(effects, level: float = 0.95) -> tuple[float, float]:
    """The ``level`` t interval of the mean of ``effects`` (mean +- t(1 - (1 - level) / 2, n - 1) x sd / sqrt(n));
    NaN for fewer than 2 values."""
    from scipy.stats import t

    e = np.asarray(effects, float)
    e = e[np.isfinite(e)]
    if e.size < 2:
        return float("nan"), float("nan")
    half = float(t.ppf(1 - (1 - level) / 2, e.size - 1)) * float(e.std(ddof=1)) / np.sqrt(e.size)
    return float(e.mean() - half), float(e.mean() + half)


def subject_tests(j: pd.DataFrame, groups: dict, per: pd.DataFrame, min_effect: float, alpha: float) -> pd.DataFrame:
    """Per group: the two-sided exact sign test of its clips' outcomes (one vote per clip, its seeds' majority:
    :func:`per_clip`), Holm over the groups, and its side.

    Clips, not clip x seed effects: the seeds of one clip share its database and start (and a deterministic
    generator repeats itself over them), so counting them as independent would let two clips look like ten.
    With the few clips a subject has, a subject is significant only when many of its clips agree; "partly" is
    correspondingly rare, which is what the data can support."""
    c = per_clip(j)
    unit = c["clip"].map(groups).fillna(c["clip"])
    out = pd.DataFrame({"for": (c["outcome"] > 0).groupby(unit, sort=False).sum().astype(int),
                        "against": (c["outcome"] < 0).groupby(unit, sort=False).sum().astype(int)}).reindex(per.index)
    out["p"] = [V.sign_test(w, f) for w, f in zip(out["for"], out["against"])]
    out["p_holm"] = V.holm(out["p"])
    sig = out["p_holm"] < alpha
    eff = per["effect"]
    out["side"] = np.where(sig & (out["for"] > out["against"]) & (eff >= min_effect), 1,
                           np.where(sig & (out["against"] > out["for"]) & (eff <= -min_effect), -1, 0))
    return out


def spread(metrics: pd.DataFrame, g: str, metric: str) -> str:
    x = pd.to_numeric(metrics.loc[metrics["generator"] == g, metric], errors="coerce")
    x = x[np.isfinite(x)].to_numpy(float)
    if not x.size:
        return "no value"
    q = np.percentile(x, [25, 50, 75])
    return f"{V.fmt(q[1])} (IQR {V.fmt(q[0])}-{V.fmt(q[2])})"


def metric_median(metrics: pd.DataFrame, g: str, metric: str) -> float:
    x = pd.to_numeric(metrics.loc[metrics["generator"] == g, metric], errors="coerce") if metric in metrics else []
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    return float(np.median(x)) if x.size else float("nan")


def floating_reason(metrics, g, vc) -> str:
    """Why ``g`` cannot take part in a skating comparison ('' when its feet touch)."""
    floor = float(vc.get("min_contact_share", 0.05))
    c = metric_median(metrics, g, "contact_share")
    if np.isfinite(c) and c < floor:
        return (f"{g}'s feet do not touch the floor (median contact_share {V.fmt(c)} below "
                f"compare.verdicts.min_contact_share {V.fmt(floor)}), so it cannot win or lose a skating comparison")
    return ""
