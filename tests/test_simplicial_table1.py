"""Gauch & Peters Table I (results/data/datasets.csv), the published lengths beside ours, and the simplicial
config checks (animsynth.simplicial.settings.check)."""

from __future__ import annotations

import copy

import pandas as pd
import pytest

from animsynth.config import ConfigError
from animsynth.published import PublishedError
from animsynth.simplicial.jobs import table1_job
from animsynth.simplicial.settings import check, check_figure_folds, read_paper_table1
from animsynth.simplicial.table1 import datasets_table, length_match
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion


def _motions(n=4):
    sk = cmu_like_skeleton("s", 1)
    return {f"t{i}": generate_motion("walk_straight", 50 + i, i, sk) for i in range(n)}


def test_datasets_table_layout():
    motions = _motions()
    df = datasets_table({"w1": ["t0", "t1"], "w2": ["t2", "t3"]}, motions, "synthetic")
    assert list(df.columns) == ["dataset", "source", "trials", "dims", "n_sequences", "lengths", "total_nodes"]
    assert df.loc[0, "trials"] == "t0 t1" and df.loc[0, "lengths"] == "50 51" and df.loc[0, "total_nodes"] == 101
    assert (df["dims"] == 56).all()
    # with published lengths: the paper's beside ours and the difference; empty for a subset the paper lacks
    dp = datasets_table({"w1": ["t0", "t1"], "w2": ["t2", "t3"]}, motions, "synthetic", paper={"w1": [50, 60]})
    assert dp.loc[0, "paper_total_nodes"] == 110 and dp.loc[0, "total_nodes_minus_paper"] == 101 - 110
    assert pd.isna(dp.loc[1, "total_nodes_minus_paper"])
    assert "t1 (51) for 60" in dp.loc[0, "length_match"]
    # published table given but empty (no file): the columns exist and stay empty
    de = datasets_table({"w1": ["t0", "t1"]}, motions, "synthetic", paper={})
    assert de.loc[0, "paper_lengths"] == "" and pd.isna(de.loc[0, "paper_total_nodes"])


def test_length_match_names_matches_and_stand_ins():
    assert length_match(["a", "b"], [10, 20], [10, 20]) == "all 2 match"
    assert length_match(["a", "b"], [10, 21], [10, 20]) == "match: a (10); stand-ins: b (21) for 20"
    assert "paper lists 3 sequences, we use 2" in length_match(["a", "b"], [10, 20], [10, 20, 30])


def test_read_paper_table1(tmp_path, caplog):
    p = tmp_path / "t1.csv"
    p.write_text("dataset,dims,n_sequences,lengths,total_nodes\nw1,56,2,400 350,750\nr1,56,1,150,150\n")
    assert read_paper_table1(p) == {"w1": [400, 350], "r1": [150]}
    with caplog.at_level("WARNING", logger="animsynth.published"):
        assert read_paper_table1(tmp_path / "absent.csv") is None
    assert "absent.csv" in caplog.text and "published.simplicial.table1" in caplog.text
    bad = tmp_path / "bad.csv"
    bad.write_text("dataset,lengths\nw1,400 350\nw2,300 x\n")
    with pytest.raises(PublishedError, match=r"bad.csv, line 3: lengths must be integers"):
        read_paper_table1(bad)
    nocol = tmp_path / "nocol.csv"
    nocol.write_text("dataset,frames\nw1,400\n")
    with pytest.raises(PublishedError, match=r"nocol.csv, line 1: .*lacks column\(s\) \['lengths'\]"):
        read_paper_table1(nocol)


def test_table1_job_writes_the_table_with_and_without_the_published_file(tmp_path):
    motions = _motions(2)
    paths = []
    for tid, m in motions.items():
        paths.append(tmp_path / f"{tid}.npz")
        m.save_npz(paths[-1])
    pub = tmp_path / "s1_table1.csv"
    pub.write_text("dataset,lengths\nw1,50 60\n")
    out = {"csv": str(tmp_path / "with" / "datasets.csv")}
    table1_job(paths, {"w1": ["t0", "t1"]}, "synthetic", out, paper_table1=pub, paper_label="../papers/s1_table1.csv")
    df = pd.read_csv(out["csv"], keep_default_na=False)
    assert df.loc[0, "paper_lengths"] == "50 60" and df.loc[0, "total_nodes_minus_paper"] == 101 - 110
    md = (tmp_path / "with" / "datasets.md").read_text()
    assert "read from ../papers/s1_table1.csv" in md and "w1: match: t0 (50); stand-ins: t1 (51) for 60" in md
    out = {"csv": str(tmp_path / "without" / "datasets.csv")}
    table1_job(paths, {"w1": ["t0", "t1"]}, "synthetic", out, paper_table1=None, paper_label="../papers/s1_table1.csv")
    df = pd.read_csv(out["csv"])
    assert df[["paper_total_nodes", "total_nodes_minus_paper"]].isna().all().all()
    assert "No published Table I at '../papers/s1_table1.csv'" in (tmp_path / "without" / "datasets.md").read_text()


@pytest.fixture
def simplicial_config():
    import yaml

    from animsynth.config import validate_config
    from conftest import REPO

    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    validate_config(cfg, str(REPO / "config" / "schema.yaml"))
    return cfg


def test_check_accepts_the_default_config(simplicial_config):
    check(simplicial_config)


@pytest.mark.parametrize("change,key", [
    (lambda c: c["simplicial"]["figures"].update(dataset="w9"), "simplicial.figures.dataset"),
    (lambda c: c["subsets"].update(w1=None), "simplicial.figures.dataset"),  # a null subset is not in use
])
def test_check_names_the_config_key(simplicial_config, change, key):
    cfg = copy.deepcopy(simplicial_config)
    change(cfg)
    with pytest.raises(ConfigError, match=rf"config key '{key}'"):
        check(cfg)


@pytest.mark.parametrize("fig, key", [({"folds": [0, 4]}, "folds"), ({"field_fold": 9}, "field_fold"),
                                      ({"walk_fold": 4}, "walk_fold")])
def test_figure_folds_outside_the_subset_name_the_key(simplicial_config, fig, key):
    figures = {**simplicial_config["simplicial"]["figures"], **fig}
    with pytest.raises(ConfigError, match=rf"config key 'simplicial.figures.{key}'"):
        check_figure_folds(figures, 4, "w1")


def test_short_subsets_pass_the_parse_time_check(simplicial_config):
    # a user's two-trial subset must not stop the run's other jobs because of the figures' default folds
    cfg = copy.deepcopy(simplicial_config)
    cfg["subsets"]["w1"] = cfg["subsets"]["w1"][:2]
    check(cfg)


def test_figure_fold_outside_the_subset_is_refused_by_the_job_too(tmp_path):
    from animsynth.simplicial.jobs import walk_job

    motions = _motions(2)
    paths = []
    for tid, m in motions.items():
        paths.append(tmp_path / f"{tid}.npz")
        m.save_npz(paths[-1])
    fig = {"folds": [0], "field_fold": 0, "walk_fold": 2, "walk_method": "delaunay", "gif_fps": 30}
    with pytest.raises(ConfigError, match=r"'simplicial.figures.walk_fold': fold index 2 outside 0..1"):
        walk_job(paths, ["t0", "t1"], "w1", {"figures": fig}, {})

