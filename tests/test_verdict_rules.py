"""The shared verdict rules (holds on all / some / none; "A beats B") and the families' decisions through them.

The facegraph trend and the meshdetail block comparison are decided by :func:`animsynth.verdicts.a_beats_b`; the
reference functions below are those families' rules written out on their own, and the shared rule must give the
same word on every constructed input, the edges included (p exactly alpha, a zero margin, one block, NaN).

The reference rules of facegraph and meshdetail here are frozen copies, kept apart from the package on purpose:
they are what the equivalence tests compare the shared rule with, and are not to follow later edits of it. Where a
word's meaning changed (one meaning per word: a rule that decides nothing is ``undecided``, a significant lead short
of its share ``partly``), the frozen rule says so in its docstring; every decision on which the meaning did not
change is the same as before."""

import itertools

import numpy as np
import pandas as pd
import pytest

from animsynth import verdicts as v
from animsynth.facegraph.verdicts import trend_verdict
from animsynth.meshdetail.verdicts import block_margin, block_verdict


@pytest.mark.parametrize("ok, none, want", [
    ([True, True, True], "short", "reproduced"),
    ([True, False, True], "short", "partly"),
    ([False, False], "short", "not reproduced"),
    ([False, False], "opposite", "contradicted"),
    ([False], "flips", "within noise"),
    ([], "short", "undecided"),          # no case at all: no evidence, never "reproduced"
    ([], "opposite", "undecided"),
    (pd.Series([1.0, 3.0]) > 2.0, "opposite", "partly"),
    (np.array([[True], [True]]), "short", "reproduced"),
])
def test_share_verdict_all_some_none(ok, none, want):
    assert v.share_verdict(ok, none=none) == want


@pytest.mark.parametrize("ok, want", [([True, True], "all"), ([True, False], "some"), ([False, False], "none"),
                                      ([], "empty"), (np.array([False, True]), "some")])
def test_share_outcome_all_some_none(ok, want):
    assert v.share_outcome(ok) == want


def test_share_verdict_refuses_an_outcome_outside_the_table():
    with pytest.raises(v.VerdictError, match="'nope'"):
        v.share_verdict([False], none="nope")
    with pytest.raises(v.VerdictError, match="'nope'"):
        v.share_verdict([True], none="nope")   # checked whatever the cases say
    with pytest.raises(v.VerdictError, match="'contradicted'"):
        v.share_verdict([False], none="contradicted")   # a word is not an outcome: the family names what happened


def test_a_beats_b_with_a_familys_own_test():
    assert v.a_beats_b(5, 0, share=1.0, significant=True) == "holds"
    assert v.a_beats_b(0, 5, share=1.0, significant=True) == "opposite"
    assert v.a_beats_b(4, 1, share=1.0, significant=True) == "lean"
    assert v.a_beats_b(5, 0, share=1.0, significant=False) == "noise"
    assert v.a_beats_b(0, 0, share=1.0, significant=True) == "none"
    with pytest.raises(ValueError, match="either significant or p / alpha"):
        v.a_beats_b(5, 0, share=1.0, significant=True, alpha=0.05)
    with pytest.raises(ValueError, match="needs the test's level"):
        v.a_beats_b(5, 0, share=1.0)


def test_a_beats_b_p_equal_to_alpha_is_not_significant():
    assert v.a_beats_b(1, 0, share=1.0, alpha=0.05, p=0.05) == "noise"
    assert v.a_beats_b(1, 0, share=1.0, alpha=0.05, p=np.nextafter(0.05, 0)) == "holds"
    assert v.a_beats_b(0, 1, share=1.0, alpha=0.05, p=0.05) == "noise"


def test_a_beats_b_an_unstable_lead_for_a_is_unstable_and_b_needs_no_stability():
    assert v.a_beats_b(1, 0, share=1.0, alpha=0.05, p=0.01, stable=False) == "unstable"
    assert v.a_beats_b(3, 2, share=1.0, alpha=0.05, p=0.01, stable=False) == "lean"   # the share short: lean
    assert v.a_beats_b(0, 1, share=1.0, alpha=0.05, p=0.01, stable=False) == "opposite"
    assert v.a_beats_b(1, 0, share=1.0, alpha=0.05, p=0.2, stable=False) == "noise"


def _facegraph_trend_rule(rho, p, share):
    """The facegraph trend rule on its own: a significant rise that is stable over the bootstrap is reproduced.

    Changed meaning: a rise or fall that Spearman's test does not find significant, and no correlation at all (NaN),
    were "within noise" / "not reproduced"; they decide nothing, so they are "undecided". A significant rise that
    flips over the bootstrap resamples stays "within noise"; the other decisions are unchanged."""
    if not np.isfinite(rho):
        return "undecided"
    if rho > 0 and p < 0.05 and (np.isnan(share) or share >= 0.95):
        return "reproduced"
    if rho > 0:
        return "within noise" if p < 0.05 else "undecided"
    return "contradicted" if p < 0.05 else "undecided"


def test_facegraph_trend_decided_by_the_shared_rule_as_by_its_own():
    rhos = [np.nan, -0.9, -1e-12, 0.0, 1e-12, 0.3, 1.0]
    ps = [np.nan, 0.0, 0.01, np.nextafter(0.05, 0), 0.05, np.nextafter(0.05, 1), 0.5, 1.0]
    shares = [np.nan, 0.0, 0.5, np.nextafter(0.95, 0), 0.95, 1.0]
    for rho, p, share in itertools.product(rhos, ps, shares):
        assert trend_verdict(rho, p, share) == _facegraph_trend_rule(rho, p, share), (rho, p, share)
    assert trend_verdict(0.8, 0.05, 1.0) == "undecided"           # p = alpha: not significant
    assert trend_verdict(0.8, 0.01, 0.5) == "within noise"        # significant, but the rise flips over resamples
    assert trend_verdict(-0.8, 0.05, 0.0) == "undecided"
    assert trend_verdict(-0.8, 0.049, np.nan) == "contradicted"


def _meshdetail_block_rule(margin, sd, share):
    """The meshdetail rule on its own: every block better and the margin above the per-block SD.

    Changed meaning: everything else was "within noise"; a margin above its spread that not every block shares is
    now "partly" (a significant lead short of its share), a margin within its spread "undecided" (the blocks cannot
    decide). Reproduced and contradicted are unchanged."""
    significant = bool(np.isfinite(margin)) and margin != 0 and (np.isnan(sd) or abs(margin) > sd)
    if significant and margin > 0 and share == 1.0:
        return "reproduced"
    if significant and margin < 0 and share == 0.0:
        return "contradicted"
    return "partly" if significant else "undecided"


@pytest.mark.parametrize("diffs", [
    [1.0, 1.1, 0.9, 1.0], [1.0, 1.0, 1.0], [-1.0, -1.2, -0.8], [0.0, 0.0, 0.0], [1.0, 0.0, 1.0],
    [-1.0, 0.0, -1.0], [-1.0, -1.0, 0.0], [0.0], [0.5], [-0.5], [1.0, -1.0], [0.1, 5.0], [-0.1, -5.0],
    [1.0, np.nan], [np.nan], [0.2, 0.2, 0.2, 3.0], [-3.0, -0.2, -0.2, -0.2]])
def test_meshdetail_blocks_decided_by_the_shared_rule_as_by_its_own(diffs):
    d = np.asarray(diffs, float)
    fig = pd.DataFrame({"block": np.arange(d.size), "better": np.zeros(d.size), "worse": d})
    margin, sd, share, k = block_margin(fig, "better", "worse")
    assert k == d.size
    assert block_verdict(margin, sd, share, k) == _meshdetail_block_rule(margin, sd, share), diffs


def test_meshdetail_margin_equal_to_its_spread_is_not_enough():
    # margin 1, per-block SD exactly 1: the margin must exceed the spread
    fig = pd.DataFrame({"block": [0, 1], "better": [0.0, 0.0], "worse": [1.0 - np.sqrt(0.5), 1.0 + np.sqrt(0.5)]})
    margin, sd, share, k = block_margin(fig, "better", "worse")
    assert share == 1.0 and sd == pytest.approx(margin)
    assert block_verdict(1.0, 1.0, 1.0, 2) == "undecided"
    assert block_verdict(1.0, np.nextafter(1.0, 0), 1.0, 2) == "reproduced"
    assert block_verdict(0.0, np.nan, 0.0, 1) == "undecided"   # one tied block: no margin


# ------------------------------------------------------------------ one word per outcome, in every family
def _pairs(n_st_smoother: int, n_iso_smoother: int, both: bool = True) -> pd.DataFrame:
    """resequencing's per-path rows: pairs where both methods re-sequence (``both``; else ST-Isomap replays), ST-Isomap
    smoother in the first ``n_st_smoother`` pairs and Isomap in the next ``n_iso_smoother``."""
    rows = []
    for p in range(n_st_smoother + n_iso_smoother):
        st = 1.0 if p < n_st_smoother else 3.0
        for method, x, cls in (("isomap", 2.0, "resequences"),
                               ("stisomap", st, "resequences" if both else "replays")):
            rows.append({"dataset": "walk", "method": method, "metric": "l2", "global_dof": False, "pair": p,
                         "root_playback": "integrate", "path_class": cls, "transitions": 1,
                         "transitions_per_100_frames": 1.0, "velocity_jump_ratio": x, "pose_jump_ratio": x,
                         "accel_jump_ratio": x, "foot_skate_ratio": x})
    return pd.DataFrame(rows)


def _effect(**kw) -> str:
    """compare's rule (animsynth.verdicts.effect_verdict) with a margin of 0.05 over 12 subjects by default."""
    args = dict(n=12, mean=0.0, p_holm=1.0, ci90=(-0.2, 0.2), margin=0.05, alpha=0.05, min_units=3)
    return v.effect_verdict(**{**args, **kw})[0]


def _families_by_outcome() -> dict:
    """outcome -> {family rule: the word it gives on an input where that outcome happened}."""
    from animsynth.meshdetail.verdicts import holds_on
    from animsynth.resequencing.verdicts import st_smoother_verdict

    reseq = lambda a, b, both=True: st_smoother_verdict(_pairs(a, b, both))["verdict"]  # noqa: E731
    return {
        "holds": {"resequencing": reseq(12, 0), "meshdetail": block_verdict(1.0, 0.1, 1.0, 5),
                  "facegraph": trend_verdict(0.9, 0.001, 1.0), "simplicial": v.agreement_verdict(1.0),
                  "compare": _effect(mean=0.1, p_holm=0.001, ci90=(0.08, 0.12)), "cases": v.share_verdict([1, 1])},
        "opposite": {"resequencing": reseq(0, 12), "meshdetail": block_verdict(-1.0, 0.1, 0.0, 5),
                     "facegraph": trend_verdict(-0.9, 0.001, 0.0), "simplicial": v.agreement_verdict(0.0),
                     "compare": _effect(mean=-0.1, p_holm=0.001, ci90=(-0.12, -0.08)),
                     "cases": v.share_verdict([0, 0], none="opposite")},
        "lean": {"resequencing": reseq(47, 23), "meshdetail": block_verdict(1.0, 0.5, 0.8, 5),
                 "compare": _effect(split=(3, 3)), "cases": v.share_verdict([1, 0])},
        "noise": {"resequencing": reseq(9, 7), "meshdetail": block_verdict(0.1, 1.0, 0.6, 5),
                  "facegraph": trend_verdict(0.3, 0.4, 0.7), "compare": _effect(mean=0.02, p_holm=0.4)},
        "none": {"resequencing": reseq(6, 6, both=False), "meshdetail": block_verdict(np.nan, np.nan, np.nan, 0),
                 "meshdetail sequences": holds_on({})[1], "facegraph": trend_verdict(np.nan, np.nan, np.nan),
                 "simplicial": v.agreement_verdict(np.nan), "compare": _effect(n=0, mean=np.nan, p_holm=np.nan),
                 "cases": v.share_verdict([])},
        "flips": {"simplicial": v.agreement_verdict(0.5), "facegraph": trend_verdict(0.9, 0.001, 0.5),
                  "meshdetail sequences": holds_on({"a": "within noise", "b": "within noise"})[1],
                  "cases": v.share_verdict([0], none="flips")},
        "did_not_run": {"compare": v.effect_verdict(n=0, mean=np.nan, p_holm=np.nan, ci90=(np.nan, np.nan),
                                                    margin=0.05, alpha=0.05, min_units=3, missing="x did not run")[0],
                        "meshdetail sequences": holds_on({"a": "did not run"})[1]},
        "equivalent": {"compare": _effect(mean=0.0, p_holm=1.0, ci90=(-0.01, 0.01))},
    }


@pytest.mark.parametrize("outcome", ["holds", "opposite", "lean", "noise", "none", "flips", "did_not_run",
                                     "equivalent"])
def test_every_family_turns_the_same_outcome_into_the_same_word(outcome):
    words = _families_by_outcome()[outcome]
    assert set(words.values()) == {v.word(outcome)}, words


def test_each_word_has_one_meaning_and_every_outcome_a_word():
    assert v.VOCABULARY == tuple(v.WORDS) and all(len(m) > 20 for m in v.WORDS.values())
    assert set(v.OUTCOME_WORDS.values()) == set(v.VOCABULARY)  # every word is reached by some outcome
    assert set(v.OUTCOMES) <= set(v.OUTCOME_WORDS)
    assert v.word("lean") == v.word("lean_opposite") == v.word("split") == "partly"
    assert v.word("noise") == v.word("none") == "undecided"
    with pytest.raises(v.VerdictError, match="'reproduced'"):
        v.word("reproduced")  # a word is not an outcome
    assert "| no material difference | equivalence shown" in v.words_markdown()


def test_no_evidence_never_gives_reproduced_nor_not_reproduced():
    """Every family's claim with nothing to decide on: no case, no unit, no published table, no run."""
    from animsynth.facegraph.verdicts import thresholds_claim
    from animsynth.meshdetail.verdicts import holds_on
    from animsynth.resequencing.verdicts import explanation_verdicts, global_dof_verdict, lee_vs_l2_verdict
    from animsynth.simplicial.verdicts import connected_claim

    empty_t2 = pd.DataFrame(columns=["dataset", "global_dof", "sign_mode", "method", "metric", "min_k", "min_k_paper"])
    empty_paths = _pairs(1, 0).iloc[:0]
    words = {
        "share of no case": v.share_verdict([]),
        "agreement of no nudge": v.agreement_verdict(float("nan")),
        "a ladder without evidence": v.ladder([(True, "holds")], "short", evidence=False),
        "compare, no subject": _effect(n=0, mean=np.nan, p_holm=np.nan, ci90=(np.nan, np.nan)),
        "compare, did not run": v.effect_verdict(n=0, mean=np.nan, p_holm=np.nan, ci90=(np.nan, np.nan), margin=0.05,
                                                 alpha=0.05, min_units=3, missing="y did not run")[0],
        "resequencing, no published table": explanation_verdicts(pd.DataFrame(), None, 1)[0]["verdict"],
        "resequencing, no configuration": lee_vs_l2_verdict(empty_t2)["verdict"],
        "resequencing, no pair": global_dof_verdict(empty_paths)["verdict"],
        "facegraph, no configuration": thresholds_claim(pd.DataFrame({"creation_in_band_pct": [],
                                                                      "merge_in_band_pct": []}), "d")["verdict"],
        "facegraph, no correlation": trend_verdict(np.nan, np.nan, np.nan),
        "meshdetail, no block": block_verdict(np.nan, np.nan, np.nan, 0),
        "meshdetail, no sequence": holds_on({})[1],
        "simplicial, no fold": connected_claim("delaunay", pd.DataFrame(
            {"components": [], "undirected_connected": [], "h_connected": []}), "d")["verdict"],
    }
    bad = {k: w for k, w in words.items() if w in ("reproduced", "not reproduced")}
    assert not bad, bad
    assert set(words.values()) <= {"undecided", "did not run"}, words
