"""Workflow tests of the facegraph family (tiny config)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from animsynth.facegraph.experiments import TABLE1_COLUMNS

from conftest import copy_workflow, run_snakemake

OUTPUTS = [
    "results/facegraph/database.csv", "results/facegraph/table1.csv", "results/facegraph/table1.md",
    "results/facegraph/table1_timing.csv", "results/facegraph/baseline_timing.csv",
    "results/facegraph/thresholds.csv", "results/facegraph/baseline.csv", "results/facegraph/uniqueness.csv",
    "results/facegraph/uniqueness_pairs.csv", "results/facegraph/region_graphs.png",
    "results/facegraph/trajectories.png", "results/facegraph/sequence.gif", "results/facegraph/verdicts.csv",
]
TABLES = ["table1.csv", "thresholds.csv", "baseline.csv", "uniqueness.csv", "uniqueness_pairs.csv", "verdicts.csv",
          "database.csv"]


def _deterministic(path):
    return pd.read_csv(path, keep_default_na=False)   # result tables hold no timings (those are in *_timing.csv)


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
    assert list(t1.columns) == TABLE1_COLUMNS
    assert t1.config.tolist() == ["c0.2t0.1_m0.5t0.3", "c0.5t0.1_m0.8t0.1"]
    assert t1.creation_target.tolist() == [0.2, 0.5] and t1.merge_tolerance.tolist() == [0.3, 0.1]
    assert (t1.nodes.diff().dropna() < 0).all()  # more compression, fewer nodes
    assert (t1.node_compression_pct == (100 * (1 - t1.nodes / t1.poses)).round(4)).all()
    assert t1.duration_diff.max() < t1.random_duration_diff.min()  # stored durations beat a random peak's
    # ours - paper beside every published column (the tiny configs are among the paper's 15); without
    # ../shared/papers (a bare copy of the project) the paper's columns and the differences are empty
    published = (wd / "../shared/papers/s4_table1.csv").exists()
    for k in ("node_compression_pct", "landmark_diff_px", "velocity_angle_diff_pct"):
        assert t1["paper_" + k].notna().all() == published and t1["paper_" + k].isna().all() != published
        np.testing.assert_allclose(t1[k + "_minus_paper"], t1[k] - t1["paper_" + k], atol=1e-4)
    tm = pd.read_csv(wd / "results/facegraph/table1_timing.csv")
    assert tm.config.tolist() == t1.config.tolist() and (tm.creation_cpu_s > 0).all()
    md = (wd / "results/facegraph/table1.md").read_text()
    assert "synthetic CK+-layout data, not the paper's CK+ data" in md and "creation_cpu_s" in md
    base = pd.read_csv(wd / "results/facegraph/baseline.csv")
    assert base.method.str.startswith("face graph").sum() == 4 and base.queries.eq(4).all()
    assert not any(c.startswith("timing") for c in base.columns)
    u = pd.read_csv(wd / "results/facegraph/uniqueness.csv")
    assert u.distinct.iloc[0] == 1 and u.runs.eq(4).all()
    assert (wd / "results/facegraph/sequence.gif").read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    v = pd.read_csv(wd / "results/facegraph/verdicts.csv")
    assert list(v.columns) == ["claim", "paper_value", "ours", "data", "verdict", "evidence", "source"]
    assert set(v.verdict) <= {"reproduced", "partly", "not reproduced", "contradicted", "within noise"}
    assert all((wd / "results" / src).exists() for src in v.source)
    # an independent second run of the facegraph targets gives identical tables (timings aside)
    wd2 = copy_workflow(tmp_path / "again")
    # targets before --configfile, which takes several values
    res = run_snakemake(wd2, "results/facegraph/verdicts.csv", "results/facegraph/thresholds.csv",
                        "results/facegraph/uniqueness_pairs.csv", "--configfile", "config/test.yaml")
    assert res.returncode == 0, res.stderr[-4000:]
    for name in TABLES:  # every result table is deterministic
        pd.testing.assert_frame_equal(_deterministic(wd / "results/facegraph" / name),
                                      _deterministic(wd2 / "results/facegraph" / name))
    assert (wd / "results/facegraph/uniqueness.csv").read_bytes() == (wd2 / "results/facegraph/uniqueness.csv").read_bytes()
