"""Workflow tests of the facegraph family (tiny config)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from animsynth.facegraph.jobs import TABLE1_COLUMNS
from animsynth.verdicts import VOCABULARY


OUTPUTS = [
    "results/facegraph/database.csv", "results/facegraph/table1.csv", "results/facegraph/table1.md",
    "results/facegraph/table1_timing.csv", "results/facegraph/baseline_timing.csv",
    "results/facegraph/thresholds.csv", "results/facegraph/baseline.csv", "results/facegraph/uniqueness.csv",
    "results/facegraph/uniqueness_pairs.csv", "results/facegraph/region_graphs.png",
    "results/facegraph/trajectories.png", "results/facegraph/sequence.gif", "results/facegraph/verdicts.csv",
]


@pytest.mark.workflow
def test_tiny_workflow_facegraph_outputs(tiny_workflow):
    wd = tiny_workflow
    missing = [p for p in OUTPUTS if not (wd / p).exists()]
    assert not missing, missing
    # synthetic CK+ layout generated and parsed
    assert (wd / "results/resources/facegraph/ckplus_synthetic/Landmarks").is_dir()
    db = pd.read_csv(wd / "results/facegraph/database.csv")
    assert db.used.sum() == 14 and (db.emotion.fillna("") == "").sum() == 1
    t1 = pd.read_csv(wd / "results/facegraph/table1.csv")
    assert list(t1.columns) == TABLE1_COLUMNS
    assert t1.config.tolist() == ["c0.2t0.1_m0.5t0.3", "c0.5t0.1_m0.8t0.1"]
    assert t1.creation_target.tolist() == [0.2, 0.5] and t1.merge_tolerance.tolist() == [0.3, 0.1]
    assert (t1.nodes.diff().dropna() < 0).all()  # more compression, fewer nodes
    assert (t1.node_compression_pct == (100 * (1 - t1.nodes / t1.poses)).round(4)).all()
    assert t1.duration_diff.max() < t1.random_duration_diff.min()  # stored durations beat a random peak's
    # ours - paper beside every published column (the tiny configs are among the paper's 15; the run sees
    # the published Table 1 at ../shared/papers, tests/papers/s4_table1.csv)
    paper = pd.read_csv(wd / "../shared/papers/s4_table1.csv")
    for k, pk in (("node_compression_pct", "nodes_compression_pct"), ("landmark_diff_px", "landmark_diff_px"),
                  ("velocity_angle_diff_pct", "velocity_angle_diff_pct")):
        assert t1["paper_" + k].notna().all() and t1[k + "_minus_paper"].notna().all()
        assert set(t1["paper_" + k]) <= set(paper[pk].astype(float))
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
    assert set(v.verdict) <= set(VOCABULARY)
    assert all((wd / "results" / src).exists() for src in v.source)


@pytest.mark.workflow
def test_without_published_table_the_paper_columns_are_empty(tiny_workflow, tiny_without_papers):
    """A bare copy of the project (no ../shared/papers): Table 1 is rebuilt with empty paper_* and
    difference columns, and ours unchanged."""
    with_paper = pd.read_csv(tiny_workflow / "results/facegraph/table1.csv")
    t1 = pd.read_csv(tiny_without_papers / "results/facegraph/table1.csv")
    assert list(t1.columns) == TABLE1_COLUMNS
    paper_cols = [c for c in t1.columns if c.startswith("paper_") or c.endswith("_minus_paper")]
    assert len(paper_cols) >= 6 and t1[paper_cols].isna().all().all()
    assert with_paper[paper_cols].notna().any().all()
    ours = [c for c in t1.columns if c not in paper_cols]
    pd.testing.assert_frame_equal(t1[ours], with_paper[ours])
