"""Workflow and real-data tests of the simplicial family."""

from __future__ import annotations

import json
import re
import shutil
import subprocess

import numpy as np
import pandas as pd
import pytest

from animsynth.simplicial import folds as fl
from animsynth.verdicts import COLUMNS, VOCABULARY
from conftest import SAFETY_TIMEOUT, SNAKEMAKE, copy_workflow, place_papers

OUTPUTS = [
    "results/simplicial/folds.csv", "results/simplicial/table2.csv", "results/simplicial/table2.md",
    "results/simplicial/table2_ensemble.csv", "results/simplicial/fold_ensemble.csv", "results/simplicial/members.csv",
    "results/simplicial/paired.csv", "results/simplicial/derivative.csv", "results/simplicial/beyond.csv",
    "results/simplicial/verdicts.csv",
] + [f"results/simplicial/figures/fig{n}_{w}.png" for n, w in (
    (1, "graph_knn"), (2, "graph_delaunay"), (3, "field_knn"), (4, "field_delaunay"), (5, "paths_knn"),
    (6, "paths_delaunay"), (7, "walk"))] + ["results/simplicial/figures/fig7_walk.gif",
                                           "results/simplicial/figures/fig7_walk.bvh"]


@pytest.mark.workflow
def test_tiny_workflow_simplicial_outputs(tiny_workflow):
    wd = tiny_workflow
    missing = [p for p in OUTPUTS if not (wd / p).exists()]
    assert not missing, missing
    folds = pd.read_csv(wd / "results/simplicial/folds.csv")
    assert list(folds.columns) == fl.FOLD_COLUMNS
    # one JSON per dataset, holding every leave-one-out fold of its subset (3 trials each in the tiny config)
    jsons = sorted((wd / "results/simplicial/folds").glob("*.json"))
    assert [p.stem for p in jsons] == sorted(["w1", "w2", "r1", "r2"])
    n_folds = sum(len({r["held_out"] for r in json.loads(p.read_text())["rows"]}) for p in jsons)
    assert n_folds == 12
    assert len(folds) == 2 * n_folds and set(folds["method"]) == {"delaunay", "knn"}
    assert np.isfinite(folds[["error_a", "error_f", "error_a_norm", "error_f_norm"]].to_numpy(float)).all()
    members = pd.read_csv(wd / "results/simplicial/members.csv")
    assert len(members) == len(folds) * int(folds["n_members"].iloc[0]) and folds["n_members"].iloc[0] > 1
    t2 = pd.read_csv(wd / "results/simplicial/table2.csv")
    assert t2[["metric", "method"]].values.tolist() == [["error_a", "delaunay"], ["error_a", "knn"],
                                                        ["error_f", "delaunay"], ["error_f", "knn"]]
    subsets = [c for c in t2.columns[2:] if not c.startswith("paper_") and not c.endswith("_minus_paper")]
    assert subsets[-1] == "all"
    assert list(t2.columns[2:]) == subsets + [f"paper_{d}" for d in subsets] + [f"{d}_minus_paper" for d in subsets]
    # the run sees the published Table II at ../shared/papers (tests/papers/s1_table2.csv): ours - paper
    paper = pd.read_csv(wd / "../shared/papers/s1_table2.csv").replace({"method": {"knn16": "knn"}})
    want = t2[["metric", "method"]].merge(paper, on=["metric", "method"], how="left")
    for d in subsets:
        np.testing.assert_allclose(t2[f"paper_{d}"], want[d], rtol=0, atol=1e-12)
        assert t2[f"{d}_minus_paper"].notna().all()
        np.testing.assert_allclose(t2[f"{d}_minus_paper"], t2[d] - t2[f"paper_{d}"], rtol=0, atol=1e-5)
    v = pd.read_csv(wd / "results/simplicial/verdicts.csv")
    assert list(v.columns) == list(COLUMNS) and len(v) >= 8
    assert set(v["verdict"]) <= set(VOCABULARY)
    assert not v["evidence"].str.contains("not available").any()
    row = json.loads(next((wd / "results/simplicial/folds").glob("*.json")).read_text())
    assert set(row["rows"][0]) == set(fl.FOLD_COLUMNS) and set(row["members"][0]) == set(fl.MEMBER_COLUMNS)
    assert (wd / "results/simplicial/figures/fig7_walk.bvh").read_text().startswith("HIERARCHY")


@pytest.mark.workflow
def test_without_published_table_the_paper_columns_are_empty(tiny_workflow, tiny_without_papers):
    """A bare copy of the project (no ../shared/papers): Table II is rebuilt with empty paper_* and
    difference columns, and ours unchanged."""
    with_paper = pd.read_csv(tiny_workflow / "results/simplicial/table2.csv")
    t2 = pd.read_csv(tiny_without_papers / "results/simplicial/table2.csv")
    assert list(t2.columns) == list(with_paper.columns)
    paper_cols = [c for c in t2.columns if c.startswith("paper_") or c.endswith("_minus_paper")]
    assert len(paper_cols) >= 4 and t2[paper_cols].isna().all().all()
    assert with_paper[paper_cols].notna().all().all()
    ours = [c for c in t2.columns if c not in paper_cols]
    pd.testing.assert_frame_equal(t2[ours], with_paper[ours])
    # and Table I of the data layer: no published lengths beside ours
    ds = pd.read_csv(tiny_without_papers / "results/data/datasets.csv")
    ds_paper = pd.read_csv(tiny_workflow / "results/data/datasets.csv")
    extra = [c for c in ds.columns if "paper" in c]
    assert extra and ds[extra].isna().all().all() and ds_paper[extra].notna().any().all()


def _dry_run_inputs(project, workdir) -> dict:
    """Rule name -> input line of each simplicial job that shows published values, from a dry run of
    ``project``'s workflow in another working directory (``--directory``)."""
    cfg = [str(project / "config" / "config.yaml"), str(project / "config" / "test.yaml")]
    res = subprocess.run([SNAKEMAKE, "-n", "-s", str(project / "Snakefile"), "--directory", str(workdir),
                          "results/data/datasets.csv", "results/simplicial/verdicts.csv", "--configfile", *cfg],
                         cwd=workdir, capture_output=True, text=True, timeout=SAFETY_TIMEOUT)
    assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]
    jobs = dict(re.findall(r"^rule (simplicial_table1|simplicial_table|simplicial_summary):\n\s+input: (.*)$",
                           res.stdout, re.M))
    assert sorted(jobs) == ["simplicial_summary", "simplicial_table", "simplicial_table1"], res.stdout[-3000:]
    return jobs


@pytest.mark.workflow
def test_published_tables_are_found_from_another_working_directory(tmp_path):
    """published.simplicial.table1/table2 are resolved against the workflow's own folder, not the working
    directory: a run with --directory elsewhere still declares them as inputs of the jobs that fill the
    paper_* columns; without the files the same jobs run with no such input (and empty columns)."""
    project = copy_workflow(tmp_path / "project")
    papers = place_papers(project)  # <project>/../shared/papers, as the default config names them
    elsewhere = tmp_path / "other" / "run"
    elsewhere.mkdir(parents=True)
    assert not (elsewhere / "../shared/papers").exists()  # resolved against the working directory: nothing
    jobs = _dry_run_inputs(project, elsewhere)
    assert str(papers / "s1_table1.csv") in jobs["simplicial_table1"]
    assert str(papers / "s1_table2.csv") in jobs["simplicial_table"]
    assert str(papers / "s1_table2.csv") in jobs["simplicial_summary"]
    shutil.rmtree(papers)
    jobs = _dry_run_inputs(project, elsewhere)
    assert not any("s1_table" in line for line in jobs.values()), jobs


@pytest.mark.realdata
def test_real_cmu_runs_fold(cmu_dir):
    """Subject 35 running (r1): real data has repeated frames (duplicate latent points) - handled, logged."""
    from animsynth.io import read_amc, read_asf

    sk = read_asf(cmu_dir / "35" / "35.asf")
    ids = ["35_17", "35_22", "35_18", "35_19"]
    trials = {t: read_amc(cmu_dir / "35" / f"{t}.amc", sk).without_root() for t in ids}
    assert all(a.shape[1] == 56 for a in trials.values())
    res = fl.run_fold([trials[t] for t in ids[1:]], trials[ids[0]], fl.Variant("delaunay"), dataset="r1",
                      held_out=ids[0])
    r = res.row
    assert r["steps"] == trials[ids[0]].shape[0] and np.isfinite(r["error_a"]) and r["error_a"] > 0
    assert r["n_duplicates"] >= 0 and r["tri_status"] in ("ok", "joggled")
