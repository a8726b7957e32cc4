"""The one reader of published tables: a missing file is None with a WARNING, a malformed one names file and line."""

import logging

import pytest

from animsynth.published import PublishedError, read_table, resolve


def test_missing_file_gives_none_and_a_warning_naming_the_path(tmp_path, caplog):
    with caplog.at_level(logging.WARNING, logger="animsynth.published"):
        assert read_table(tmp_path / "absent.csv", ["a"], what="Table X", config_key="published.x.t") is None
    assert "absent.csv" in caplog.text and "published.x.t" in caplog.text
    assert read_table(None, ["a"]) is None


def test_reads_numbers_and_keeps_empty_cells_as_nan(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("metric,w1,note\nerror_a,0.023,x\nerror_f,,y\n")
    df = read_table(p, ["metric", "w1"], ["w1"])
    assert df["w1"].iloc[0] == 0.023 and df["w1"].isna().iloc[1] and df["note"].tolist() == ["x", "y"]


@pytest.mark.parametrize("text, match", [
    ("metric,w2\nerror_a,1\n", r"line 1: .* lacks column\(s\) \['w1'\]"),
    ("metric,w1\nerror_a,0.1\nerror_f,zero\n", r"t.csv, line 3: column 'w1' holds 'zero'"),
    ("metric,w1\n", "has no rows"),
    ("", "empty file"),
])
def test_malformed_tables_name_file_and_line(tmp_path, text, match):
    p = tmp_path / "t.csv"
    p.write_text(text)
    with pytest.raises(PublishedError, match=match):
        read_table(p, ["metric", "w1"], ["w1"])


def test_relative_paths_resolve_against_the_given_base(tmp_path):
    assert resolve("../papers/a.csv", tmp_path / "proj") == (tmp_path / "papers" / "a.csv").resolve()
    assert resolve(str(tmp_path / "a.csv"), "/elsewhere") == tmp_path / "a.csv"
    assert resolve(None, tmp_path) is None and resolve("", tmp_path) is None
