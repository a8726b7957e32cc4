"""The side-by-side claims, declared in advance and decided over independent groups of clips, in the common
verdict format (:mod:`animsynth.verdicts`).

Declared claims
---------------
The primary claims are a list fixed in advance (``compare.claims``; :data:`DEFAULT_CLAIMS` when none is given):
each has an ``id``, the claim text, generators ``a`` and ``b`` (``b: "*"``: every generator of the run but the
references, one intersection-union finding), a ``metric``, a ``direction`` (``lower`` / ``higher``: which value of
``a`` the claim expects), a ``min_effect`` in the metric's units (``skating``: :func:`skating_claim`). Only
these are findings (``verdicts.csv``, with their numbers in ``claims_stats.csv``) and Holm's correction runs over
them alone. Every other pair of generators on the main metrics (:data:`EXPLORATORY_METRICS`), including a pair whose
claim a user removed from the list, is **exploratory** (:func:`exploratory_table`, ``exploratory.csv``): numbers
only, no verdict word, a Holm correction of its own, never a finding.

Independent units
-----------------
Clips are not independent: the leave-one-out clips of a subset share most of their database trials and the
subject, and a re-sequencing clip may be a trial that a subset's clips use. The unit of every test is the
**group** (:func:`animsynth.compare.groups.independent_groups`, ``compare.verdicts.grouping``):

* ``subject`` (default): every clip of one subject (the CMU subject id of its held-out trial), joined with every
  other group with which it shares a trial (held out or in a database): clips that share a subject or database
  trials are one group. On the paper run's CMU protocol: subject 35 (w1, r1, run, walk), 16 (w2), 127 (r2),
  05 (dance) and the eight sets of ``compare.subjects`` (02, 09, 07, 12, 49, 17, 06, 10): 12 groups for 38 clips.
* ``subset_subject``: the clips of one subset (or re-sequencing dataset) and one subject, joined where they
  share a trial. It counts the subsets of one subject as independent, which they are not for a claim about
  people's motion; kept as an option.

A clip without a subject id (not a CMU trial name) is grouped by its subset. The grouping lives in
:mod:`animsynth.compare.groups`; the per-clip and per-group effects, the t interval and the per-subject tests in
:mod:`animsynth.compare.claim_stats`.

A group's **effect** is the median over its clips of each clip's median over seeds of ``a - b`` (signed so that
positive favours the claim), in the metric's units. A group **holds** when more of its clips hold than not and its
effect is at least the claim's minimum effect, holds the **opposite** for the reverse, and votes neither way
otherwise (:func:`group_outcomes`).

The test
--------
Over the ``n`` group effects: the claim's effect is their **mean**, with a **95 % t interval** over the groups
(mean +- t(0.975, n - 1) x standard deviation / sqrt(n); none for one group). Its p is an **exact sign-flip
permutation test** of that mean (:func:`sign_flip_p`): under "no effect" each group's effect is as likely
negative as positive, so the p is the share of the 2^n sign flips whose mean is at least as far from 0 as the
observed one (two-sided; ``n > 16``: ``compare.verdicts.permutations`` seeded random flips, the seed
``compare.seed``). Equal non-zero effects give p = 2 / 2^n, never 0; effects that are all 0 give 1. With 4 groups
the smallest possible p is 2 / 2^4 = 0.125: four subjects cannot decide any claim, whatever its effect. Holm's
step-down correction (Holm 1979) runs over the declared claims with a test.

Per subject (for "partly" only): a two-sided exact sign test of the subject's clip outcomes (one vote per clip,
the majority of its seeds: seeds share the clip's database and start, so they are not independent), Holm over
the subjects of the claim; a subject is **significantly for** when its adjusted p is below ``alpha``, more of its
clips favour the claim and its effect is at least the minimum effect (**against** the reverse).

The verdict of a claim
----------------------
In this order (:func:`decide`):

* ``not reproduced`` -- a generator did not run (the evidence says why), or on a skating claim a generator's feet
  do not touch the floor (its median ``contact_share`` below ``compare.verdicts.min_contact_share``): a generator
  that never touches cannot win (or lose) a skating comparison;
* significant (Holm-adjusted p < ``alpha``, at least ``min_groups`` groups): ``reproduced`` when the mean effect
  is at least the minimum effect, ``contradicted`` when it is at most minus it, ``not reproduced`` (no material
  effect) when it lies between;
* ``partly`` -- a significant split between subjects: some subjects significantly for and some significantly
  against by the per-subject test;
* ``not reproduced`` (no material effect) -- the 95 % interval lies inside (-minimum effect, +minimum effect);
* ``within noise`` -- the groups vote both ways (some hold, some hold the opposite, by the minimum effect)
  without a significant split; the evidence gives the share;
* ``undecided`` -- anything else: too few groups or too wide an interval to decide; the text reads
  "undecided (n subjects)" with the mean effect, its interval, p and the Holm-adjusted p.

The capture claim ("the held-out capture skates less than every generator") holds only if it holds against each
generator: one finding whose p is the largest of its parts' (an intersection-union test needs no correction among
its parts), decided by the rules above with the effect and interval of its weakest part (the generator against
which the mean effect is smallest). One significant part the other way refutes it: when some parts lean the other
way by the minimum effect, the claim is tested for a contradiction instead, its p the smallest p of those parts
times the number of parts (Bonferroni), with that part's effect and interval. Its parts show numbers (groups
holding / opposite / neither, mean effect, interval, p), never a verdict word of their own. A generator whose
feet do not touch is left out of it, named.

Claims true by construction (re-sequencers copy database frames, so their novelty is 0; random concatenation
is unblended, so a blended transition jumps less) are **sanity checks** (:func:`sanity_checks`): decided by the
same rules with the metric's ``compare.verdicts.min_effect``, Holm among themselves, in their own table.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import verdicts as V
from .claim_stats import floating_reason, group_outcomes, metric_median, pair_outcomes, per_clip, spread, \
    subject_tests, t_interval
from .groups import GROUPINGS, clip_groups
from .generators.names import REFERENCES
from .measures.metric_table import EXPLORATORY_METRICS, SKATING_CLAIM_METRICS, metric_or_blank

__all__ = ["sign_flip_p", "Stats", "decide", "decide_claims", "build_verdicts", "exploratory_table", "sanity_checks",
           "DEFAULT_CLAIMS", "STATS_COLUMNS", "EXPLORATORY_COLUMNS"]

def _sweep_evidence(sweep: pd.DataFrame | None, a: str, b: str, metric: str) -> str:
    """What the transition budget sweep (``compare/budget_sweep.csv``) says of ``a`` vs ``b`` on ``metric``
    (lower is better): the medians at every budget, over the clips both graphs were built on."""
    if sweep is None or not len(sweep):
        return ""
    col = f"{metric}_median"
    parts, lower = [], 0
    budgets = sorted(sweep["transitions_per_s"].unique())
    for bud in budgets:
        s = sweep[sweep["transitions_per_s"] == bud].set_index("generator")
        if a not in s.index or b not in s.index:
            continue
        va, vb = float(s.loc[a, col]), float(s.loc[b, col])
        lower += int(va < vb)
        parts.append(f"{V.fmt(va)} vs {V.fmt(vb)} at {V.fmt(bud)}/s")
    if not parts:
        return ""
    return (f"the budget sweep (budget_sweep.csv; medians over the clips both graphs were built on): {a} vs {b} "
            f"{'; '.join(parts)}; {a} lower at {lower} of {len(parts)} budgets")


#: ``b`` of the capture claim: every generator of the run but the references
EVERY = "*"
#: the largest number of groups whose 2^n sign flips are all enumerated
EXACT_MAX = 16

#: The declared primary claims of the comparison (``compare.claims`` of config/config.yaml repeats them; a test
#: keeps the two equal): used when a caller gives none.
DEFAULT_CLAIMS = (
    {"id": "graph_vs_stisomap_skating", "claim": "the classic motion graph skates less than ST-Isomap re-sequencing",
     "a": "motion_graph", "b": "stisomap", "metric": "skate_share", "direction": "lower", "min_effect": 0.02},
    {"id": "graph_vs_fairmotion_transitions",
     "claim": "our motion graph's transitions skate less than fairmotion 0.0.4's as released (at its native 60 fps)",
     "a": "motion_graph", "b": "fairmotion", "metric": "transition_skate_share", "direction": "lower",
     "min_effect": 0.02,
     "note": "fairmotion as released: its walk blends from a held pose and turns an appended piece without its path "
             "(animsynth.compare.generators.fairmotion_peer); both graphs keep the same transition budget"},
    {"id": "graph_vs_fairmotion_fixed_transitions",
     "claim": "our motion graph's transitions skate less than fairmotion's with upstream's walk fixes",
     "a": "motion_graph", "b": "fairmotion_fixed", "metric": "transition_skate_share", "direction": "lower",
     "min_effect": 0.02,
     "note": "fairmotion with the fixes output_rate, blend_source, rigid_turn, cut_copy; both graphs keep the same "
             "transition budget"},
    {"id": "stisomap_vs_isomap_jumps",
     "claim": "ST-Isomap re-sequencing jumps less than Isomap re-sequencing (95th percentile of the per-frame "
              "velocity jump)",
     "a": "stisomap", "b": "isomap", "metric": "velocity_jump_p95", "direction": "lower", "min_effect": 0.1,
     "paper_value": "ST-Isomap re-sequences more smoothly than Isomap (the re-sequencing paper)"},
    {"id": "delaunay_vs_knn_l2p",
     "claim": "Delaunay field following stays closer to the held-out continuation than k-NN field following (L2P)",
     "a": "delaunay", "b": "knn", "metric": "l2p", "direction": "lower", "min_effect": 0.25,
     "paper_value": "Delaunay gives lower Error A/F than k-NN (Gauch & Peters Table II)"},
    {"id": "mm_vs_graph_skating", "claim": "motion matching skates less than the motion graph",
     "a": "motion_matching", "b": "motion_graph", "metric": "skate_share", "direction": "lower", "min_effect": 0.02,
     "note": "motion matching with the reference's foot locking and leg IK, its query a steady gamepad from the "
             "start; deterministic, so inside a clip only the motion graph's seeds vary"},
    {"id": "mm_traj_vs_graph_skating",
     "claim": "motion matching (queried with the held-out future trajectory) skates less than the motion graph",
     "a": "motion_matching_traj", "b": "motion_graph", "metric": "skate_share", "direction": "lower",
     "min_effect": 0.02,
     "note": "motion matching with the reference's foot locking and leg IK, its query the held-out future trajectory "
             "(information no other generator is given)"},
    {"id": "genmm_vs_graph_coverage", "claim": "GenMM covers more of the database than the motion graph",
     "a": "genmm", "b": "motion_graph", "metric": "coverage", "direction": "higher", "min_effect": 0.02,
     "note": "coverage: the share of the database's windows that a generated window comes within "
             "compare.metrics.coverage_threshold_m of"},
    {"id": "capture_skates_least",
     "claim": "the held-out capture skates less than every generator (the realism upper bound holds for this metric)",
     "a": "replay", "b": EVERY, "metric": "skate_share", "direction": "lower", "min_effect": 0.02},
)
#: the columns of ``claims_stats.csv``
STATS_COLUMNS = ("claim_id", "a", "b", "metric", "direction", "n_groups", "mean_effect", "ci_low", "ci_high", "p",
                 "p_holm", "min_effect", "verdict", "a_contact_share", "b_contact_share")
#: the columns of ``exploratory.csv``
EXPLORATORY_COLUMNS = ("label", "a", "b", "metric", "direction", "n_groups", "groups_holding", "groups_opposite",
                       "mean_effect", "ci_low", "ci_high", "p", "p_holm", "min_effect")
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
    n, mean, lo, hi, p : the groups, their mean effect, its 95 % t interval, the sign-flip p
    subjects : DataFrame per group: ``for``, ``against`` (clips each way, by the majority of their seeds), ``p`` (sign test),
        ``p_holm`` (Holm over the groups), ``side`` (+1 significantly for, -1 against, 0 neither); None when built
        with ``subjects=False`` (the exploratory table, which decides nothing)
    """

    def __init__(self, j: pd.DataFrame, groups: dict, min_effect: float, vc: dict, seed: int, subjects: bool = True):
        self.j, self.min_effect = j, float(min_effect)
        self.per = group_outcomes(j, groups, min_effect)
        eff = self.per["effect"].to_numpy(float)
        self.n = int(np.isfinite(eff).sum())
        self.mean = float(np.nanmean(eff)) if self.n else float("nan")
        self.lo, self.hi = t_interval(eff)
        self.p = sign_flip_p(eff, seed=seed, draws=int(vc.get("permutations", 100000)))
        self.subjects = subject_tests(j, groups, self.per, min_effect, float(vc["alpha"])) if subjects else None

    @property
    def holding(self) -> int:
        return int((self.per["vote"] > 0).sum())

    @property
    def opposite(self) -> int:
        return int((self.per["vote"] < 0).sum())

    def numbers(self, unit: str = "") -> str:
        """'mean effect 0.05 [95 % t interval 0.03, 0.07], p = 0.125' (the sign-flip p)."""
        return (f"mean effect {V.fmt(self.mean)}{' ' + unit if unit else ''} [95 % t interval {V.fmt(self.lo)}, "
                f"{V.fmt(self.hi)}], p = {V.fmt(self.p, 3)}")


def _units(vc: dict, n: int | None = None) -> str:
    word = "subject" if vc.get("grouping", "subject") == "subject" else "group"
    return word + ("s" if n is None or n != 1 else "")


def decide(st: Stats, p_holm: float, min_effect: float, vc: dict) -> tuple[str, str]:
    """The verdict of a tested claim and its reason, by the rules of the module's docstring (in their order).

    Parameters
    ----------
    st : the claim's statistics (for the capture claim: its weakest part's)
    p_holm : its Holm-adjusted p
    min_effect : its minimum effect (metric units)
    vc : ``compare.verdicts`` (``alpha``, ``min_groups``)

    Returns
    -------
    (verdict, reason): a word of :data:`animsynth.verdicts.VOCABULARY` and why, in words.
    """
    alpha, me = float(vc["alpha"]), float(min_effect)
    if st.n >= int(vc.get("min_groups", 2)) and np.isfinite(p_holm) and p_holm < alpha:
        if st.mean >= me:
            return "reproduced", "significant and the mean effect at least the minimum effect"
        if st.mean <= -me:
            return "contradicted", "significant, the mean effect at least the minimum effect the other way"
        return "not reproduced", "significant but the mean effect below the minimum effect (no material effect)"
    n_for, n_against = int((st.subjects["side"] > 0).sum()), int((st.subjects["side"] < 0).sum())
    if n_for and n_against:
        return "partly", (f"a significant split: {n_for} {_units(vc, n_for)} significantly for and {n_against} "
                          "significantly against (per-subject sign tests over clips, Holm over the subjects)")
    if np.isfinite(st.lo) and -me < st.lo and st.hi < me:
        return "not reproduced", "the 95 % interval lies inside plus or minus the minimum effect (no material effect)"
    if st.holding and st.opposite:
        return "within noise", (f"not significant; the groups vote both ways: {st.holding} of {st.n} hold, "
                                f"{st.opposite} of {st.n} the opposite (share holding {V.fmt(st.holding / st.n, 2)}), "
                                "without a significant split")
    floor = (2.0 / 2 ** st.n if st.n <= EXACT_MAX else 1.0 / (1 + int(vc.get("permutations", 100000)))) if st.n \
        else float("nan")
    return "undecided", (f"too few {_units(vc)} or too wide an interval to decide (with {st.n} the smallest "
                         f"possible p is {V.fmt(floor, 3)})")


def skating_claim(spec: dict) -> bool:
    """Whether a declared claim is a skating claim (its contact shares shown beside it; a generator whose feet do not
    touch the floor cannot win it): its ``skating`` key when given, else its metric's record in the metric table
    (:data:`animsynth.compare.measures.metric_table.SKATING_CLAIM_METRICS`)."""
    return spec["metric"] in SKATING_CLAIM_METRICS if spec.get("skating") is None else bool(spec["skating"])


class _Claim:
    """One declared claim: its statistics (or why it has none) and how to write its row once Holm has run."""

    def __init__(self, spec: dict, metrics: pd.DataFrame, groups: dict, vc: dict, data: str, left_out: dict,
                 seed: int, sweep=None):
        self.spec, self.data, self.vc = spec, data, vc
        self.a, self.b, self.metric = spec["a"], spec["b"], spec["metric"]
        self.better = spec.get("direction", "lower")
        self.me = float(spec["min_effect"])
        self.skating = skating_claim(spec)
        self.missing, self.blocked, self.st, self.parts, self.left = "", "", None, [], []
        self.mode = "claim"
        self.metrics, self.sweep = metrics, sweep
        present = set(metrics["generator"])
        gone = [g for g in (self.a, self.b) if g != EVERY and g not in present]
        if gone:
            self.missing = "; ".join(f"{g} did not run: {(left_out or {}).get(g, 'not in this run')}" for g in gone)
            return
        if self.b == EVERY:
            self._every(metrics, groups, seed)
        else:
            j = pair_outcomes(metrics, self.a, self.b, self.metric, self.better)
            if not len(j):
                self.missing = f"no clip x seed with a {self.metric} value for both {self.a} and {self.b}"
                return
            self.st = Stats(j, groups, self.me, vc, seed)
            if self.skating:
                self.blocked = "; ".join(w for w in (floating_reason(metrics, g, vc) for g in (self.a, self.b)) if w)

    def _every(self, metrics, groups, seed):
        """The capture claim: one part per generator (its feet touching), the weakest part deciding."""
        if self.skating and (w := floating_reason(metrics, self.a, self.vc)):
            self.blocked = w
        for g in dict.fromkeys(metrics["generator"]):
            if g in REFERENCES or g == self.a:
                continue
            why = floating_reason(metrics, g, self.vc) if self.skating else ""
            j = pair_outcomes(metrics, self.a, g, self.metric, self.better)
            if why or not len(j):
                self.left.append(f"{g} left out: {why or 'no value shared with ' + self.a}")
                continue
            self.parts.append((g, Stats(j, groups, self.me, self.vc, seed)))
        if not self.parts:
            self.missing = "no generator to compare with" + (f" ({'; '.join(self.left)})" if self.left else "")
            return
        # One significant opposite part refutes "less than every generator": when some parts lean the other way
        # by the minimum effect, the claim is tested for a contradiction (union-intersection: the smallest p of
        # those parts times the number of parts, Bonferroni); otherwise for the claim (intersection-union: the
        # largest p), the weakest part (smallest mean effect) carrying the claim's effect.
        opposite = [s for _g, s in self.parts if s.mean <= -self.me]
        if opposite:
            self.mode = "contradiction"
            self.st = min(opposite, key=lambda s: (s.p, s.mean))
        else:
            self.mode = "claim"
            self.st = min((s for _g, s in self.parts), key=lambda s: (s.mean, -s.p))

    @property
    def p(self) -> float:
        """The claim's p for Holm: NaN when it has no test or is blocked (a blocked claim is not a finding, so it
        does not tighten the others' correction); the capture claim's by its mode (see :meth:`_every`)."""
        if self.st is None or self.blocked:
            return float("nan")
        if self.parts:
            if self.mode == "contradiction":
                return float(min(1.0, len(self.parts) * self.st.p))
            ps = np.array([s.p for _g, s in self.parts], float)
            return float(ps.max()) if np.all(np.isfinite(ps)) else float("nan")
        return self.st.p

    def contact(self, g: str) -> float:
        return metric_median(self.metrics, g, "contact_share")

    def verdict(self, p_holm: float) -> tuple[str, str]:
        if self.missing:
            return "not reproduced", self.missing
        if self.blocked:
            return "not reproduced", self.blocked
        return decide(self.st, p_holm, self.me, self.vc)

    def stats_row(self, p_holm: float) -> dict:
        word, _why = self.verdict(p_holm)
        st = self.st
        row = {"claim_id": self.spec["id"], "a": self.a, "b": "every generator" if self.b == EVERY else self.b,
               "metric": self.metric, "direction": self.better, "n_groups": st.n if st else 0,
               "mean_effect": st.mean if st else np.nan, "ci_low": st.lo if st else np.nan,
               "ci_high": st.hi if st else np.nan, "p": self.p, "p_holm": p_holm, "min_effect": self.me,
               "verdict": word, "a_contact_share": np.nan, "b_contact_share": np.nan}
        if self.skating and not self.missing:
            row["a_contact_share"] = self.contact(self.a)
            bs = [self.contact(g) for g, _s in self.parts] if self.b == EVERY else [self.contact(self.b)]
            row["b_contact_share"] = float(np.nanmin(bs)) if np.any(np.isfinite(bs)) else np.nan
        return row

    def _ours(self, word: str, p_holm: float) -> str:
        st, vc = self.st, self.vc
        unit = metric_or_blank(self.metric).unit
        head = f"{word} ({st.n} {_units(vc, st.n)})" if word == "undecided" else f"{st.n} {_units(vc, st.n)}"
        which = ("" if not self.parts else "weakest part " if self.mode == "claim" else
                 "the most significant opposite part ")
        text = (f"{head}: {which}mean {_units(vc, 1)}-level effect "
                f"{V.fmt(st.mean)} {unit} (95 % t interval over {_units(vc)} {V.fmt(st.lo)} to {V.fmt(st.hi)}), "
                f"sign-flip p = {V.fmt(self.p, 3)}, Holm p = {V.fmt(p_holm, 3)}")
        if self.b == EVERY:
            med = {g: metric_median(self.metrics, g, self.metric) for g, _s in self.parts}
            text += f"; {self.metric} median {self.a} {spread(self.metrics, self.a, self.metric)}"
            if med:
                lo, hi = min(med, key=med.get), max(med, key=med.get)
                text += (f" vs the generators' medians from {lo} {V.fmt(med[lo])} to {hi} {V.fmt(med[hi])}")
        else:
            text += (f"; {self.metric} ({unit}) median {self.a} {spread(self.metrics, self.a, self.metric)} vs "
                     f"{self.b} {spread(self.metrics, self.b, self.metric)}")
        if self.skating:
            gens = [self.a] + ([g for g, _s in self.parts] if self.b == EVERY else [self.b])
            text += "; contact_share (share of foot joint-frames) median " + ", ".join(
                f"{g} {V.fmt(self.contact(g))}" for g in gens)
        return text

    def row(self, p_holm: float, m: int) -> dict:
        spec, vc = self.spec, self.vc
        word, why = self.verdict(p_holm)
        if self.missing:
            return V.row(spec["claim"], "not reproduced", f"no pair to compare ({self.missing})",
                         paper_value=spec.get("paper_value", ""), data=self.data, source="compare/metrics.csv")
        st = self.st
        unit = metric_or_blank(self.metric).unit
        grouping = GROUPINGS[vc.get("grouping", "subject")]
        lead = (f"tested: {self.a} {self.better} than "
                f"{'every generator' if self.b == EVERY else self.b} on {self.metric}; ")
        text = f"{lead}{word} because {why}. "
        test = (f"exact sign-flip permutation test of the mean of the {_units(vc)}' effects (all 2^n flips up to "
                f"n = {EXACT_MAX}, else {int(vc.get('permutations', 100000))} seeded random flips; two-sided), Holm "
                f"over the {m} declared claims with a test; 95 % t interval over the {_units(vc)} (shown for the size of the "
                f"effect; the verdict rests on the sign-flip p, so with skewed effects the two can disagree); minimum effect "
                f"{V.fmt(self.me)} {unit}; independent {_units(vc)}: {grouping}")
        if self.b == EVERY:
            parts = "; ".join(f"{g}: {s.holding}/{s.opposite}/{s.n - s.holding - s.opposite}, {s.numbers()}"
                              for g, s in self.parts)
            if self.mode == "contradiction":
                text += (f"Tested for a contradiction: {sum(s.mean <= -self.me for _g, s in self.parts)} of the "
                         f"{len(self.parts)} generators compared lean the other way by the minimum effect, and one "
                         f"significant such part refutes the claim (union-intersection test: the smallest p of those "
                         f"parts times the {len(self.parts)} parts, Bonferroni, p = {V.fmt(self.p, 3)}; one finding of "
                         f"the Holm correction: adjusted p = {V.fmt(p_holm, 3)}); {test}; per generator (groups "
                         f"holding / opposite / neither, mean effect, interval, p): {parts}")
            else:
                text += (f"One intersection-union test over the {len(self.parts)} generators compared (the claim "
                         f"holds only if it holds against each, so its p is the largest of theirs, p = "
                         f"{V.fmt(self.p, 3)}, and it is one finding of the Holm correction: adjusted p = "
                         f"{V.fmt(p_holm, 3)}); {test}; per generator (groups holding / opposite / neither, mean "
                         f"effect, interval, p): {parts}")
            if self.left:
                text += "; " + "; ".join(self.left)
        else:
            c = per_clip(st.j)
            ch, cf = int((c["outcome"] > 0).sum()), int((c["outcome"] < 0).sum())
            groups = ", ".join(f"{g} {int(r.clips_for)}/{int(r.clips_for + r.clips_against)} clips, effect "
                               f"{V.fmt(r.effect)}" for g, r in st.per.iterrows())
            subj = ", ".join(f"{g} {int(r['for'])}/{int(r['for'] + r['against'])} (Holm p {V.fmt(r.p_holm, 2)})"
                             for g, r in st.subjects.iterrows())
            text += (f"{st.n} independent {_units(vc, st.n)}: {st.numbers(unit)}, Holm-adjusted p = "
                     f"{V.fmt(p_holm, 3)}; {test}; holds in {st.holding}, opposite in {st.opposite}, neither in "
                     f"{st.n - st.holding - st.opposite}; per group (clips holding / untied clips, median effect): "
                     f"{groups}; per-subject sign tests (clips for / untied clips): {subj}; counted by clips "
                     f"instead: {ch} of {ch + cf} untied clips")
        if spec.get("note"):
            text += "; " + spec["note"]
        if self.sweep is not None and len(self.sweep) and self.a == "motion_graph":
            if self.b == "fairmotion":
                text += "; the budget sweep runs the fixed row (the released row builds the same graph)"
            elif ev := _sweep_evidence(self.sweep, self.a, self.b, self.metric):
                text += "; " + ev
        return V.row(spec["claim"], word, text, paper_value=spec.get("paper_value", ""),
                     ours=self._ours(word, p_holm), data=self.data, source="compare/metrics.csv")


def decide_claims(metrics: pd.DataFrame, vc: dict, data: str, left_out: dict | None = None,
                  clips: pd.DataFrame | None = None, sweep: pd.DataFrame | None = None, claims=None,
                  seed: int = 0) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The declared claims decided: the verdict table and ``claims_stats.csv`` (:data:`STATS_COLUMNS`).

    Parameters
    ----------
    metrics : DataFrame, ``compare/metrics.csv``
    vc : the ``compare.verdicts`` block (``alpha``, ``min_groups``, ``grouping``, ``min_contact_share``,
        ``permutations``)
    data : what the numbers ran on (e.g. "CMU: 19 held-out clips x 5 seeds")
    left_out : {generator: why it did not run}
    clips : DataFrame, ``compare/clips.csv`` (for :func:`.groups.independent_groups`; ``None``: each subset one group)
    sweep : DataFrame or None, the budget sweep table (:func:`animsynth.compare.tables.sweep_table`): quoted as
        evidence in the claims against the peer (decided at the default budget)
    claims : the declared claims (``compare.claims``; ``None``: :data:`DEFAULT_CLAIMS`); every one gets a row
        (a claim on a generator that did not run: "not reproduced", saying why)
    seed : the seed of the random sign flips (more than :data:`EXACT_MAX` groups; ``compare.seed``)
    """
    groups = clip_groups(metrics, clips, vc)
    specs = list(DEFAULT_CLAIMS if claims is None else claims)
    cs = [_Claim(dict(s), metrics, groups, vc, data, left_out or {}, seed, sweep) for s in specs]
    ps = [c.p for c in cs]
    adj = V.holm(ps)
    m = int(np.sum(np.isfinite(ps)))
    rows = [c.row(float(a), m) for c, a in zip(cs, adj)]
    stats = pd.DataFrame([c.stats_row(float(a)) for c, a in zip(cs, adj)], columns=list(STATS_COLUMNS))
    return V.table(rows), stats


def build_verdicts(metrics: pd.DataFrame, vc: dict, data: str, left_out: dict | None = None,
                   clips: pd.DataFrame | None = None, sweep: pd.DataFrame | None = None, claims=None,
                   seed: int = 0) -> pd.DataFrame:
    """The findings of the comparison: the verdict table of :func:`decide_claims` (same parameters)."""
    return decide_claims(metrics, vc, data, left_out, clips, sweep, claims, seed)[0]


def exploratory_table(metrics: pd.DataFrame, vc: dict, clips: pd.DataFrame | None = None, claims=None,
                      order=None, seed: int = 0) -> pd.DataFrame:
    """Every pair of generators on the main metrics that no declared claim tests: numbers, no verdict.

    Parameters
    ----------
    metrics : DataFrame, ``compare/metrics.csv``
    vc : ``compare.verdicts`` (``min_effect`` per metric: the groups' votes; ``permutations``)
    clips : ``compare/clips.csv`` (the groups)
    claims : the declared claims (``None``: :data:`DEFAULT_CLAIMS`): their pairs and metrics are left out (and their
        metrics join :data:`EXPLORATORY_METRICS`)
    order : the generators' order (``a`` is the earlier of a pair; default the table's order)
    seed : the random flips' seed

    Returns
    -------
    DataFrame with :data:`EXPLORATORY_COLUMNS`: ``label`` "exploratory", the pair (effect positive favours ``a``
    in the metric's direction), the groups, the groups holding / opposite by the metric's minimum effect, the mean
    effect with its 95 % t interval, the sign-flip p and a Holm p over this table alone. Never a verdict.
    """
    groups = clip_groups(metrics, clips, vc)
    specs = list(DEFAULT_CLAIMS if claims is None else claims)
    present = list(dict.fromkeys(metrics["generator"]))
    gens = [g for g in (order or present) if g in set(present)]
    declared = set()
    for s in specs:
        bs = [g for g in gens if g not in REFERENCES and g != s["a"]] if s["b"] == EVERY else [s["b"]]
        if s["b"] == EVERY and skating_claim(s):  # a floating generator is no part of the claim: exploratory
            bs = [g for g in bs if not floating_reason(metrics, g, vc)]
        declared |= {(frozenset((s["a"], b)), s["metric"]) for b in bs}
    mets = list(dict.fromkeys([*EXPLORATORY_METRICS, *(s["metric"] for s in specs)]))
    rows = []
    for metric in mets:
        better = metric_or_blank(metric).better or next((s["direction"] for s in specs if s["metric"] == metric), "")
        if metric not in metrics or better not in ("lower", "higher"):
            continue
        me = float(vc.get("min_effect", {}).get(metric, 0.0))
        for i, a in enumerate(gens):
            for b in gens[i + 1:]:
                if (frozenset((a, b)), metric) in declared:
                    continue
                j = pair_outcomes(metrics, a, b, metric, better)
                if not len(j):
                    continue
                st = Stats(j, groups, me, vc, seed, subjects=False)
                rows.append({"label": "exploratory", "a": a, "b": b, "metric": metric, "direction": better,
                             "n_groups": st.n, "groups_holding": st.holding, "groups_opposite": st.opposite,
                             "mean_effect": st.mean, "ci_low": st.lo, "ci_high": st.hi, "p": st.p, "min_effect": me})
    out = pd.DataFrame(rows, columns=[c for c in EXPLORATORY_COLUMNS if c != "p_holm"])
    out.insert(out.columns.get_loc("p") + 1, "p_holm", V.holm(out["p"]) if len(out) else [])
    return out


def _copy_claim(metrics, groups, vc, data, seed):
    claim = "re-sequencers copy database frames (novelty ~ 0) while field followers synthesise new poses"
    copiers = [g for g in ("isomap", "stisomap") if g in set(metrics["generator"])]
    makers = [g for g in ("delaunay", "knn") if g in set(metrics["generator"])]
    tol = float(vc["novelty_copy_m"])
    if not copiers or not makers:
        return None, V.row(claim, "not reproduced", "no pair to compare (a re-sequencer or a field follower did not "
                           "run)", data=data, source="compare/metrics.csv")
    wide = metrics[metrics["generator"].isin(copiers + makers)].pivot_table(
        index=["clip", "seed"], columns="generator", values="novelty_median_m", aggfunc="first").dropna()
    # effect: how far the nearest field follower lies beyond the farthest re-sequencer (m)
    eff = wide[makers].min(axis=1) - wide[copiers].max(axis=1)
    ok = (wide[copiers].max(axis=1) <= tol) & (wide[makers].min(axis=1) > tol)
    j = pd.DataFrame({"clip": [c for c, _s in wide.index], "effect": np.where(ok, np.abs(eff), -np.abs(eff)),
                      "outcome": np.where(ok.to_numpy(), 1, -1)})
    me = float(vc["min_effect"].get("novelty_median_m", 0.0))
    ours = "; ".join(f"{g} novelty median {spread(metrics, g, 'novelty_median_m')} m" for g in copiers + makers)
    lead = f"every re-sequencer at most {V.fmt(tol)} m from the database and every field follower farther"
    if not len(j):
        return None, V.row(claim, "not reproduced", "no pair to compare (no clip with every novelty value)", data=data,
                           source="compare/metrics.csv")
    return Stats(j, groups, me, vc, seed), (claim, ours, lead, me, "novelty_median_m")


def sanity_checks(metrics: pd.DataFrame, vc: dict, data: str, left_out: dict | None = None,
                  clips: pd.DataFrame | None = None, seed: int = 0) -> pd.DataFrame:
    """Claims true by construction, decided by the same rules (:func:`decide`; the metric's
    ``compare.verdicts.min_effect``; Holm over the sanity checks alone): not findings."""
    groups = clip_groups(metrics, clips, vc)
    configured = set(metrics["generator"]) | set(left_out or {})
    present = set(metrics["generator"])
    tests = []  # (stats or None, (claim, ours, lead, min effect, metric) or a finished row)
    if {"isomap", "stisomap", "delaunay", "knn"} & configured:
        tests.append(_copy_claim(metrics, groups, vc, data, seed))
    if {"motion_graph", "concat"} <= configured:
        claim = ("the motion graph's blended transitions jump less than random concatenation's unblended seams "
                 "(95th percentile of the per-frame velocity jump)")
        gone = [g for g in ("motion_graph", "concat") if g not in present]
        j = pd.DataFrame() if gone else pair_outcomes(metrics, "motion_graph", "concat", "velocity_jump_p95")
        me = float(vc["min_effect"].get("velocity_jump_p95", 0.0))
        if gone or not len(j):
            why = "; ".join(f"{g}: {(left_out or {}).get(g, 'not in this run')}" for g in gone) or "no shared value"
            tests.append((None, V.row(claim, "not reproduced", f"no pair to compare ({why})", data=data,
                                      source="compare/metrics.csv")))
        else:
            ours = (f"velocity_jump_p95 (m/s) median motion_graph {spread(metrics, 'motion_graph', 'velocity_jump_p95')}"
                    f" vs concat {spread(metrics, 'concat', 'velocity_jump_p95')}")
            tests.append((Stats(j, groups, me, vc, seed),
                          (claim, ours, "motion_graph lower than concat on velocity_jump_p95", me, "velocity_jump_p95")))
    ps = [st.p if st is not None else np.nan for st, _x in tests]
    adj = V.holm(ps)
    m = int(np.sum(np.isfinite(ps)))
    rows = []
    for (st, x), pa in zip(tests, adj):
        if st is None:
            rows.append(x)
            continue
        claim, ours, lead, me, metric = x
        word, why = decide(st, float(pa), me, vc)
        unit = metric_or_blank(metric).unit
        rows.append(V.row(claim, word, f"tested: {lead}; {word} because {why}. {st.n} independent "
                          f"{_units(vc, st.n)}: {st.numbers(unit)}, Holm-adjusted over the {m} sanity checks p = "
                          f"{V.fmt(pa, 3)}; holds in {st.holding}, opposite in {st.opposite} (minimum effect "
                          f"{V.fmt(me)} {unit})", ours=ours, data=data, source="compare/metrics.csv"))
    return V.table(rows)
