"""The long track: its contexts and seeds, run from the same build per database as the 2-s track, its "did not run"
rows (a generator that cannot continue that long, never a silently shorter motion), its claims (checked at parse
time, decided with Holm within the track) and its settings per generator row."""

from __future__ import annotations

import copy

import numpy as np
import pandas as pd
import pytest

from animsynth.compare import jobs, long_track, protocol, runner, settings
from animsynth.config import ConfigError
from animsynth.motion import Motion

from conftest import default_config

LONG = {"seconds": 4.5, "contexts_per_subject": 2, "seeds": 2}  # first and last 2 s apart


@pytest.fixture(scope="module")
def clips(walks, cfg):
    """Three held-out walks (leave one out): three databases, t1 with two windows."""
    trials = {f"t{i}": w for i, w in enumerate(walks)}
    cc = {k: cfg[k] for k in settings.CLIP_KEYS}
    return protocol.prepare_clips(trials, {"w1": ["t0", "t1", "t2"]}, {}, dict(cc, length=20))


def _db(ids: list[str]) -> dict:
    """A ``by_database`` mapping of stand-in clips (only ``.clip`` is read)."""
    class C:
        def __init__(self, clip):
            self.clip = clip

    out: dict = {}
    for c in ids:
        out.setdefault(c.split("@")[0], []).append(C(c))
    return out


def test_long_contexts_spread_over_the_databases_then_take_their_next_windows():
    by_db = _db(["a@0", "a@30", "b@0", "c@0", "d@0", "d@30"])
    assert long_track.long_contexts(by_db, 1) == ["a@0"]
    assert long_track.long_contexts(by_db, 2) == ["a@0", "d@0"]  # the first and the last database
    assert long_track.long_contexts(by_db, 4) == ["a@0", "b@0", "c@0", "d@0"]
    assert long_track.long_contexts(by_db, 6) == ["a@0", "b@0", "c@0", "d@0", "a@30", "d@30"]
    assert long_track.long_contexts(by_db, 9) == ["a@0", "b@0", "c@0", "d@0", "a@30", "d@30"]  # no more windows


def test_settings_per_row_and_off():
    block = {"seconds": 20, "contexts_per_subject": 1, "seeds": 2, "seeds_by_generator": {"fairmotion": 1}}
    assert long_track.long_settings(block, "genmm") == {"seconds": 20.0, "contexts_per_subject": 1, "seeds": 2}
    assert long_track.long_settings(block, "fairmotion")["seeds"] == 1  # the slow peer: fewer seeds, same contexts
    assert long_track.long_settings(None, "genmm") is None
    assert long_track.long_settings(dict(block, enabled=False), "genmm") is None
    config = default_config()
    assert settings.job_cfg(config, "fairmotion_fixed")["long_track"]["seeds"] == 1
    assert settings.job_cfg(config, "genmm")["long_track"] == {"seconds": 20.0, "contexts_per_subject": 1, "seeds": 2}
    assert "long_track" not in settings.job_cfg(config, "motion_graph", budget=2.0)  # the sweep's rows: short only


def test_both_tracks_share_one_build_per_database(monkeypatch, clips, cfg):
    fits = []
    real = runner.make_generator

    def counting(name, c):
        gen = real(name, c)
        fit = gen.fit
        gen.fit = lambda *a, **k: (fits.append(name), fit(*a, **k))[1]
        return gen

    monkeypatch.setattr(runner, "make_generator", counting)
    metrics, timing, _shown, long = runner.run_tracks(clips, "concat", dict(cfg, long_track=LONG), 7)
    assert len(fits) == 3 == len(timing)  # three databases, three builds, for both tracks
    m = long["metrics"]
    # the first window of the first and the last database, each with the short track's first two seeds
    assert list(m["clip"]) == ["w1/t0@0", "w1/t0@0", "w1/t2@0", "w1/t2@0"] and list(m["seed"]) == [0, 1, 0, 1]
    assert list(m.columns) == long_track.LONG_COLUMNS and (m["note"] == "").all()
    assert m[["repetition_share", "freezing_share", "drift_share", "skate_share_change"]].notna().all().all()
    n = int(round(LONG["seconds"] * cfg["fps"]))
    assert list(long["timing"]["frames_generated"]) == [2 * n, 2 * n] and list(long["timing"]["database"]) == [
        "w1/t0", "w1/t2"]
    assert long["shown"].n_frames == clips[0].context + n and long["shown"].meta["context"] == clips[0].context
    # the short track's rows are those of the run without the long track
    alone, _t, _s = runner.run_generator(clips, "concat", cfg, 7)
    pd.testing.assert_frame_equal(metrics, alone)


def test_the_cost_guard_counts_the_long_tracks_frames(monkeypatch, clips, cfg):
    """The estimate before a build counts every frame the build serves: each window's seeds and, for the databases
    with a long context, the long track's seeds x seconds x fps."""
    from animsynth.compare import cost

    asked = {}
    real = cost.guard

    def recording(generator, key, frames, c, length=0, seeds=0):
        asked[key] = int(length) * int(seeds)
        return real(generator, key, frames, c, length, seeds)

    monkeypatch.setattr(cost, "guard", recording)
    runner.run_tracks(clips, "concat", dict(cfg, long_track=LONG), 7)
    n = int(round(LONG["seconds"] * cfg["fps"]))
    for key, cs in runner.by_database(clips).items():
        short = sum(c.length for c in cs) * int(cfg["seeds"])
        assert asked[key] == short + (2 * n if key in ("w1/t0", "w1/t2") else 0), key  # two long seeds there


def test_replay_cannot_run_longer_than_the_held_out_capture(clips, cfg, caplog):
    _m, _t, _s, long = runner.run_tracks(clips, "replay", dict(cfg, long_track=dict(LONG, contexts_per_subject=1)), 7)
    m = long["metrics"]
    assert len(m) == 2 and m["note"].str.startswith("did not run: its query is the held-out future").all()
    assert m[long_track.LONG_NAMES].isna().all().all()
    assert sum("did not run the long track" in r.message for r in caplog.records) == 1  # said once per job
    assert long["shown"].n_frames == clips[0].context and long["shown"].meta["note"]  # the start alone


def test_a_short_return_is_a_did_not_run_row_never_a_shorter_motion(monkeypatch, clips, cfg):
    real = runner.make_generator

    def short(name, c):
        gen = real(name, c)
        generate = gen.generate

        def cut(start, length, seed, **kw):
            m = generate(start, length, seed, **kw)
            return Motion(m.values[:40], m.skeleton, m.fps, m.name, m.meta) if length > 40 else m

        gen.generate = cut
        return gen

    monkeypatch.setattr(runner, "make_generator", short)
    metrics, _t, _s, long = runner.run_tracks(clips, "concat", dict(cfg, long_track=LONG), 7)
    assert (metrics["note"] == "").all()  # the 2-s windows are shorter than the cut: scored as ever
    n = int(round(LONG["seconds"] * cfg["fps"]))
    assert (long["metrics"]["note"] == f"did not run: returned 40 frames, {n} asked for").all()
    assert long["metrics"][long_track.LONG_NAMES].isna().all().all()


def test_run_job_writes_the_long_files(tmp_path, clips, cfg):
    protocol.save_clips(tmp_path / "clips.npz", clips)
    out = {k: str(tmp_path / f"{k}{ext}") for k, ext in
           (("metrics", ".csv"), ("timing", "_timing.csv"), ("shown", ".npz"), ("long_metrics", "_long.csv"),
            ("long_timing", "_long_timing.csv"), ("long_shown", "_long.npz"))}
    jobs.run_job(tmp_path / "clips.npz", "concat", dict(cfg, long_track=dict(LONG, contexts_per_subject=1)), 7, None,
                 ("w1/t1", 0), out)
    m = pd.read_csv(out["long_metrics"])
    assert list(m["clip"]) == ["w1/t0@0"] * 2 and np.isfinite(m["repetition_share"]).all()
    assert runner.load_shown(out["long_shown"]).name.startswith("concat w1/t0@0 seed 0")


@pytest.mark.parametrize("pair", [("replay", "concat"), ("delaunay", "knn")])
def test_the_rows_of_one_job_share_each_clips_reference_and_write_what_their_own_jobs_write(tmp_path, clips, cfg,
                                                                                              monkeypatch, pair):
    """A job of two rows (as compare_run_<method> runs them): each clip's reference is made once for both rows and
    both tracks, and each row's tables and showcases are those the row writes in a job of its own (the bounds; the
    field followers, whose fit keeps state and whose path kernel is compiled)."""
    from animsynth.compare import scoring

    protocol.save_clips(tmp_path / "clips.npz", clips)
    c = dict(cfg, long_track=dict(LONG, contexts_per_subject=1))
    ext = {"metrics": ".csv", "timing": "_timing.csv", "shown": ".npz", "long_metrics": "_long.csv",
           "long_timing": "_long_timing.csv", "long_shown": "_long.npz"}
    made, real = [], scoring.reference
    monkeypatch.setattr(scoring, "reference", lambda clip, *a: made.append(clip.clip) or real(clip, *a))
    (tmp_path / "together").mkdir()
    rows = [[g, c, {}, f"{g}_", ["w1/t1", 0]] for g in pair]

    def together(name):
        g, k = next((g, name[len(g) + 1:]) for g in pair if name.startswith(f"{g}_"))
        return str(tmp_path / "together" / f"{g}{ext[k]}")

    jobs.run_rows(tmp_path / "clips.npz", rows, 7, together)
    assert sorted(made) == sorted(x.clip for x in clips)  # once per clip, not per row and track
    for g in pair:
        alone = tmp_path / g
        alone.mkdir()
        made.clear()
        jobs.run_job(tmp_path / "clips.npz", g, c, 7, {}, ("w1/t1", 0), {k: str(alone / f"{g}{e}") for k, e in ext.items()})
        assert sorted(made) == sorted(x.clip for x in clips)  # a job of its own makes them again
        for k in ("metrics", "long_metrics"):
            assert (alone / f"{g}{ext[k]}").read_bytes() == (tmp_path / "together" / f"{g}{ext[k]}").read_bytes(), (g, k)
        for k in ("shown", "long_shown"):
            a, b = runner.load_shown(alone / f"{g}{ext[k]}"), runner.load_shown(tmp_path / "together" / f"{g}{ext[k]}")
            assert np.array_equal(a.values, b.values) and a.name == b.name, (g, k)


# ----------------------------------------------------------------------------- claims of the long track


def _with_claim(**over) -> dict:
    cfg = copy.deepcopy(default_config())
    claim = {"id": "extra_long", "claim": "knn repeats less than delaunay", "a": "knn", "b": "delaunay",
             "metric": "repetition_share", "direction": "lower", "track": "long"}
    claim.update(over)
    cfg["compare"]["claims"].append({k: v for k, v in claim.items() if v is not None})
    return cfg


def test_long_claims_pass_and_bad_ones_are_refused_naming_the_key():
    settings.check(_with_claim())
    settings.check(_with_claim(metric="skate_share"))  # a record of both tracks
    n = len(default_config()["compare"]["claims"])
    for over, key, words in (({"track": "longer"}, "track", "'longer' is not a track"),
                             ({"metric": "l2p"}, "metric", "not a metric of the long track"),
                             ({"track": None}, "metric", "not a metric of the short track")):
        with pytest.raises(ConfigError, match=rf"compare\.claims\[{n}\]\.{key}'.*{words}"):
            settings.check(_with_claim(**over))
    short_run = _with_claim(metric="coverage_after_20s")
    settings.check(short_run)  # 20 s runs: coverage after 20 s is there
    short_run["compare"]["long_track"] = dict(short_run["compare"]["long_track"], seconds=10)
    with pytest.raises(ConfigError, match=rf"compare\.claims\[{n}\]\.metric'.*needs a run of at least 20 s"):
        settings.check(short_run)
    off = _with_claim()
    off["compare"]["long_track"] = None
    first = next(i for i, c in enumerate(off["compare"]["claims"]) if c.get("track") == "long")
    with pytest.raises(ConfigError, match=rf"compare\.claims\[{first}\]\.track'.*long_track' is off"):
        settings.check(off)


def _long_metrics(effects: list[float]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Long-track rows of genmm and motion_graph: one subject (one context) per effect, motion_graph's
    repetition share above genmm's by it; and the clips table."""
    rows, crow = [], []
    for i, e in enumerate(effects):
        clip = f"s{i}/{10 + i}_01@0"
        crow.append({"clip": clip, "group": f"s{i}", "held_out": f"{10 + i}_01", "database": f"{10 + i}_02",
                     "subject": f"s{i}"})
        for s in range(2):
            for g, v in (("genmm", 0.1), ("motion_graph", 0.1 + e)):
                rows.append({"clip": clip, "group": f"s{i}", "protocol": "leave one out", "generator": g, "seed": s,
                             **dict.fromkeys(long_track.LONG_NAMES, np.nan), "repetition_share": v + 0.001 * s,
                             "note": ""})
    return pd.DataFrame(rows), pd.DataFrame(crow).astype(str)


def test_a_long_claim_is_decided_by_the_same_rule_and_words(tmp_path):
    from animsynth.compare.long_tables import long_tables

    config = default_config()
    cmp = config["compare"]
    decided = {}
    for name, effects in (("holds", [0.3, 0.25, 0.35, 0.3, 0.28, 0.32]), ("opposite", [-0.3, -0.25, -0.35, -0.3,
                                                                                        -0.28, -0.32])):
        metrics, clips = _long_metrics(effects)
        metrics.to_csv(tmp_path / f"{name}.csv", index=False)
        pd.DataFrame(columns=long_track.LONG_TIMING_COLUMNS).to_csv(tmp_path / f"{name}_t.csv", index=False)
        t = long_tables({"long_metrics": [tmp_path / f"{name}.csv"], "long_timing": [tmp_path / f"{name}_t.csv"]},
                        {}, cmp, clips, "constructed")
        v = t["verdicts"].set_index("claim")
        claim = next(c["claim"] for c in cmp["claims"] if c.get("track") == "long" and c["metric"] ==
                     "repetition_share" and (c["a"], c["b"]) == ("genmm", "motion_graph"))
        decided[name] = v.loc[claim, "verdict"]
        assert (t["verdicts"]["source"] == "compare/metrics_long.csv").all()
        # the other long claims' rows did not run here: Holm runs over the long claims alone
        assert len(t["verdicts"]) == sum(c.get("track") == "long" for c in cmp["claims"])
        assert "Holm over the long track's claims alone" in t["markdown"]
    assert decided == {"holds": "reproduced", "opposite": "contradicted"}


def test_every_long_record_is_a_column_of_the_long_file():
    assert {"repetition_share", "freezing_share", "drift_share", "coverage_after_20s"} <= set(long_track.LONG_NAMES)
    assert "l2p" not in long_track.LONG_NAMES  # the held-out continuation is 2 s: no ground truth for 20 s



def test_null_long_track_as_a_user_types_it_validates_as_off():
    # "null (or enabled: false): off" (the schema): the validator fills the block's defaults, so null must not reach
    # it as null (it failed with "'NoneType' object has no attribute 'setdefault'")
    import yaml

    from animsynth.config import validate_config
    from conftest import REPO

    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    cfg["compare"]["long_track"] = None
    long_ids = [c["id"] for c in cfg["compare"]["claims"] if c.get("track") == "long"]
    assert long_ids
    validate_config(cfg, str(REPO / "config" / "schema.yaml"))
    assert cfg["compare"]["long_track"]["enabled"] is False
    assert long_track.long_settings(cfg["compare"]["long_track"], "genmm") is None
    first = next(i for i, c in enumerate(cfg["compare"]["claims"]) if c["id"] == long_ids[0])
    with pytest.raises(ConfigError, match=rf"compare\.claims\[{first}\]\.track'.*long_track' is off"):
        settings.check(cfg)  # its long claims name the track that is off
    cfg["compare"]["claims"] = [c for c in cfg["compare"]["claims"] if c["id"] not in long_ids]
    settings.check(cfg)
