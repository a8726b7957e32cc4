"""A user's data (mocap_source: user): what a family's selection keys leave out is said at parse time, naming the
key, and a compare.fps that does not divide a trial's rate is refused at config check, naming the trial."""

from __future__ import annotations

import copy

import pytest

from animsynth.compare import settings
from animsynth.config import ConfigError, unused_trials
from animsynth.io.bvh import bvh_frame_rate, read_bvh, write_bvh
from animsynth.resequencing import settings as rs_settings
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

from conftest import copy_workflow, default_config, run_snakemake


def _bvh(path, fps: float, frames: int = 120, seed: int = 0):
    path.parent.mkdir(parents=True, exist_ok=True)
    write_bvh(path, generate_motion("walk_straight", frames, seed, cmu_like_skeleton("u", 3), fps=fps, name=path.stem))
    return path


def _user_config(data, rates: dict) -> dict:
    """The default config over a user's BVH trials (``rates``: {trial id: fps}); subsets w1 (a, b) and r1 (c, d),
    re-sequencing walk: a, run: c."""
    cfg = copy.deepcopy(default_config())
    cfg["mocap_source"], cfg["data_dir"] = "user", str(data)
    cfg["trials"] = []
    for i, (tid, fps) in enumerate(rates.items()):
        _bvh(data / f"{tid}.bvh", fps, seed=i)
        cfg["trials"].append({"id": tid, "subject": "u", "kind": "walk_straight", "bvh": f"{tid}.bvh"})
    cfg["subsets"] = {"w1": ["a", "b"], "r1": ["c", "d"], "w2": None, "r2": None}
    cfg["resequencing_trials"] = {"walk": "a", "run": "c"}
    cfg["resequencing"]["datasets"] = ["walk"]
    return cfg


def test_bvh_frame_rate_reads_the_header_only(tmp_path):
    p = _bvh(tmp_path / "x.bvh", 30.0)
    assert bvh_frame_rate(p) == read_bvh(p).fps == 30.0
    # a file whose motion is broken after the header: the rate is still read (the motion is never parsed)
    p.write_text(p.read_text() + "not numbers at all\n")
    assert bvh_frame_rate(p) == 30.0


def test_left_out_groups_are_named_with_their_key(tmp_path):
    cfg = _user_config(tmp_path / "data", {"a": 120, "b": 120, "c": 120, "d": 120, "e": 120})
    cfg["compare"]["subsets"] = ["r1"]
    cfg["compare"]["resequencing"] = ["run"]
    lines = settings.left_out(cfg)
    assert lines == [
        "compare: subset 'w1' (a, b) of this run left out by compare.subsets: [r1] (set compare.subsets: null for "
        "every subset)",
        "compare: re-sequencing clip 'walk' (a) of this run left out by compare.resequencing: [run] (set "
        "compare.resequencing: null for every clip of resequencing_trials)"]
    assert rs_settings.left_out(cfg) == ["resequencing: clip 'run' (c) of resequencing_trials left out by "
                                         "resequencing.datasets: [walk] (add run to resequencing.datasets)"]
    assert unused_trials(cfg) == ["trial 'e' is in no subset (subsets) and no re-sequencing clip "
                                  "(resequencing_trials): no family uses it"]
    cfg["compare"]["subsets"] = cfg["compare"]["resequencing"] = None
    assert settings.left_out(cfg) == []


def test_compare_fps_that_does_not_divide_a_bvh_trial_is_refused_at_config_check(tmp_path):
    cfg = _user_config(tmp_path / "data", {"a": 120, "b": 120, "c": 30, "d": 120})
    cfg["compare"]["subsets"] = None
    cfg["compare"]["fps"] = 60
    with pytest.raises(ConfigError, match=r"config key 'compare\.fps': 60 fps is not the rate of trial 'c' \(30 fps, "
                                          r"the Frame Time of .*c\.bvh\)"):
        settings.check(cfg)
    cfg["compare"]["fps"] = 30
    settings.check(cfg)  # 120 / 30 and 30 / 30 are whole
    # trial c left out of the comparison: 60 fps passes again
    cfg["compare"]["fps"], cfg["compare"]["subsets"], cfg["compare"]["resequencing"] = 60, ["w1"], ["walk"]
    settings.check(cfg)


def test_an_unreadable_bvh_is_left_to_the_clips_job(tmp_path):
    cfg = _user_config(tmp_path / "data", {"a": 120, "b": 120, "c": 30, "d": 120})
    (tmp_path / "data" / "c.bvh").unlink()
    cfg["compare"]["subsets"], cfg["compare"]["fps"] = None, 60
    settings.check(cfg)  # no file yet: not refused here
    assert settings.trial_rate(cfg, cfg["trials"][2])[0] is None


@pytest.mark.workflow
def test_the_workflow_prints_what_a_user_config_leaves_out_at_parse_time(tmp_path):
    import yaml

    cfg = _user_config(tmp_path / "data", {"a": 120, "b": 120, "c": 120, "d": 120, "e": 120})
    mine = {k: cfg[k] for k in ("mocap_source", "data_dir", "trials", "subsets", "resequencing_trials")}
    mine["resequencing"] = {"datasets": ["walk"]}
    wd = copy_workflow(tmp_path / "wf")
    (wd / "config" / "mine.yaml").write_text(yaml.safe_dump(mine))
    res = run_snakemake(wd, "-n", "--configfile", "config/mine.yaml", "--until", "compare_clips")
    assert res.returncode == 0, (res.stdout + res.stderr)[-3000:]
    err = res.stderr
    assert ("animsynth: compare: subset 'w1' (a, b) of this run left out by compare.subsets: [r1] (set "
            "compare.subsets: null for every subset)") in err
    assert "animsynth: resequencing: clip 'run' (c) of resequencing_trials left out by resequencing.datasets" in err
    assert "animsynth: trial 'e' is in no subset" in err


def test_the_fps_hint_offers_the_rates_that_fit_every_trial(tmp_path):
    """Files at 24, 30 and 120 fps: 24, 12 or 8 fit the first one refused, only 6 (and 3, 2, 1) fit every file."""
    cfg = _user_config(tmp_path / "data", {"a": 24, "b": 120, "c": 30, "d": 120})
    cfg["compare"]["subsets"] = None
    with pytest.raises(ConfigError) as exc:
        settings.check(cfg)  # compare.fps 30: not a divisor of a's 24
    msg = str(exc.value)
    assert "30 fps is not the rate of trial 'a' (24 fps" in msg
    assert msg.endswith("set compare.fps to one that fits every trial the comparison uses: 6, 3, 2, 1")
    assert settings.common_rates([120, 60, 30]) == ["30", "15", "10", "6"]
    assert settings.common_rates([25, 24]) == ["1"]
