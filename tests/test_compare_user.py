"""A researcher's own generator in the comparison (compare.user_generators): it runs as ours do, and every way it
can fail leaves its rows empty with one error line naming the file, the class and the generator."""

from __future__ import annotations

import copy
import textwrap

import numpy as np
import pandas as pd
import pytest
import yaml

from animsynth.compare import jobs, protocol, runner, settings

from animsynth.compare.measures import metric_table
from animsynth.config import ConfigError, validate_config
from animsynth.io.bvh import read_bvh
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

from conftest import REPO, default_config

SHOWCASE = ("w1/t1", 1)


_config = default_config


@pytest.fixture(scope="module")
def clips_file(tmp_path_factory):
    """Three short synthetic walks, leave one out (3 clips, one window of each trial), 12 generated frames at 30 fps."""
    sk = cmu_like_skeleton("cmp", 3)
    walks = {f"t{s}": protocol.resample(generate_motion("walk_straight", 200, s, sk, name=f"t{s}"), 30.0) for s in range(3)}
    cfg = _config()["compare"]
    cc = {k: cfg[k] for k in settings.CLIP_KEYS}
    clips = protocol.prepare_clips(walks, {"w1": ["t0", "t1", "t2"]}, {}, dict(cc, length=12, max_clips_per_subject=3))
    assert [c.clip for c in clips] == ["w1/t0@0", "w1/t1@0", "w1/t2@0"]
    path = tmp_path_factory.mktemp("user_clips") / "clips.npz"
    protocol.save_clips(path, clips)
    return path


def _cfg(**user) -> dict:
    return dict(settings.job_cfg(_config()), seeds=2, user_generators=user)


def _run(tmp_path, name, cfg, clips_file):
    out = {k: str(tmp_path / f"{name}_{k}{ext}") for k, ext in
           (("metrics", ".csv"), ("timing", "_timing.csv"), ("shown", ".npz"), ("bvh", ".bvh"))}
    jobs.run_job(clips_file, name, cfg, 7, None, SHOWCASE, out)
    return out


#: a user's class that runs the family's own random concatenation through the public interface only
CONCAT_WRAPPER = """
from animsynth.compare.generators.references import Concat


class Wrapped:
    def fit(self, database):
        assert [c.n_frames for c in database.clips] and database.skeleton is not None and database.fps > 0
        self.gen = Concat(0.5, 1.5).fit(database.clips)
        return self

    def generate(self, start, length, seed):
        return self.gen.generate(start, length, seed)
"""


def test_a_user_generator_runs_on_the_clips_seeds_and_metrics_of_ours(tmp_path, clips_file):
    (tmp_path / "mine.py").write_text(CONCAT_WRAPPER)
    cfg = _cfg(wrapped=f"{tmp_path / 'mine.py'}:Wrapped")
    ours = pd.read_csv(_run(tmp_path, "concat", cfg, clips_file)["metrics"])
    out = _run(tmp_path, "wrapped", cfg, clips_file)
    theirs = pd.read_csv(out["metrics"])
    assert list(theirs.columns) == list(ours.columns) and (theirs["generator"] == "wrapped").all()
    assert theirs["note"].isna().all() and len(theirs) == 3 * 2
    # the same clips, seeds and metrics: the wrapped concatenation scores exactly as the family's own row
    pd.testing.assert_frame_equal(theirs.drop(columns="generator"), ours.drop(columns="generator"))
    shown = runner.load_shown(out["shown"])
    assert shown.n_frames == 8 + 12 and "note" not in shown.meta
    assert read_bvh(out["bvh"]).n_frames == 20


def test_a_relative_path_is_read_from_the_working_directory(tmp_path, clips_file, monkeypatch):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "mine.py").write_text(CONCAT_WRAPPER)
    monkeypatch.chdir(tmp_path)
    m = pd.read_csv(_run(tmp_path, "rel", _cfg(rel="sub/mine.py:Wrapped"), clips_file)["metrics"])
    assert m["note"].isna().all() and m["skate_share"].notna().all()


GOOD_HEAD = """
import numpy as np
from animsynth.motion import Motion
"""

#: (case, file text or None for no file, class, what the one error line says)
FAILURES = [
    ("missing file", None, "Hold", "no such file"),
    ("missing class", GOOD_HEAD, "Hold", "the file has no class 'Hold'"),
    ("not a class", GOOD_HEAD + "def Hold():\n    pass\n", "Hold", "'Hold' is a function, not a class"),
    ("no fit", GOOD_HEAD + "class Hold:\n    def generate(self, start, length, seed):\n        pass\n", "Hold",
     "the class has no method fit(database)"),
    ("no generate", GOOD_HEAD + "class Hold:\n    def fit(self, database):\n        return self\n", "Hold",
     "the class has no method generate(start, length, seed)"),
    ("generate takes too few", GOOD_HEAD + "class Hold:\n    def fit(self, database):\n        return self\n"
     "    def generate(self, start):\n        pass\n", "Hold", "cannot be called as generate(start, length, seed)"),
    ("needs arguments", GOOD_HEAD + "class Hold:\n    def __init__(self, k):\n        self.k = k\n"
     "    def fit(self, database):\n        return self\n    def generate(self, start, length, seed):\n        pass\n",
     "Hold", "Hold() raised TypeError"),
    ("syntax error", "class Hold:\n    def fit(self database):\n", "Hold", "importing the file raised SyntaxError at"),
    ("import fails", "import no_such_module_here\n", "Hold", "ModuleNotFoundError at mine.py:1"),
    ("fit raises", GOOD_HEAD + "class Hold:\n    def fit(self, database):\n        raise ValueError('too few clips')\n"
     "    def generate(self, start, length, seed):\n        pass\n", "Hold",
     "fit(database) raised ValueError at mine.py:6: too few clips"),
]
HOLD = GOOD_HEAD + """
class Hold:
    def fit(self, database):
        return self

    def generate(self, start, length, seed):
        v = np.repeat(start.values[-1:], length, axis=0)
{body}
"""
FAILURES += [
    ("generate raises", HOLD.format(body="        raise RuntimeError('no luck')"), "Hold",
     "generate(start, length, seed) raised RuntimeError at mine.py:11: no luck"),
    ("exits", HOLD.format(body="        raise SystemExit(3)"), "Hold",
     "generate(start, length, seed) raised SystemExit at mine.py:11: 3"),
    ("too few frames", HOLD.format(body="        return Motion(v[:-1], start.skeleton, start.fps)"), "Hold",
     "returned values of shape (11, "),
    ("wrong DOF", HOLD.format(body="        return Motion(v[:, 1:], start.skeleton, start.fps)"), "Hold",
     "expected (12, "),
    ("not a Motion", HOLD.format(body="        return v"), "Hold", "returned a ndarray, not an animsynth.motion.Motion"),
    ("not finite", HOLD.format(body="        v[3, 7] = np.nan\n        return Motion(v, start.skeleton, start.fps)"),
     "Hold", "non-finite values"),
    ("no skeleton", HOLD.format(body="        return Motion(v, None, start.fps)"), "Hold",
     "returned a motion on another skeleton"),
    ("wrong rate", HOLD.format(body="        return Motion(v, start.skeleton, 2 * start.fps)"), "Hold",
     "returned 60 fps, the database runs at 30 fps"),
    ("seams outside", HOLD.format(body="        return Motion(v, start.skeleton, start.fps, '', {'seams': [40]})"),
     "Hold", "seam indices outside 0..11"),
]


@pytest.mark.parametrize("case, text, cls, says", FAILURES, ids=[f[0] for f in FAILURES])
def test_every_failure_is_one_error_line_and_empty_rows(tmp_path, clips_file, capsys, case, text, cls, says):
    path = tmp_path / "mine.py"
    if text is not None:
        path.write_text(textwrap.dedent(text))
    spec = f"{path}:{cls}"
    capsys.readouterr()
    out = _run(tmp_path, "mine", _cfg(mine=spec), clips_file)  # the job completes: every file is written
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(err) == 1, err  # one error line ...
    line = err[0]
    assert f"user generator 'mine' ({path}:{cls})" in line and says in line, line  # ... naming generator, file, class
    assert "Traceback" not in line
    m = pd.read_csv(out["metrics"], keep_default_na=False, na_values=[""])
    assert len(m) == 3 * 2 and m[metric_table.METRIC_NAMES].isna().all().all()  # every row empty ...
    assert (m["note"] == "failed: " + line.removeprefix("animsynth: ERROR: ")).all()  # ... and says why
    t = pd.read_csv(out["timing"])
    assert len(t) == 3 and (t["frames_generated"] == 0).all() and t["build_cpu_s"].isna().all()
    shown = runner.load_shown(out["shown"])  # the showcase: the start alone, with the reason
    assert shown.n_frames == shown.meta["context"] == 8 and shown.meta["note"].startswith("failed: ")
    assert read_bvh(out["bvh"]).n_frames == 8


def test_a_failing_generator_stops_at_its_first_failure_with_one_line(tmp_path, clips_file, capsys):
    """Failing on the second clip only: one line, and the first clip's rows are empty too (no partial row)."""
    (tmp_path / "mine.py").write_text(CONCAT_WRAPPER + """

class Second(Wrapped):
    n = 0

    def fit(self, database):
        Second.n += 1
        if Second.n == 2:
            raise ValueError("second clip")
        return super().fit(database)
""")
    out = _run(tmp_path, "mine", _cfg(mine=f"{tmp_path / 'mine.py'}:Second"), clips_file)
    assert len([x for x in capsys.readouterr().err.splitlines() if x.strip()]) == 1
    m = pd.read_csv(out["metrics"])
    assert m["skate_share"].isna().all() and m["note"].str.contains("second clip").all()


@pytest.mark.parametrize("users, key", [
    ({"concat": "x.py:A"}, "compare.user_generators.concat"),
    ({"mine_timing": "x.py:A"}, "compare.user_generators.mine_timing"),
    ({"concat_long": "x.py:A"}, "compare.user_generators.concat_long"),  # concat's long-track file
])
def test_settings_check_refuses_names_of_ours_and_of_other_files(users, key):
    cfg = _config()
    cfg["compare"]["user_generators"] = users
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        settings.check(cfg)


@pytest.mark.parametrize("users, says", [
    ({"mine": "x.py"}, "does not match"),
    ({"my-gen": "x.py:A"}, "does not match"),
    ({"mine": "x.py:not a name"}, "does not match"),
])
def test_the_schema_refuses_a_bad_spec_or_name(users, says):
    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    cfg["compare"]["user_generators"] = users
    with pytest.raises(ConfigError, match=says):
        validate_config(cfg, str(REPO / "config" / "schema.yaml"))


def test_user_generators_run_after_ours_and_their_job_reruns_when_the_file_changes(tmp_path):
    cfg = _config()
    (tmp_path / "mine.py").write_text("class A:\n    pass\n")
    cfg["compare"]["user_generators"] = {"mine": f"{tmp_path / 'mine.py'}:A", "gone": f"{tmp_path / 'no.py'}:B"}
    settings.check(cfg)
    run, _left = settings.run_generators(cfg)
    assert run[-2:] == ["mine", "gone"] and settings.generator_order(cfg)[-2:] == ["mine", "gone"]
    before = settings.user_job_cfg(cfg, "mine")
    assert before["user_generators"] == {"mine": f"{tmp_path / 'mine.py'}:A"}
    (tmp_path / "mine.py").write_text("class A:\n    x = 1\n")
    assert settings.user_job_cfg(cfg, "mine")["user_file_sha256"] != before["user_file_sha256"]
    assert settings.user_job_cfg(cfg, "gone")["user_file_sha256"] == "missing"
    plain = _config()
    assert settings.run_generators(plain)[0] == [g for g in plain["compare"]["generators"]
                                                  if not settings.unavailable(g)]


def test_tables_show_a_user_row_and_leave_the_claims_unchanged(tmp_path, clips_file):
    """The family's tables with two user rows (one working, one failed) beside the family's: the user rows are in
    metrics, summary, winners, cost and the page; verdicts and sanity checks are byte for byte the ones without."""
    (tmp_path / "mine.py").write_text(CONCAT_WRAPPER)
    cfg = _cfg(wrapped=f"{tmp_path / 'mine.py'}:Wrapped", broken=f"{tmp_path / 'none.py'}:X")
    own = ["knn", "motion_graph", "replay", "concat"]
    runs = {g: _run(tmp_path, g, cfg, clips_file) for g in own + ["wrapped", "broken"]}
    clips = protocol.load_clips(clips_file)
    jobs_clips = protocol.clips_table(clips)
    jobs_clips.to_csv(tmp_path / "clips.csv", index=False)
    tcfg = {"generators": list(_config()["compare"]["generators"]), "seeds": 2, "fps": 30, "context": 8, "length": 12,
            "verdicts": _config()["compare"]["verdicts"], "claims": _config()["compare"]["claims"]}

    def tables_for(gens, folder):
        folder.mkdir()
        out = {k: str(folder / f"{k}.{ext}") for k, ext in (
            ("metrics", "csv"), ("metrics_timing", "csv"), ("summary", "csv"), ("winners", "csv"), ("winners_md", "md"),
            ("cost", "csv"), ("cost_md", "md"), ("verdicts", "csv"), ("verdicts_md", "md"), ("sanity", "csv"),
            ("sanity_md", "md"), ("sensitivity", "csv"), ("sensitivity_md", "md"), ("summary_md", "md"),
            ("claims_stats", "csv"), ("exploratory", "csv"), ("exploratory_md", "md"), ("clips", "csv"),
            ("clips_md", "md"))}
        users = [g for g in gens if g not in own]
        jobs.tables_job({"clips": [str(tmp_path / "clips.csv")], "metrics": [runs[g]["metrics"] for g in gens],
                           "timing": [runs[g]["timing"] for g in gens]}, out, gens, {},
                          dict(tcfg, generators=tcfg["generators"] + users), "synthetic")
        return out

    a = tables_for(own, tmp_path / "without")
    b = tables_for(own + ["wrapped", "broken"], tmp_path / "with")
    for k in ("verdicts", "verdicts_md", "sanity", "sanity_md"):
        assert open(a[k]).read() == open(b[k]).read(), k
    m = pd.read_csv(b["metrics"])
    assert list(dict.fromkeys(m["generator"])) == own + ["wrapped", "broken"]
    ours_only = [r for r in open(b["metrics"]).read().splitlines() if ",wrapped," not in r and ",broken," not in r]
    assert ours_only == open(a["metrics"]).read().splitlines()  # the family's rows byte for byte
    assert {"wrapped", "broken"} <= set(pd.read_csv(b["summary"])["generator"])
    assert list(pd.read_csv(b["cost"])["generator"]) == own + ["wrapped", "broken"]
    w = pd.read_csv(b["winners"])
    assert "wrapped" in set(w["best"]) | set(w["second"])  # a user row competes in "which generator wins"
    page = open(b["summary_md"]).read()
    assert "Your own generators (compare.user_generators): **wrapped**, **broken**" in page
    assert "Failed (no values at all): **broken**: user generator 'broken'" in page and "no such file" in page
    assert "Your own generators" not in open(a["summary_md"]).read()


def test_the_strips_figure_shows_a_failed_generator_by_its_start(tmp_path, clips_file):
    from animsynth.compare.plots import strips_figure

    runs = {g: _run(tmp_path, g, _cfg(broken=f"{tmp_path / 'none.py'}:X"), clips_file) for g in ("concat", "broken")}
    strips_figure(tmp_path / "strips.png", {g: runner.load_shown(r["shown"]) for g, r in runs.items()})
    assert (tmp_path / "strips.png").stat().st_size > 0


def test_without_user_generators_the_job_config_is_unchanged():
    """A run without user generators gives the family's jobs the config keys they had (no rerun, same files)."""
    cfg = _config()
    c2 = copy.deepcopy(cfg)
    c2["compare"].pop("user_generators")
    assert settings.run_generators(cfg) == settings.run_generators(c2)
    assert settings.generator_order(cfg) == list(cfg["compare"]["generators"])
    assert np.all([g in cfg["compare"]["generators"] for g in settings.run_generators(cfg)[0]])


# ----------------------------------------------------------------------------- the child process (compare.user_process)

def _guarded_run(tmp_path, name, cfg, clips_file):
    """The job's files below ``tmp_path/results/compare`` (so the guarded results folder is that one)."""
    folder = tmp_path / "results" / "compare" / "runs"
    folder.mkdir(parents=True, exist_ok=True)
    return _run(folder, name, cfg, clips_file)


def test_in_a_child_process_a_well_behaved_class_scores_as_in_process(tmp_path, clips_file):
    (tmp_path / "mine.py").write_text(CONCAT_WRAPPER)
    spec = f"{tmp_path / 'mine.py'}:Wrapped"
    child = pd.read_csv(_run(tmp_path, "wrapped", dict(_cfg(wrapped=spec), user_timeout_s=60), clips_file)["metrics"])
    inproc = pd.read_csv(_run(tmp_path, "inproc", dict(_cfg(inproc=spec), user_process=False), clips_file)["metrics"])
    assert child["note"].isna().all()
    pd.testing.assert_frame_equal(child.drop(columns="generator"), inproc.drop(columns="generator"))
    t = pd.read_csv(tmp_path / "wrapped_timing_timing.csv")  # the child's CPU is counted
    assert (t["build_cpu_s"] >= 0).all() and (t["generate_cpu_s"] > 0).all()


def test_a_class_that_hangs_is_stopped_at_the_time_limit(tmp_path, clips_file, capsys, caplog):
    (tmp_path / "mine.py").write_text(CONCAT_WRAPPER + """

class Hangs(Wrapped):
    def fit(self, database):
        import time
        time.sleep(30)
""")
    import time

    t0 = time.perf_counter()
    with caplog.at_level("INFO", logger="animsynth"):
        out = _run(tmp_path, "mine", dict(_cfg(mine=f"{tmp_path / 'mine.py'}:Hangs"), user_timeout_s=2), clips_file)
    assert time.perf_counter() - t0 < 25  # stopped at 2 s, not after the sleep
    err = [x for x in capsys.readouterr().err.splitlines() if x.strip()]
    assert len(err) == 1 and "user generator 'mine'" in err[0] and "fit(database) on clip w1/t0" in err[0]
    assert "time limit of 2 s (config key 'compare.user_timeout_s')" in err[0]
    m = pd.read_csv(out["metrics"])
    assert m["skate_share"].isna().all() and m["note"].str.contains("time limit").all()
    # the job's log: a line before the call (it is not an empty log while the class runs)
    assert "user generator mine: fit on clip w1/t0 (" in caplog.text and "frames) ..." in caplog.text


def test_relative_writes_land_in_the_temporary_working_directory(tmp_path, clips_file, monkeypatch):
    (tmp_path / "mine.py").write_text(CONCAT_WRAPPER + f"""

class Writes(Wrapped):
    def fit(self, database):
        import os
        with open("scratch.txt", "w") as fh:
            fh.write("hello")
        with open({str(tmp_path / 'cwd.txt')!r}, "w") as fh:
            fh.write(os.getcwd())
        return super().fit(database)
""")
    project = tmp_path / "project"
    project.mkdir()
    monkeypatch.chdir(project)
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    out = _guarded_run(tmp_path, "mine", _cfg(mine=f"{tmp_path / 'mine.py'}:Writes"), clips_file)
    assert pd.read_csv(out["metrics"])["note"].isna().all()
    workdir = (tmp_path / "cwd.txt").read_text()
    assert workdir.startswith(str(tmp_path / "tmp" / "animsynth-user-mine-"))
    assert (tmp_path / "tmp" / workdir.rsplit("/", 1)[1] / "scratch.txt").read_text() == "hello"  # kept: not empty
    assert not (project / "scratch.txt").exists() and not list((tmp_path / "results").rglob("scratch.txt"))


def test_a_write_into_the_results_folder_is_refused_and_named(tmp_path, clips_file, capsys):
    target = tmp_path / "results" / "compare" / "runs" / "knn.csv"
    (tmp_path / "mine.py").write_text(CONCAT_WRAPPER + f"""

class Spoils(Wrapped):
    def fit(self, database):
        with open({str(target)!r}, "w") as fh:
            fh.write("spoilt")
        return super().fit(database)
""")
    out = _guarded_run(tmp_path, "mine", _cfg(mine=f"{tmp_path / 'mine.py'}:Spoils"), clips_file)
    err = [x for x in capsys.readouterr().err.splitlines() if x.strip()]
    assert len(err) == 1 and "fit(database) raised PermissionError at mine.py:" in err[0] and str(target) in err[0]
    assert not target.exists()
    assert pd.read_csv(out["metrics"])["note"].str.contains("PermissionError").all()


@pytest.mark.parametrize("body, says", [
    ("import os\n        os._exit(3)", "ended its process with exit code 3"),
    ("import os, signal\n        os.kill(os.getpid(), signal.SIGSEGV)", "was killed by signal SIGSEGV"),
])
def test_an_exit_inside_the_class_is_blamed_on_it_and_the_job_completes(tmp_path, clips_file, capsys, body, says):
    (tmp_path / "mine.py").write_text(HOLD.format(body=f"        {body}"))
    out = _run(tmp_path, "mine", _cfg(mine=f"{tmp_path / 'mine.py'}:Hold"), clips_file)
    err = [x for x in capsys.readouterr().err.splitlines() if x.strip()]
    assert len(err) == 1, err
    assert f"user generator 'mine' ({tmp_path / 'mine.py'}:Hold): generate(start, 12, " in err[0]
    assert "on clip w1/t0" in err[0] and says in err[0]
    m = pd.read_csv(out["metrics"], keep_default_na=False, na_values=[""])
    assert len(m) == 6 and m["skate_share"].isna().all() and m["note"].str.contains(says).all()
    assert runner.load_shown(out["shown"]).meta["note"].startswith("failed: ")


def test_a_user_job_reads_the_time_limit_and_the_route():
    cfg = _config()
    cfg["compare"]["user_generators"] = {"mine": "x.py:A"}
    c = settings.job_cfg(cfg, "mine")
    assert c["user_timeout_s"] == 600 and c["user_process"] is True
    assert "user_timeout_s" not in settings.job_cfg(cfg, "knn")  # the family's jobs: unchanged, no rerun
