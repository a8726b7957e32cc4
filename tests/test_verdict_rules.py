"""The shared verdict rules (holds on all / some / none; "A beats B") and the families' decisions through them.

The facegraph trend and the meshdetail block comparison are decided by :func:`animsynth.verdicts.a_beats_b`; the
reference functions below are those families' rules written out on their own, and the shared rule must give the
same word on every constructed input, the edges included (p exactly alpha, a zero margin, one block, NaN).

The reference rules of facegraph and meshdetail here are frozen copies, kept apart from the package on purpose:
they are what the equivalence tests compare the shared rule with, and are not to follow later edits of it."""

import itertools

import numpy as np
import pandas as pd
import pytest

from animsynth import verdicts as v
from animsynth.facegraph.verdicts import trend_verdict
from animsynth.meshdetail.verdicts import block_margin, block_verdict


@pytest.mark.parametrize("ok, none, want", [
    ([True, True, True], "not reproduced", "reproduced"),
    ([True, False, True], "not reproduced", "partly"),
    ([False, False], "not reproduced", "not reproduced"),
    ([False, False], "contradicted", "contradicted"),
    ([False], "within noise", "within noise"),
    ([], "not reproduced", "reproduced"),          # all of nothing, as numpy's all()
    (pd.Series([1.0, 3.0]) > 2.0, "contradicted", "partly"),
    (np.array([[True], [True]]), "not reproduced", "reproduced"),
])
def test_share_verdict_all_some_none(ok, none, want):
    assert v.share_verdict(ok, none=none) == want


@pytest.mark.parametrize("ok, want", [([True, True], "all"), ([True, False], "some"), ([False, False], "none"),
                                      ([], "all"), (np.array([False, True]), "some")])
def test_share_outcome_all_some_none(ok, want):
    assert v.share_outcome(ok) == want


def test_share_verdict_refuses_a_word_outside_the_vocabulary():
    with pytest.raises(v.VerdictError, match="'nope'"):
        v.share_verdict([False], none="nope")
    with pytest.raises(v.VerdictError, match="'nope'"):
        v.share_verdict([True], none="nope")   # checked whatever the cases say


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


def test_a_beats_b_an_unstable_lead_for_a_leans_and_b_needs_no_stability():
    assert v.a_beats_b(1, 0, share=1.0, alpha=0.05, p=0.01, stable=False) == "lean"
    assert v.a_beats_b(0, 1, share=1.0, alpha=0.05, p=0.01, stable=False) == "opposite"
    assert v.a_beats_b(1, 0, share=1.0, alpha=0.05, p=0.2, stable=False) == "noise"


def _facegraph_trend_rule(rho, p, share):
    """The facegraph trend rule on its own: a significant rise that is stable over the bootstrap is reproduced."""
    if not np.isfinite(rho):
        return "not reproduced"
    if rho > 0 and p < 0.05 and (np.isnan(share) or share >= 0.95):
        return "reproduced"
    if rho > 0:
        return "within noise"
    return "contradicted" if p < 0.05 else "not reproduced"


def test_facegraph_trend_decided_by_the_shared_rule_as_by_its_own():
    rhos = [np.nan, -0.9, -1e-12, 0.0, 1e-12, 0.3, 1.0]
    ps = [np.nan, 0.0, 0.01, np.nextafter(0.05, 0), 0.05, np.nextafter(0.05, 1), 0.5, 1.0]
    shares = [np.nan, 0.0, 0.5, np.nextafter(0.95, 0), 0.95, 1.0]
    for rho, p, share in itertools.product(rhos, ps, shares):
        assert trend_verdict(rho, p, share) == _facegraph_trend_rule(rho, p, share), (rho, p, share)
    assert trend_verdict(0.8, 0.05, 1.0) == "within noise"        # p = alpha: not significant
    assert trend_verdict(-0.8, 0.05, 0.0) == "not reproduced"
    assert trend_verdict(-0.8, 0.049, np.nan) == "contradicted"


def _meshdetail_block_rule(margin, sd, share):
    """The meshdetail rule on its own: every block better and the margin above the per-block SD."""
    if margin > 0 and share == 1.0 and (np.isnan(sd) or margin > sd):
        return "reproduced"
    if margin < 0 and share == 0.0 and (np.isnan(sd) or -margin > sd):
        return "contradicted"
    return "within noise"


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
    assert block_verdict(1.0, 1.0, 1.0, 2) == "within noise"
    assert block_verdict(1.0, np.nextafter(1.0, 0), 1.0, 2) == "reproduced"
    assert block_verdict(0.0, np.nan, 0.0, 1) == "within noise"   # one tied block: no margin
