"""Summary and benchmark aggregation (generated from CSVs, never typed)."""

import pandas as pd
import pytest

from animsynth.report import aggregate_rule_benchmarks, build_summary, read_verdicts, rule_benchmark_summary

TSV = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n{s}\t0:00:01\t{m}\t200\t1\t1\t0\t0\t50\t{s}\n"


def test_rule_benchmarks(tmp_path):
    root = tmp_path / "benchmarks" / "rules"
    for rel, s, m in [("data/parse_trial/a.tsv", 1.5, 100), ("data/parse_trial/b.tsv", 2.5, 120),
                      ("data/datasets_table.tsv", 0.5, 90)]:
        p = root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(TSV.format(s=s, m=m))
    jobs = aggregate_rule_benchmarks(sorted(root.rglob("*.tsv")), root=str(root))
    assert sorted(jobs["rule"]) == ["data/datasets_table", "data/parse_trial", "data/parse_trial"]
    per = rule_benchmark_summary(jobs).set_index("rule")
    assert per.loc["data/parse_trial", "jobs"] == 2
    assert per.loc["data/parse_trial", "total_seconds"] == pytest.approx(4.0)
    assert per.loc["data/parse_trial", "peak_rss_mb"] == pytest.approx(120)


def test_summary_renders_tables_and_verdicts(tmp_path):
    t = tmp_path / "t.csv"
    pd.DataFrame({"dataset": ["w1"], "error_a": [0.0123]}).to_csv(t, index=False)
    v = tmp_path / "simplicial" / "verdicts.csv"
    v.parent.mkdir()
    pd.DataFrame({"claim": ["Delaunay beats k-NN"], "verdict": ["no"], "evidence": ["p=0.2"]}).to_csv(v, index=False)
    md = build_summary([{"title": "Table II", "csv": str(t), "note": "synthetic"}], [v], "Data: synthetic.")
    assert "| simplicial | Delaunay beats k-NN | no | p=0.2 |" in md
    assert "## Table II" in md and "| w1 | 0.0123 |" in md
    bad = tmp_path / "x" / "verdicts.csv"
    bad.parent.mkdir()
    pd.DataFrame({"claim": ["c"]}).to_csv(bad, index=False)
    with pytest.raises(ValueError, match="lacks columns"):
        read_verdicts([bad])
