"""The statistics of one comparison of two generators on one metric, over clips, seeds and groups.

* :func:`pair_outcomes`, :func:`per_clip`, :func:`group_outcomes` -- the effect of ``a`` against ``b`` per clip x
  seed, per clip (its seeds' median and majority) and per independent group (:mod:`animsynth.compare.groups`),
  with each group's vote (:func:`animsynth.verdicts.unit_votes`);
* :func:`subject_tests` -- per group, the sign test of its clips' outcomes, Holm over the groups;
* :func:`sign_flip_p` -- the exact sign-flip permutation test of the mean of the groups' effects;
* :class:`Stats` -- all of it for one comparison: the groups' effects, their mean, 95 % and 90 % t intervals
  (:func:`animsynth.verdicts.t_interval`), the sign-flip p, the subjects 80 % power would need, the per-subject tests;
* :func:`touching` -- the clips on which both generators' feet touch the floor (a skating comparison compares only
  those);
* :func:`no_values`, :func:`generic_clips` -- why a generator has no value at all (it did not run), and the clips
  of subjects on a generic figure (they leave the declared tests);
* :func:`metric_median`, :func:`spread` -- one generator's values of a metric in words.

The verdicts (:mod:`animsynth.compare.verdicts`) decide from these by :func:`animsynth.verdicts.effect_verdict`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import verdicts as V

__all__ = ["pair_outcomes", "metric_wide", "pair_from_wide", "per_clip", "group_outcomes", "subject_tests",
           "sign_flip_p", "Stats", "EXACT_MAX", "touching", "contact_by_clip", "no_values", "generic_clips", "few_clips",
           "metric_median", "spread"]


def pair_outcomes(metrics: pd.DataFrame, a: str, b: str, metric: str, better: str = "lower") -> pd.DataFrame:
    """Per clip x seed where both ``a`` and ``b`` have a finite ``metric``: ``group``, ``a``, ``b``, ``effect``
    (the difference signed so that positive favours ``a``, in the metric's units) and ``outcome`` (+1: ``a``
    better, -1: ``b`` better, 0: tie)."""
    key = ["clip", "seed"]
    if metric not in metrics:  # no such column in this run: no pair to compare
        return pd.DataFrame(columns=[*key, "group", "a", "b", "effect", "outcome"])
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


def metric_wide(metrics: pd.DataFrame, metric: str) -> pd.DataFrame:
    """``metric`` as one column per generator, one row per clip x seed in the order of ``metrics`` (for many pairs
    on one metric: :func:`pair_from_wide` gives each pair's :func:`pair_outcomes` without a join per pair)."""
    keys = metrics[["clip", "seed"]].drop_duplicates()
    values = pd.to_numeric(metrics[metric], errors="coerce") if metric in metrics else np.nan
    wide = metrics.assign(_v=values).pivot_table(index=["clip", "seed"], columns="generator", values="_v",
                                                 aggfunc="first", dropna=False)
    return wide.reindex(pd.MultiIndex.from_frame(keys))


def pair_from_wide(wide: pd.DataFrame, a: str, b: str, better: str = "lower") -> pd.DataFrame:
    """:func:`pair_outcomes` of ``a`` against ``b`` from :func:`metric_wide` (the same values, rows and signs)."""
    if a not in wide or b not in wide:
        return pd.DataFrame(columns=["clip", "seed", "a", "b", "effect", "outcome"])
    va, vb = wide[a].to_numpy(float), wide[b].to_numpy(float)
    ok = np.isfinite(va) & np.isfinite(vb)
    d = va[ok] - vb[ok]
    effect = -d if better == "lower" else d
    return pd.DataFrame({"clip": wide.index.get_level_values(0)[ok], "seed": wide.index.get_level_values(1)[ok],
                         "a": va[ok], "b": vb[ok], "effect": effect, "outcome": np.sign(effect).astype(int)})


def _by(keys, *columns) -> tuple:
    """Group rows by ``keys`` in order of first appearance (a groupby with sort=False, in numpy: the tables here
    hold a few hundred rows and many comparisons, where pandas' per-call cost dominates): the unique keys, then
    per column its groups' sums (bool or int columns) or medians (float columns)."""
    codes, uniq = pd.factorize(np.asarray(keys, object), sort=False)
    n = len(uniq)
    out = [uniq]
    for col in columns:
        col = np.asarray(col)
        if col.dtype.kind in "biu":
            out.append(np.bincount(codes, weights=col.astype(float), minlength=n).astype(int))
        else:
            order = np.argsort(codes, kind="stable")
            parts = np.split(col.astype(float)[order], np.cumsum(np.bincount(codes, minlength=n))[:-1])
            out.append(np.array([np.nan if not len(x) or np.isnan(x).all() else np.nanmedian(x) for x in parts]))
    return tuple(out)


def per_clip(j: pd.DataFrame) -> pd.DataFrame:
    """Clip x seed outcomes (``clip, outcome[, effect]``) -> one row per clip: ``clip``, ``outcome`` (+1 when
    the claim holds on more of its seeds than its opposite, -1 for the reverse, 0 for a tie), ``effect`` (the
    median over seeds) and the seed counts ``seeds_for, seeds_against``."""
    o = np.asarray(j["outcome"], int)
    eff = j["effect"] if "effect" in j else np.full(len(j), np.nan)
    clips, f, a, e = _by(j["clip"], o > 0, o < 0, eff)
    return pd.DataFrame({"clip": clips, "seeds_for": f, "seeds_against": a, "effect": e,
                         "outcome": np.sign(f - a).astype(int)})


def group_outcomes(j: pd.DataFrame, groups: dict, min_effect: float) -> pd.DataFrame:
    """Per group: ``clips_for``, ``clips_against`` (clip outcomes, :func:`per_clip`), ``effect`` (median of its
    clips' effects) and ``vote`` (:func:`animsynth.verdicts.unit_votes`): +1 (holds: more clips for than against
    and effect >= ``min_effect``), -1 (the opposite), 0 (neither)."""
    c = per_clip(j)
    unit = c["clip"].map(groups).fillna(c["clip"])
    units, n, f, a, e = _by(unit, np.ones(len(c), int), c["outcome"].to_numpy() > 0, c["outcome"].to_numpy() < 0,
                            c["effect"])
    out = pd.DataFrame({"clips": n, "clips_for": f, "clips_against": a, "effect": e}, index=pd.Index(units))
    out["vote"] = V.unit_votes(out["clips_for"] - out["clips_against"], out["effect"], min_effect)
    return out


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
    """``g``'s median of ``metric`` with its IQR, in words ('no value' without one)."""
    if metric not in metrics:
        return "no value"
    x = pd.to_numeric(metrics.loc[metrics["generator"] == g, metric], errors="coerce")
    x = x[np.isfinite(x)].to_numpy(float)
    if not x.size:
        return "no value"
    q = np.percentile(x, [25, 50, 75])
    return f"{V.fmt(q[1])} (IQR {V.fmt(q[0])}-{V.fmt(q[2])})"


def metric_median(metrics: pd.DataFrame, g: str, metric: str) -> float:
    """``g``'s median of ``metric`` over its clips x seeds (NaN without a value)."""
    x = pd.to_numeric(metrics.loc[metrics["generator"] == g, metric], errors="coerce") if metric in metrics else []
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    return float(np.median(x)) if x.size else float("nan")


#: the largest number of groups whose 2^n sign flips are all enumerated
EXACT_MAX = 16
_SIGNS: dict = {}


def _signs(n: int) -> np.ndarray:
    """Every one of the 2^n sign vectors of length ``n`` (rows, +1 / -1), cached."""
    if n not in _SIGNS:
        bits = (np.arange(2 ** n)[:, None] >> np.arange(n)) & 1
        _SIGNS[n] = (1 - 2 * bits).astype(float)
    return _SIGNS[n]


def sign_flip_p(effects, *, seed: int = 0, draws: int = 100000, exact_max: int = EXACT_MAX) -> float:
    """Two-sided sign-flip permutation test of the mean of independent effects against 0.

    Parameters
    ----------
    effects : array (n,)
        One effect per independent unit (NaN dropped).
    seed : int
        Seed of the random flips when ``n > exact_max``.
    draws : int
        Random flips when ``n > exact_max``.
    exact_max : int
        Up to this many units every one of the 2^n flips is enumerated (the exact test).

    Returns
    -------
    float
        The share of flips whose mean is at least as far from 0 as the observed mean (exact: the observed sign
        vector and its negation count, so the smallest p is 2 / 2^n; random flips: (1 + hits) / (1 + draws));
        1 when every effect is 0; NaN without a unit.
    """
    e = np.asarray(effects, float)
    e = e[np.isfinite(e)]
    n = e.size
    if n == 0:
        return float("nan")
    obs = abs(float(e.mean()))
    if obs == 0.0:
        return 1.0
    tol = 1e-9 * obs  # flips that reach the observed mean up to rounding count as reaching it
    if n <= exact_max:
        return float(np.mean(np.abs(_signs(n) @ e) / n >= obs - tol))
    rng = np.random.default_rng(int(seed))
    hits, left = 0, int(draws)
    while left > 0:
        k = min(left, 20000)
        s = rng.integers(0, 2, size=(k, n)) * 2 - 1
        hits += int(np.sum(np.abs(s @ e) / n >= obs - tol))
        left -= k
    return (1 + hits) / (1 + int(draws))


class Stats:
    """The subject-level statistics of one comparison ``a`` vs ``b`` on one metric.

    Attributes
    ----------
    per : DataFrame, :func:`group_outcomes` (one row per group: clips, clip counts, ``effect``, ``vote``)
    j : DataFrame, :func:`pair_outcomes` (clip x seed effects)
    n, mean, lo, hi, lo90, hi90, p : the groups, their mean effect, its 95 % and 90 % t intervals, the sign-flip p
    power : the groups 80 % power would need at the observed effect (:func:`animsynth.verdicts.power_text`; '' with
        ``subjects=False``)
    subjects : DataFrame per group: ``for``, ``against`` (clips each way, by the majority of their seeds), ``p`` (sign
        test), ``p_holm`` (Holm over the groups), ``side`` (+1 significantly for, -1 against, 0 neither); None when
        built with ``subjects=False`` (the exploratory table, which decides nothing)
    """

    def __init__(self, j: pd.DataFrame, groups: dict, margin: float, vc: dict, seed: int, subjects: bool = True):
        self.j, self.margin = j, float(margin)
        self.per = group_outcomes(j, groups, margin)
        eff = self.per["effect"].to_numpy(float)
        self.n = int(np.isfinite(eff).sum())
        self.mean = float(np.nanmean(eff)) if self.n else float("nan")
        self.lo, self.hi = V.t_interval(eff)
        self.lo90, self.hi90 = V.t_interval(eff, 0.90)
        self.p = sign_flip_p(eff, seed=seed, draws=int(vc.get("permutations", 100000)))
        self.power = V.power_text(eff, float(vc["alpha"])) if subjects else ""
        self.subjects = subject_tests(j, groups, self.per, margin, float(vc["alpha"])) if subjects else None

    @property
    def holding(self) -> int:
        return int((self.per["vote"] > 0).sum())

    @property
    def opposite(self) -> int:
        return int((self.per["vote"] < 0).sum())

    @property
    def split(self) -> tuple[int, int]:
        """(groups significantly for, significantly against) by the per-subject tests."""
        if self.subjects is None:
            return 0, 0
        return int((self.subjects["side"] > 0).sum()), int((self.subjects["side"] < 0).sum())

    def numbers(self, unit: str = "") -> str:
        """'mean effect 0.05 [95 % t interval 0.03, 0.07], p = 0.125' (the sign-flip p)."""
        return (f"mean effect {V.fmt(self.mean)}{' ' + unit if unit else ''} [95 % t interval {V.fmt(self.lo)}, "
                f"{V.fmt(self.hi)}], p = {V.fmt(self.p, 3)}")


def contact_by_clip(metrics: pd.DataFrame, g: str) -> pd.Series:
    """``g``'s median ``contact_share`` over the seeds of each clip (index: clip)."""
    if "contact_share" not in metrics:
        return pd.Series(dtype=float)
    rows = metrics[metrics["generator"] == g]
    return pd.to_numeric(rows["contact_share"], errors="coerce").groupby(rows["clip"], sort=False).median()


def touching(metrics: pd.DataFrame, gens, floor: float) -> tuple[set, dict]:
    """The clips on which every generator of ``gens`` touches the floor: its median ``contact_share`` over the
    clip's seeds is at least ``floor`` (``compare.verdicts.min_contact_share``), so a skating comparison there
    compares feet on the ground.

    Returns
    -------
    (kept, left) : the clips kept (of those where every generator has a row); ``{generator: [clips]}`` where its
    feet do not touch (a clip can be counted under both generators).
    """
    per = {g: contact_by_clip(metrics, g) for g in gens}
    clips = set.intersection(*(set(c.index) for c in per.values())) if per else set()
    left = {g: sorted(c.index[c.lt(float(floor))].intersection(list(clips))) for g, c in per.items()}
    gone = {c for cs in left.values() for c in cs}
    return clips - gone, {g: cs for g, cs in left.items() if cs}


def no_values(metrics: pd.DataFrame, g: str, left_out: dict | None = None, metric: str | None = None) -> str:
    """Why ``g`` did not run ('' when it has a finite value of ``metric`` -- of any metric when None -- on some
    clip): its reason in ``left_out`` (left out at parse time), else its rows' notes (not built, failed), else
    'no values'."""
    if left_out and g in left_out:
        return f"{g} did not run: {left_out[g]}"
    from .measures.metric_table import METRIC_NAMES

    rows = metrics[metrics["generator"] == g]
    cols = [metric] if metric is not None else [m for m in METRIC_NAMES if m in metrics]
    cols = [c for c in cols if c in rows]
    if len(rows) and cols and np.isfinite(rows[cols].apply(pd.to_numeric, errors="coerce").to_numpy(float)).any():
        return ""
    if not len(rows):
        return f"{g} did not run: not in this run"
    notes = sorted({str(x).removeprefix("did not run: ") for x in rows.get("note", pd.Series(dtype=str)).fillna("")
                    if str(x)})
    return f"{g} did not run: " + ("; ".join(notes) if notes else f"no values{' of ' + metric if metric else ''}")


def generic_clips(clips: pd.DataFrame | None) -> set:
    """The clips of subjects on a generic figure (``figure == "generic"`` in ``compare/clips.csv``: hierarchies
    identical to another subject's); none when the table has no ``figure`` column (every subject on its own
    skeleton)."""
    if clips is None or "figure" not in clips:
        return set()
    return set(clips.loc[clips["figure"].astype(str).str.strip() == "generic", "clip"])


def few_clips(clips: pd.DataFrame | None) -> tuple[set, dict]:
    """The clips of subjects with fewer clips than ``compare.min_clips_per_subject`` (``enough_clips`` false in
    ``compare/clips.csv``), and ``{subject: its clips}`` of those subjects: they leave the declared tests, the
    sanity checks and the exploratory table; none when the table has no ``enough_clips`` column."""
    if clips is None or "enough_clips" not in clips or "subject" not in clips:
        return set(), {}
    few = ~clips["enough_clips"].astype(str).str.strip().str.lower().isin(("true", "1", "yes"))
    part = clips[few]
    return set(part["clip"]), {str(k): int(v) for k, v in part.groupby("subject")["clip"].nunique().items()}


def few_clips_text(subjects: dict) -> str:
    """The line naming the subjects :func:`few_clips` leaves out ("" when none)."""
    if not subjects:
        return ""
    return ("; left out of the tests, fewer clips than compare.min_clips_per_subject: "
            + ", ".join(f"subject {s} ({n} clip{'s' if n != 1 else ''})" for s, n in sorted(subjects.items())))
