"""Known-answer tests of the long track's measures (repetition, freezing, drift, coverage against time, the first
against the last seconds), each on a constructed motion, and :func:`score` on a 600-frame motion."""

from __future__ import annotations

import numpy as np
import pytest

from animsynth.compare import measures as M
from animsynth.compare import scoring, settings
from animsynth.compare.measures import metric_table
from animsynth.compare.measures.over_time import coverage_after
from animsynth.compare.measures.repetition import earliest_repeat_distance, repetition_share
from animsynth.compare.measures.root import drift_share, root_tilt_deg, still_frames
from animsynth.compare.protocol import Clip
from animsynth.motion import Motion
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

from conftest import default_config

FPS = 30.0
SK = cmu_like_skeleton("long", 0)
COLS = SK.columns()
LONG = 600  # 20 s at 30 fps


@pytest.fixture(scope="module")
def mcfg():
    return settings.job_cfg(default_config())["metrics"]


def _features(values) -> np.ndarray:
    m = Motion(np.asarray(values, float), SK, FPS)
    return M.pose_features(M.positions(m), M.facing(m))


def _clip(held_out, database, context=8, length=LONG) -> Clip:
    return Clip("t/held", "t", "leave one out", "held", held_out, database, context, length)


def _standing(n: int) -> np.ndarray:
    """``n`` frames of the rest pose, its lowest foot joint 1 cm above y = 0 (every foot joint on the floor)."""
    v = np.zeros((n, SK.n_dof))
    low = M.positions(Motion(v[:1], SK, FPS))[0, M.foot_indices(SK), 1].min()
    v[:, COLS.index("root.ty")] = (0.01 - low) / SK.length_to_m
    return v


def _score_long(clip, values, mcfg, generator="gen"):
    ref = scoring.reference(clip, mcfg)
    return scoring.score(clip, ref, Motion(values, SK, FPS, generator), generator, mcfg, track="long")[0]


# ---------------------------------------------------------------------------------------------------------------
# repetition
# ---------------------------------------------------------------------------------------------------------------
def test_a_clip_played_three_times_repeats_two_thirds_of_its_frames():
    walk = generate_motion("walk_straight", LONG, 1, SK, fps=FPS)
    assert repetition_share(_features(walk.values), 30, 0.01) == 0.0  # its steps are alike, not within 1 cm
    looped = np.vstack([walk.values[:50]] * 3)  # a 50-frame piece played three times
    assert repetition_share(_features(looped), 30, 0.01) == pytest.approx(2 / 3, abs=1e-12)


def test_repetition_counts_the_frames_of_repeating_windows_only():
    rng = np.random.default_rng(0)
    F = rng.normal(0.0, 1.0, (100, 3))
    F[60:90] = F[10:40]  # one window repeats exactly; its neighbours differ by a whole frame's noise
    d = earliest_repeat_distance(F, 30)
    assert d[60] == 0.0 and np.all(np.isinf(d[:30]))
    assert repetition_share(F, 30, 1e-9) == pytest.approx(0.3)  # frames 60..89
    assert np.isnan(repetition_share(F[:59], 30, 1e-9))  # no two windows' frames


# ---------------------------------------------------------------------------------------------------------------
# freezing
# ---------------------------------------------------------------------------------------------------------------
def test_still_frames_need_both_the_root_and_the_pose_below_their_floors():
    pos = np.zeros((4, 2, 3))
    pos[:, 0, 0] = [0.0, 0.001, 0.1, 0.101]  # root: still, then 3 m/s, then still
    feats = np.zeros((4, 1))
    feats[3, 0] = 0.1  # the pose moves at 3 m/s into the last frame
    np.testing.assert_array_equal(still_frames(pos, feats, FPS, 0.1, 0.1), [True, False, False])


def test_a_still_pose_freezes_where_the_capture_walks(mcfg):
    walk = generate_motion("walk_straight", 240, 2, SK, fps=FPS)
    clip = _clip(Motion(walk.values[:128], SK, FPS), [Motion(walk.values[120:], SK, FPS)])
    row = _score_long(clip, np.repeat(walk.values[7:8], LONG, axis=0), mcfg)  # the last start frame, held
    assert row["still_share"] == 1.0 and row["freezing_share"] == 1.0
    moving = _score_long(clip, generate_motion("walk_straight", LONG, 3, SK, fps=FPS).values, mcfg)
    assert moving["still_share"] == 0.0 and moving["freezing_share"] == 0.0


def test_freezing_is_only_the_still_share_beyond_the_capture_own(mcfg):
    walk = generate_motion("walk_straight", 240, 2, SK, fps=FPS)
    held = np.vstack([walk.values[:68], np.repeat(walk.values[67:68], 60, axis=0)])  # 60 walking, 60 still frames
    clip = _clip(Motion(held, SK, FPS), [Motion(walk.values[120:], SK, FPS)])
    row = _score_long(clip, np.repeat(walk.values[7:8], LONG, axis=0), mcfg)
    assert row["freezing_share"] == pytest.approx(1.0 - 60 / 120)


# ---------------------------------------------------------------------------------------------------------------
# drift
# ---------------------------------------------------------------------------------------------------------------
def test_root_tilt_is_the_angle_of_the_root_up_axis_from_the_vertical():
    v = np.zeros((3, SK.n_dof))
    v[:, COLS.index("root.rx")] = [0.0, 30.0, -45.0]
    v[:, COLS.index("root.ry")] = 70.0  # a turn about the vertical is no tilt
    np.testing.assert_allclose(root_tilt_deg(SK, v), [0.0, 30.0, 45.0], atol=1e-9)


def test_drift_share_counts_frames_outside_either_widened_range():
    h = np.array([1.0, 0.94, 0.96, 1.0, 1.0])
    a = np.array([5.0, 5.0, 5.0, 21.0, 17.0])
    assert drift_share(h, a, (1.0, 1.0), (0.0, 8.0), 0.05, 10.0) == pytest.approx(2 / 5)  # 0.94 m, 21 deg
    assert np.isnan(drift_share(h[:0], a[:0], (1.0, 1.0), (0.0, 8.0), 0.05, 10.0))


def test_a_sinking_root_drifts_once_below_the_capture_and_its_tolerance(mcfg):
    stand = _standing(LONG + 8)
    clip = _clip(Motion(stand[:100], SK, FPS), [Motion(stand, SK, FPS)])
    gen = stand[:LONG].copy()
    gen[:, COLS.index("root.ty")] -= 0.013 * np.arange(1, LONG + 1) / SK.length_to_m  # 1.3 cm deeper each frame
    assert mcfg["drift_height_tolerance_m"] == 0.05  # frame t is 1.3 (t + 1) cm down: out from t = 3
    assert _score_long(clip, gen, mcfg)["drift_share"] == pytest.approx((LONG - 3) / LONG)
    assert _score_long(clip, stand[:LONG], mcfg)["drift_share"] == 0.0


# ---------------------------------------------------------------------------------------------------------------
# coverage against time
# ---------------------------------------------------------------------------------------------------------------
def test_a_motion_through_the_whole_database_covers_it_by_the_end_and_less_before():
    parts = [generate_motion(k, 200, 4, SK, fps=FPS).values for k in ("walk_straight", "run_straight", "dance")]
    db = [_features(p) for p in parts]
    through = _features(np.vstack(parts))  # every database clip played once, one after the other: 20 s
    cov = coverage_after(through, db, FPS, 8, 0.05, (5, 10, 20))
    walk_windows = (200 - 7) / (3 * (200 - 7))
    assert cov[20] == 1.0
    assert cov[5] < cov[10] < cov[20]
    assert cov[5] <= walk_windows + 1e-12  # the first 5 s walk: at most the walk's windows are reached
    assert np.isnan(coverage_after(through[:299], db, FPS, 8, 0.05, (10,))[10])  # shorter than 10 s


# ---------------------------------------------------------------------------------------------------------------
# the first against the last seconds, and score() on the long track
# ---------------------------------------------------------------------------------------------------------------
def test_a_motion_that_starts_clean_and_skates_at_the_end(mcfg):
    stand = _standing(LONG + 8)
    clip = _clip(Motion(stand[:100], SK, FPS), [Motion(stand, SK, FPS)])
    gen = stand[:LONG].copy()
    gen[540:, COLS.index("root.tx")] = 0.02 * (-1.0) ** np.arange(540, LONG) / SK.length_to_m  # shuffles 2 cm
    row = _score_long(clip, gen, mcfg)
    assert row["contact_share"] == 1.0  # every foot joint is on the floor throughout
    assert row["skate_share_first_2s"] == 0.0 and row["skate_share_last_2s"] == 1.0  # steps of 0.6, 1.2 m/s
    assert row["skate_share_change"] == 1.0
    # velocity jumps: 0 in the first 2 s; in the last 0.6 and 1.8 m/s at its first two frames, then 2.4 m/s
    assert row["velocity_jump_p95_first_2s"] == 0.0
    assert row["velocity_jump_p95_last_2s"] == pytest.approx(2.4, rel=1e-9)
    assert row["velocity_jump_p95_change"] == pytest.approx(2.4, rel=1e-9)


def test_score_on_the_long_track_gives_its_records_and_no_ground_truth(mcfg):
    walk = generate_motion("walk_turn", LONG + 130, 5, SK, fps=FPS)
    clip = _clip(Motion(walk.values[:130], SK, FPS), [Motion(walk.values[130:], SK, FPS)])
    row = _score_long(clip, walk.values[130:], mcfg)
    by_run = set(metric_table.names_needing(*metric_table.RUN_NEEDS, track="long"))
    assert set(row) == set(metric_table.track_names("long")) - by_run
    assert not {"l2p", "l2p_m", "l2q", "npss"} & set(row)
    assert row["coverage_after_20s"] == 1.0  # the motion is its database
    assert row["drift_share"] == 0.0 and row["repetition_share"] == 0.0
    short_clip = _clip(clip.held_out, clip.database, length=60)
    short = scoring.score(short_clip, scoring.reference(short_clip, mcfg), Motion(walk.values[8:68], SK, FPS), "g",
                          mcfg)[0]
    assert "repetition_share" not in short and "l2p" in short


def test_the_long_track_records_declare_a_margin_and_why():
    long_only = [m for m in metric_table.METRICS if m.tracks == ("long",)]
    assert {m.name for m in long_only} >= {"repetition_share", "freezing_share", "drift_share", "coverage_after_5s",
                                          "coverage_after_10s", "coverage_after_20s", "skate_share_last_2s",
                                          "velocity_jump_p95_change"}
    for m in long_only:
        assert (m.margin is None) == (m.better == ""), m.name
    assert metric_table.names_needing("", track="long")[:1] == ("velocity_jump_p95",)
    with pytest.raises(ValueError, match="unknown track"):
        metric_table.on_track("medium")



def test_run_values_are_the_generator_count_and_the_spread_over_seeds_on_either_track():
    class Counted:
        def run_notes(self):
            return {"transitions_kept": 3}

    f = np.zeros((10, 6))
    g = f + np.array([0.3, 0.0, 0.0, 0.0, 0.0, 0.0])
    for track in ("short", "long"):
        assert scoring.run_values(Counted(), [f, g], track) == {"transitions_kept": 3.0,
                                                                 "seed_diversity_m": pytest.approx(0.3)}

    class Silent:
        def run_notes(self):
            return {}

    assert np.isnan(scoring.run_values(Silent(), [f])["transitions_kept"])
