"""The comparison's protocol: held-out windows, temporal blocks, the clips per subject, one build per database, scores
that do not depend on the company, and GenMM's pyramid on every clip's database."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from animsynth.compare import protocol, runner, settings
from animsynth.compare.generators.genmm import level_scales, make_genmm, pyramid_note
from animsynth.motion import Motion
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

from conftest import CMU, CMU_MANY, default_config, need


def _walk(seed: int, frames: int, name: str, sk=None) -> Motion:
    """A synthetic walk of ``frames`` frames at 120 fps (the trials' rate) on the CMU-like skeleton."""
    return generate_motion("walk_straight", frames, seed, sk or cmu_like_skeleton("cmp", 3), name=name)


# ----------------------------------------------------------------------------- windows, blocks and shares


def test_windows_are_non_overlapping_along_usable_stretches_with_the_last_shorter_one_kept():
    u = np.ones(100, bool)
    assert protocol.window_offsets(u, 30, 12) == [(0, 30, 100), (30, 30, 100), (60, 30, 100)]  # 10 < 12 left
    assert protocol.window_offsets(u, 30, 10) == [(0, 30, 100), (30, 30, 100), (60, 30, 100), (90, 10, 100)]
    u[40:45] = False  # a flagged stretch: no window crosses it, each stretch has its own
    assert protocol.window_offsets(u, 30, 10) == [(0, 30, 40), (30, 10, 40), (45, 30, 100), (75, 25, 100)]
    assert protocol.window_offsets(u, 30, 12) == [(0, 30, 40), (45, 30, 100), (75, 25, 100)]
    assert protocol.window_offsets(np.zeros(50, bool), 30, 10) == []


def test_a_temporal_split_has_equal_blocks_and_fewer_when_the_trial_is_short():
    assert protocol.split_blocks(90, 3, 20) == [(0, 30), (30, 60), (60, 90)]
    assert protocol.split_blocks(100, 3, 20) == [(0, 33), (33, 67), (67, 100)]
    assert protocol.split_blocks(42, 3, 20) == [(0, 21), (21, 42)]  # the run 35_17: two blocks of 21 frames
    assert protocol.split_blocks(39, 3, 20) == []  # not even two blocks: no database would be left


def test_the_cap_is_shared_evenly_over_groups_parts_and_windows():
    assert protocol.share(8, [8, 4, 3, 2]) == [2, 2, 2, 2]
    assert protocol.share(8, [1, 20, 20]) == [1, 3, 4]  # what the first cannot take goes to the others
    assert sum(protocol.share(5, [1] * 10)) == 5 and protocol.share(5, [1] * 10) == [1, 0] * 5  # spread, not first
    assert protocol.share(100, [2, 3]) == [2, 3]  # fewer windows than the cap: every one
    # a subject of three held-out trials with 2, 15 and 14 windows (36_01, 36_02, 36_03): the long trials take no
    # more than their share, and each trial's windows are spread along it
    picked = protocol.choose_windows([[2, 15, 14]], 8)[0]
    assert [len(p) for p in picked] == [2, 3, 3] and picked[1] == [2, 7, 12]
    assert protocol.choose_windows([[2, 2]], None) == [[[0, 1], [0, 1]]]
    assert protocol.choose_windows([[4]], 1) == [[[1]]] and protocol.choose_windows([[2]], 1) == [[[0]]]


def test_the_cap_keeps_every_group_of_a_subject_and_builds_only_the_chosen_databases():
    """Subject 35's layout: four groups (two subsets, two temporal splits); a cap of 8 keeps two windows of each
    group, and a held-out trial none of whose windows is chosen is not built."""
    sk = cmu_like_skeleton("cmp", 3)
    trials = {f"a{i}": _walk(i, 480, f"a{i}", sk) for i in range(4)}  # 120 frames at 30 fps: 2 windows each
    trials |= {f"b{i}": _walk(10 + i, 160, f"b{i}", sk) for i in range(4)}  # 40 frames: one shorter window
    trials |= {"c": _walk(20, 360, "c", sk), "d": _walk(21, 168, "d", sk)}
    cfg = {"fps": 30, "context": 8, "length": 60, "min_length": 12, "split_blocks": 3, "max_clips_per_subject": 8}
    subjects = {t: "35" for t in trials}
    clips = protocol.prepare_clips(trials, {"w1": [f"a{i}" for i in range(4)], "r1": [f"b{i}" for i in range(4)]},
                                   {"walk": "c", "run": "d"}, cfg, subjects=subjects)
    per_group = pd.Series([c.group for c in clips]).value_counts().to_dict()
    assert per_group == {"w1": 2, "r1": 2, "walk": 2, "run": 2} and {c.subject for c in clips} == {"35"}
    # one window from each of two of the four held-out trials, spread (the first and the third)
    assert [c.clip for c in clips if c.group == "w1"] == ["w1/a0@0", "w1/a2@0"]
    assert len({c.database_id for c in clips}) == 8  # eight databases, one build each per generator
    assert len(clips) == len({c.clip for c in clips})


def test_a_database_longer_than_its_cap_keeps_the_first_frames_of_each_piece():
    sk = cmu_like_skeleton("cmp", 3)
    trials = {f"t{i}": _walk(i, 1200, f"t{i}", sk) for i in range(3)}  # 300 frames at 30 fps each
    cfg = {"fps": 30, "context": 8, "length": 60, "min_length": 12, "split_blocks": 3, "max_database_s": 10.0}
    clips = protocol.prepare_clips(trials, {"s": ["t0", "t1", "t2"]}, {}, cfg)
    db = clips[0].database
    assert [d.n_frames for d in db] == [150, 150] and [d.name for d in db] == ["t1[0:150]", "t2[0:150]"]
    assert clips[0].database_names == ["t1 frames 0-149", "t2 frames 0-149"]
    assert np.array_equal(db[0].values, protocol.prepare_clips(trials, {"s": ["t0", "t1", "t2"]}, {}, dict(
        cfg, max_database_s=None))[0].database[0].values[:150])


def test_unusable_frames_stay_out_of_windows_and_databases():
    """A capture check's flagged frames (at the trial's own rate): no held-out window and no database piece holds a
    working frame that stands for one of them."""
    sk = cmu_like_skeleton("cmp", 3)
    trials = {f"t{i}": _walk(i, 480, f"t{i}", sk) for i in range(3)}  # 120 frames at 30 fps
    usable = {t: np.ones(480, bool) for t in trials}
    usable["t0"][:10] = False  # the first 10 source frames: working frames 0-3 (each within 3 of a flagged one)
    usable["t1"][200:206] = False  # working frames 50-52
    usable["t2"][36:38] = False  # working frames 8-10: leaves a stretch of 8 frames, too short to be a database piece
    cfg = {"fps": 30, "context": 8, "length": 30, "min_length": 8, "split_blocks": 3}
    clips = protocol.prepare_clips(trials, {"s": ["t0", "t1", "t2"]}, {}, cfg, usable=usable)
    t0 = [c for c in clips if c.trial == "t0"]
    assert [c.frame for c in t0] == [4, 42, 80]  # from the first usable frame on
    t1 = [c for c in clips if c.trial == "t1"]
    assert all(not (c.frame <= 50 < c.frame + c.context + c.length) for c in t1)
    assert [(c.frame, c.length) for c in t1] == [(0, 30), (53, 30), (91, 21)]
    assert [c.frame for c in clips if c.trial == "t2"] == [11, 49, 87]
    pieces = {d.name for c in clips for d in c.database}
    assert "t2[11:120]" in pieces and not any(p.startswith("t2[0:") for p in pieces)  # 8 frames < 8 + 8: dropped
    for c in clips:
        for d in c.database:
            bad = {"t0": range(0, 4), "t1": range(50, 53), "t2": range(8, 11)}.get(d.name.split("[")[0], range(0))
            if "[" in d.name:
                a, b = (int(x) for x in d.name.split("[")[1].rstrip("]").split(":"))
                assert not set(range(a, b)) & set(bad), (c.clip, d.name)
            else:
                assert not bad, (c.clip, d.name)


# ----------------------------------------------------------------------------- one build per database


def test_one_build_serves_every_window_and_seed_of_its_database(monkeypatch):
    from animsynth.compare.generators.references import Concat

    sk = cmu_like_skeleton("cmp", 3)
    trials = {f"t{i}": _walk(i, 480, f"t{i}", sk) for i in range(3)}
    config = default_config()
    cfg = dict(settings.job_cfg(config), seeds=2)
    cc = dict(settings.clips_cfg(config), max_clips_per_subject=None)
    clips = protocol.prepare_clips(trials, {"s": ["t0", "t1", "t2"]}, {}, cc)
    assert len(clips) == 9 and len({c.database_id for c in clips}) == 3
    fits = []
    real = Concat.fit

    def counted(self, database, native_clips=None):
        fits.append([d.name for d in database])
        return real(self, database)

    monkeypatch.setattr(Concat, "fit", counted)
    metrics, timing, _ = runner.run_generator(clips, "concat", cfg, 7)
    assert fits == [["t1", "t2"], ["t0", "t2"], ["t0", "t1"]]  # three builds for nine windows x two seeds
    assert len(metrics) == 18 and list(timing["clips"]) == [3, 3, 3] and timing["build_cpu_s"].notna().all()


# ----------------------------------------------------------------------------- scores independent of the company


def test_a_clips_scores_are_the_same_alone_and_beside_other_subjects():
    """L2P is normalised by the clip's own database: subject a's rows are the same, value for value, whether its
    clips run alone or beside subject b's (same skeleton, other motions; the whole-run statistics of before would
    have changed them)."""
    sk = cmu_like_skeleton("cmp", 3)
    a = {f"a{i}": _walk(i, 400, f"a{i}", sk) for i in range(3)}
    b = {f"b{i}": generate_motion("run_straight", 400, 30 + i, sk, name=f"b{i}") for i in range(3)}
    config = default_config()
    cfg = dict(settings.job_cfg(config), seeds=2)
    cc = settings.clips_cfg(config)
    subjects = {**{t: "a" for t in a}, **{t: "b" for t in b}}
    alone = protocol.prepare_clips(a, {"sa": list(a)}, {}, cc, subjects=subjects)
    both = protocol.prepare_clips({**a, **b}, {"sa": list(a), "sb": list(b)}, {}, cc, subjects=subjects)
    assert [c.clip for c in both if c.subject == "a"] == [c.clip for c in alone]
    for gen in ("knn", "motion_graph", "genmm"):
        m_alone, _t, _s = runner.run_generator(alone, gen, cfg, 7)
        m_both, _t, _s = runner.run_generator(both, gen, cfg, 7)
        mine = m_both[m_both["clip"].isin(m_alone["clip"])].reset_index(drop=True)
        assert m_alone["l2p"].notna().all()
        pd.testing.assert_frame_equal(mine, m_alone, check_exact=True, obj=gen)


# ----------------------------------------------------------------------------- GenMM's levels per clip


def _levels(clip: protocol.Clip, gm: dict) -> int:
    """GenMM's level count on ``clip``'s database (``gm``: the ``compare.genmm`` block)."""
    longest = max(d.n_frames for d in clip.database)
    return len(level_scales(longest, gm["patch_size"], gm["coarse_patches"], gm["pyramid_factor"], gm["min_levels"],
                            gm["min_coarse_patches"]))


def test_genmm_has_its_levels_on_every_clip_of_constructed_short_databases():
    """Databases of 35 to 120 frames (runs, short splits): every clip's GenMM has min_levels levels, its coarsest at
    least min_coarse_patches patches; a database at or under the floor (a 21-frame split) is refused (GenMM never
    runs below its level; with min_levels 1 it would run on one level) and its note says so."""
    sk = cmu_like_skeleton("cmp", 3)
    gm = default_config()["compare"]["genmm"]
    floor = gm["min_coarse_patches"] * gm["patch_size"]
    trials = {f"r{i}": _walk(i, n, f"r{i}", sk) for i, n in enumerate((140, 150, 160, 480))}
    trials["short"] = _walk(9, 168, "short", sk)
    cfg = {"fps": 30, "context": 8, "length": 60, "min_length": 12, "split_blocks": 3}
    clips = protocol.prepare_clips(trials, {"runs": ["r0", "r1", "r2", "r3"]}, {"run": "short"}, cfg)
    for c in clips:
        longest = max(d.n_frames for d in c.database)
        if longest > floor:
            g = make_genmm(gm).fit(c.database)
            assert len(g.scales_) >= gm["min_levels"] and g.scales_[0] * longest >= floor - 1e-6, (c.clip, longest)
            assert pyramid_note(longest, gm["patch_size"], gm["min_coarse_patches"], gm["min_levels"]) == ""
        else:
            assert "pyramid floor" in pyramid_note(longest, gm["patch_size"], gm["min_coarse_patches"],
                                                   gm["min_levels"])
            with pytest.raises(ValueError, match="not run below its level"):
                make_genmm(gm).fit(c.database)
            assert make_genmm(dict(gm, min_levels=1)).fit(c.database).scales_ == [1.0]  # asked for: one level
    assert {max(d.n_frames for d in c.database) for c in clips if c.group == "run"} == {21}


@pytest.mark.realdata
def test_genmm_has_its_levels_on_every_clip_of_the_paper_protocol():
    """The paper run's clips (config/cmu.yaml's groups, the trials read from ../shared/data as the workflow reads
    them): GenMM's level count per clip; only the run's temporal split (35_17, 42 frames at 30 fps: databases of
    21 frames) is too short for the floor, and the clips table's note says so."""
    from animsynth.capture_check import check_capture
    from cmu_yaml_trials import cmu_yaml_trials, paper_config

    need(CMU)
    need(CMU_MANY)
    config = paper_config()
    parsed = cmu_yaml_trials()  # read as the parse job reads them, parsed once per process (tests/cmu_yaml_trials.py)
    cc = dict(settings.clips_cfg(config), native_fps=[])
    gm = config["compare"]["genmm"]
    rows, short = [], set()
    for subject, (loo, split) in settings.subject_groups(config).items():
        ids = list(dict.fromkeys([t for v in loo.values() for t in v] + list(split.values())))
        trials = {t: parsed[t][1] for t in ids}
        checks = {t: check_capture(m, t, config["capture_check"]).usable for t, m in trials.items()}
        clips = protocol.prepare_clips(trials, loo, split, cc, subjects=settings.trial_subjects(config), usable=checks)
        for c in clips:
            n = _levels(c, gm)
            rows.append(protocol.clips_table([c]).iloc[0])
            if n < gm["min_levels"]:
                short.add(c.group)
                assert n == 1 and max(d.n_frames for d in c.database) <= gm["min_coarse_patches"] * gm["patch_size"]
    assert short == {"run"}, short
    table = pd.DataFrame(rows)
    for _, r in table.iterrows():  # the clips table's note (compare.jobs.gather_clips) on the run's clips only
        note = pyramid_note(int(r["database_longest"]), gm["patch_size"], gm["min_coarse_patches"], gm["min_levels"])
        assert bool(note) == (r["group"] == "run"), r["clip"]
