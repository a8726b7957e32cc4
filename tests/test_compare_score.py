"""``animsynth score``: BVH files from anywhere scored with the compare family's metrics."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from animsynth import cli
from animsynth.compare import jobs, protocol, runner, settings
from animsynth.compare.measures import metric_table
from animsynth.compare.scoring import DATABASE_METRICS, SKATING_METRICS, UNSCORED
from animsynth.io.bvh import read_bvh, write_bvh
from animsynth.motion import Motion
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

from conftest import default_config

SK = cmu_like_skeleton("cmp", 3)
UNIT = str(SK.length_to_m)  # the synthetic skeleton's metres per unit, which a BVH file does not carry


_config = default_config


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A comparison of one walk's temporal split (its first block's database is one stretch of the walk) with the
    project's defaults: knn, replay and a user's generator run by the family's job, each writing its BVH of the
    first clip."""
    d = tmp_path_factory.mktemp("score_run")
    (d / "mine.py").write_text("from animsynth.compare.generators.references import Concat\n\n\nclass Mine:\n"
                               "    def fit(self, database):\n        self.g = Concat().fit(database.clips)\n"
                               "        return self\n\n    def generate(self, start, length, seed):\n"
                               "        return self.g.generate(start, length, seed)\n")
    cfg = dict(settings.job_cfg(_config()), user_generators={"mine": f"{d / 'mine.py'}:Mine"})
    walk = protocol.resample(generate_motion("walk_straight", 480, 0, SK, name="t0"), 30.0)
    cc = settings.clips_cfg(_config())
    clips = protocol.prepare_clips({"t0": walk}, {}, {"walk": "t0"}, cc)
    protocol.save_clips(d / "clips.npz", clips)
    for g in ("knn", "replay", "mine"):
        out = {k: str(d / f"{g}{ext}") for k, ext in (("metrics", ".csv"), ("timing", "_timing.csv"),
                                                      ("shown", ".npz"), ("bvh", ".bvh"))}
        jobs.run_job(d / "clips.npz", g, cfg, 7, None, ("walk/t0", 1), out)
    write_bvh(d / "held_out.bvh", clips[0].held_out)
    write_bvh(d / "database.bvh", clips[0].database[0])
    return d, clips[0]


def _score(*args) -> int:
    return cli.main(["score", *map(str, args), "--length-to-m", UNIT])


@pytest.mark.parametrize("generator", ["knn", "replay", "mine"])
def test_scoring_the_comparisons_own_bvh_gives_its_metrics(run, tmp_path, generator):
    d, clip = run
    bvh = read_bvh(d / f"{generator}.bvh")
    # what the showcase BVH holds: the start (the held-out clip's first context frames), then the generated frames
    shown = runner.load_shown(d / f"{generator}.npz")
    assert bvh.n_frames == clip.context + clip.length == shown.n_frames and shown.meta["context"] == clip.context
    assert np.allclose(shown.values[:clip.context], clip.held_out.values[:clip.context])
    assert _score(d / f"{generator}.bvh", "--reference", d / "held_out.bvh", "--database", d / "database.bvh",
                  "--out", tmp_path / "s.csv") == 0
    s = pd.read_csv(tmp_path / "s.csv")
    m = pd.read_csv(d / f"{generator}.csv")
    assert list(s.columns) == list(m.columns)
    row = m[m["seed"] == 1].iloc[0]  # the showcase seed
    scored = [c for c in metric_table.METRIC_NAMES if c not in UNSCORED]
    # a file has no reported seams, no transition count, no other seeds
    assert set(UNSCORED) == {"transition_skate_share", "n_seams", "seams_per_s", "transitions_kept", "velocity_jump",
                             "velocity_jump_ratio", "velocity_jump_pct", "accel_jump", "accel_jump_ratio",
                             "accel_jump_pct", "seed_diversity_m"}
    for c in scored:  # every metric a file gives equals the run's (BVH keeps 6 decimals)
        assert np.isclose(s[c].iloc[0], row[c], rtol=1e-4, atol=1e-6, equal_nan=True), (c, s[c].iloc[0], row[c])
        assert np.isfinite(s[c].iloc[0]) or not np.isfinite(row[c]), c
    assert s[list(UNSCORED)].isna().all().all()  # the generator's seams, transitions and seeds: not in a file
    assert s["generator"].iloc[0] == str(d / f"{generator}.bvh") and s["clip"].iloc[0] == str(d / "held_out.bvh")


def test_the_held_out_capture_against_itself_scores_zero(run, tmp_path):
    d, _clip = run
    held = d / "held_out.bvh"
    assert _score(held, "--reference", held, "--out", tmp_path / "a.csv") == 0
    a = pd.read_csv(tmp_path / "a.csv")
    assert (a[["l2p_m", "l2q", "npss"]] == 0).all().all()
    assert a[list(DATABASE_METRICS) + list(SKATING_METRICS)].isna().all().all()  # no database: left empty
    assert a["ldlj"].notna().all() and a["note"].str.startswith("no database").all()
    assert _score(held, "--reference", held, "--database", d / "database.bvh", "--out", tmp_path / "b.csv") == 0
    b = pd.read_csv(tmp_path / "b.csv")
    assert (b[["l2p", "l2p_m", "l2q", "npss"]] == 0).all().all() and b["skate_share"].notna().all()


def test_a_floor_height_scores_skating_without_a_database_and_one_row_per_file(run, tmp_path):
    d, _clip = run
    files = [d / "knn.bvh", d / "mine.bvh", d / "replay.bvh"]
    assert _score(*files, "--reference", d / "held_out.bvh", "--floor-m", "0", "--out", tmp_path / "s.csv") == 0
    s = pd.read_csv(tmp_path / "s.csv")
    assert list(s["generator"]) == [str(f) for f in files]
    assert s["skate_share"].notna().all() and s[list(DATABASE_METRICS)].isna().all().all()


def test_the_config_gives_the_start_and_the_metric_settings(run, tmp_path):
    d, clip = run
    (tmp_path / "c.yaml").write_text("compare: {context: 4, metrics: {window: 3}}\n")
    assert _score(d / "knn.bvh", "--reference", d / "held_out.bvh", "--database", d / "database.bvh",
                  "--config", tmp_path / "c.yaml", "--out", tmp_path / "a.csv") == 0
    assert _score(d / "knn.bvh", "--reference", d / "held_out.bvh", "--database", d / "database.bvh",
                  "--context", "4", "--out", tmp_path / "b.csv") == 0
    a, b = pd.read_csv(tmp_path / "a.csv"), pd.read_csv(tmp_path / "b.csv")
    assert a["l2p_m"].iloc[0] == b["l2p_m"].iloc[0]  # the same 4 start frames
    assert a["coverage"].iloc[0] != b["coverage"].iloc[0] or a["local_diversity_m"].iloc[0] != b["local_diversity_m"].iloc[0]


def _other_rate(d, tmp_path):
    m = read_bvh(d / "knn.bvh")
    write_bvh(tmp_path / "fast.bvh", Motion(m.values, m.skeleton, 2 * m.fps, "fast"))
    return tmp_path / "fast.bvh"


def _long(d, tmp_path):
    m = read_bvh(d / "held_out.bvh")
    write_bvh(tmp_path / "long.bvh", Motion(np.vstack([m.values, m.values]), m.skeleton, m.fps, "long"))
    return tmp_path / "long.bvh"


def _renamed(path, dest, old="ltoes", new="zeh_links"):
    dest.write_text(path.read_text().replace(f"JOINT {old}\n", f"JOINT {new}\n"))
    return dest


def _other_joints(d, tmp_path):
    return _renamed(d / "knn.bvh", tmp_path / "other.bvh")


@pytest.mark.parametrize("make, args, says", [
    (_other_rate, (), "fps, the reference"),
    (_long, (), "has 40 frames to compare them with"),
    (_other_joints, (), "its joints differ from the reference's"),
    (None, ("--context", "40"), "none after the 40 start frames"),
    (None, ("--database", "NODB.bvh"), "no such file"),
    (None, ("--config", "BAD.yaml"), "compare.context"),
])
def test_bad_input_is_one_line_naming_it_and_writes_nothing(run, tmp_path, capsys, make, args, says):
    d, clip = run
    assert clip.held_out.n_frames == 40  # the first block of the walk's temporal split (120 frames in 3)
    gen = make(d, tmp_path) if make else d / "knn.bvh"
    (tmp_path / "BAD.yaml").write_text("compare: {context: -1}\n")
    args = [str(tmp_path / a) if a.endswith((".bvh", ".yaml")) else a for a in args]
    capsys.readouterr()
    assert _score(gen, "--reference", d / "held_out.bvh", *args, "--out", tmp_path / "s.csv") == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and says in err[0], err
    assert not (tmp_path / "s.csv").exists()


def test_the_output_must_be_a_csv_file(run, tmp_path, capsys):
    d, _clip = run
    assert _score(d / "knn.bvh", "--reference", d / "held_out.bvh", "--out", tmp_path / "s.txt") == 2
    assert "use a .csv file name" in capsys.readouterr().err
    assert _score(d / "knn.bvh", "--reference", d / "held_out.bvh") == 2
    assert "--out" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_joint_roles_are_resolved_as_everywhere_else(run, tmp_path, capsys):
    """A toe joint no name rule knows: one line naming the role without --role, the same numbers with it."""
    d, _clip = run
    files = [_renamed(d / f, tmp_path / f) for f in ("knn.bvh", "held_out.bvh", "database.bvh")]
    args = [files[0], "--reference", files[1], "--database", files[2]]
    assert _score(*args, "--out", tmp_path / "a.csv") == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "left_toe" in err[0], err
    assert _score(*args, "--role", "left_toe=zeh_links", "--out", tmp_path / "a.csv") == 0
    assert _score(d / "knn.bvh", "--reference", d / "held_out.bvh", "--database", d / "database.bvh",
                  "--out", tmp_path / "b.csv") == 0
    a, b = pd.read_csv(tmp_path / "a.csv"), pd.read_csv(tmp_path / "b.csv")
    pd.testing.assert_frame_equal(a[metric_table.METRIC_NAMES], b[metric_table.METRIC_NAMES])


def test_without_a_database_no_foot_roles_are_needed(run, tmp_path, capsys):
    """No database and no floor height: no foot metric is computed, so a skeleton without a toe joint that the
    name rules know is scored (the skating columns empty) instead of asking for --role left_toe."""
    d, _clip = run
    files = [_renamed(d / f, tmp_path / f) for f in ("knn.bvh", "held_out.bvh")]
    assert _score(files[0], "--reference", files[1], "--out", tmp_path / "a.csv") == 0, capsys.readouterr().err
    assert _score(d / "knn.bvh", "--reference", d / "held_out.bvh", "--out", tmp_path / "b.csv") == 0
    a, b = pd.read_csv(tmp_path / "a.csv"), pd.read_csv(tmp_path / "b.csv")
    assert a[list(SKATING_METRICS)].isna().all().all()
    pd.testing.assert_frame_equal(a[metric_table.METRIC_NAMES], b[metric_table.METRIC_NAMES])
    # a floor height asks for the feet again: one line naming the role
    assert _score(files[0], "--reference", files[1], "--floor-m", "0", "--out", tmp_path / "c.csv") == 2
    assert "left_toe" in capsys.readouterr().err


def test_a_file_with_an_extra_end_joint_is_read_joint_by_joint(run, tmp_path, capsys):
    """docs/compare/own_generator.md: files are read onto the reference's skeleton joint by joint; a joint the reference
    does not have (here a hat on the head) is left out and the scores are the file's without it."""
    import copy

    from animsynth.skeleton import Joint

    d, _clip = run
    m = read_bvh(d / "knn.bvh")
    sk = copy.deepcopy(m.skeleton)
    sk.joints.append(Joint("hat", sk.index("head"), np.array([0.0, 1.0, 0.0]), np.array([0.0, 1.0, 0.0]),
                           ["rz", "rx", "ry"]))
    sk.__post_init__()
    n = m.n_frames
    write_bvh(tmp_path / "hat.bvh", Motion(np.hstack([m.values, np.full((n, 3), 10.0)]), sk, m.fps, "hat"))
    assert _score(tmp_path / "hat.bvh", "--reference", d / "held_out.bvh", "--out", tmp_path / "a.csv") == 0, \
        capsys.readouterr().err
    assert _score(d / "knn.bvh", "--reference", d / "held_out.bvh", "--out", tmp_path / "b.csv") == 0
    a, b = pd.read_csv(tmp_path / "a.csv"), pd.read_csv(tmp_path / "b.csv")
    pd.testing.assert_frame_equal(a[metric_table.METRIC_NAMES], b[metric_table.METRIC_NAMES], rtol=1e-6)


@pytest.mark.parametrize("generator", ["replay", "any_generator"])
def test_score_writes_exactly_the_metrics_of_the_table_that_one_motion_gives(generator):
    """Every key :func:`score` writes is a record of the metric table, and every record is written by it but those
    that a run gives (the generator's count, the spread over seeds: the runner adds them)."""
    from animsynth.compare import scoring

    mcfg = settings.job_cfg(_config())["metrics"]
    walk = protocol.resample(generate_motion("walk_straight", 480, 0, SK, name="t0"), 30.0)
    clip = protocol.prepare_clips({"t0": walk}, {}, {"walk": "t0"}, settings.clips_cfg(_config()))[0]
    row, _f = scoring.score(clip, scoring.reference(clip, mcfg), clip.truth, generator, mcfg)
    by_runner = {m.name for m in metric_table.METRICS if m.needs in ("generator", "seeds")}
    assert by_runner == {"transitions_kept", "seed_diversity_m"}
    assert set(row) == set(metric_table.METRIC_NAMES) - by_runner
    assert len(metric_table.METRIC_NAMES) == len(set(metric_table.METRIC_NAMES))
