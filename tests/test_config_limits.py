"""Config values that used to hang validation, pass unchecked or ask for
tens of GiB: refused before anything runs, naming the key."""

import importlib.util
import re
import os

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


# the same expansion through dictionaries: Snakemake's merge of a --configfile
# walks every one of them before the Snakefile runs
DICT_LAUGHS = "a: &a {x1: lol, x2: lol, x3: lol, x4: lol, x5: lol, x6: lol, x7: lol, x8: lol, x9: lol}\n" + "".join(
    f"{n}: &{n} {{" + ", ".join(f"x{k}: *{p}" for k in range(1, 10)) + "}\n" for p, n in zip("abcdefgh", "bcdefghi"))
# and through merge keys, which a YAML loader expands while constructing
MERGE_LAUGHS = "a: &a {x1: lol, x2: lol, x3: lol, x4: lol, x5: lol, x6: lol, x7: lol, x8: lol, x9: lol}\n" + "".join(
    f"{n}: &{n} {{<<: [" + ", ".join(f"*{p}" for _ in range(9)) + "], y: 1}\n" for p, n in zip("abcdefgh", "bcdefghi"))


def _run_py():
    spec = importlib.util.spec_from_file_location("run_py", REPO / "run.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def default_config():
    return yaml.safe_load((REPO / "config" / "config.yaml").read_text())


def test_billion_laughs_is_refused_at_once():
    cfg = default_config()
    cfg.update(yaml.safe_load(LAUGHS))
    with pytest.raises(ConfigError, match="YAML aliases"):
        validate_config(cfg, SCHEMA)


def test_recursive_alias_is_refused():
    cfg = default_config()
    cfg["note"] = yaml.safe_load("a: &a [1, *a]")
    with pytest.raises(ConfigError, match="recursive"):
        validate_config(cfg, SCHEMA)


@pytest.mark.workflow
def test_billion_laughs_configfile_stops_the_workflow_quickly(tmp_path):
    wd = copy_workflow(tmp_path / "wf")
    (wd / "config" / "laughs.yaml").write_text(LAUGHS)
    res = run_snakemake(wd, "-n", "--configfile", "config/laughs.yaml")
    assert res.returncode != 0 and "YAML aliases" in res.stdout + res.stderr


def test_run_py_finds_every_configfile():
    args = ["--cores", "2", "--configfile", "a.yaml", "b.yaml", "-n", "--configfile=c.yaml", "--configfiles", "d.yaml",
            "--config", "x=1"]
    assert _run_py().configfiles(args) == ["a.yaml", "b.yaml", "c.yaml", "d.yaml"]


@pytest.mark.parametrize("text", [LAUGHS, DICT_LAUGHS, MERGE_LAUGHS], ids=["lists", "dicts", "merge_keys"])
def test_run_py_refuses_a_configfile_with_exploding_aliases(tmp_path, text):
    p = tmp_path / "laughs.yaml"
    p.write_text(text)
    msg = _run_py().check_configfiles(["config/config.yaml", str(p)])
    assert msg is not None and "\n" not in msg
    assert str(p) in msg and "more than 200000 values once YAML aliases" in msg


def test_dictionary_aliases_expand_past_the_limit():
    # what the check refuses is really that large: 9**9 leaves below 'i'
    cfg = yaml.safe_load(DICT_LAUGHS)
    node = cfg["i"]
    for _ in range(8):
        node = node["x1"]
    assert node == cfg["a"] and len(cfg["a"]) == 9


def test_run_py_refuses_a_recursive_alias_and_broken_yaml(tmp_path):
    (tmp_path / "rec.yaml").write_text("a: &a [1, *a]\n")
    (tmp_path / "bad.yaml").write_text("a: [1,\n")
    run_py = _run_py()
    assert "recursive" in run_py.check_configfiles([str(tmp_path / "rec.yaml")])
    assert "bad.yaml: not valid YAML" in run_py.check_configfiles([str(tmp_path / "bad.yaml")])


def test_run_py_passes_the_shipped_configs():
    files = sorted(str(p.relative_to(REPO)) for p in (REPO / "config").glob("*.yaml"))
    assert "config/paper.yaml" in files
    assert _run_py().check_configfiles(files) is None


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


@pytest.mark.parametrize("path", [
    ("meshdetail", "character", "frames"),
    ("facegraph", "synthetic", "total_frames"),
    ("facegraph", "synthetic", "n_sequences"),
    ("facegraph", "synthetic", "n_subjects"),
    ("resequencing", "path", "pad_to"),
    ("simplicial", "ensemble", "n_starts"),
    ("simplicial", "bootstrap"),
    ("facegraph", "uniqueness", "runs"),
    ("facegraph", "baseline", "max_queries"),
], ids=".".join)
def test_sizes_are_bounded(path):
    cfg = default_config()
    validate_config(cfg, SCHEMA)  # fills the defaults, so every block exists
    node = cfg
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = 10**9
    with pytest.raises(ConfigError, match=re.escape(f"config key '{'.'.join(path)}'") + ".*maximum"):
        validate_config(cfg, SCHEMA)


@pytest.fixture(scope="module")
def walk():
    from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

    return generate_motion("walk_straight", 120, 0, cmu_like_skeleton("c", 1))


def test_resequencing_over_the_memory_budget_is_refused_before_the_distances(walk, monkeypatch):
    from animsynth.limits import BudgetError
    from animsynth.resequencing import jobs
    from conftest import config_block

    def no_distances(*a, **k):
        raise AssertionError("distance matrices built before the budget check")

    monkeypatch.setattr(jobs, "base_distances", no_distances)
    monkeypatch.setattr(jobs, "config_resequencer", no_distances)
    cfg = config_block("resequencing", {"explanations": {"frame_steps": [4, 1]}})
    n = walk.n_frames
    msg = rf"re-sequencing trial 'syn_walk': {n} frames .*{n} x {n}.*needs about .* GiB.*memory budget of 1e-05 GiB"
    with pytest.raises(BudgetError, match=msg):
        jobs.analyse(walk, "walk", "syn_walk", False, cfg, budget_gib=1e-5)
    with pytest.raises(BudgetError, match=msg):
        jobs.explain(walk, "walk", "syn_walk", cfg, budget_gib=1e-5)
    walk = walk.__class__(walk.values, walk.skeleton, walk.fps, "syn_walk")
    with pytest.raises(BudgetError, match=msg):
        jobs.resequence(walk, False, "isomap", "l2", 5, cfg, budget_gib=1e-5)
    jobs.check_distance_budget(n, "syn_walk", 8.0 * 4 * n * n / 2**30 * 1.01)  # fits: no error
