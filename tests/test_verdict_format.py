"""The one verdict format: columns, vocabulary, refusal of unknown words (file and line named)."""

import pandas as pd
import pytest

from animsynth import verdicts as v


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
                                         (float("nan"), "not reproduced"), (None, "not reproduced")])
def test_agreement_verdict(share, word):
    assert v.agreement_verdict(share) == word


def test_fmt():
    assert v.fmt(0.0123456) == "0.0123" and v.fmt(None) == "nan" and v.fmt(float("inf")) == "nan"
