"""Workflow tests of the facegraph family (tiny config)."""

from __future__ import annotations

import pandas as pd
import pytest

from animsynth.facegraph.experiments import TABLE1_COLUMNS

from conftest import copy_workflow, run_snakemake

OUTPUTS = [
    "results/facegraph/database.csv", "results/facegraph/table1.csv", "results/facegraph/table1.md",
    "results/facegraph/thresholds.csv", "results/facegraph/baseline.csv", "results/facegraph/uniqueness.csv",
    "results/facegraph/uniqueness_pairs.csv", "results/facegraph/region_graphs.png",
    "results/facegraph/trajectories.png", "results/facegraph/sequence.gif", "results/facegraph/verdicts.csv",
]
TABLES = ["table1.csv", "thresholds.csv", "baseline.csv", "uniqueness.csv", "uniqueness_pairs.csv", "verdicts.csv",
          "database.csv"]


def _deterministic(path):
    df = pd.read_csv(path, keep_default_na=False)
    return df[[c for c in df.columns if not c.startswith("timing_")]]


@pytest.mark.workflow
def test_tiny_workflow_facegraph_outputs(tiny_workflow, tmp_path):
    wd = tiny_workflow
    missing = [p for p in OUTPUTS if not (wd / p).exists()]
    assert not missing, missing
    # synthetic CK+ layout generated and parsed
    assert (wd / "resources/facegraph/ckplus_synthetic/Landmarks").is_dir()
    db = pd.read_csv(wd / "results/facegraph/database.csv")
    assert db.used.sum() == 14 and (db.emotion.fillna("") == "").sum() == 1
    t1 = pd.read_csv(wd / "results/facegraph/table1.csv")
    assert list(t1.columns) == TABLE1_COLUMNS and t1.config.tolist() == ["c50_m30", "c50_m70"]
    assert t1.thresholds_converged.all()
    assert (t1.nodes.diff().dropna() < 0).all()  # more merge compression, fewer nodes
    assert "synthetic CK+-layout data, not the paper's CK+ data" in (wd / "results/facegraph/table1.md").read_text()
    base = pd.read_csv(wd / "results/facegraph/baseline.csv")
    assert base.method.str.startswith("face graph").sum() == 4 and base.queries.eq(4).all()
    u = pd.read_csv(wd / "results/facegraph/uniqueness.csv")
    assert u.distinct.iloc[0] == 1 and u.runs.eq(4).all()
    assert (wd / "results/facegraph/sequence.gif").read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    v = pd.read_csv(wd / "results/facegraph/verdicts.csv")
    assert list(v.columns) == ["claim", "verdict", "evidence"] and len(v) == 6
    # an independent second run of the facegraph targets gives identical tables (timings aside)
    wd2 = copy_workflow(tmp_path / "again")
    # targets before --configfile, which takes several values
    res = run_snakemake(wd2, "results/facegraph/verdicts.csv", "results/facegraph/thresholds.csv",
                        "results/facegraph/uniqueness_pairs.csv", "--configfile", "config/test.yaml")
    assert res.returncode == 0, res.stderr[-4000:]
    for name in TABLES:
        pd.testing.assert_frame_equal(_deterministic(wd / "results/facegraph" / name),
                                      _deterministic(wd2 / "results/facegraph" / name))
    assert (wd / "results/facegraph/uniqueness.csv").read_bytes() == (wd2 / "results/facegraph/uniqueness.csv").read_bytes()
