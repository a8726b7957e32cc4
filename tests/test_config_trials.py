"""Adding trials and subjects without copying the shipped config: trials keyed by id merge across config files,
compare.subjects (and each set) can be dropped from a later config, every trial file is probed with
on_missing_data: skip, and the walk of docs/data.md ("Adding a subject") works as written."""

from __future__ import annotations

import copy
import hashlib
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from snakemake.utils import update_config

from animsynth.compare import settings
from animsynth.config import ConfigError, check_config, trial_records, validate_config

from conftest import REPO, SAFETY_TIMEOUT, SNAKEMAKE, copy_workflow, merged_config

SCHEMA = str(REPO / "config" / "schema.yaml")
PAPER_FILES = ("config.yaml", "cmu.yaml", "samba.yaml", "paper.yaml")


def _merged(*extra: dict, files=PAPER_FILES) -> dict:
    """The shipped config files merged as Snakemake merges --configfile files, then ``extra`` (a user's configs)."""
    cfg = merged_config(*files, validate=False)
    for e in extra:
        update_config(cfg, copy.deepcopy(e))
    return cfg


NEW = {"subject": "143", "kind": "walk_straight", "amc": "subjects/143/143_01.amc", "asf": "subjects/143/143.asf",
       "sha256": "0" * 64, "asf_sha256": "1" * 64, "mirror": "many"}


def test_a_trials_mapping_adds_replaces_and_drops_records_by_id():
    shipped = trial_records(yaml.safe_load((REPO / "config" / "cmu.yaml").read_text())["trials"])
    walk = next(t for t in shipped if t["id"] == "35_01")
    cfg = _merged({"trials": {"143_01": NEW, "35_01": dict(walk, note="mine"), "05_02": None}})
    validate_config(cfg, SCHEMA)
    ids = [t["id"] for t in cfg["trials"]]
    assert isinstance(cfg["trials"], list) and len(ids) == len(shipped)  # one added, one dropped
    assert ids[-1] == "143_01" and "05_02" not in ids and ids[:3] == ["35_16", "35_07", "35_08"]
    assert next(t for t in cfg["trials"] if t["id"] == "35_01")["note"] == "mine"
    # a list replaces them all (the user's own data)
    listed = _merged({"trials": [dict(NEW, id="143_01")]})
    validate_config(listed, SCHEMA)
    assert [t["id"] for t in listed["trials"]] == ["143_01"]


def test_a_subset_naming_a_trial_without_a_record_says_which_and_where_to_add_it():
    cfg = _merged({"trials": [dict(NEW, id="143_01")]})  # a list: the shipped records are gone
    validate_config(cfg, SCHEMA)
    with pytest.raises(ConfigError) as exc:
        check_config(cfg)
    msg = str(exc.value)
    assert msg.startswith("config key 'subsets.w1': trial(s) '35_16', '35_07', '35_08', '35_13' have no record in "
                          "'trials' (1 records)")
    assert "as a mapping keyed by the quoted id" in msg and "a list of records replaces them all" in msg


@pytest.mark.parametrize("trials, says", [
    ({143_01: NEW}, "the trial id 14301 was read as a number (YAML reads 35_16 as 3516); quote the id: \"14301\":"),
    ({"143_01": dict(NEW, id="143_02")}, "config key 'trials.143_01.id': '143_02' differs from its key '143_01'"),
])
def test_a_mapping_key_read_as_a_number_or_an_id_unlike_its_key_is_refused(trials, says):
    cfg = _merged({"trials": trials})
    with pytest.raises(ConfigError) as exc:
        validate_config(cfg, SCHEMA)
    assert says in str(exc.value)


def test_a_later_config_drops_one_subject_set_or_all_of_them():
    one = _merged({"compare": {"subjects": {"s06": None, "s10": None}}})
    validate_config(one, SCHEMA)
    settings.check(one)
    assert "s06" not in settings.subject_sets(one) and "s07" in settings.subject_sets(one)
    assert not any(c.startswith(("s06/", "s10/")) for c in settings.held_out_trials(one))
    none = _merged({"compare": {"subjects": None}})
    validate_config(none, SCHEMA)
    settings.check(none)
    assert settings.subject_sets(none) == {}
    assert {c.split("/")[0] for c in settings.held_out_trials(none)} == {"w1", "w2", "r1", "r2", "walk", "run", "dance"}
    # and a set of the user's own joins, from a config after that one
    mine = _merged({"compare": {"subjects": None}}, {"trials": {"143_01": NEW}, "compare": {"subjects": {"s143": [
        "143_01"]}}})
    validate_config(mine, SCHEMA)
    assert settings.subject_sets(mine) == {"s143": ["143_01"]}


# ----------------------------------------------------------------------------- the workflow (dry runs)

def _fake_mirrors(root: Path, cfg: dict) -> tuple[Path, Path]:
    """Two local mirrors holding an empty file at every path config/cmu.yaml's records name (main and many): enough
    for a dry run, which reads no file."""
    main, many = root / "main", root / "many"
    for t in trial_records(cfg["trials"]):
        for key in ("amc", "asf", "bvh"):
            if key in t:
                p = (many if t.get("mirror") == "many" else main) / t[key]
                p.parent.mkdir(parents=True, exist_ok=True)
                p.touch()
    return main, many


def _dry_run(wd: Path, *config: str, configfiles=("config/cmu.yaml", "config/samba.yaml", "config/paper.yaml")):
    res = subprocess.run([SNAKEMAKE, "-n", "--cores", "1", "--configfile", *configfiles, "--config", *config],
                         cwd=wd, capture_output=True, text=True, timeout=SAFETY_TIMEOUT)
    assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]
    return res.stdout + res.stderr


@pytest.mark.workflow
def test_on_missing_data_skip_leaves_out_what_a_mirror_lacks(tmp_path):
    wd = copy_workflow(tmp_path / "run")
    main, many = _fake_mirrors(tmp_path, yaml.safe_load((REPO / "config" / "cmu.yaml").read_text()))
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    base = (f"cmu_mirror={main}", f"mesh_dir={meshes}")
    # the second mirror lacks one ASF: that subject's set is left out, the rest runs
    (many / "subjects" / "07" / "07.asf").unlink()
    out = _dry_run(wd, *base, f"cmu_many_mirror={many}")
    assert (f"animsynth: compare: leaving out set(s) s07 of compare.subjects: files missing below mirror {many} "
            "(07_01: subjects/07/07.asf; 07_04: subjects/07/07.asf; 07_06: subjects/07/07.asf)") in out
    assert "trial=07_01" not in out and "trial=12_01" in out
    # the second mirror is a file: its trials are left out
    (tmp_path / "a_file").write_text("x\n")
    out = _dry_run(wd, *base, f"cmu_many_mirror={tmp_path / 'a_file'}")
    assert f"of mirror {tmp_path / 'a_file'}: data unavailable ({tmp_path / 'a_file'} is a file, not a folder)" in out
    assert "trial=12_01" not in out and "trial=02_01" in out
    # a file of the papers' own trials is missing: the mocap families are skipped, naming it
    (main / "subjects" / "35" / "35_07.amc").unlink()
    out = _dry_run(wd, *base, f"cmu_many_mirror={many}")
    assert ("animsynth: skipping simplicial and resequencing and compare: data unavailable (files missing below the "
            "mirror: 35_07: subjects/35/35_07.amc)") in out


def _sha(path: Path) -> str:
    """SHA-256 with line endings read as LF: what `tr -d '\\r' < FILE | sha256sum` prints (docs/data.md)."""
    return hashlib.sha256(path.read_bytes().replace(b"\r", b"")).hexdigest()


@pytest.mark.workflow
def test_adding_a_subject_as_docs_data_md_walks_through_it(tmp_path):
    """docs/data.md, "Adding a subject": a mirror of the new subject's files beside links to another mirror, the
    records keyed by id in a config of one's own after the paper run's, a dry run that includes the subject, and
    one trial fetched and parsed."""
    from animsynth.io import write_amc, write_asf
    from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

    wd = copy_workflow(tmp_path / "run")
    for name in ("run.py", "pyproject.toml"):
        (wd / name).write_bytes((REPO / name).read_bytes())
    main, shared_many = _fake_mirrors(tmp_path / "shipped", yaml.safe_load((REPO / "config" / "cmu.yaml").read_text()))
    # 1. the mirror: the new subject's files, and links to the other mirror's subjects
    mirror = tmp_path / "mirror" / "subjects"
    (mirror / "143").mkdir(parents=True)
    sk = cmu_like_skeleton("143", 5)
    write_asf(mirror / "143" / "143.asf", sk, length_unit=0.45)
    for k, kind in ((1, "walk_straight"), (2, "walk_straight"), (3, "walk_turn")):
        write_amc(mirror / "143" / f"143_0{k}.amc", generate_motion(kind, 240, k, sk))
    for subject in (shared_many / "subjects").iterdir():
        (mirror / subject.name).symlink_to(subject)
    # 2.-3. the checksums and the user's config
    asf = _sha(mirror / "143" / "143.asf")
    trials = {f"143_0{k}": {"subject": "143", "kind": kind, "amc": f"subjects/143/143_0{k}.amc",
                            "asf": "subjects/143/143.asf", "sha256": _sha(mirror / "143" / f"143_0{k}.amc"),
                            "asf_sha256": asf, "mirror": "many"}
              for k, kind in ((1, "walk_straight"), (2, "walk_straight"), (3, "walk_turn"))}
    (wd / "mine.yaml").write_text(yaml.safe_dump({"trials": trials, "compare": {"subjects": {
        "s143": ["143_01", "143_02", "143_03"]}}}))
    assert '"143_01":' in (wd / "mine.yaml").read_text() or "'143_01':" in (wd / "mine.yaml").read_text()
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    config = ["--config", f"cmu_mirror={main}", f"cmu_many_mirror={mirror.parent}", f"mesh_dir={meshes}"]
    env = dict(os.environ, ANIMSYNTH_VENV=str(Path(sys.executable).parents[1]))

    def run_py(*args):
        res = subprocess.run([sys.executable, "run.py", "paper", *args], cwd=wd, env=env, capture_output=True,
                             text=True, timeout=SAFETY_TIMEOUT)
        assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]
        return res.stdout + res.stderr

    # 4. the dry run: the new trials are fetched, parsed and read by the comparison's clips job
    out = run_py("-n", "--configfile", "mine.yaml", *config)
    assert "--configfile config/cmu.yaml config/samba.yaml config/paper.yaml mine.yaml" in out
    for k in (1, 2, 3):
        assert f"trial=143_0{k}" in out
    jobs = [j[:j.index("\n\n")] for j in out.split("rule compare_clips:")[1:]]
    clips_job = [j for j in jobs if "cmpsubj=143" in j]
    assert len(clips_job) == 1, jobs  # the new subject's own clips job, which reads its three trials
    assert all(f"results/paper/data/trials/143_0{k}.npz" in clips_job[0] for k in (1, 2, 3))
    assert not (wd / "results/paper/report.html").exists()
    # the subject is one more group of the comparison
    cfg = _merged(yaml.safe_load((wd / "mine.yaml").read_text()))
    validate_config(cfg, SCHEMA)
    assert settings.groups(cfg)[0]["s143"] == ["143_01", "143_02", "143_03"]
    # one trial fetched (its checksum checked) and parsed
    run_py("results/paper/data/trials/143_01.npz", "--configfile", "mine.yaml", *config)
    assert (wd / "results/paper/data/trials/143_01.npz").is_file()
