"""The metric table collects the records each measure module declares (those listed in their order, then any other
module by name); the docs' metric table is generated from them and kept up to date; every record names a
computation that exists."""

from __future__ import annotations

import sys
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


def _package(root: Path, name: str, modules: dict[str, str]) -> str:
    """A package ``name`` under ``root`` with one module per entry: its ``RECORDS`` (Python text) or None."""
    (root / name).mkdir()
    (root / name / "__init__.py").write_text("")
    for module, records in modules.items():
        body = "def score(s):\n    return {}\n"
        if records is not None:
            body = f"from animsynth.compare.measures.metric_record import Metric\n{body}RECORDS = {records}\n"
        (root / name / f"{module}.py").write_text(body)
    return name


@pytest.fixture
def packages(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    made = []

    def make(name, modules):
        made.append(_package(tmp_path, name, modules))
        return name

    yield make
    for key in [k for k in sys.modules if k.split(".")[0] in made]:
        del sys.modules[key]


def _rec(module: str, name: str) -> str:
    return f'Metric("{name}", "m", "", "", compute="{module}:score"),'


def test_the_table_takes_the_listed_modules_in_order_then_every_other_module_with_records_by_name(packages):
    pkg = packages("measures_fake_a", {"zeta": f"({_rec('zeta', 'z1')} {_rec('zeta', 'z2')})",
                                       "alpha": f"({_rec('alpha', 'a1')})", "new_b": f"({_rec('new_b', 'b1')})",
                                       "new_a": f"({_rec('new_a', 'n1')})", "helper": None,
                                       "docs": "1 / 0"})  # skipped: never imported
    names = [m.name for m in metric_table.records_of(pkg, ("zeta", "alpha"), ("docs",))]
    assert names == ["z1", "z2", "a1", "n1", "b1"]


def test_a_record_outside_its_module_or_a_listed_module_without_records_is_refused(packages):
    pkg = packages("measures_fake_b", {"mine": f"({_rec('other', 'x')})", "bare": None})
    with pytest.raises(ValueError, match=r"measures_fake_b\.mine: the record 'x' names the computation 'other:score'"):
        metric_table.records_of(pkg)
    with pytest.raises(ValueError, match=r"measures_fake_b\.bare: RECORDS must be"):
        metric_table.records_of(pkg, ("bare",), ("mine",))
