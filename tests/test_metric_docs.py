"""The docs' metric table is generated from the metric table's records and kept up to date; every record names a
computation that exists."""

from __future__ import annotations

from pathlib import Path

import pytest

from animsynth.compare.measures import metric_table
from animsynth.compare.measures.metric_docs import BEGIN, END, main, metric_table_markdown, render_page

PAGE = Path(__file__).resolve().parents[1] / "docs" / "compare" / "metrics.md"


def test_the_metrics_page_holds_the_table_rendered_from_the_records():
    text = PAGE.read_text(encoding="utf-8")
    assert render_page(text, str(PAGE)) == text, \
        "docs/compare/metrics.md is out of date: .venv/bin/python -m animsynth.compare.measures.metric_docs"


def test_the_table_has_one_row_per_record_with_its_margin_and_computation():
    rows = [r for r in metric_table_markdown().splitlines() if r.startswith("| `")]
    assert [r.split(" | ")[0] for r in rows] == [f"| `{m.name}`" for m in metric_table.METRICS]
    l2p = next(r for r in rows if r.startswith("| `l2p` |"))
    assert "| 0.25 |" in l2p and "`ground_truth:score_l2p`" in l2p and "| short |" in l2p


def test_render_keeps_the_page_around_the_markers_and_refuses_a_page_without_them(tmp_path):
    page = f"# Title\n\n{BEGIN}\nold rows\n{END}\n\nafter\n"
    out = render_page(page)
    assert out.startswith(f"# Title\n\n{BEGIN}\n| column |") and out.endswith(f"{END}\n\nafter\n")
    assert render_page(out) == out
    with pytest.raises(ValueError, match="markers"):
        render_page("# Title\n\nno table\n", "x.md")
    (tmp_path / "bad.md").write_text(f"{END}\n{BEGIN}\n")
    assert main([str(tmp_path / "bad.md")]) == 2 and main([str(tmp_path / "none.md")]) == 2


def test_every_record_names_a_computation_that_exists():
    for path in metric_table.by_computation(metric_table.METRICS):
        assert callable(metric_table.computation(path)), path
