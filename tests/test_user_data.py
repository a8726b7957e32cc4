"""'Your own data': the worked example config runs on a copy of a few CMU trials."""

import shutil

import pandas as pd
import pytest
import yaml

from conftest import REPO, copy_workflow, run_snakemake

pytestmark = [pytest.mark.workflow, pytest.mark.realdata]


def test_user_example_config_runs_on_a_copy_of_cmu_trials(tmp_path, cmu_dir):
    cfg = yaml.safe_load((REPO / "config" / "user_example.yaml").read_text())
    data = tmp_path / "my_mocap"
    for t in cfg["trials"]:
        for key in ("amc", "asf"):
            dest = data / t[key]
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(cmu_dir.parent / t[key], dest)
    wd = copy_workflow(tmp_path / "wf")
    res = run_snakemake(wd, "--configfile", "config/user_example.yaml", "--until", "simplicial_table1",
                        "--config", f"data_dir={data}")
    assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]
    df = pd.read_csv(wd / "results" / "data" / "datasets.csv")
    assert list(df["dataset"]) == ["w1", "r1"]
    assert df.loc[0, "lengths"] == "358 406 427" and df.loc[1, "lengths"] == "167 175 160"
    assert set(df["source"]) == {"user"}
    # the whole DAG (every mocap experiment) resolves on user data
    res = run_snakemake(wd, "-n", "--configfile", "config/user_example.yaml", "--config", f"data_dir={data}")
    assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]


def test_user_file_missing_is_a_clear_error(tmp_path, cmu_dir):
    wd = copy_workflow(tmp_path / "wf")
    (tmp_path / "empty").mkdir()
    res = run_snakemake(wd, "--configfile", "config/user_example.yaml", "--until", "simplicial_table1",
                        "--config", f"data_dir={tmp_path / 'empty'}")
    assert res.returncode != 0
    logs = "".join(p.read_text() for p in (wd / "logs").rglob("*.log"))
    assert "cannot read" in logs and "subjects/35/35.asf" in logs
