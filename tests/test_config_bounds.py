"""Config values the schema used to let through: sizes without a maximum or
beyond the memory budget, NaN and infinity, a results_dir leaving the project
through a symbolic link, and boolean keys given as text. Each is refused (or
read) at validation, naming the key, before any job starts."""

import copy
import os
import re

import pytest
import yaml

from animsynth.config import ConfigError, check_config, validate_config
from conftest import REPO

SCHEMA = str(REPO / "config" / "schema.yaml")


def default_config():
    return yaml.safe_load((REPO / "config" / "config.yaml").read_text())


_FILLED = []


def filled_config():
    """The default config with every schema default filled in (validated once per session, then copied)."""
    if not _FILLED:
        cfg = default_config()
        validate_config(cfg, SCHEMA)  # fills the defaults, so every block exists
        _FILLED.append(cfg)
    return copy.deepcopy(_FILLED[0])


def _set(cfg, path, value):
    node = cfg
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value


# ---- every numeric key has a minimum and a maximum --------------------------

def _numeric_without_bounds(node, path=""):
    """Paths of numeric schema entries lacking a minimum or a maximum."""
    out = []
    if not isinstance(node, dict):
        return out
    types = node.get("type")
    types = [types] if isinstance(types, str) else (types or [])
    if {"integer", "number"} & set(types):
        lo = "minimum" in node or "exclusiveMinimum" in node
        hi = "maximum" in node or "exclusiveMaximum" in node
        if not (lo and hi):
            out.append(path)
    for group in ("properties", "patternProperties", "$defs"):
        for key, sub in (node.get(group) or {}).items():
            out += _numeric_without_bounds(sub, f"{path}.{key}" if path else key)
    if isinstance(node.get("items"), dict):
        out += _numeric_without_bounds(node["items"], path + "[]")
    if isinstance(node.get("additionalProperties"), dict):
        out += _numeric_without_bounds(node["additionalProperties"], path + ".*")
    for group in ("oneOf", "anyOf"):
        for sub in node.get(group) or []:
            out += _numeric_without_bounds(sub, path)
    return out


def test_every_numeric_schema_key_has_a_minimum_and_a_maximum():
    schema = yaml.safe_load((REPO / "config" / "schema.yaml").read_text())
    assert _numeric_without_bounds(schema) == []


@pytest.mark.parametrize("path,value", [
    (("simplicial", "steps"), 10**12),
    (("meshdetail", "character", "skirt_rings"), 10**9),
    (("meshdetail", "character", "substeps"), 10**9),
    (("meshdetail", "iterations"), 10**9),
    (("resequencing", "path", "random_pairs"), 10**9),
    (("meshdetail", "character", "skirt_around"), 10**9),
    (("simplicial", "beyond", "max_all_pairs"), 10**9),
    (("seed",), 2**64),
], ids=lambda x: ".".join(x) if isinstance(x, tuple) else str(x))
def test_unbounded_sizes_are_refused_naming_the_key(path, value):
    cfg = filled_config()
    _set(cfg, path, value)
    with pytest.raises(ConfigError, match=re.escape(f"config key '{'.'.join(path)}'")):
        validate_config(cfg, SCHEMA)


def test_simplicial_steps_over_the_memory_budget_is_refused_before_the_run():
    cfg = filled_config()
    cfg["simplicial"]["steps"] = 1_000_000  # the schema's maximum: about 3.8 GiB of paths with 7 starts
    cfg["memory_budget_gib"] = 1
    validate_config(cfg, SCHEMA)
    with pytest.raises(ConfigError, match=r"config key 'simplicial\.steps' \(1000000\).*GiB.*memory budget of 1 GiB"):
        check_config(cfg)
    cfg["memory_budget_gib"] = 16
    check_config(cfg)
    cfg["memory_budget_gib"] = 1
    cfg["simplicial"]["steps"] = 1000
    check_config(cfg)


def test_skirt_size_over_the_memory_budget_is_refused_before_the_run():
    cfg = filled_config()
    ch = cfg["meshdetail"]["character"]
    ch.update(skirt_rings=1000, skirt_around=10000)
    validate_config(cfg, SCHEMA)
    with pytest.raises(ConfigError, match=r"config keys 'meshdetail\.character\.skirt_rings' \(1000\).*memory budget"):
        check_config(cfg)
    cfg["mesh_dir"] = "some/meshes"  # real meshes: no synthetic character is built
    check_config(cfg)


@pytest.mark.parametrize("name", sorted(p.name for p in (REPO / "config").glob("*.yaml") if p.name != "schema.yaml"))
def test_shipped_configs_fit_the_default_budget(name):
    from snakemake.utils import update_config

    cfg = default_config()
    if name != "config.yaml":
        update_config(cfg, yaml.safe_load((REPO / "config" / name).read_text()) or {})
    validate_config(cfg, SCHEMA)
    check_config(cfg)


# ---- NaN and infinity ---------------------------------------------------------

@pytest.mark.parametrize("key,text", [
    ("memory_budget_gib", ".nan"),
    ("simplicial.alpha", ".nan"),
    ("bvh_length_to_m", ".nan"),
    ("fps", ".nan"),
    ("compare.fps", ".nan"),
    ("fps", ".inf"),
    ("resequencing.lee.weights.hips", "-.inf"),
    ("meshdetail.ridge_alphas[0]", ".nan"),
])
def test_nan_and_infinity_are_refused_naming_the_key(key, text):
    cfg = default_config()
    value = yaml.safe_load(f"x: {text}")["x"]
    parts = re.findall(r"[^.\[\]]+", key)
    node = cfg
    for part in parts[:-1]:
        node = node.setdefault(part, {} if not parts[parts.index(part) + 1].isdigit() else [0.1])
    last = parts[-1]
    if last.isdigit():
        node[int(last)] = value
    else:
        node[last] = value
    with pytest.raises(ConfigError, match=re.escape(f"config key '{key}'") + ".*not a finite number"):
        validate_config(cfg, SCHEMA)


def test_nan_budget_no_longer_switches_the_budget_off():
    cfg = default_config()
    cfg["memory_budget_gib"] = float("nan")
    cfg["trials"][0]["frames"] = 1_000_000
    with pytest.raises(ConfigError, match="memory_budget_gib"):
        validate_config(cfg, SCHEMA)
        check_config(cfg)


# ---- results_dir through a symbolic link ------------------------------------

@pytest.mark.parametrize("target", ["outside", "root"])
def test_results_dir_through_a_link_leaving_the_project_is_refused(tmp_path, target):
    project = tmp_path / "project"
    project.mkdir()
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (project / "tmplink").symlink_to(outside if target == "outside" else "/")
    cfg = filled_config()
    cfg["results_dir"] = "tmplink/run" if target == "outside" else "tmplink"
    from animsynth.config import check_results_dir

    with pytest.raises(ConfigError, match="config key 'results_dir'.*outside the project.*symbolic link"):
        check_results_dir(cfg, str(project))


def test_results_dir_through_a_link_inside_the_project_is_fine(tmp_path):
    from animsynth.config import check_results_dir

    project = tmp_path / "project"
    (project / "store").mkdir(parents=True)
    (project / "results").symlink_to(project / "store")
    cfg = filled_config()
    cfg["results_dir"] = "results/paper"
    check_results_dir(cfg, str(project))


# ---- text booleans from --config ----------------------------------------------

@pytest.mark.parametrize("text,value", [("true", True), ("false", False), ("TRUE", True)])
def test_text_booleans_are_read_as_booleans(tmp_path, text, value):
    cfg = default_config()
    cfg.update(results_outside_project=text, results_dir=str(tmp_path / "runs"))
    cfg["scale"] = {"enabled": "false"}
    validate_config(cfg, SCHEMA)
    assert cfg["results_outside_project"] is value and cfg["scale"]["enabled"] is False
    if value:
        check_config(cfg)


def test_other_text_for_a_boolean_is_still_refused():
    cfg = default_config()
    cfg["results_outside_project"] = "yes please"
    with pytest.raises(ConfigError, match="results_outside_project"):
        validate_config(copy.deepcopy(cfg), SCHEMA)


def test_results_dir_through_a_link_with_the_opt_in(tmp_path):
    # results_outside_project: true lets a link name an outside folder, never the root or the home folder
    from animsynth.config import check_results_dir

    project = tmp_path / "project"
    project.mkdir()
    (tmp_path / "scratch").mkdir()
    (project / "scratchlink").symlink_to(tmp_path / "scratch")
    (project / "rootlink").symlink_to("/")
    (project / "homelink").symlink_to(os.path.expanduser("~"))
    cfg = filled_config()
    cfg.update(results_outside_project=True, results_dir="scratchlink/run")
    check_results_dir(cfg, str(project))
    for bad in ("rootlink", "homelink"):
        cfg["results_dir"] = bad
        with pytest.raises(ConfigError, match="config key 'results_dir'.*filesystem root, the home folder"):
            check_results_dir(cfg, str(project))
