"""The side-by-side claims, decided over independent groups of clips, in the common verdict format
(:mod:`animsynth.verdicts`).

Independent units
-----------------
Clips are not independent: the leave-one-out clips of a subset share most of their database trials and the
subject, and a re-sequencing clip may be a trial that a subset's clips use. The unit of every test is the
**group** (:func:`independent_groups`, ``compare.verdicts.grouping``):

* ``subject`` (default): every clip of one subject (the CMU subject id of its held-out trial), joined with every
  other group with which it shares a trial (held out or in a database): clips that share a subject or database
  trials are one group. On the CMU protocol: subject 35 (w1, r1, run, walk), 16 (w2), 127 (r2), 05 (dance):
  4 groups for 19 clips.
* ``subset_subject``: the clips of one subset (or re-sequencing dataset) and one subject, joined where they
  share a trial: w1, w2, r1 + run (trial 35_17), r2, walk, dance: 6 groups. It counts the subsets of one
  subject as independent, which they are not for a claim about people's motion; kept as an option.

A clip without a subject id (not a CMU trial name) is grouped by its subset.

Inside a group, seeds vote inside each clip (its outcome is the majority of its seeds; seed ``i`` is the same
seed for every generator) and clips vote inside the group. The group's **effect** is the median over its clips
of each clip's median difference over seeds (``a - b``, signed so that positive favours the claim), in the
metric's units. A group **holds** when more of its clips hold than not and its effect is at least the
metric's minimum effect (``compare.verdicts.min_effect``); it holds the **opposite** for the reverse; otherwise
it is within noise (no vote).

The verdict of a claim
----------------------
By the common rule for "A beats B over units" (:func:`animsynth.verdicts.a_beats_b`, the groups the units):

* ``reproduced`` -- at least ``compare.verdicts.share`` of the groups hold (a group within noise does not),
  there are at least ``compare.verdicts.min_groups`` groups, and a one-sample t-test of the group effects against zero gives
  a Holm-adjusted p below ``compare.verdicts.alpha`` (Holm over every finding of the family: the claims of
  :func:`build_verdicts`, not the sanity checks; the capture bound over every generator is one finding, an
  intersection-union test whose p is the largest of its parts');
* ``contradicted`` -- the same for the opposite;
* ``partly`` -- neither, but some groups hold and others hold the opposite;
* ``within noise`` -- anything else (the evidence gives the group counts, the effects and both p);
* ``not reproduced`` -- no pair can be compared (a generator did not run: the evidence says why).

A t-test of group effects rather than a sign test over groups: with 6 groups the smallest two-sided sign-test p
is 2 / 2^6 = 0.031, which no Holm correction over several claims can pass, whatever the effect.

Claims true by construction (re-sequencers copy database frames, so their novelty is 0; random concatenation
is unblended, so a blended transition jumps less) are **sanity checks** (:func:`sanity_checks`): decided the
same way, written to their own table and not counted among the findings or in the Holm correction.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from .. import verdicts as V
from .generators import REFERENCES
from .metrics import METRICS

__all__ = ["independent_groups", "group_outcomes", "decide_groups", "pair_outcomes", "per_clip", "build_verdicts",
           "sanity_checks"]

_UNITS = {m: u for m, u, _b in METRICS}
_TRIAL = re.compile(r"\d+_\d+")
#: how the evidence names each grouping (``compare.verdicts.grouping``)
GROUPINGS = {
    "subject": "subject, joined where clips share a trial (held out or in a database)",
    "subset_subject": ("subset (or re-sequencing dataset) x subject, joined where clips share a trial (held out or "
                       "in a database)"),
}


def independent_groups(clips: pd.DataFrame, by: str = "subject") -> dict:
    """``{clip: group label}`` from the clips table (``clip``, ``group``, ``held_out``, ``database``).

    A clip's trials are its held-out trial and its database trials (CMU ids ``<subject>_<trial>`` found in the
    clip id and the ``held_out`` and ``database`` columns; other names: the clip's trial and the database's
    names); its subject is the held-out trial's subject (the text before ``_``; none for other names, so the
    subset alone makes the group). ``by="subject"``: the clips of one subject form a group (a clip without a
    subject: its subset); ``by="subset_subject"``: the clips of one subset and subject. Groups sharing a trial
    are joined. The label names the subsets / datasets joined (``r1 + run``) and, when one subset holds several
    groups, the subject; by subject, ``subject 35 (w1, r1, run, walk)``.
    """
    if by not in GROUPINGS:
        raise ValueError(f"config key 'compare.verdicts.grouping': {by!r} is not one of {list(GROUPINGS)}")
    rows = list(clips.itertuples(index=False))
    trials, base = {}, {}
    for r in rows:
        own = str(r.clip).split("/", 1)[-1]
        text = f"{own} {r.held_out} {r.database}"
        ts = set(_TRIAL.findall(text))
        if not ts:  # not CMU ids: the clip's trial and the database's names (without a temporal split's range)
            ts = {own} | {t for t in str(r.database).split() if t != "frames" and not re.fullmatch(r"\d+-\d+", t)}
        trials[r.clip] = ts
        held = _TRIAL.findall(own) or _TRIAL.findall(str(r.held_out))
        subject = held[0].split("_")[0] if held else ""  # no subject id: the subset is the group
        base[r.clip] = ("", subject) if by == "subject" and subject else (str(r.group), subject)
    parent = {k: k for k in set(base.values())}

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    owner = {}
    for r in rows:
        for t in trials[r.clip]:
            if t in owner:
                parent[find(base[r.clip])] = find(owner[t])
            else:
                owner[t] = base[r.clip]
    members = {}
    for r in rows:
        members.setdefault(find(base[r.clip]), []).append(base[r.clip])
    per_subset = {}
    for g, s in set(base.values()):
        per_subset[g] = per_subset.get(g, 0) + 1
    labels = {}
    subsets = {}
    for r in rows:
        subsets.setdefault(find(base[r.clip]), []).append(str(r.group))
    for root, keys in members.items():
        keys = list(dict.fromkeys(keys))
        if by == "subject" and any(not g for g, _s in keys):
            subj = " + ".join(dict.fromkeys(f"subject {s}" for g, s in keys if not g))
            others = [g for g, _s in keys if g]
            labels[root] = f"{subj} ({', '.join(dict.fromkeys(subsets[root] + others))})"
            continue
        parts = [g if per_subset[g] == 1 else f"{g} subject {s}" for g, s in keys]
        labels[root] = " + ".join(dict.fromkeys(parts))
    return {r.clip: labels[find(base[r.clip])] for r in rows}


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
    out = pd.DataFrame({"seeds_for": g["outcome"].apply(lambda o: int((o > 0).sum())),
                        "seeds_against": g["outcome"].apply(lambda o: int((o < 0).sum()))})
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
    out = pd.DataFrame({"clips": g.size(), "clips_for": g["outcome"].apply(lambda o: int((o > 0).sum())),
                        "clips_against": g["outcome"].apply(lambda o: int((o < 0).sum())),
                        "effect": g["effect"].median()})
    out["vote"] = V.unit_votes(out["clips_for"] - out["clips_against"], out["effect"], min_effect)
    return out


def _t_p(effects: np.ndarray) -> float:
    """Two-sided one-sample t-test of the group effects against 0 (NaN for fewer than 2 groups; 0 when every
    effect is the same non-zero number, 1 when all are 0)."""
    from scipy.stats import ttest_1samp

    e = np.asarray(effects, float)
    e = e[np.isfinite(e)]
    if e.size < 2:
        return float("nan")
    if np.ptp(e) == 0:
        return 0.0 if e[0] != 0 else 1.0
    return float(ttest_1samp(e, 0.0).pvalue)


def decide_groups(per: pd.DataFrame, p_adj: float, vc: dict) -> str:
    """The verdict from the group votes (:func:`group_outcomes`) and the Holm-adjusted p, by the common rule
    :func:`animsynth.verdicts.a_beats_b`: the share is over every group with a value (a group within noise
    counts and does not hold), at least ``min_groups`` groups."""
    n = len(per)
    h, f = int((per["vote"] > 0).sum()), int((per["vote"] < 0).sum())
    outcome = V.a_beats_b(h, f, n - h - f, share=float(vc["share"]), alpha=float(vc["alpha"]), p=p_adj,
                          min_units=int(vc["min_groups"]))
    if outcome == "none":
        return "not reproduced"
    if outcome == "holds":
        return "reproduced"
    if outcome == "opposite":
        return "contradicted"
    if h and f:
        return "partly"
    return "within noise"


def _spread(metrics: pd.DataFrame, g: str, metric: str) -> str:
    x = pd.to_numeric(metrics.loc[metrics["generator"] == g, metric], errors="coerce")
    x = x[np.isfinite(x)].to_numpy(float)
    if not x.size:
        return "no value"
    q = np.percentile(x, [25, 50, 75])
    return f"{V.fmt(q[1])} (IQR {V.fmt(q[0])}-{V.fmt(q[2])})"


class _Claim:
    """One claim under test: its per-group outcomes, raw p, and how to write its row once Holm has run."""

    def __init__(self, claim, data, *, paper_value="", ours="", missing="", per=None, j=None, metric="",
                 min_effect=np.nan, lead="", caveat=""):
        self.claim, self.data, self.paper_value, self.ours = claim, data, paper_value, ours
        self.missing, self.per, self.j, self.metric = missing, per, j, metric
        self.min_effect, self.lead, self.caveat = min_effect, lead, caveat
        self.p = _t_p(per["effect"].to_numpy()) if per is not None and len(per) else float("nan")

    def row(self, p_adj: float, vc: dict, correction: str) -> dict:
        if self.missing:
            return V.row(self.claim, "not reproduced", f"no pair to compare ({self.missing})",
                         paper_value=self.paper_value, data=self.data, source="compare/metrics.csv")
        per, j = self.per, self.j
        verdict = decide_groups(per, p_adj, vc)
        h, f = int((per["vote"] > 0).sum()), int((per["vote"] < 0).sum())
        c = per_clip(j)
        ch, cf = int((c["outcome"] > 0).sum()), int((c["outcome"] < 0).sum())
        unit = _UNITS.get(self.metric, "")
        groups = ", ".join(f"{g} {int(r.clips_for)}/{int(r.clips_for + r.clips_against)} clips, effect "
                           f"{V.fmt(r.effect)} ({'holds' if r.vote > 0 else 'opposite' if r.vote < 0 else 'within noise'})"
                           for g, r in per.iterrows())
        text = (f"{self.lead}decided over {len(per)} independent groups ({GROUPINGS[vc.get('grouping', 'subject')]}): "
                f"holds in {h}, opposite in "
                f"{f}, within noise in {len(per) - h - f} (minimum effect {V.fmt(self.min_effect)} {unit}); "
                f"t-test of the group effects p = {V.fmt(self.p, 2)}, {correction} p = {V.fmt(p_adj, 2)}; "
                f"per group (clips holding / untied clips, median effect): {groups}; counted by clips instead: "
                f"{ch} of {ch + cf} untied clips")
        if self.caveat:
            text += "; " + self.caveat
        return V.row(self.claim, verdict, text, paper_value=self.paper_value, ours=self.ours, data=self.data,
                     source="compare/metrics.csv")


def _pair(metrics, groups, claim, a, b, metric, better, vc, data, left_out, paper_value="", caveat=""):
    missing = [g for g in (a, b) if g not in set(metrics["generator"])]
    if missing:
        return _Claim(claim, data, paper_value=paper_value,
                      missing="; ".join(f"{g}: {(left_out or {}).get(g, 'not in this run')}" for g in missing))
    j = pair_outcomes(metrics, a, b, metric, better)
    me = float(vc["min_effect"].get(metric, 0.0))
    per = group_outcomes(j, groups, me)
    ours = (f"{metric} ({_UNITS[metric]}) median {a} {_spread(metrics, a, metric)} vs {b} "
            f"{_spread(metrics, b, metric)}")
    # the hypothesis under test (what "holds" means below), not the finding
    lead = f"tested: {a} {'lower' if better == 'lower' else 'higher'} than {b}; "
    return _Claim(claim, data, paper_value=paper_value, ours=ours, per=per, j=j, metric=metric, min_effect=me,
                  lead=lead, caveat=caveat)


def _copy_claim(metrics, groups, vc, data):
    claim = "re-sequencers copy database frames (novelty ~ 0) while field followers synthesise new poses"
    copiers = [g for g in ("isomap", "stisomap") if g in set(metrics["generator"])]
    makers = [g for g in ("delaunay", "knn") if g in set(metrics["generator"])]
    tol = float(vc["novelty_copy_m"])
    if not copiers or not makers:
        return _Claim(claim, data, missing="a re-sequencer or a field follower did not run")
    wide = metrics[metrics["generator"].isin(copiers + makers)].pivot_table(
        index=["clip", "seed"], columns="generator", values="novelty_median_m", aggfunc="first").dropna()
    # effect: how far the nearest field follower lies beyond the farthest re-sequencer (m)
    eff = wide[makers].min(axis=1) - wide[copiers].max(axis=1)
    ok = (wide[copiers].max(axis=1) <= tol) & (wide[makers].min(axis=1) > tol)
    j = pd.DataFrame({"clip": [c for c, _s in wide.index], "effect": np.where(ok, np.abs(eff), -np.abs(eff)),
                      "outcome": np.where(ok.to_numpy(), 1, -1)})
    me = float(vc["min_effect"].get("novelty_median_m", 0.0))
    per = group_outcomes(j, groups, me)
    ours = "; ".join(f"{g} novelty median {_spread(metrics, g, 'novelty_median_m')} m" for g in copiers + makers)
    return _Claim(claim, data, ours=ours, per=per, j=j, metric="novelty_median_m", min_effect=me,
                  lead=f"every re-sequencer at most {V.fmt(tol)} m from the database and every field follower "
                       "farther; ")


def _capture_claims(metrics, groups, vc, data):
    """'The held-out capture skates less than every generator': one sub-claim per generator (each a finding)."""
    gens = [g for g in dict.fromkeys(metrics["generator"]) if g not in REFERENCES]
    return [_pair(metrics, groups, f"the held-out capture skates less than {g}", "replay", g, "skate_share",
                  "lower", vc, data, {}) for g in gens]


def _iut_p(capture: list) -> float:
    """The intersection-union test's p of the capture claim: the largest of its parts' (NaN if one has none)."""
    ps = np.array([c.p for c in capture], float)
    return float(np.max(ps)) if ps.size and np.all(np.isfinite(ps)) else float("nan")


def _holm_rows(claims: list, vc: dict, correction_name: str, extra: list = ()) -> tuple[list, list]:
    """Every claim's row with its Holm-adjusted p, Holm run over the claims' p and the ``extra`` p (findings
    written elsewhere, e.g. the capture claim's); returns (rows, the extra p adjusted)."""
    ps = [c.p for c in claims] + list(extra)
    adj = V.holm(ps)
    n = int(np.sum(np.isfinite(ps)))
    rows = [c.row(a, vc, f"Holm-adjusted over the {n} {correction_name}") for c, a in zip(claims, adj)]
    return rows, [float(a) for a in adj[len(claims):]]


def _capture_rows(capture: list, p_adj: float, vc: dict, data: str, metrics: pd.DataFrame) -> dict | None:
    """The capture claim over every generator as one intersection-union test.

    "The capture skates less than every generator" holds only if it holds against each one, so it is one
    finding: its p is the largest of the generators' p (the intersection-union test needs no correction among
    its parts) and it enters the family's Holm correction once (``p_adj``). Each generator's part is decided
    with its own p scaled by the same Holm factor (so every part is reproduced exactly when the claim's p and
    every part's groups allow it). Verdict: reproduced when every part is, contradicted when every part is
    contradicted, partly when some parts are reproduced and others contradicted, else within noise. The
    evidence lists every part (groups holding / opposite / within noise, t-test p, verdict)."""
    if not capture:
        return None
    claim = "the held-out capture skates less than every generator (the realism upper bound holds for this metric)"
    p_iut = _iut_p(capture)
    factor = p_adj / p_iut if np.isfinite(p_iut) and p_iut > 0 and np.isfinite(p_adj) else 1.0
    parts, words = [], []
    for c in capture:
        gen = c.claim.removeprefix("the held-out capture skates less than ")
        if c.missing:
            words.append("not reproduced")
            parts.append(f"{gen}: not compared ({c.missing})")
            continue
        per = c.per
        w = decide_groups(per, min(1.0, c.p * factor) if np.isfinite(c.p) else float("nan"), vc)
        words.append(w)
        h, f = int((per["vote"] > 0).sum()), int((per["vote"] < 0).sum())
        parts.append(f"{gen}: {h}/{f}/{len(per) - h - f}, p = {V.fmt(c.p, 2)}, {w}")
    if all(w == "reproduced" for w in words):
        verdict = "reproduced"
    elif all(w == "contradicted" for w in words):
        verdict = "contradicted"
    elif "reproduced" in words and "contradicted" in words:
        verdict = "partly"
    else:
        verdict = "within noise"
    me = float(vc["min_effect"].get("skate_share", 0.0))
    evidence = (f"one intersection-union test over the {len(capture)} generators (the claim holds only if it holds "
                f"against each, so its p is the largest of theirs, p = {V.fmt(p_iut, 2)}, and it is one finding of "
                f"the Holm correction: adjusted p = {V.fmt(p_adj, 2)}); each generator decided over the independent "
                f"groups in which both have values ({GROUPINGS[vc.get('grouping', 'subject')]}, minimum effect {V.fmt(me)} "
                f"{_UNITS['skate_share']}), its t-test p scaled by the claim's Holm factor; per generator (groups "
                "holding / opposite / within noise, t-test p, verdict): " + "; ".join(parts))
    med = (metrics[metrics["generator"] != "replay"].assign(x=pd.to_numeric(metrics["skate_share"], errors="coerce"))
           .groupby("generator")["x"].median().dropna())
    ours = f"skate_share median replay {_spread(metrics, 'replay', 'skate_share')}"
    if len(med):
        ours += (f" vs the generators' medians from {med.idxmin()} {V.fmt(med.min())} to {med.idxmax()} "
                 f"{V.fmt(med.max())}")
    return V.row(claim, verdict, evidence, ours=ours, data=data, source="compare/metrics.csv")


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


def build_verdicts(metrics: pd.DataFrame, vc: dict, data: str, left_out: dict | None = None,
                   clips: pd.DataFrame | None = None, sweep: pd.DataFrame | None = None) -> pd.DataFrame:
    """The findings of the comparison (the verdict table; the sanity checks: :func:`sanity_checks`).

    Parameters
    ----------
    metrics : DataFrame, ``compare/metrics.csv``
    vc : the ``compare.verdicts`` block (``share``, ``alpha``, ``min_groups``, ``min_effect``,
        ``novelty_copy_m``)
    data : what the numbers ran on (e.g. "CMU: 19 held-out clips x 5 seeds")
    left_out : {generator: why it did not run}
    clips : DataFrame, ``compare/clips.csv`` (for :func:`independent_groups`; ``None``: each subset one group)
    sweep : DataFrame or None, the budget sweep table (:func:`animsynth.compare.tables.sweep_table`): quoted as
        evidence in the claims against the peer (decided at the default budget)
    """
    groups = _groups(metrics, clips, vc)
    present = set(metrics["generator"])
    configured = present | set(left_out or {})
    claims, capture = [], []

    def pair(claim, a, b, metric, better="lower", paper_value="", caveat=""):
        if {a, b} <= configured:
            claims.append(_pair(metrics, groups, claim, a, b, metric, better, vc, data, left_out, paper_value,
                                caveat))

    pair("the classic motion graph skates less than ST-Isomap re-sequencing", "motion_graph", "stisomap",
         "skate_share")
    pair("our motion graph's transitions skate less than fairmotion 0.0.4's as released (at its native 60 fps)",
         "motion_graph", "fairmotion", "transition_skate_share",
         caveat="fairmotion as released: its walk blends from a held pose and turns an appended piece without "
                "its path (animsynth.compare.fairmotion_peer); both graphs keep the same transition budget"
                + ("; the budget sweep runs the fixed row (the released row builds the same graph)"
                   if sweep is not None and len(sweep) else ""))
    pair("our motion graph's transitions skate less than fairmotion's with upstream's walk fixes",
         "motion_graph", "fairmotion_fixed", "transition_skate_share",
         caveat="fairmotion with the fixes output_rate, blend_source, rigid_turn, cut_copy; both graphs keep the same "
                "transition budget" + (f"; {ev}" if (ev := _sweep_evidence(sweep, "motion_graph", "fairmotion_fixed",
                                                                          "transition_skate_share")) else ""))
    pair("ST-Isomap re-sequencing jumps less than Isomap re-sequencing (95th percentile of the per-frame velocity "
         "jump)", "stisomap", "isomap", "velocity_jump_p95",
         paper_value="ST-Isomap re-sequences more smoothly than Isomap (the re-sequencing paper)")
    pair("Delaunay field following stays closer to the held-out continuation than k-NN field following (L2P)",
         "delaunay", "knn", "l2p", paper_value="Delaunay gives lower Error A/F than k-NN (Gauch & Peters Table II)")
    pair("motion matching skates less than the motion graph", "motion_matching", "motion_graph",
         "skate_share", caveat="motion matching with the reference's foot locking and leg IK, its query a steady "
                               "gamepad from the start; deterministic, so inside a clip only the motion graph's "
                               "seeds vary")
    pair("GenMM covers more of the database than the motion graph", "genmm", "motion_graph", "coverage",
         better="higher", caveat="coverage: the share of the database's windows that a generated window comes within "
                                 "compare.metrics.coverage_threshold_m of")
    if "replay" in configured and "replay" in present:
        capture = _capture_claims(metrics, groups, vc, data)
    # the capture claim is one finding (an intersection-union test over the generators: its p the largest)
    out, cap_adj = _holm_rows(claims, vc, "findings of this table", [_iut_p(capture)] if capture else [])
    cap = _capture_rows(capture, cap_adj[0], vc, data, metrics) if capture else None
    if cap is not None:
        out.append(cap)
    elif "replay" in configured:
        out.append(V.row("the held-out capture skates less than every generator (the realism upper bound holds "
                         "for this metric)", "not reproduced", "no pair to compare (replay or every generator "
                         "missing)", data=data, source="compare/metrics.csv"))
    return V.table(out)


def sanity_checks(metrics: pd.DataFrame, vc: dict, data: str, left_out: dict | None = None,
                  clips: pd.DataFrame | None = None) -> pd.DataFrame:
    """Claims true by construction, decided the same way (Holm over the sanity checks alone): not findings."""
    groups = _groups(metrics, clips, vc)
    configured = set(metrics["generator"]) | set(left_out or {})
    claims = []
    if {"isomap", "stisomap", "delaunay", "knn"} & configured:
        claims.append(_copy_claim(metrics, groups, vc, data))
    if {"motion_graph", "concat"} <= configured:
        claims.append(_pair(metrics, groups, "the motion graph's blended transitions jump less than random "
                            "concatenation's unblended seams (95th percentile of the per-frame velocity jump)",
                            "motion_graph", "concat", "velocity_jump_p95", "lower", vc, data, left_out))
    return V.table(_holm_rows(claims, vc, "sanity checks")[0])


def _groups(metrics: pd.DataFrame, clips: pd.DataFrame | None, vc: dict) -> dict:
    if clips is not None and {"clip", "group", "held_out", "database"} <= set(clips.columns):
        return independent_groups(clips, vc.get("grouping", "subject"))
    return dict(metrics.drop_duplicates("clip").set_index("clip")["group"])
