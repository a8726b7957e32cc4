"""Summary and benchmark aggregation (generated from CSVs, never typed)."""

import pandas as pd
import pytest

from animsynth.benchmark_tables import aggregate_rule_benchmarks, family_benchmark_summary, rule_benchmark_summary
from animsynth.verdicts import VerdictError
from animsynth.report import build_summary, claims_rst, claims_table

TSV = ("s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"
       "{s}\t0:00:01\t{m}\t200\t1\t1\t0\t0\t50\t{s}\n")


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
    fam = family_benchmark_summary(jobs).set_index("family")
    assert fam.loc["data", "jobs"] == 3
    assert fam.loc["data", "wall_s"] == pytest.approx(4.5)
    assert fam.loc["data", "cpu_s"] == pytest.approx(4.5)
    assert fam.loc["data", "peak_rss_mb"] == pytest.approx(120)


def test_summary_renders_tables_and_verdicts(tmp_path):
    t = tmp_path / "t.csv"
    pd.DataFrame({"dataset": ["w1"], "error_a": [0.0123]}).to_csv(t, index=False)
    v = tmp_path / "simplicial" / "verdicts.csv"
    v.parent.mkdir()
    row = {"claim": "Delaunay beats k-NN", "paper_value": "", "ours": "", "data": "", "verdict": "partly",
           "evidence": "p=0.2", "source": ""}
    pd.DataFrame([row]).to_csv(v, index=False)
    md = build_summary([{"title": "Table II", "csv": str(t), "note": "synthetic"}], [v], "Data: synthetic.",
                       family_data={"simplicial": "synthetic mocap"}, family_real={"simplicial": False})
    assert md.index("## Claims of the four papers") < md.index("## Table II")
    assert "| [S1](#claim-s1) | Gauch & Peters | Delaunay beats k-NN |  |  | **partly** |" in md
    assert "**Data:** synthetic mocap (synthetic data)" in md  # what it ran on: in the family's section
    assert "## Table II" in md and "| w1 | 0.0123 |" in md
    # a word outside the vocabulary is refused, naming the file and line
    pd.DataFrame([{**row, "verdict": "no"}]).to_csv(v, index=False)
    with pytest.raises(VerdictError, match=r"verdicts.csv, line 2: verdict 'no'"):
        claims_table([v], family_real={"simplicial": False})
    bad = tmp_path / "x" / "verdicts.csv"
    bad.parent.mkdir()
    pd.DataFrame({"claim": ["c"]}).to_csv(bad, index=False)
    with pytest.raises(VerdictError, match="missing"):
        claims_table([bad], family_real={"x": True})


def _verdicts(tmp_path, family, rows):
    p = tmp_path / family / "verdicts.csv"
    p.parent.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(rows).to_csv(p, index=False)
    return p


def test_claims_put_real_data_first_and_link_unique_report_files(tmp_path):
    face = _verdicts(tmp_path, "facegraph", [
        {"claim": "duration difference near 0", "paper_value": "0-0.11", "ours": "0.02", "data": "synthetic CK+-layout",
         "verdict": "reproduced", "evidence": "e", "source": "facegraph/table1.csv"}])
    simp = _verdicts(tmp_path, "simplicial", [
        {"claim": "Delaunay better in 5 of 8 cells", "paper_value": "5/8", "ours": "3/8", "data": "CMU w1 w2 r1 r2",
         "verdict": "not reproduced", "evidence": "e", "source": "simplicial/table2.csv"},
        {"claim": "overall median A", "paper_value": "0.068 vs 0.079", "ours": "0.05 vs 0.04", "data": "",
         "verdict": "contradicted", "evidence": "e", "source": "simplicial/verdicts.csv"}])
    claims = claims_table([face, simp], {"simplicial": "CMU mocap from mirror"},
                          family_real={"simplicial": True, "facegraph": False})
    assert list(claims["family"]) == ["simplicial", "simplicial", "facegraph"]
    assert list(claims["real"]) == [True, True, False]
    assert claims.loc[1, "data"] == "CMU mocap from mirror"  # empty data filled from the family's source
    prov = pd.DataFrame([{"family": "simplicial", "data": "CMU", "status": "ran"},
                         {"family": "meshdetail", "data": "samba", "status": "skipped: absent"}])
    rst = claims_rst(claims, prov, ["results/paper/simplicial/table2.csv", "results/paper/simplicial/verdicts.csv",
                                    "results/paper/facegraph/verdicts.csv", "results/paper/facegraph/table1.csv"])
    assert "`table2.csv`_" in rst and "`table1.csv`_" in rst
    assert "``simplicial/verdicts.csv``" in rst  # verdicts.csv is not unique in the report: no link
    assert rst.index("Claims on real data") < rst.index("Claims on synthetic data")
    assert "skipped: absent" in rst
    # it is valid reStructuredText once the report's link targets are appended
    from docutils.core import publish_parts
    from docutils.utils import Reporter

    targets = "\n.. _table2.csv: javascript:void(0)\n.. _table1.csv: javascript:void(0)\n"
    html = publish_parts(rst + targets, writer="html",
                         settings_overrides={"report_level": Reporter.WARNING_LEVEL, "halt_level": Reporter.WARNING_LEVEL})
    assert html["html_body"].count("<tr>") == 5  # two tables: header + 2 rows, header + 1 row
