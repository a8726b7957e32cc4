"""The one verdict format: columns, vocabulary, refusal of unknown words (file and line named)."""

import pandas as pd
import pytest

from animsynth import verdicts as v
from animsynth.families import names


def test_row_refuses_a_word_outside_the_vocabulary():
    with pytest.raises(v.VerdictError, match="'yes' for claim 'c'"):
        v.row("c", "yes")
    with pytest.raises(v.VerdictError, match="needs a claim"):
        v.row(" ", "reproduced")


def test_table_orders_columns_and_renders_numbers_as_text():
    t = v.table([v.row("c", "within noise", "share 0.6", ours=0.25, paper_value=None, source="x.csv")])
    assert list(t.columns) == list(v.COLUMNS)
    assert t.iloc[0].to_dict() == {"claim": "c", "paper_value": "", "ours": "0.25", "data": "", "verdict": "within noise",
                                   "evidence": "share 0.6", "source": "x.csv"}


def test_read_names_file_and_line_of_a_bad_verdict(tmp_path):
    p = tmp_path / "verdicts.csv"
    rows = [v.row("a", "reproduced"), {**v.row("b", "partly"), "verdict": "lean"}]
    pd.DataFrame(rows).to_csv(p, index=False)
    with pytest.raises(v.VerdictError, match=r"verdicts.csv, line 3: verdict 'lean'"):
        v.read(p)
    pd.DataFrame(rows[:1]).assign(extra=1).to_csv(p, index=False)
    with pytest.raises(v.VerdictError, match=r"unexpected \['extra'\]"):
        v.read(p)
    p.write_text("")
    with pytest.raises(v.VerdictError, match="empty"):
        v.read(p)


@pytest.mark.parametrize("share, word", [(1.0, "reproduced"), (0.0, "contradicted"), (0.5, "within noise"),
                                         (float("nan"), "undecided"), (None, "undecided")])
def test_agreement_verdict(share, word):
    assert v.agreement_verdict(share) == word


def test_fmt():
    assert v.fmt(0.0123456) == "0.0123" and v.fmt(None) == "nan" and v.fmt(float("inf")) == "nan"


# ------------------------------------------------------------------ the one rule for "A beats B over units"
def test_unit_votes_need_the_lead_and_the_minimum_effect():
    import numpy as np

    lead = [3, 3, -2, -2, 0, 1]
    effect = [0.5, 0.05, -0.5, -0.05, 0.9, float("nan")]
    assert v.unit_votes(lead, effect, 0.1).tolist() == [1, 0, -1, 0, 0, 0]
    assert v.unit_votes(np.array([0.2, -1e-9, 0.0])).tolist() == [1, -1, 0]  # no effect given: the lead's sign


def test_sign_test_is_the_two_sided_binomial_over_voting_units():
    assert v.sign_test(6, 0) == pytest.approx(2 / 2 ** 6)
    assert v.sign_test(3, 3) == pytest.approx(1.0)
    assert v.sign_test(0, 0) == 1.0


def test_a_beats_b_share_test_and_minimum_units():
    rule = dict(share=0.75, alpha=0.05)
    assert v.a_beats_b(60, 10, **rule) == "holds"                   # 86 %, sign test p tiny
    assert v.a_beats_b(10, 60, **rule) == "opposite"
    assert v.a_beats_b(49, 23, **rule, p=0.003) == "lean"          # significant, 68 % < 75 %
    assert v.a_beats_b(23, 49, **rule, p=0.003) == "lean_opposite"
    assert v.a_beats_b(9, 7, **rule) == "noise"
    assert v.a_beats_b(0, 0, **rule) == "none"
    assert v.a_beats_b(6, 0, **rule) == "holds"                     # p = 0.031 by the sign test
    # units voting for neither count in the share: 3 of 5 is below 75 % whatever the p
    assert v.a_beats_b(3, 0, 2, **rule, p=0.001) == "lean"
    assert v.a_beats_b(4, 0, 1, **rule, p=0.001) == "holds"
    assert v.a_beats_b(4, 0, 1, **rule, p=0.001, min_units=6) == "noise"   # too few units to decide
    assert v.a_beats_b(4, 0, 1, **rule, p=float("nan")) == "noise"          # no test, no decision


@pytest.mark.parametrize("family", names())
def test_every_family_builds_its_verdicts_with_build_verdicts(family):
    import importlib

    mod = importlib.import_module(f"animsynth.{family}.verdicts")
    assert callable(getattr(mod, "build_verdicts", None))
    assert not {"verdicts", "build", "all_verdicts"} & set(vars(mod)), "one entry point name per family"
