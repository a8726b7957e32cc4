"""The side-by-side claims, declared in advance and decided over independent subjects, in the common verdict format
(:mod:`animsynth.verdicts`); the full rule, with its reasons, is docs/compare/verdicts.md.

Declared claims
---------------
The findings are the claims of ``compare.claims`` (config/config.yaml alone; read by
:func:`animsynth.compare.claims.declared_claims`, checked at config time by
:func:`animsynth.compare.claims.check_claims`): generators ``a`` and ``b`` (``b: "*"``: every generator of the run
but the references, one intersection-union finding), a ``metric``, a ``direction`` and a margin (the claim's
``min_effect``, else the metric's margin: :func:`animsynth.compare.claims.margin`). Holm's correction runs over them
alone. Every other pair on the main metrics is **exploratory** (:func:`exploratory_table`): numbers, no verdict.
Claims true by construction are **sanity checks** (:func:`sanity_checks`): the same rule, Holm among themselves.

Units, effects, tests (:mod:`animsynth.compare.claim_stats`)
-------------------------------------------------------------
The unit is the independent group of clips, by default the subject (:mod:`animsynth.compare.groups`). A group's
effect is the median over its clips of each clip's median over seeds of ``a - b``, signed so that positive favours
the claim. Over the groups: the mean effect, its 95 % and 90 % t intervals, an exact sign-flip permutation p (Holm
over the declared claims) and the subjects 80 % power would need at the observed effect; per subject, a sign test
of its clips (Holm over the subjects) for a significant split. Subjects on a generic figure (``figure: generic`` in
``compare/clips.csv``) leave every test; each claim's evidence gives its numbers with them included. A skating claim
compares only the clips on which both generators' feet touch the floor (their median ``contact_share`` over the
clip's seeds at least ``compare.verdicts.min_contact_share``); the clips left out are counted in its evidence.

The verdict
-----------
:func:`animsynth.verdicts.effect_verdict`, in this order: ``did not run`` (a generator of the claim has no value on
any clip), ``reproduced``, ``contradicted``, ``no material difference`` (the 90 % interval inside plus or minus the
margin), ``partly`` (a significant split), otherwise ``undecided (n subjects)``. The capture claim holds only if it
holds against each generator: its p is the largest of its parts' (intersection-union), its effect the weakest part's;
when some parts lean the other way by the margin it is tested for a contradiction instead (the smallest p of those
parts times the number of parts, Bonferroni). It is equivalent only when every part's 90 % interval lies inside the
margins.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import verdicts as V
from .claim_stats import (EXACT_MAX, Stats, few_clips, few_clips_text, generic_clips, metric_median, metric_wide,
                          no_values, pair_from_wide, pair_outcomes, per_clip, spread, touching)
from .claims import EVERY, declared_claims, margin
from .groups import GROUPINGS, clip_groups
from .generators.names import REFERENCES
from .measures.metric_table import EXPLORATORY_METRICS, SKATING_CLAIM_METRICS, metric_or_blank

__all__ = ["decide", "decide_claims", "build_verdicts", "exploratory_table", "sanity_checks", "skating_claim",
           "STATS_COLUMNS", "EXPLORATORY_COLUMNS"]

#: the columns of ``claims_stats.csv``
STATS_COLUMNS = ("claim_id", "a", "b", "metric", "direction", "n_groups", "mean_effect", "ci_low", "ci_high",
                 "ci90_low", "ci90_high", "p", "p_holm", "margin", "subjects_for_80_power", "verdict",
                 "a_contact_share", "b_contact_share")
#: the columns of ``exploratory.csv``
EXPLORATORY_COLUMNS = ("label", "a", "b", "metric", "direction", "n_groups", "groups_holding", "groups_opposite",
                       "mean_effect", "ci_low", "ci_high", "p", "p_holm", "margin")


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




def _units(vc: dict, n: int | None = None) -> str:
    word = "subject" if vc.get("grouping", "subject") == "subject" else "group"
    return word + ("s" if n is None or n != 1 else "")


def decide(st: Stats, p_holm: float, margin: float, vc: dict, ci90: tuple | None = None) -> tuple[str, str]:
    """The verdict of a tested comparison and its reason: :func:`animsynth.verdicts.effect_verdict` on its
    statistics.

    Parameters
    ----------
    st : the comparison's statistics (for the capture claim: its deciding part's)
    p_holm : its Holm-adjusted p
    margin : its margin (metric units)
    vc : ``compare.verdicts`` (``alpha``, ``min_groups``, ``permutations``, ``grouping``)
    ci90 : the 90 % interval that decides equivalence (default ``st``'s; the capture claim: the envelope of its
        parts')

    Returns
    -------
    (verdict, reason): a word of :data:`animsynth.verdicts.VOCABULARY` and why, in words.
    """
    word, why = V.effect_verdict(n=st.n, mean=st.mean, p_holm=p_holm, ci90=ci90 or (st.lo90, st.hi90),
                                 margin=float(margin), alpha=float(vc["alpha"]), min_units=int(vc.get("min_groups", 3)),
                                 split=st.split, units=_units(vc))
    n_for, n_against = st.split
    if word == "partly":
        why += " (per-subject sign tests over clips, Holm over the subjects)"
    elif word == "no material difference" and n_for and n_against:  # the mean is equivalent, the subjects are not
        why += (f"; but the {_units(vc)} split: {n_for} significantly for and {n_against} significantly against "
                "(per-subject sign tests over clips, Holm over the subjects)")
    if word == "undecided" and st.n:
        floor = 2.0 / 2 ** st.n if st.n <= EXACT_MAX else 1.0 / (1 + int(vc.get("permutations", 100000)))
        why += (f" (with {st.n} {_units(vc, st.n)} the smallest possible p is {V.fmt(floor, 3)}; 80 % power at the "
                f"observed effect would need {st.power or 'an estimate from at least 2'} {_units(vc)}, before Holm's "
                "correction: a lower bound)")
    return word, why


def skating_claim(spec: dict) -> bool:
    """Whether a declared claim is a skating claim (its contact shares shown beside it; it compares only clips on
    which both generators' feet touch the floor): its ``skating`` key when given, else its metric's record in the
    metric table (:data:`animsynth.compare.measures.metric_table.SKATING_CLAIM_METRICS`)."""
    return spec["metric"] in SKATING_CLAIM_METRICS if spec.get("skating") is None else bool(spec["skating"])


def _stats(metrics, groups, a, b, metric, better, margin, vc, seed, skating) -> tuple:
    """(Stats or None, {generator: clips left out because its feet do not touch}, why there is no Stats)."""
    j = pair_outcomes(metrics, a, b, metric, better)
    dropped: dict = {}
    if skating and len(j):
        kept, dropped = touching(metrics, (a, b), float(vc.get("min_contact_share", 0.05)))
        j = j[j["clip"].isin(kept)]
        if not len(j):
            return None, dropped, (f"no clip on which both {a}'s and {b}'s feet touch the floor (median contact_share "
                                   f"over the clip's seeds at least compare.verdicts.min_contact_share "
                                   f"{V.fmt(vc.get('min_contact_share', 0.05))})")
    if not len(j):
        return None, dropped, f"no clip x seed with a {metric} value for both {a} and {b}"
    return Stats(j, groups, margin, vc, seed), dropped, ""


class _Claim:
    """One declared claim: its statistics (or why it has none) and how to write its row once Holm has run."""

    def __init__(self, spec: dict, metrics: pd.DataFrame, groups: dict, vc: dict, data: str, left_out: dict,
                 seed: int, sweep=None, generic=frozenset(), source: str = "compare/metrics.csv"):
        self.spec, self.data, self.vc, self.groups, self.seed = spec, data, vc, groups, seed
        self.source = source
        self.a, self.b, self.metric = spec["a"], spec["b"], spec["metric"]
        if spec["margin"] is None or not spec["direction"]:
            raise ValueError(f"claim {spec['id']!r}: metric {self.metric!r} needs a margin (min_effect) and a direction "
                             "(animsynth.compare.claims.check_claims refuses such a claim at config time)")
        self.better, self.me = spec["direction"], float(spec["margin"])
        self.skating = skating_claim(spec)
        self.missing, self.empty, self.st, self.all_st = "", "", None, None
        self.parts, self.left, self.dropped, self.mode = [], [], {}, "claim"
        self.metrics, self.sweep, self.generic = metrics, sweep, set(generic)
        self.main = metrics[~metrics["clip"].isin(self.generic)] if self.generic else metrics
        gone = [w for w in (no_values(metrics, g, left_out, self.metric) for g in (self.a, self.b) if g != EVERY) if w]
        if gone:
            self.missing = "; ".join(gone)
        elif self.b == EVERY:
            self._every(left_out)
        else:
            self.st, self.dropped[self.b], self.empty = self._stats(self.main, self.b)
            self.all_st = self._stats(metrics, self.b)[0] if self.generic else None

    def _stats(self, metrics, b):
        return _stats(metrics, self.groups, self.a, b, self.metric, self.better, self.me, self.vc, self.seed,
                      self.skating)

    def _every(self, left_out):
        """The capture claim: one part per generator that ran (and, on skating, touches the floor somewhere)."""
        for g in dict.fromkeys([*self.metrics["generator"], *(left_out or {})]):
            if g in REFERENCES or g == self.a:
                continue
            why = no_values(self.metrics, g, left_out, self.metric)
            st, dropped, empty = (None, {}, "") if why else self._stats(self.main, g)
            if st is None:
                self.left.append(why or f"{g} left out: {empty}")
                continue
            self.parts.append((g, st))
            self.dropped[g] = dropped
        if not self.parts:
            self.empty = "no generator to compare with" + (f" ({'; '.join(self.left)})" if self.left else "")
            return
        # One significant opposite part refutes "less than every generator": when some parts lean the other way
        # by the margin, the claim is tested for a contradiction (union-intersection: the smallest p of those
        # parts times the number of parts, Bonferroni); otherwise for the claim (intersection-union: the largest
        # p), the weakest part (smallest mean effect) carrying the claim's effect.
        opposite = [(g, s) for g, s in self.parts if s.mean <= -self.me]
        self.mode = "contradiction" if opposite else "claim"
        g, self.st = (min(opposite, key=lambda x: (x[1].p, x[1].mean)) if opposite else
                      min(self.parts, key=lambda x: (x[1].mean, -x[1].p)))
        self.all_st = self._stats(self.metrics, g)[0] if self.generic else None

    @property
    def p(self) -> float:
        """The claim's p for Holm: NaN when it has no test; the capture claim's by its mode (see :meth:`_every`)."""
        if self.st is None:
            return float("nan")
        if self.parts:
            if self.mode == "contradiction":
                return float(min(1.0, len(self.parts) * self.st.p))
            ps = np.array([s.p for _g, s in self.parts], float)
            return float(ps.max()) if np.all(np.isfinite(ps)) else float("nan")
        return self.st.p

    def ci90(self) -> tuple[float, float]:
        """The 90 % interval that decides equivalence: the claim's; the capture claim's parts' envelope."""
        if self.parts:
            return (min(s.lo90 for _g, s in self.parts), max(s.hi90 for _g, s in self.parts))
        return self.st.lo90, self.st.hi90

    def verdict(self, p_holm: float) -> tuple[str, str]:
        if self.missing:
            return V.word("did_not_run"), self.missing
        if self.st is None:
            return V.word("none"), self.empty
        return decide(self.st, p_holm, self.me, self.vc, self.ci90())

    def contact(self, g: str) -> float:
        return metric_median(self.metrics, g, "contact_share")

    def stats_row(self, p_holm: float) -> dict:
        word, _why = self.verdict(p_holm)
        st = self.st
        lo90, hi90 = self.ci90() if st is not None else (np.nan, np.nan)
        row = {"claim_id": self.spec["id"], "a": self.a, "b": "every generator" if self.b == EVERY else self.b,
               "metric": self.metric, "direction": self.better, "n_groups": st.n if st else 0,
               "mean_effect": st.mean if st else np.nan, "ci_low": st.lo if st else np.nan,
               "ci_high": st.hi if st else np.nan, "ci90_low": lo90, "ci90_high": hi90, "p": self.p, "p_holm": p_holm,
               "margin": self.me, "subjects_for_80_power": st.power if st else "", "verdict": word,
               "a_contact_share": np.nan, "b_contact_share": np.nan}
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
        if word == "undecided":
            text += (f", {_units(vc)} for 80 % power at this effect (t test at alpha, before Holm: a lower bound): "
                     f"{st.power or 'no estimate'}")
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

    def _guard_text(self) -> str:
        """The clips a skating claim left out because a generator's feet do not touch (and the subjects gone)."""
        if not self.skating:
            return ""
        floor = V.fmt(self.vc.get("min_contact_share", 0.05))
        parts = [f"{len(cs)} clip{'s' if len(cs) != 1 else ''} of {g}" for d in self.dropped.values()
                 for g, cs in d.items()]
        clips = {c for d in self.dropped.values() for cs in d.values() for c in cs}
        return (f"; skating compared only on clips where both generators' feet touch the floor (median contact_share "
                f"over the clip's seeds at least compare.verdicts.min_contact_share {floor}): "
                + (f"{len(clips)} clip{'s' if len(clips) != 1 else ''} left out ({', '.join(parts)}: "
                   f"{', '.join(sorted(clips))})" if clips else "no clip left out"))

    def _generic_text(self, unit: str) -> str:
        """The sensitivity line: the claim's numbers with the generic-figure subjects included."""
        if not self.generic:
            return ""
        n = self.metrics.loc[self.metrics["clip"].isin(self.generic), "clip"].nunique()
        head = f"; sensitivity, with the {n} clips of subjects on a generic figure included (left out above)"
        if self.all_st is None:
            return head + ": no comparison"
        s = self.all_st
        return (f"{head}: {s.n} {_units(self.vc, s.n)}, {s.numbers(unit)} (not Holm-adjusted), 90 % t interval "
                f"{V.fmt(s.lo90)} to {V.fmt(s.hi90)}")

    def row(self, p_holm: float, m: int) -> dict:
        spec, vc = self.spec, self.vc
        word, why = self.verdict(p_holm)
        lead = (f"tested: {self.a} {self.better} than "
                f"{'every generator' if self.b == EVERY else self.b} on {self.metric}; ")
        if self.st is None:
            return V.row(spec["claim"], word, f"{lead}{word} because {why}", paper_value=spec.get("paper_value", ""),
                         ours=f"{word} (0 {_units(vc)})" if word == "undecided" else word, data=self.data,
                         source=self.source)
        st = self.st
        unit = metric_or_blank(self.metric).unit
        grouping = GROUPINGS[vc.get("grouping", "subject")]
        src = "the claim's min_effect" if spec.get("min_effect") is not None else "the metric's margin"
        text = f"{lead}{word} because {why}. "
        test = (f"exact sign-flip permutation test of the mean of the {_units(vc)}' effects (all 2^n flips up to "
                f"n = {EXACT_MAX}, else {int(vc.get('permutations', 100000))} seeded random flips; two-sided), Holm "
                f"over the {m} declared claims with a test; 95 % t interval over the {_units(vc)} (the size of the "
                f"effect); equivalence: the 90 % t interval inside plus or minus the margin (two one-sided tests at "
                f"5 %); margin {V.fmt(self.me)} {unit} ({src}); independent {_units(vc)}: {grouping}")
        if self.b == EVERY:
            parts = "; ".join(f"{g}: {s.holding}/{s.opposite}/{s.n - s.holding - s.opposite}, {s.numbers()}"
                              for g, s in self.parts)
            if self.mode == "contradiction":
                text += (f"Tested for a contradiction: {sum(s.mean <= -self.me for _g, s in self.parts)} of the "
                         f"{len(self.parts)} generators compared lean the other way by the margin, and one "
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
            text += f"; 90 % t intervals' envelope {V.fmt(self.ci90()[0])} to {V.fmt(self.ci90()[1])}"
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
                     f"{V.fmt(p_holm, 3)}, 90 % t interval {V.fmt(st.lo90)} to {V.fmt(st.hi90)}, {_units(vc)} for "
                     f"80 % power at this effect (before Holm): {st.power or 'no estimate'}; {test}; holds in {st.holding}, "
                     f"opposite in {st.opposite}, neither in {st.n - st.holding - st.opposite}; per group (clips "
                     f"holding / untied clips, median effect): {groups}; per-subject sign tests (clips for / untied "
                     f"clips): {subj}; counted by clips instead: {ch} of {ch + cf} untied clips")
        text += self._guard_text() + self._generic_text(unit)
        if spec.get("note"):
            text += "; " + spec["note"]
        if self.sweep is not None and len(self.sweep) and self.a == "motion_graph":
            if self.b == "fairmotion":
                text += "; the budget sweep runs the fixed row (the released row builds the same graph)"
            elif ev := _sweep_evidence(self.sweep, self.a, self.b, self.metric):
                text += "; " + ev
        return V.row(spec["claim"], word, text, paper_value=spec.get("paper_value", ""),
                     ours=self._ours(word, p_holm), data=self.data, source=self.source)


def decide_claims(metrics: pd.DataFrame, vc: dict, data: str, left_out: dict | None = None,
                  clips: pd.DataFrame | None = None, sweep: pd.DataFrame | None = None, *, claims,
                  seed: int = 0, source: str = "compare/metrics.csv") -> tuple[pd.DataFrame, pd.DataFrame]:
    """The declared claims decided: the verdict table and ``claims_stats.csv`` (:data:`STATS_COLUMNS`).

    Parameters
    ----------
    metrics : DataFrame, ``compare/metrics.csv``
    vc : the ``compare.verdicts`` block (``alpha``, ``min_groups``, ``grouping``, ``min_contact_share``,
        ``permutations``, ``min_effect``)
    data : what the numbers ran on (e.g. "CMU: 19 held-out clips x 5 seeds")
    left_out : {generator: why it did not run}
    clips : DataFrame, ``compare/clips.csv`` (the groups, :func:`.groups.independent_groups`, and the ``figure``
        column; ``None``: each subset one group, every subject on its own skeleton)
    sweep : DataFrame or None, the budget sweep table (:func:`animsynth.compare.tables.sweep_table`): quoted as
        evidence in the claims against the peer (decided at the default budget)
    claims : the declared claims (``compare.claims`` of the config); every one gets a row, and Holm's correction
        runs over them (one track's claims: :func:`animsynth.compare.claims.track_claims`)
    seed : the seed of the random sign flips (more than :data:`EXACT_MAX` groups; ``compare.seed``)
    source : the table the claims read (``compare/metrics_long.csv`` for the long track), the rows' ``source``
    """
    few, few_subjects = few_clips(clips)
    metrics = metrics[~metrics["clip"].isin(few)]  # subjects below the minimum of clips are no unit of the tests
    data = data + few_clips_text(few_subjects)
    groups = clip_groups(metrics, clips, vc)
    specs = declared_claims({"claims": claims, "verdicts": vc})
    generic = generic_clips(clips)
    cs = [_Claim(s, metrics, groups, vc, data, left_out or {}, seed, sweep, generic, source) for s in specs]
    ps = [c.p for c in cs]
    adj = V.holm(ps)
    m = int(np.sum(np.isfinite(ps)))
    rows = [c.row(float(a), m) for c, a in zip(cs, adj)]
    stats = pd.DataFrame([c.stats_row(float(a)) for c, a in zip(cs, adj)], columns=list(STATS_COLUMNS))
    return V.table(rows), stats


def build_verdicts(metrics: pd.DataFrame, vc: dict, data: str, left_out: dict | None = None,
                   clips: pd.DataFrame | None = None, sweep: pd.DataFrame | None = None, *, claims,
                   seed: int = 0) -> pd.DataFrame:
    """The findings of the comparison: the verdict table of :func:`decide_claims` (same parameters)."""
    return decide_claims(metrics, vc, data, left_out, clips, sweep, claims=claims, seed=seed)[0]


def _did_not_run(metrics: pd.DataFrame, gens, left_out: dict | None) -> dict:
    """``{generator: why}`` of the generators of ``gens`` (and ``left_out``) with no value of any metric."""
    out = {g: no_values(metrics, g, left_out) for g in dict.fromkeys([*gens, *(left_out or {})])}
    return {g: w for g, w in out.items() if w}


def exploratory_table(metrics: pd.DataFrame, vc: dict, clips: pd.DataFrame | None = None, *, claims, order=None,
                      seed: int = 0, left_out: dict | None = None) -> pd.DataFrame:
    """Every pair of generators on the main metrics that no declared claim tests: numbers, no verdict.

    Parameters
    ----------
    metrics : DataFrame, ``compare/metrics.csv``
    vc : ``compare.verdicts`` (the margins' overrides ``min_effect``: the groups' votes; ``permutations``)
    clips : ``compare/clips.csv`` (the groups; subjects on a generic figure left out)
    claims : the declared claims (``compare.claims``): their pairs and metrics are left out (and their metrics join
        :data:`EXPLORATORY_METRICS`)
    order : the generators' order (``a`` is the earlier of a pair; default the table's order)
    seed : the random flips' seed
    left_out : {generator: why it did not run}

    Returns
    -------
    DataFrame with :data:`EXPLORATORY_COLUMNS`: ``label`` "exploratory", the pair (effect positive favours ``a``
    in the metric's direction), the groups, the groups holding / opposite by the metric's margin
    (:func:`animsynth.compare.claims.margin`), the mean effect with its 95 % t interval, the sign-flip p and a Holm p
    over this table alone; then one row labelled "did not run" per generator without any value (``a``). Never a
    verdict.
    """
    groups = clip_groups(metrics, clips, vc)
    main = metrics[~metrics["clip"].isin(generic_clips(clips) | few_clips(clips)[0])]
    specs = declared_claims({"claims": claims, "verdicts": vc})
    present = list(dict.fromkeys(metrics["generator"]))
    ran = [g for g in (order or present) if g in set(present)]
    gone = _did_not_run(metrics, ran, left_out)
    gens = [g for g in ran if g not in gone]
    declared = set()
    floor = float(vc.get("min_contact_share", 0.05))
    for s in specs:
        bs = [g for g in gens if g not in REFERENCES and g != s["a"]] if s["b"] == EVERY else [s["b"]]
        if s["b"] == EVERY and skating_claim(s):  # a generator whose feet touch on no clip is no part of it
            bs = [g for g in bs if touching(main, (s["a"], g), floor)[0]]
        declared |= {(frozenset((s["a"], b)), s["metric"]) for b in bs}
    mets = list(dict.fromkeys([*EXPLORATORY_METRICS, *(s["metric"] for s in specs)]))
    rows = []
    for metric in mets:
        better = metric_or_blank(metric).better or next((s["direction"] for s in specs if s["metric"] == metric), "")
        if metric not in metrics or better not in ("lower", "higher"):
            continue
        me = margin(metric, vc) or 0.0
        wide = metric_wide(main, metric)
        for i, a in enumerate(gens):
            for b in gens[i + 1:]:
                if (frozenset((a, b)), metric) in declared:
                    continue
                j = pair_from_wide(wide, a, b, better)
                if not len(j):
                    continue
                st = Stats(j, groups, me, vc, seed, subjects=False)
                rows.append({"label": "exploratory", "a": a, "b": b, "metric": metric, "direction": better,
                             "n_groups": st.n, "groups_holding": st.holding, "groups_opposite": st.opposite,
                             "mean_effect": st.mean, "ci_low": st.lo, "ci_high": st.hi, "p": st.p, "margin": me})
    cols = [c for c in EXPLORATORY_COLUMNS if c != "p_holm"]
    out = pd.DataFrame(rows, columns=cols)
    out.insert(out.columns.get_loc("p") + 1, "p_holm", V.holm(out["p"]) if len(out) else [])
    if gone:
        dnr = pd.DataFrame([{"label": "did not run", "a": g, "b": "", "metric": "", "direction": "", "n_groups": 0}
                            for g in gone], columns=list(EXPLORATORY_COLUMNS))
        out = pd.concat([out, dnr], ignore_index=True) if len(out) else dnr
    return out


def _copy_test(metrics, groups, vc, seed, left_out):
    """The copy claim's statistics: (Stats, ours, lead, margin, metric), or (None, why) when it cannot be tested."""
    metric = "novelty_median_m"
    why = {g: no_values(metrics, g, left_out, metric) for g in ("isomap", "stisomap", "delaunay", "knn")}
    copiers = [g for g in ("isomap", "stisomap") if g in set(metrics["generator"]) and not why[g]]
    makers = [g for g in ("delaunay", "knn") if g in set(metrics["generator"]) and not why[g]]
    if not copiers or not makers:
        side = "re-sequencer" if not copiers else "field follower"
        reasons = "; ".join(w for w in why.values() if w) or "not in this run"
        return None, ("did_not_run", f"no {side} ran ({reasons})")
    tol = float(vc["novelty_copy_m"])
    wide = metrics[metrics["generator"].isin(copiers + makers)].pivot_table(
        index=["clip", "seed"], columns="generator", values=metric, aggfunc="first").reindex(
        columns=copiers + makers).dropna()
    if not len(wide):
        return None, ("none", "no clip x seed with a novelty value for every re-sequencer and field follower")
    # effect: how far the nearest field follower lies beyond the farthest re-sequencer (m)
    eff = wide[makers].min(axis=1) - wide[copiers].max(axis=1)
    ok = (wide[copiers].max(axis=1) <= tol) & (wide[makers].min(axis=1) > tol)
    j = pd.DataFrame({"clip": [c for c, _s in wide.index], "effect": np.where(ok, np.abs(eff), -np.abs(eff)),
                      "outcome": np.where(ok.to_numpy(), 1, -1)})
    me = margin(metric, vc) or 0.0
    ours = "; ".join(f"{g} novelty median {spread(metrics, g, metric)} m" for g in copiers + makers)
    lead = f"every re-sequencer at most {V.fmt(tol)} m from the database and every field follower farther"
    return Stats(j, groups, me, vc, seed), (ours, lead, me, metric)


def _blend_test(metrics, groups, vc, seed, left_out):
    """The motion graph's blended transitions against random concatenation's seams (velocity_jump_p95)."""
    metric = "velocity_jump_p95"
    gone = [w for w in (no_values(metrics, g, left_out, metric) for g in ("motion_graph", "concat")) if w]
    if gone:
        return None, ("did_not_run", "; ".join(gone))
    j = pair_outcomes(metrics, "motion_graph", "concat", metric)
    if not len(j):
        return None, ("none", "no clip x seed with a value for both")
    me = margin(metric, vc) or 0.0
    ours = (f"{metric} (m/s) median motion_graph {spread(metrics, 'motion_graph', metric)} vs concat "
            f"{spread(metrics, 'concat', metric)}")
    return Stats(j, groups, me, vc, seed), (ours, "motion_graph lower than concat on velocity_jump_p95", me, metric)


#: the sanity checks: (claim, which generators make it testable, its test)
_SANITY = (
    ("re-sequencers copy database frames (novelty ~ 0) while field followers synthesise new poses",
     {"isomap", "stisomap", "delaunay", "knn"}, False, _copy_test),
    ("the motion graph's blended transitions jump less than random concatenation's unblended seams (95th percentile "
     "of the per-frame velocity jump)", {"motion_graph", "concat"}, True, _blend_test),
)


def sanity_checks(metrics: pd.DataFrame, vc: dict, data: str, left_out: dict | None = None,
                  clips: pd.DataFrame | None = None, seed: int = 0) -> pd.DataFrame:
    """Claims true by construction, decided by the same rule (:func:`decide`; the metric's margin,
    :func:`animsynth.compare.claims.margin`; Holm over the sanity checks alone; subjects on a generic figure left
    out): not findings. A check whose generators are not configured has no row; one whose generators did not run
    is ``did not run``."""
    groups = clip_groups(metrics, clips, vc)
    main = metrics[~metrics["clip"].isin(generic_clips(clips) | few_clips(clips)[0])]
    configured = set(metrics["generator"]) | set(left_out or {})
    tests = []
    for claim, gens, need_all, test in _SANITY:
        if (gens <= configured) if need_all else (gens & configured):
            tests.append((claim, *test(main, groups, vc, seed, left_out)))
    ps = [st.p if st is not None else np.nan for _c, st, _x in tests]
    adj = V.holm(ps)
    m = int(np.sum(np.isfinite(ps)))
    rows = []
    for (claim, st, x), pa in zip(tests, adj):
        if st is None:
            w = V.word(x[0])
            rows.append(V.row(claim, w, f"{w}: {x[1]}", data=data, source="compare/metrics.csv"))
            continue
        ours, lead, me, metric = x
        word, why = decide(st, float(pa), me, vc)
        unit = metric_or_blank(metric).unit
        rows.append(V.row(claim, word, f"tested: {lead}; {word} because {why}. {st.n} independent "
                          f"{_units(vc, st.n)}: {st.numbers(unit)}, Holm-adjusted over the {m} sanity checks p = "
                          f"{V.fmt(pa, 3)}; holds in {st.holding}, opposite in {st.opposite} (margin "
                          f"{V.fmt(me)} {unit})", ours=ours, data=data, source="compare/metrics.csv"))
    return V.table(rows)
