"""Config values that used to hang validation, pass unchecked or ask for
tens of GiB: refused before anything runs, naming the key."""

import os
import time

import pytest
import yaml

from animsynth.config import ConfigError, check_config, validate_config
from conftest import REPO, copy_workflow, run_snakemake

SCHEMA = str(REPO / "config" / "schema.yaml")

LAUGHS = """a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]
b: &b [*a,*a,*a,*a,*a,*a,*a,*a,*a]
c: &c [*b,*b,*b,*b,*b,*b,*b,*b,*b]
d: &d [*c,*c,*c,*c,*c,*c,*c,*c,*c]
e: &e [*d,*d,*d,*d,*d,*d,*d,*d,*d]
f: &f [*e,*e,*e,*e,*e,*e,*e,*e,*e]
g: &g [*f,*f,*f,*f,*f,*f,*f,*f,*f]
h: &h [*g,*g,*g,*g,*g,*g,*g,*g,*g]
i: &i [*h,*h,*h,*h,*h,*h,*h,*h,*h]
"""


def default_config():
    return yaml.safe_load((REPO / "config" / "config.yaml").read_text())


def test_billion_laughs_is_refused_at_once():
    cfg = default_config()
    cfg.update(yaml.safe_load(LAUGHS))
    t0 = time.perf_counter()
    with pytest.raises(ConfigError, match="YAML aliases"):
        validate_config(cfg, SCHEMA)
    assert time.perf_counter() - t0 < 5


def test_recursive_alias_is_refused():
    cfg = default_config()
    cfg["note"] = yaml.safe_load("a: &a [1, *a]")
    with pytest.raises(ConfigError, match="recursive"):
        validate_config(cfg, SCHEMA)


@pytest.mark.workflow
def test_billion_laughs_configfile_stops_the_workflow_quickly(tmp_path):
    wd = copy_workflow(tmp_path / "wf")
    (wd / "config" / "laughs.yaml").write_text(LAUGHS)
    t0 = time.perf_counter()
    res = run_snakemake(wd, "-n", "--configfile", "config/laughs.yaml", timeout=120)
    assert res.returncode != 0 and "YAML aliases" in res.stdout + res.stderr
    assert time.perf_counter() - t0 < 60


@pytest.mark.parametrize("key,value", [("fps", 1e308), ("fps", 0.001), ("fps", 1e9)])
def test_fps_is_bounded(key, value):
    cfg = default_config()
    cfg[key] = value
    with pytest.raises(ConfigError, match="'fps'"):
        validate_config(cfg, SCHEMA)


def test_trial_frames_are_bounded():
    cfg = default_config()
    cfg["trials"][0]["frames"] = 10**9
    with pytest.raises(ConfigError, match=r"trials\[0\]\.frames"):
        validate_config(cfg, SCHEMA)


def test_synthetic_trial_over_the_memory_budget_is_refused():
    cfg = default_config()
    validate_config(cfg, SCHEMA)
    cfg["trials"][0]["frames"] = 1_000_000
    cfg["memory_budget_gib"] = 0.5
    with pytest.raises(ConfigError, match=r"trials\[0\]\.frames.*GiB.*memory budget of 0.5 GiB"):
        check_config(cfg)


@pytest.mark.parametrize("rd", ["/", "..", ".", "../elsewhere", "/tmp/x", os.path.expanduser("~")])
def test_results_dir_outside_the_project_is_refused(rd):
    cfg = default_config()
    cfg["results_dir"] = rd
    validate_config(cfg, SCHEMA)
    with pytest.raises(ConfigError, match="results_dir"):
        check_config(cfg)


def test_results_dir_outside_the_project_when_named_explicitly(tmp_path):
    cfg = default_config()
    cfg.update(results_dir=str(tmp_path / "runs"), results_outside_project=True)
    validate_config(cfg, SCHEMA)
    check_config(cfg)
    for bad in ("/", os.path.expanduser("~"), str(REPO.parent)):
        cfg["results_dir"] = bad
        with pytest.raises(ConfigError, match="results_dir"):
            check_config(cfg)


def test_results_dir_inside_the_project_is_fine():
    cfg = default_config()
    cfg["results_dir"] = "results/paper"
    validate_config(cfg, SCHEMA)
    check_config(cfg)


def test_joint_roles_key_is_validated():
    cfg = default_config()
    cfg["joint_roles"] = {"left_knee": "Knee_L"}
    validate_config(cfg, SCHEMA)
    cfg["joint_roles"] = {"left_kne": "Knee_L"}
    with pytest.raises(ConfigError, match="left_kne"):
        validate_config(cfg, SCHEMA)
