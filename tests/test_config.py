"""Config validation: the schema and cross-key checks name the offending key."""

import copy

import pytest
import yaml
from snakemake.utils import validate

from animsynth.config import ConfigError, check_config, derive_seed
from conftest import REPO, copy_workflow, run_snakemake

SCHEMA = str(REPO / "config" / "schema.yaml")


def default_config():
    return yaml.safe_load((REPO / "config" / "config.yaml").read_text())


def test_default_config_is_valid_and_gets_defaults():
    cfg = default_config()
    validate(cfg, SCHEMA)
    check_config(cfg)
    assert cfg["fps"] == 120


@pytest.mark.parametrize(
    "mutate,fragment",
    [
        (lambda c: c.update(sed=1), "sed"),
        (lambda c: c.update(seed="one"), "one"),
        (lambda c: c.update(mocap_source="web"), "web"),
        (lambda c: c["trials"][0].update(frames="many"), "many"),
        (lambda c: c["trials"][0].update(colour="red"), "colour"),
    ],
)
def test_schema_errors_name_the_key(mutate, fragment):
    cfg = default_config()
    mutate(cfg)
    with pytest.raises(Exception) as ei:
        validate(cfg, SCHEMA)
    assert fragment in str(ei.value)


def test_cross_key_errors():
    cfg = default_config()
    bad = copy.deepcopy(cfg)
    bad["subsets"]["w1"][0] = "nope"
    with pytest.raises(ConfigError, match=r"subsets\.w1.*nope"):
        check_config(bad)
    bad = copy.deepcopy(cfg)
    bad["trials"].append(dict(bad["trials"][0]))
    with pytest.raises(ConfigError, match="duplicate id"):
        check_config(bad)
    bad = copy.deepcopy(cfg)
    bad["mocap_source"] = "cmu"
    with pytest.raises(ConfigError, match=r"trials\[0\].*needs 'amc' and 'asf'"):
        check_config(bad)


@pytest.mark.parametrize("mutate,lines", [
    (lambda c: c.update(fsp=30), ["config key 'fsp' is not allowed (at the top level)", "closest valid key: 'fps'"]),
    (lambda c: c["trials"][0].update(colour="red"), ["config key 'trials[0].colour' is not allowed (in 'trials[0]')"]),
    (lambda c: c["simplicial"].update(sed=1), ["config key 'simplicial.sed' is not allowed (in 'simplicial')"]),
])
def test_unknown_key_message_is_short(mutate, lines):
    from animsynth.config import validate_config

    cfg = default_config()
    mutate(cfg)
    with pytest.raises(ConfigError) as ei:
        validate_config(cfg, SCHEMA)
    msg = str(ei.value)
    assert all(line in msg for line in lines) and len(msg.splitlines()) <= 4


def test_derive_seed_is_stable():
    assert derive_seed(1, "a", 2) == derive_seed(1, "a", 2)
    assert derive_seed(1, "a", 2) != derive_seed(1, "a", 3)
    assert derive_seed(20260101, "x") == 1734937408  # pinned: changing it changes every table


@pytest.mark.workflow
def test_snakemake_stops_on_unknown_key(tmp_path):
    wd = copy_workflow(tmp_path)
    res = run_snakemake(wd, "-n", "--config", "fsp=30")
    out = (res.stdout + res.stderr).strip()
    assert res.returncode != 0
    # a few lines: the key, where it is, the closest valid key (not the whole schema and config)
    assert "config key 'fsp' is not allowed (at the top level)" in out
    assert "closest valid key: 'fps'" in out
    assert len(out.splitlines()) <= 10, out
    # once, without stack lines of the Snakefile or the library
    assert out.count("animsynth: config error: config key 'fsp'") == 1 and 'File "' not in out, out
    # a check of workflow/rules/common.smk's, likewise
    res = run_snakemake(wd, "-n", "--config", "results_dir=../elsewhere")
    out = (res.stdout + res.stderr).strip()
    assert res.returncode == 1 and out.count("animsynth: config error: config key 'results_dir'") == 1, out
    assert 'File "' not in out and "Traceback" not in out, out
    res = run_snakemake(wd, "-n", "--config", "fps=fast")
    out = (res.stdout + res.stderr).strip()
    assert res.returncode != 0 and "config key 'fps': 'fast' is not of type" in out
    assert len(out.splitlines()) <= 10, out


# --- every real trial on its own subject's skeleton -------------------------

def _paper_config(**top) -> dict:
    """config.yaml, cmu.yaml, samba.yaml and paper.yaml merged as the paper run merges them, validated."""
    from animsynth.config import validate_config
    from conftest import merged_config

    cfg = merged_config("config.yaml", "cmu.yaml", "samba.yaml", "paper.yaml", validate=False)
    cfg.update(top)
    validate_config(cfg, SCHEMA)
    return cfg


def test_the_shipped_cmu_trials_are_each_on_their_own_subjects_skeleton():
    cfg = _paper_config()
    check_config(cfg)
    for t in cfg["trials"]:
        if "asf" in t:
            subject = t["id"].split("_")[0]
            assert t["asf"] == f"subjects/{subject}/{subject}.asf", t["id"]


@pytest.mark.parametrize("asf", ["subjects/16/16.asf", "subjects/127/16.asf", "subjects/16/127.asf"])
def test_a_trial_on_another_subjects_asf_is_refused_naming_trial_and_file(asf):
    cfg = _paper_config()
    k = next(i for i, t in enumerate(cfg["trials"]) if t["id"] == "127_09")
    cfg["trials"][k]["asf"] = asf
    with pytest.raises(ConfigError) as ei:
        check_config(cfg)
    msg = str(ei.value)
    assert f"trials[{k}]" in msg and "'127_09'" in msg and repr(asf) in msg and "subjects/127/127.asf" in msg


def test_an_asf_whose_subject_cannot_be_told_is_refused_for_cmu():
    cfg = _paper_config()
    cfg["trials"][0]["asf"] = "skeletons/any.asf"
    with pytest.raises(ConfigError, match=r"'35_16'.*'skeletons/any\.asf' is not subjects/<SS>/<SS>\.asf"):
        check_config(cfg)


@pytest.mark.parametrize("source", ["cmu", "user"])
def test_an_amc_trial_without_a_skeleton_is_refused_naming_the_file(source, tmp_path):
    cfg = _paper_config()
    if source == "user":
        cfg.update(mocap_source="user", data_dir=str(tmp_path))
        for t in cfg["trials"]:
            t.pop("mirror", None)
    k = next(i for i, t in enumerate(cfg["trials"]) if t["id"] == "07_01")
    del cfg["trials"][k]["asf"]
    with pytest.raises(ConfigError) as ei:
        check_config(cfg)
    msg = str(ei.value)
    assert f"trials[{k}]" in msg and "AMC file 'subjects/07/07_01.amc' has no skeleton" in msg


def test_a_trials_mirror_field_picks_cmu_many_mirror_or_cmu_mirror():
    from animsynth.config import trial_mirror

    cfg = _paper_config(cmu_mirror="../shared/data/cmu_mocap")
    many = next(t for t in cfg["trials"] if t["id"] == "07_01")
    main = next(t for t in cfg["trials"] if t["id"] == "02_01")
    assert many["mirror"] == "many" and "mirror" not in main
    assert trial_mirror(cfg, many) == "../shared/data/cmu_mocap_many"
    assert trial_mirror(cfg, main) == "../shared/data/cmu_mocap"
    cfg["cmu_many_mirror"] = None  # null: the official site (or cmu_mirror) holds them too
    assert trial_mirror(cfg, many) == "../shared/data/cmu_mocap"
    user = dict(cfg, mocap_source="user", data_dir="mine")
    with pytest.raises(ConfigError, match=r"trials\[\d+\]\.mirror.*needs mocap_source 'cmu'"):
        check_config(user)


@pytest.mark.parametrize("names", [("config.yaml",), ("config.yaml", "test.yaml"),
                                   ("config.yaml", "cmu.yaml", "samba.yaml", "paper.yaml"),
                                   ("config.yaml", "scale.yaml"), ("config.yaml", "user_example.yaml")])
def test_our_validator_fills_what_snakemakes_validate_fills(names):
    """validate_config validates with a validator built once per schema (config._default_filling_validator), not
    through snakemake.utils.validate, which parses the schema again on every call: on each shipped config the
    two fill in the same defaults, and the same bad value fails both."""
    from animsynth.config import _schema_entry
    from conftest import merged_config

    ours = merged_config(*names, validate=False)
    theirs = copy.deepcopy(ours)
    _schema_entry(SCHEMA).validator.validate(ours)
    validate(theirs, SCHEMA)
    assert ours == theirs
    assert len(ours) > len(merged_config(*names, validate=False))  # defaults were filled in
    bad = merged_config(*names, validate=False)
    bad.setdefault("compare", {})["seeds"] = "three"
    with pytest.raises(Exception, match="three"):
        _schema_entry(SCHEMA).validator.validate(copy.deepcopy(bad))
    with pytest.raises(Exception, match="three"):
        validate(bad, SCHEMA)


def test_filled_defaults_are_not_shared_between_configs():
    """The validator is cached, so a default list or mapping filled into one config must be a copy: changing it
    leaves the next config's default (and the cached schema) as declared."""
    from animsynth.config import _read_schema, validate_config

    def without_simplicial():
        cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
        del cfg["simplicial"]
        validate_config(cfg, SCHEMA)
        return cfg

    first = without_simplicial()
    assert first["simplicial"]["methods"] == ["delaunay", "knn"]  # filled in from the schema's defaults
    first["simplicial"]["methods"].append("kdelaunay")
    first["simplicial"]["latent_dim"] = 7
    second = without_simplicial()
    assert second["simplicial"]["methods"] == ["delaunay", "knn"]
    assert second["simplicial"]["latent_dim"] == 2
    assert _read_schema(SCHEMA)["properties"]["simplicial"]["properties"]["methods"]["default"] == ["delaunay", "knn"]


@pytest.mark.parametrize("where,key", [(("joint_roles",), 1), (("compare", "user_generators"), 5),
                                       (("facegraph",), True)])
def test_a_key_yaml_read_as_a_number_is_named_not_a_traceback(where, key):
    # JSON Schema's name patterns cannot match a number: the validator would stop with a TypeError
    from animsynth.config import validate_config

    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    block = cfg
    for k in where:
        block = block.setdefault(k, {})
    block[key] = "x"
    with pytest.raises(ConfigError, match=rf"config key '{'.'.join(where)}': the key {key!r} was read as a "
                                          rf"(number|boolean).*quote it"):
        validate_config(cfg, SCHEMA)
