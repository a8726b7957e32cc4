"""The compare family: generators behind one interface, the protocol, the verdict builder, the config checks."""

from __future__ import annotations

import copy

import numpy as np
import pandas as pd
import pytest

from animsynth.compare.generators import names as N
from animsynth.compare.generators import registry as G
from animsynth.compare import jobs, protocol, runner, scoring
from animsynth.compare.measures import metric_table
from animsynth.compare import tables
from animsynth.compare import settings
from animsynth.compare import claim_stats as CS
from animsynth.compare import groups as GR
from animsynth.compare import verdicts as CV
from animsynth.compare.claims import track_claims
from animsynth.config import ConfigError
from animsynth.generator import Database, align_root
from animsynth.retarget import unwrap_angles
from animsynth.kinematics import heading, root_translation
from animsynth.motion import Motion
from animsynth.verdicts import VOCABULARY, VerdictError

from conftest import default_config

_config = default_config


# the fixtures cfg (the generator jobs' config) and walks (the synthetic database) live in conftest.py


def _start(m: Motion, n: int = 8) -> Motion:
    return Motion(m.values[:n].copy(), m.skeleton, m.fps, "start")


NAMES = ["delaunay", "knn", "isomap", "stisomap", "motion_graph", "fairmotion", "motion_matching", "motion_matching_pose",
         "genmm", "replay", "concat"]


@pytest.fixture(scope="module")
def fitted(walks, cfg):
    out = {}
    for name in NAMES:
        if not settings.unavailable(name):
            out[name] = G.make_generator(name, cfg).fit(walks[1:])
    return out


@pytest.mark.parametrize("name", NAMES)
def test_generator_returns_length_frames_on_the_skeleton_and_is_seeded(fitted, walks, name):
    if name not in fitted:
        pytest.skip(f"{name}: {settings.unavailable(name)}")
    gen, start, length = fitted[name], _start(walks[0]), 40
    kw = runner.generation_query(gen, protocol.Clip("w/t@0", "w", "leave one out", "t", walks[0], walks[1:], 8, 40))
    a = gen.generate(start, length, 5, **kw)
    assert a.values.shape == (length, walks[0].skeleton.n_dof)
    assert a.skeleton.columns() == walks[0].skeleton.columns() and a.fps == 30.0
    assert np.all(np.isfinite(a.values))
    seams = np.asarray(a.meta["seams"])
    assert seams.ndim == 1 and (seams.size == 0 or (seams.min() >= 0 and seams.max() < length))
    src = np.asarray(a.meta["source_frames"])
    assert src.shape == (length, 2)
    b = gen.generate(start, length, 5, **kw)
    assert np.array_equal(a.values, b.values) and np.array_equal(seams, b.meta["seams"])
    c = gen.generate(start, length, 6, **kw)
    if name in N.DETERMINISTIC:  # the capture itself, or motion matching: whatever the seed
        assert np.array_equal(a.values, c.values), f"{name}: the seed changes the motion"
    else:
        assert not np.array_equal(a.values, c.values), f"{name}: the seed changes nothing"
    # the output continues the start where it stands: its first root is within a stride of the start's last
    step = np.linalg.norm(np.diff(root_translation(start.skeleton, walks[0].values)[:, [0, 2]], axis=0), axis=1)
    gap = np.linalg.norm(root_translation(a.skeleton, a.values[:1])[0, [0, 2]]
                         - root_translation(start.skeleton, start.values[-1:])[0, [0, 2]])
    assert gap < 6 * step.max(), (name, gap, step.max())


def test_replay_plays_the_held_out_future_it_is_given_and_declares_no_entry_seam(fitted, walks):
    rep = fitted["replay"]
    assert rep.query == "future_trajectory" and rep.entry_seam is False
    assert all(fitted[g].entry_seam for g in fitted if g != "replay")
    future = Motion(walks[0].values[8:].copy(), walks[0].skeleton, 30.0, "future")
    m = rep.generate(_start(walks[0]), 10, 0, trajectory=future)
    assert np.array_equal(m.values, walks[0].values[8:18]) and m.meta["seams"].size == 0
    with pytest.raises(ValueError, match="held-out future"):
        rep.generate(_start(walks[0]), 10, 0)
    with pytest.raises(ValueError, match="asked for"):
        rep.generate(_start(walks[0]), future.n_frames + 1, 0, trajectory=future)


def test_resequencers_copy_database_frames_and_record_their_sources(fitted, walks):
    db = Database(walks[1:])
    for name in ("isomap", "stisomap"):
        m = fitted[name].generate(_start(walks[0]), 25, 1)
        src = m.meta["source_frames"]
        angles = np.array([walks[1 + c].values[f, 6:] for c, f in src])
        assert np.allclose(m.values[:, 6:], angles)  # joint angles are the database frames' own
        follows = (src[1:, 0] == src[:-1, 0]) & (src[1:, 1] == src[:-1, 1] + 1)
        assert set(np.flatnonzero(~follows) + 1) == set(m.meta["seams"])
        assert db.n_frames == sum(w.n_frames for w in walks[1:])


def test_concat_segments_keep_their_heading_and_continue_the_root_position(fitted, walks):
    m = fitted["concat"].generate(_start(walks[0]), 40, 3)
    seams = m.meta["seams"]
    assert seams.size >= 1  # 40 frames of 15-45 frame segments
    p = root_translation(m.skeleton, m.values)
    for s in seams:
        assert np.allclose(p[s, [0, 2]], p[s - 1, [0, 2]])  # root position made continuous, no step
    p0 = root_translation(m.skeleton, m.values[:1])[0]
    assert np.allclose(p0[[0, 2]], root_translation(m.skeleton, walks[0].values[7:8])[0, [0, 2]])


def test_align_root_puts_the_frame_on_the_anchor(walks):
    sk, v = walks[1].skeleton, walks[1].values[:20]
    anchor = walks[2].values[5]
    out = align_root(sk, v, anchor, index=3)
    assert np.allclose(root_translation(sk, out[3:4])[0, [0, 2]], root_translation(sk, anchor[None])[0, [0, 2]])
    assert np.isclose(heading(sk, out[3:4])[0], heading(sk, anchor[None])[0])
    assert np.allclose(out[:, 6:], v[:, 6:])  # joint angles untouched
    d_in = np.linalg.norm(np.diff(root_translation(sk, v), axis=0), axis=1)
    d_out = np.linalg.norm(np.diff(root_translation(sk, out), axis=0), axis=1)
    assert np.allclose(d_in, d_out)  # a rigid move on the ground


def test_database_refuses_mixed_rates_and_counts_seams(walks):
    other = Motion(walks[1].values, walks[1].skeleton, 60.0, "fast")
    with pytest.raises(ValueError, match="fps"):
        Database([walks[0], other])
    db = Database(walks[:2])
    n0 = walks[0].n_frames
    path = [0, 1, 2, 5, 6, n0 - 2, n0 - 1, n0, n0 + 1]  # a skip, a jump, then from clip 0's end into clip 1
    assert list(db.seams(path)) == [3, 5, 7]


def test_unknown_generator_names_the_key(cfg):
    with pytest.raises(ValueError, match="compare.generators"):
        G.make_generator("nope", cfg)


# ----------------------------------------------------------------------------- the protocol


def test_clips_leave_one_out_and_temporal_split(walks):
    """Leave one out: every trial's windows share the database of the other trials; a temporal split: each block
    held out with the rest of the trial (before and after it) as its database; windows of context + length frames,
    the last shorter one kept; the held-out frames are the trial's own (made continuous at its rate, resampled)."""
    trials = {f"t{i}": Motion(w.values, w.skeleton, 30.0, f"t{i}") for i, w in enumerate(walks)}
    cc = {"fps": 15, "context": 4, "length": 10, "min_length": 6, "split_blocks": 3}
    clips = protocol.prepare_clips(trials, {"w1": ["t0", "t1", "t2"]}, {"walk": "t3"}, cc)
    # 30 frames at 15 fps: windows of 14 frames at 0 and 14, the last 2 frames too few; blocks of 10 frames
    assert [c.clip for c in clips] == ["w1/t0@0", "w1/t0@14", "w1/t1@0", "w1/t1@14", "w1/t2@0", "w1/t2@14",
                                       "walk/t3@0", "walk/t3@10", "walk/t3@20"]
    c0, c1 = clips[0], clips[1]
    assert [d.name for d in c0.database] == ["t1", "t2"] and c0.held_out.fps == 15.0
    assert c0.database is c1.database and c0.database_id == c1.database_id == "w1/t0"
    assert (c0.length, c0.start.n_frames, c1.frame) == (10, 4, 14)
    # every trial's angles continuous at its own rate (the synthetic root's Euler angles wrap), then resampled
    cont = {k: unwrap_angles(m).values for k, m in trials.items()}
    assert np.array_equal(c1.held_out.values, cont["t0"][::2][14:])
    assert np.array_equal(c1.truth.values, cont["t0"][::2][18:28])
    mid = clips[-2]
    assert mid.protocol == "temporal split" and mid.database_id == "walk/t3#1" and mid.length == 6
    assert [d.name for d in mid.database] == ["t3[0:10]", "t3[20:30]"]
    whole = cont["t3"][::2]
    assert np.array_equal(np.vstack([mid.database[0].values, mid.held_out.values, mid.database[1].values]), whole)
    assert mid.database_names == ["t3 frames 0-9", "t3 frames 20-29"]
    assert {c.subject for c in clips} == {"w1", "walk"}  # no subjects given: each group its own


def test_clips_round_trip_and_table(tmp_path, walks):
    trials = {f"t{i}": w for i, w in enumerate(walks)}
    cc = {"fps": 30, "context": 6, "length": 20, "min_length": 6, "split_blocks": 3, "min_clips_per_subject": 3}
    subjects = {"t0": "s", "t1": "s", "t2": "s"}
    clips = protocol.prepare_clips(trials, {"w1": ["t0", "t1"]}, {"walk": "t2"}, cc, subjects=subjects)
    protocol.save_clips(tmp_path / "c.npz", clips)
    back = protocol.load_clips(tmp_path / "c.npz")
    assert [c.clip for c in back] == [c.clip for c in clips]
    for a, b in zip(clips, back):
        assert (a.clip, a.protocol, a.length, a.context, a.subject, a.database_id, a.frame) == \
            (b.clip, b.protocol, b.length, b.context, b.subject, b.database_id, b.frame)
        assert np.array_equal(a.held_out.values, b.held_out.values)
        assert all(np.array_equal(x.values, y.values) for x, y in zip(a.database, b.database))
        assert b.held_out.skeleton.columns() == a.held_out.skeleton.columns()
    table = protocol.clips_table(back, 3)
    assert set(table["protocol"]) == {"leave one out", "temporal split"} and set(table["subject"]) == {"s"}
    assert (table["subject_clips"] == len(back)).all() and table["enough_clips"].all()
    assert (table["held_out_frames"] == table["context"] + table["length"]).all()
    assert list(table["held_out"])[0] == "t0 frames 0-25"


def test_clip_errors_name_the_keys(walks, caplog):
    import logging

    trials = {"a": walks[0], "b": walks[1]}
    cc = {"fps": 30, "context": 8, "length": 20, "min_length": 200, "split_blocks": 3}
    with pytest.raises(ValueError, match="compare.min_length"):
        protocol.prepare_clips(trials, {"w1": ["a", "b"]}, {}, cc)
    with pytest.raises(ValueError, match="compare.split_blocks"):
        protocol.prepare_clips(trials, {}, {"walk": "a"}, dict(cc, min_length=25))
    with pytest.raises(ValueError, match="compare.fps"):
        protocol.prepare_clips(trials, {"w1": ["a", "b"]}, {}, dict(cc, fps=7, min_length=6))
    with caplog.at_level(logging.WARNING, logger="animsynth.compare.protocol"):
        clips = protocol.prepare_clips(trials, {"w1": ["a", "b"]}, {}, dict(cc, min_length=6, min_clips_per_subject=9))
    assert "fewer than compare.min_clips_per_subject (9): left out of the declared tests" in caplog.text
    assert not protocol.clips_table(clips, 9)["enough_clips"].any()


def test_seeds_are_the_same_for_every_generator_and_differ_by_clip():
    assert protocol.clip_seeds(1, 11, "w1/a", 3) == protocol.clip_seeds(1, 11, "w1/a", 3)
    assert protocol.clip_seeds(1, 11, "w1/a", 3) != protocol.clip_seeds(1, 11, "w1/b", 3)
    assert len(set(protocol.clip_seeds(1, 11, "w1/a", 5))) == 5


def test_run_generator_scores_every_clip_and_seed_and_writes_a_bvh_our_reader_reads(tmp_path, walks, cfg):
    from animsynth.io.bvh import read_bvh
    from animsynth.kinematics import forward_kinematics

    trials = {f"t{i}": w for i, w in enumerate(walks)}
    cc = {k: cfg[k] for k in settings.CLIP_KEYS}
    clips = protocol.prepare_clips(trials, {"w1": ["t0", "t1", "t2"]}, {}, dict(cc, length=20))
    protocol.save_clips(tmp_path / "clips.npz", clips)
    out = {k: str(tmp_path / f"{k}{ext}") for k, ext in
           (("metrics", ".csv"), ("timing", "_timing.csv"), ("shown", ".npz"), ("bvh", ".bvh"))}
    jobs.run_job(tmp_path / "clips.npz", "stisomap", cfg, 7, None, ("w1/t1", 1), out)
    m = pd.read_csv(out["metrics"])
    # 60-frame trials: two windows of 28 frames each; at most 4 clips (compare.max_clips_per_subject of the demo)
    assert [c.clip for c in clips] == ["w1/t0@0", "w1/t1@0", "w1/t1@28", "w1/t2@0"]
    assert len(m) == 4 * cfg["seeds"] and list(m.columns) == metric_table.KEY_COLUMNS + metric_table.METRIC_NAMES + ["note"]
    assert (m["n_seams"] >= 1).all()  # the entry is a seam
    assert m["copy_share"].between(0.99, 1).all()  # a re-sequencer copies database poses
    t = pd.read_csv(out["timing"])  # one build per database: the two windows of t1 share one
    assert list(t["database"]) == ["w1/t0", "w1/t1", "w1/t2"] and list(t["clips"]) == [1, 2, 1]
    assert list(t["frames_generated"]) == [20 * cfg["seeds"], 40 * cfg["seeds"], 20 * cfg["seeds"]]
    assert (t["peak_rss_mb"] > 10).all() and t["peak_rss_mb"].is_monotonic_increasing
    shown = runner.load_shown(out["shown"])  # the first clip of the held-out trial w1/t1
    assert shown.n_frames == clips[1].context + clips[1].length and shown.meta["context"] == clips[1].context
    assert shown.name == "stisomap w1/t1@0 seed 1"
    back = read_bvh(out["bvh"])
    assert back.n_frames == shown.n_frames and np.isclose(back.fps, shown.fps)
    a = forward_kinematics(shown.skeleton, shown.values, ends=False)
    b = forward_kinematics(back.skeleton, back.values, ends=False)
    assert np.allclose(a, b, atol=1e-3)  # same joint positions, in the file's units


# ----------------------------------------------------------------------------- tables and verdicts


def _metrics(values: dict) -> pd.DataFrame:
    """A metrics table: {generator: list of skate shares over clips x seeds} (two groups of clips)."""
    rows = []
    for g, vals in values.items():
        for i, v in enumerate(vals):
            row = {"clip": f"{'ab'[i % 2]}/c{i // 4}", "group": "ab"[i % 2], "protocol": "leave one out",
                   "generator": g, "seed": i // 2 % 2}
            row.update({m: np.nan for m in metric_table.METRIC_NAMES})
            row.update(skate_share=v, transition_skate_share=v, velocity_jump=v, l2p=v, novelty_median_m=v)
            rows.append(row)
    return pd.DataFrame(rows)


#: the rule's settings with smaller margins than the metric table's (compare.verdicts.min_effect overrides them), so
#: the constructed effects of a few hundredths count
VC = {"alpha": 0.05, "min_groups": 3, "novelty_copy_m": 0.01,
      "min_effect": {"skate_share": 0.02, "transition_skate_share": 0.02, "velocity_jump_p95": 0.1, "l2p": 0.25,
                     "novelty_median_m": 0.005, "coverage": 0.02}}
#: the declared 2-s claims of the shipped config (the long track's: tests/test_compare_long_track.py)
CLAIMS = track_claims(_config()["compare"]["claims"], "short")


def _claim(a: str, b: str, metric: str) -> str:
    """The text of the declared claim of ``a`` against ``b`` on ``metric`` (from the config)."""
    return next(c["claim"] for c in CLAIMS if (c["a"], c["b"], c["metric"]) == (a, b, metric))


def test_holm_adjusts_a_family_of_p_values():
    from animsynth import verdicts as V

    adj = V.holm([0.01, 0.04, np.nan, 0.03])
    np.testing.assert_allclose(adj[[0, 1, 3]], [0.03, 0.06, 0.06])  # 3 x 0.01, max(2 x 0.03, 0.03), 1 x 0.04 -> 0.06
    assert np.isnan(adj[2])


def _grouped(group_effects: list[list[float]], seeds: int = 2, pair=("motion_graph", "stisomap"),
             metric: str = "skate_share") -> tuple[pd.DataFrame, pd.DataFrame]:
    """Metrics of ``pair`` (default motion_graph and stisomap) on ``metric`` and a clips table: one subset per
    group (its own subject), clip ``i`` of a group with effect ``group_effects[g][i]`` (the second's value minus
    the first's)."""
    rows, crow = [], []
    for gi, effects in enumerate(group_effects):
        subset = f"s{gi}"
        trials = [f"{10 + gi}_{i:02d}" for i in range(len(effects))]
        for i, e in enumerate(effects):
            clip = f"{subset}/{trials[i]}"
            crow.append({"clip": clip, "group": subset, "held_out": trials[i],
                         "database": " ".join(t for t in trials if t != trials[i])})
            for s in range(seeds):
                for g, v in ((pair[0], 0.2), (pair[1], 0.2 + e)):
                    row = {"clip": clip, "group": subset, "protocol": "leave one out", "generator": g, "seed": s}
                    row.update({m: np.nan for m in metric_table.METRIC_NAMES})
                    row[metric] = v + 0.001 * s
                    rows.append(row)
    return pd.DataFrame(rows), pd.DataFrame(crow)


def test_counting_clips_says_reproduced_where_counting_groups_cannot_decide():
    # 19 clips in 7 independent groups: 5 groups of 3 clips all hold clearly; in 2 groups of 2 clips one clip
    # holds and one the opposite (the group votes neither way)
    effects = [[0.05, 0.06, 0.05]] * 5 + [[0.05, -0.05]] * 2
    metrics, clips = _grouped(effects)
    claim = _claim("motion_graph", "stisomap", "skate_share")
    j = CS.pair_outcomes(metrics, "motion_graph", "stisomap", "skate_share")
    c = CS.per_clip(j)
    h, f = int((c["outcome"] > 0).sum()), int((c["outcome"] < 0).sum())
    # by clips it would read reproduced: 17 of 19 untied clips hold (89 %), a sign test p of 0.0007
    assert (h, f) == (17, 2)
    groups = GR.independent_groups(clips)
    assert len(set(groups.values())) == 7
    v = CV.build_verdicts(metrics, VC, "test data", {}, clips, claims=CLAIMS).set_index("claim")
    # by groups: 5 effects of 0.05 and 2 of 0: the sign-flip p is 8/128 = 0.0625, no group the opposite
    assert v.loc[claim, "verdict"] == "undecided" and v.loc[claim, "ours"].startswith("undecided (7 subjects)")
    ev = v.loc[claim, "evidence"]
    assert "7 independent subjects" in ev and "holds in 5, opposite in 0, neither in 2" in ev
    assert "Holm-adjusted" in ev and "margin 0.02" in ev and "17 of 19 untied clips" in ev
    assert ev.startswith("tested: motion_graph lower than stisomap on skate_share; ")  # the hypothesis
    # every group holding: reproduced (p = 2/2^7); two groups holding the opposite without a significant split
    # between subjects (2 or 3 clips x 2 seeds per subject): undecided, not partly
    def verdict(effects):
        m, c = _grouped(effects)
        return CV.build_verdicts(m, VC, "test data", {}, c, claims=CLAIMS).set_index("claim").loc[claim, "verdict"]

    assert verdict([[0.05, 0.06, 0.05]] * 7) == "reproduced"
    assert verdict([[0.05, 0.06, 0.05]] * 5 + [[-0.05, -0.04]] * 2) == "undecided"
    # effects below the margin, however consistent, with a tight interval: equivalent within the margin
    assert verdict([[0.01, 0.012, 0.011]] * 7) == "no material difference"


@pytest.mark.parametrize("pair, metric, sign", [
    (("motion_matching", "motion_graph"), "skate_share", 1),
    (("genmm", "motion_graph"), "coverage", -1),
])
def test_the_modern_rows_claims_are_decided_over_groups(pair, metric, sign):
    # effect = second minus first: motion matching skating less is a positive effect, GenMM covering more a
    # negative one (coverage: higher is better)
    claim = _claim(*pair, metric)

    def verdict(effects, left_out=None, **kw):
        m, c = _grouped([[sign * e for e in g] for g in effects], pair=pair, metric=metric)
        if left_out:
            m = m[m["generator"] != left_out]
        v = CV.build_verdicts(m, dict(VC, **kw), "test data", {left_out: "not in this run"} if left_out else {}, c,
                              claims=CLAIMS)
        return v.set_index("claim").loc[claim]

    row = verdict([[0.05, 0.06, 0.05]] * 7)
    assert row["verdict"] == "reproduced" and "7 independent subjects" in row["evidence"]
    assert "Holm-adjusted" in row["evidence"] and f"{metric} (" in row["ours"]
    assert verdict([[-0.05, -0.06, -0.05]] * 7)["verdict"] == "contradicted"
    # groups both ways, no subject significant on its own 4-6 clip x seed effects: undecided, not partly
    assert verdict([[0.05, 0.06, 0.05]] * 4 + [[-0.05, -0.04]] * 3)["verdict"] == "undecided"
    assert verdict([[0.01, 0.012, 0.011]] * 7)["verdict"] == "no material difference"  # within the margin
    missing = verdict([[0.05, 0.06, 0.05]] * 7, left_out=pair[0])
    assert missing["verdict"] == "did not run" and "not in this run" in missing["evidence"]


def test_every_declared_claim_and_sanity_check_has_a_margin_by_default():
    """The shipped config names no margin: every declared claim takes its metric's margin from the metric table, and
    so do the sanity checks' metrics (compare.verdicts.min_effect is an empty override)."""
    from animsynth.compare.claims import declared_claims, margin

    cmp = _config()["compare"]
    assert cmp["verdicts"]["min_effect"] == {} and not any("min_effect" in c for c in cmp["claims"])
    for c in declared_claims(cmp):
        assert c["margin"] == metric_table.metric(c["metric"]).margin > 0, c["claim"]
    for m in ("velocity_jump_p95", "novelty_median_m", *metric_table.EXPLORATORY_METRICS):
        assert margin(m, cmp["verdicts"]) == metric_table.metric(m).margin > 0, m
    # the override and a claim's own min_effect come first, in that order
    assert margin("skate_share", {"min_effect": {"skate_share": 0.1}}) == 0.1
    assert margin("skate_share", {"min_effect": {"skate_share": 0.1}}, {"min_effect": 0.2}) == 0.2


def test_the_modern_rows_from_the_config(cfg):
    mm = G.make_generator("motion_matching", cfg)
    pose = G.make_generator("motion_matching_pose", cfg)
    assert (mm.name, pose.name) == ("motion_matching", "motion_matching_pose")
    assert mm.foot_lock is True and pose.foot_lock is True  # the reference's default, in both rows
    assert mm.trajectory_weight == 1.0 and pose.trajectory_weight == 0.0
    assert list(mm.weights) == [0.75, 1.0, 1.0, 1.0, 1.5] and mm.exclude_s == pytest.approx(1 / 3, abs=1e-15)
    gm = G.make_generator("genmm", cfg)
    assert gm.name == "genmm" and gm.alpha == 0.01 and gm.patch_size == 11 and gm.root == "local"
    no_norm = G.make_generator("genmm", dict(cfg, genmm=dict(cfg["genmm"], alpha=None)))
    assert no_norm.alpha == float("inf")  # null in the config: the ablation without completeness normalisation
    assert set(N.DETERMINISTIC) <= set(N.GENERATORS) and "genmm" not in N.DETERMINISTIC


def test_motion_matching_rows_have_seed_diversity_zero_and_genmm_does_not(walks, cfg):
    trials = {f"t{i}": w for i, w in enumerate(walks)}
    cc = {k: cfg[k] for k in settings.CLIP_KEYS}
    clips = protocol.prepare_clips(trials, {"w1": ["t0", "t1", "t2"]}, {}, dict(cc, length=20))
    for name, zero in (("motion_matching", True), ("genmm", False)):
        metrics, timing, _ = runner.run_generator(clips, name, cfg, 7)
        assert len(metrics) == len(clips) * cfg["seeds"] and (metrics["note"] == "").all()
        div = metrics.groupby("clip")["seed_diversity_m"].first()
        # motion matching is deterministic; GenMM's seeds differ (its noise), though two may meet on a clip
        assert ((div == 0).all() if zero else (div > 0).mean() >= 0.5), (name, div)
        assert np.isfinite(timing["generate_cpu_s"]).all()
        assert list(timing["frames_generated"]) == [20 * cfg["seeds"] * n for n in timing["clips"]]


def test_clips_sharing_a_trial_or_a_subject_in_a_subset_are_one_group():
    clips = pd.DataFrame([
        {"clip": "r1/35_17", "group": "r1", "held_out": "35_17", "database": "35_22 35_18"},
        {"clip": "r1/35_22", "group": "r1", "held_out": "35_22", "database": "35_17 35_18"},
        {"clip": "w1/35_16", "group": "w1", "held_out": "35_16", "database": "35_07"},
        {"clip": "run/35_17", "group": "run", "held_out": "35_17[26:42]", "database": "35_17 frames 0-25"},
        {"clip": "dance/05_02", "group": "dance", "held_out": "05_02[197:281]", "database": "05_02 frames 0-196"},
    ])
    g = GR.independent_groups(clips, "subset_subject")
    assert g["r1/35_17"] == g["r1/35_22"] == g["run/35_17"] == "r1 + run"
    assert g["w1/35_16"] == "w1" and g["dance/05_02"] == "dance"
    # by subject (the default): every clip of subject 35 is one group, whatever its subset
    g = GR.independent_groups(clips)
    assert g["r1/35_17"] == g["r1/35_22"] == g["run/35_17"] == g["w1/35_16"] == "subject 35 (r1, w1, run)"
    assert g["dance/05_02"] == "subject 05 (dance)"
    # a clip without a subject id keeps its subset as its group
    other = pd.concat([clips, pd.DataFrame([{"clip": "x/walkA", "group": "x", "held_out": "walkA", "database": "walkB"}])])
    assert GR.independent_groups(other)["x/walkA"] == "x"
    # the declared subject (clips.csv's column, the trial records') joins two sets of one person with other ids
    mine = pd.DataFrame([{"clip": "a/walkA", "group": "a", "held_out": "walkA", "database": "walkB", "subject": "ann"},
                         {"clip": "b/runA", "group": "b", "held_out": "runA", "database": "runB", "subject": "ann"},
                         {"clip": "c/jogA", "group": "c", "held_out": "jogA", "database": "jogB", "subject": "bob"}])
    g = GR.independent_groups(mine)
    assert g["a/walkA"] == g["b/runA"] != g["c/jogA"] and len(set(g.values())) == 2
    assert len(set(GR.independent_groups(mine.drop(columns="subject")).values())) == 3  # without it: by subset
    with pytest.raises(ValueError, match="compare.verdicts.grouping"):
        GR.independent_groups(clips, "trial")


def test_verdict_builder_on_known_outcomes():
    n = 16
    lo, hi = list(np.linspace(0.1, 0.2, n)), list(np.linspace(0.3, 0.4, n))
    metrics = _metrics({"motion_graph": lo, "stisomap": hi, "isomap": [0.0] * n, "delaunay": hi, "knn": hi,
                        "concat": hi, "replay": [0.05] * n})
    vc = dict(VC, min_groups=2)
    v = CV.build_verdicts(metrics, vc, "test data", {"fairmotion": "not installed here"},
                          claims=CLAIMS).set_index("claim")
    assert set(v["verdict"]) <= set(VOCABULARY)
    claim = _claim("motion_graph", "stisomap", "skate_share")
    # two groups hold clearly, but two groups cannot decide: the smallest sign-flip p is 2 / 2^2 = 0.5
    assert v.loc[claim, "verdict"] == "undecided" and v.loc[claim, "ours"].startswith("undecided (2 subjects)")
    ev = v.loc[claim, "evidence"]
    assert "2 independent subjects" in ev and "holds in 2, opposite in 0" in ev and "p = 0.5" in ev
    fm = v.loc[_claim("motion_graph", "fairmotion", "transition_skate_share")]
    assert fm["verdict"] == "did not run" and "not installed here" in fm["evidence"]
    jumps = v.loc[_claim("stisomap", "isomap", "velocity_jump_p95")]
    assert jumps["verdict"] == "did not run" and "no values of velocity_jump_p95" in jumps["evidence"]
    capture = v.loc[_claim("replay", "*", "skate_share")]
    # isomap skates less than the capture: its part holds the opposite in both groups; the parts carry numbers only
    import re

    ev = capture["evidence"]
    assert "isomap: 0/2/0, mean effect -0.05" in ev and capture["verdict"] == "undecided"
    parts = [float(x) for x in re.findall(r": \d+/\d+/\d+, mean effect [^]]+\], p = ([0-9.e-]+)", ev)]
    # isomap leans the other way by the minimum effect: the claim is tested for a contradiction (the smallest p of
    # the opposite parts times the 5 parts, Bonferroni), not by the largest p of the intersection-union test
    got = float(re.search(r"parts, Bonferroni, p = ([0-9.e-]+)", ev).group(1))
    assert len(parts) == 5 and "Tested for a contradiction" in ev and got == min(1.0, 5 * 0.5)
    n_declared = {int(x) for x in re.findall(r"Holm over the (\d+) declared claims", " ".join(v["evidence"]))}
    tested = sum(bool(re.search(r"\d+ independent subjects: mean effect", e)) for e in v["evidence"])
    assert n_declared == {tested + 1}  # the pair claims with a test, and the capture claim once
    # sanity checks: true by construction, not among the findings
    s = CV.sanity_checks(metrics, vc, "test data", {}).set_index("claim")
    assert any(c.startswith("re-sequencers copy database frames") for c in s.index)
    assert not any(c.startswith("re-sequencers copy database frames") for c in v.index)
    assert not v.index.str.contains("concatenation").any() and s.index.str.contains("concatenation").any()


def test_verdict_rows_use_the_common_vocabulary():
    from animsynth import verdicts as V

    with pytest.raises(VerdictError):
        V.row("a claim", "holds")


def test_summary_and_winners_tables():
    n = 8
    metrics = _metrics({"motion_graph": [0.1] * n, "stisomap": [0.2] * n, "isomap": [0.3] * n,
                        "replay": [0.0] * n, "concat": [0.5] * n})
    order = list(N.GENERATORS)
    s = tables.summary_table(metrics, order)
    row = s[(s["generator"] == "stisomap") & (s["metric"] == "skate_share")].iloc[0]
    assert row["n"] == n and row["median"] == pytest.approx(0.2) and row["better"] == "lower"
    assert list(dict.fromkeys(s["generator"])) == ["isomap", "stisomap", "motion_graph", "replay", "concat"]
    w = tables.winners_table(metrics, s, order).set_index("metric")
    r = w.loc["skate_share"]
    assert (r["best"], r["second"], bool(r["beyond_spread"])) == ("motion_graph", "stisomap", True)
    assert r["best_wins_share"] == 1.0 and r["replay_median"] == 0.0 and r["concat_median"] == 0.5


# ----------------------------------------------------------------------------- config checks


@pytest.mark.parametrize("mutate, key", [
    (lambda c: c["compare"].update(fps=50), "compare.fps"),
    (lambda c: c["compare"].update(min_length=100), "compare.min_length"),
    (lambda c: c["compare"]["showcase"].update(clip="w1/nope"), "compare.showcase.clip"),
    (lambda c: c["compare"]["showcase"].update(seed=9), "compare.showcase.seed"),
    (lambda c: c["compare"]["concat"].update(min_segment_s=2.0), "compare.concat.min_segment_s"),
    (lambda c: c["compare"]["motion_graph"].update(blend=20), "compare.motion_graph.blend"),
    (lambda c: c["compare"]["metrics"].update(window=50), "compare.metrics.window"),
    (lambda c: c["compare"]["fairmotion"].update(blend=15), "compare.fairmotion.blend"),
    (lambda c: c["compare"]["fairmotion"].update(compare=5), "compare.fairmotion.compare"),
    (lambda c: c["compare"]["fairmotion"].update(stride=20), "compare.fairmotion.stride"),
    (lambda c: c["compare"].update(subsets=[], resequencing=[]), "compare.subsets"),
    (lambda c: c["compare"]["motion_matching"].update(future_s=[0.5, 0.4, 1.0]), "compare.motion_matching.future_s"),
    (lambda c: c["compare"]["motion_matching"].update(weights=[0, 0, 0, 1, 1.5]), "compare.motion_matching.weights"),
    (lambda c: c["compare"]["genmm"].update(patch_size=10), "compare.genmm.patch_size"),
    (lambda c: c["compare"]["genmm"].update(patch_size=21), "compare.genmm.patch_size"),
    (lambda c: c["compare"].update(max_clips_per_subject=2), "compare.min_clips_per_subject"),
])
def test_settings_check_names_the_key(mutate, key):
    cfg = _config()
    settings.check(cfg)
    bad = copy.deepcopy(cfg)
    mutate(bad)
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        settings.check(bad)


def test_settings_lists_held_out_trials_subjects_and_showcase():
    cfg = _config()
    ids = settings.held_out_trials(cfg)
    first = cfg["compare"]["subsets"][0] if cfg["compare"]["subsets"] else "w1"
    assert ids[0] == f"{first}/{cfg['subsets'][first][0]}" and ids[-1] == f"dance/{cfg['resequencing_trials']['dance']}"
    every = dict(cfg, compare=dict(cfg["compare"], subsets=None))
    assert len(settings.held_out_trials(every)) == sum(len(v) for v in cfg["subsets"].values() if v) + 3
    # the demo: subject syn35 (r1, walk, run) and syn05 (dance), each its own clips job
    by = settings.subject_groups(cfg)
    assert list(by) == ["syn35", "syn05"] and list(by["syn35"][0]) == ["r1"] and list(by["syn05"][1]) == ["dance"]
    assert settings.showcase(cfg) == (None, 0, "syn35")
    assert settings.subject_showcase(cfg, "syn35") == [None, 0, True]
    assert settings.subject_showcase(cfg, "syn05") == [None, 0, False]
    dance = dict(cfg, compare=dict(cfg["compare"], showcase={"clip": "dance/syn05_02@20", "seed": 1}))
    settings.check(dance)
    assert settings.showcase(dance) == ("dance/syn05_02@20", 1, "syn05")
    assert settings.subject_showcase(dance, "syn35") == [None, 1, False]
    run, left = settings.run_generators(cfg)
    assert set(run) | set(left) == set(cfg["compare"]["generators"]) and "motion_graph" in run
    assert all(why for why in left.values())


def test_a_generator_not_built_on_a_clip_keeps_its_rows_with_the_reason(walks, cfg):
    trials = {"a": walks[0], "b": walks[1], "c": Motion(walks[2].values[:18], walks[2].skeleton, 30.0, "c")}
    cc = {k: cfg[k] for k in settings.CLIP_KEYS}
    clips = protocol.prepare_clips(trials, {"w1": ["a", "b"], "w2": ["b", "c"]}, {}, dict(cc, length=10))
    # the w2/b clip's database is c alone: 18 frames, too short for windows of 20 frames
    mg = dict(cfg, motion_graph=dict(cfg["motion_graph"], window=20))
    metrics, timing, _ = runner.run_generator(clips, "motion_graph", mg, 7)
    bad = metrics[metrics["clip"].str.startswith("w2/b@")]
    assert len(bad) == cfg["seeds"] * bad["clip"].nunique() and bad["note"].str.startswith("not built: ").all()
    assert bad[metric_table.METRIC_NAMES].isna().all().all()
    assert (metrics.loc[~metrics["clip"].str.startswith("w2/b@"), "note"] == "").all()
    assert timing.set_index("database").loc["w2/b", "frames_generated"] == 0
    with pytest.raises(ValueError, match="compare.showcase.clip"):
        runner.run_generator(clips, "motion_graph", mg, 7, showcase=("w2/b", 0))
    # a subject's own showcase (not the run's) that cannot be built: its start alone, the job goes on
    _m, _t, shown = runner.run_generator(clips, "motion_graph", mg, 7, showcase=("w2/b", 0, False))
    assert shown.n_frames == clips[0].context and shown.meta["note"].startswith("not built: ")


def test_root_rotation_is_the_root_of_local_rotations(walks):
    from animsynth.kinematics import local_rotations, root_rotation

    sk, v = walks[0].skeleton, walks[0].values[:10]
    a = root_rotation(sk, v).as_quat()
    b = local_rotations(sk, v)[0].as_quat()
    assert np.allclose(np.abs(np.sum(a * b, axis=1)), 1.0)


def test_the_seeds_of_one_clip_count_once():
    # five seeds of one clip for the claim, one seed each of four clips against: 5 of 9 pairs, but 1 of 5 clips
    j = pd.DataFrame({"clip": ["x"] * 5 + ["y", "z", "u", "w"], "group": ["g"] * 9,
                      "outcome": [1, 1, 1, 1, 1, -1, -1, -1, -1]})
    c = CS.per_clip(j).set_index("clip")
    assert c["outcome"].to_dict() == {"x": 1, "y": -1, "z": -1, "u": -1, "w": -1}
    assert c.loc["x", "seeds_for"] == 5 and c.loc["x", "seeds_against"] == 0
    tie = CS.per_clip(pd.DataFrame({"clip": ["x", "x"], "group": ["g", "g"], "outcome": [1, -1]}))
    assert tie["outcome"].tolist() == [0]


@pytest.mark.parametrize("mutate, key", [
    (lambda c: c["compare"].update(subsets=["w1", "w9"]), "compare.subsets"),
    (lambda c: (c["subsets"].update(w2=None), c["compare"].update(subsets=["w1", "w2"])), "compare.subsets"),
    (lambda c: c["compare"].update(resequencing=["walk", "hop"]), "compare.resequencing"),
])
def test_names_the_run_lacks_are_warnings_naming_the_key(mutate, key, caplog):
    import copy
    import logging

    cfg = copy.deepcopy(_config())
    mutate(cfg)
    with caplog.at_level(logging.WARNING, logger="animsynth.compare"):
        settings.check(cfg)
    assert f"config key '{key}'" in caplog.text and "left out of the comparison" in caplog.text


def test_a_subset_the_run_lacks_is_left_out_with_a_warning(caplog):
    import copy
    import logging

    cfg = copy.deepcopy(_config())
    cfg["subsets"] = {"w1": cfg["subsets"]["w1"], "w2": None, "r1": None, "r2": None}
    cfg["compare"]["subsets"] = ["r1"]  # the demo default, on a run that only has w1
    with caplog.at_level(logging.WARNING, logger="animsynth.compare"):
        settings.check(cfg)
    assert "'compare.subsets': 'r1' is not a subset of this run" in caplog.text
    subsets, reseq = settings.groups(cfg)
    assert subsets == {} and reseq  # the re-sequencing clips still give the comparison its clips


def test_the_job_config_holds_the_generators_block_and_nothing_of_the_others():
    config = _config()
    mg = settings.job_cfg(config, "motion_graph")
    assert list(mg) == [*settings.RUN_KEYS, "motion_graph", "long_track"]
    assert mg["motion_graph"] == config["compare"]["motion_graph"]
    st = settings.job_cfg(config, "stisomap")
    assert st["stisomap"] == config["resequencing"]["stisomap"] and "resequencing_graph" in st and "field" not in st
    assert list(settings.job_cfg(config, "replay")) == [*settings.RUN_KEYS, "long_track"]  # no block of its own
    every = settings.job_cfg(config)
    assert {*settings.GENERATOR_BLOCKS.values(), "stisomap"} <= set(every)
    sweep = settings.job_cfg(dict(config, compare=dict(config["compare"], seeds=5, budget_sweep_seeds=2)),
                             "motion_graph", budget="12.5")
    assert sweep["transitions_per_s"] == 12.5 and sweep["seeds"] == 2


def test_the_jobs_shared_kinematics_give_the_references_of_separate_computations(walks, cfg):
    from animsynth.compare import measures as M

    trials = {f"t{i}": Motion(w.values, w.skeleton, 30.0, f"t{i}") for i, w in enumerate(walks)}
    cc = {"fps": 15, "context": 4, "length": 20, "min_length": 6, "split_blocks": 3}
    clips = protocol.prepare_clips(trials, {"w1": ["t0", "t1", "t2"]}, {"walk": "t3"}, cc)
    mcfg = cfg["metrics"]
    kin = scoring.DatabaseKinematics()
    std = scoring.run_stats(clips, mcfg, None, kin)
    assert np.array_equal(std, scoring.run_stats(clips, mcfg))
    for c in clips:
        shared, alone = scoring.reference(c, mcfg, None, std, kin), scoring.reference(c, mcfg, None, std)
        for name in ("floor", "std", "truth_pos", "truth_q", "truth_forward", "capture_max"):
            assert np.array_equal(getattr(shared, name), getattr(alone, name)), (c.clip, name)
        assert all(np.array_equal(a, b) for a, b in zip(shared.features, alone.features))
        # the ground truth's rotations from the held-out clip's one pass are those of the truth on its own
        assert np.array_equal(shared.truth_q, M.global_quaternions(c.truth))
    pos, fwd = kin(clips[0].database[0])
    assert not pos.flags.writeable and not fwd.flags.writeable  # shared by every clip: read-only
    other = Motion(clips[0].database[0].values[::-1].copy(), walks[0].skeleton, 15.0, clips[0].database[0].name)
    assert np.array_equal(kin(other)[0], M.positions(other))  # same name, other values: computed apart
    import copy

    db0 = clips[0].database[0]
    longer = copy.deepcopy(db0.skeleton)
    for j in longer.joints[1:]:
        j.offset = j.offset * 1.25  # the same values on longer bones (a trial read onto another's rest pose)
    moved = Motion(db0.values, longer, db0.fps, db0.name)
    assert np.array_equal(kin(moved)[0], M.positions(moved))  # same name and values, other bones: computed apart
    assert not np.array_equal(kin(moved)[0], kin(db0)[0])


def test_budget_sweep_compares_the_graphs_on_the_clips_both_were_built_on():
    """A peer that cannot be built on one clip: the sweep's medians leave that clip out for every graph."""
    rows = []
    for g, kept in (("motion_graph", {"a": 10, "b": 20, "c": 90}), ("fairmotion_fixed", {"a": 10, "b": 20, "c": None})):
        for clip, k in kept.items():
            for seed in range(2):
                note = "" if k is not None else "not built: too short"
                rows.append({"clip": clip, "generator": g, "seed": seed, "note": note,
                             **{m: (np.nan if k is None else float(k)) for m in tables.SWEEP_METRICS}})
    t = tables.sweep_table({4.0: pd.DataFrame(rows)}, ["motion_graph", "fairmotion_fixed"]).set_index("generator")
    assert list(t["clips_compared"]) == [2, 2] and list(t["clips_not_built"]) == [0, 1]
    # counted over every clip it was built on, the motion graph's median would be 20; over the shared clips, 15
    assert t.loc["motion_graph", "transitions_kept_median"] == t.loc["fairmotion_fixed", "transitions_kept_median"] == 15


def test_the_claims_against_the_peer_quote_the_budget_sweep():
    n = 16
    lo, hi = list(np.linspace(0.1, 0.2, n)), list(np.linspace(0.3, 0.4, n))
    metrics = _metrics({"motion_graph": lo, "fairmotion_fixed": hi, "fairmotion": hi})
    sweep = pd.DataFrame([{"transitions_per_s": b, "generator": g, "transition_skate_share_median": v}
                          for b, g, v in ((2.0, "motion_graph", 0.2), (2.0, "fairmotion_fixed", 0.3),
                                          (4.0, "motion_graph", 0.25), (4.0, "fairmotion_fixed", 0.2),
                                          (8.0, "motion_graph", 0.3), (8.0, "fairmotion_fixed", 0.5))])
    fixed = _claim("motion_graph", "fairmotion_fixed", "transition_skate_share")
    released = _claim("motion_graph", "fairmotion", "transition_skate_share")
    v = CV.build_verdicts(metrics, dict(VC, min_groups=2), "test data", {}, sweep=sweep, claims=CLAIMS).set_index("claim")
    ev = v.loc[fixed, "evidence"]
    assert "0.2 vs 0.3 at 2/s; 0.25 vs 0.2 at 4/s; 0.3 vs 0.5 at 8/s; motion_graph lower at 2 of 3 budgets" in ev
    assert "the budget sweep runs the fixed row" in v.loc[released, "evidence"]
    without = CV.build_verdicts(metrics, dict(VC, min_groups=2), "test data", {}, claims=CLAIMS).set_index("claim")
    assert "budget sweep" not in without.loc[fixed, "evidence"]
    assert (v["verdict"] == without["verdict"]).all()  # evidence, not a vote: decided at the default budget


# --- one group per CMU subject: the paper run's 18 subjects -----------------

def _paper_config() -> dict:
    """config.yaml, cmu.yaml, samba.yaml and paper.yaml merged as the paper run merges them, validated."""
    from conftest import merged_config

    return merged_config("config.yaml", "cmu.yaml", "samba.yaml", "paper.yaml")


def _clips_table_of(config: dict, missing=()) -> pd.DataFrame:
    """The clips table's identifying columns as compare_clips writes them (clip, group, protocol, held_out,
    database), built from the config alone (no trial read: a temporal split's frame range is a placeholder)."""
    subsets, reseq = settings.groups(config, missing)
    rows = [{"clip": f"{g}/{t}@0", "group": g, "protocol": "leave one out", "held_out": f"{t} frames 0-67",
             "database": " ".join(o for o in ids if o != t)} for g, ids in subsets.items() for t in ids]
    rows += [{"clip": f"{g}/{t}@70", "group": g, "protocol": "temporal split", "held_out": f"{t} frames 70-99",
              "database": f"{t} frames 0-69 {t} frames 100-140"} for g, t in reseq.items()]
    return pd.DataFrame(rows)


def test_the_paper_configs_clips_make_one_group_per_subject_eighteen_in_all():
    cfg = _paper_config()
    settings.check(cfg)
    table = _clips_table_of(cfg)
    assert [c.split("@")[0] for c in table["clip"]] == settings.held_out_trials(cfg)
    groups = GR.independent_groups(table)
    subjects = {c.split("/")[1].split("_")[0] for c in table["clip"]}
    assert subjects == {"35", "16", "127", "05", "02", "09", "07", "12", "49", "17", "06", "10", "26", "27", "32",
                        "36", "91", "131"}
    assert len(set(groups.values())) == 18
    for clip, label in groups.items():  # each group is one subject, named by it
        assert label.startswith(f"subject {clip.split('/')[1].split('_')[0]} ("), (clip, label)
    # the Table I subsets and re-sequencing clips are as before; the new subjects come after them
    assert [c.split("@")[0] for c in table["clip"] if c.split("/")[0] in ("w1", "w2", "r1", "r2", "walk", "run",
                                                                            "dance")] == \
        settings.held_out_trials(dict(cfg, compare=dict(cfg["compare"], subjects={})))
    proto = dict(zip(table["group"], table["protocol"]))
    assert proto["s09"] == proto["s07"] == proto["s02"] == "leave one out"
    assert proto["s17"] == proto["s06"] == proto["s10"] == proto["s26"] == proto["s27"] == proto["s36"] == \
        "temporal split"
    assert proto["s32"] == proto["s91"] == proto["s131"] == "leave one out"
    assert len(table) == 19 + (3 + 4 + 3 + 3 + 3 + 2 + 2 + 2) + 6
    # a mirror that cannot be read: its subjects' groups are left out, the others stay
    many = [t["id"] for t in cfg["trials"] if t.get("mirror") == "many"]
    left = GR.independent_groups(_clips_table_of(cfg, many))
    assert len(set(left.values())) == 6  # 35, 16, 127, 05, 02, 09


def test_the_demo_has_no_subject_sets_and_its_clips_are_unchanged():
    cfg = _config()
    assert cfg["compare"]["subjects"] == {}
    subsets, reseq = settings.groups(cfg)
    assert subsets == {s: cfg["subsets"][s] for s in cfg["compare"]["subsets"]}
    assert reseq == dict(cfg["resequencing_trials"])


def test_a_subject_set_is_left_one_out_or_split_in_time_by_its_size(walks):
    cfg = copy.deepcopy(_config())
    ids = [t["id"] for t in cfg["trials"]]
    cfg["compare"]["subjects"] = {"pair": ids[:2], "one": [ids[2]]}
    settings.check(cfg)
    subsets, reseq = settings.groups(cfg)
    assert subsets["pair"] == ids[:2] and reseq["one"] == ids[2]
    assert settings.held_out_trials(cfg)[-1] == f"one/{ids[2]}"
    trials = {t: Motion(w.values, w.skeleton, 30.0, t) for t, w in zip(ids, walks)}
    cc = {"fps": 15, "context": 4, "length": 20, "min_length": 6, "split_blocks": 3}
    clips = protocol.prepare_clips(trials, {"pair": ids[:2]}, {"one": ids[2]}, cc)
    assert [(c.clip, c.protocol) for c in clips] == [(f"pair/{ids[0]}@0", "leave one out"),
                                                     (f"pair/{ids[1]}@0", "leave one out"),
                                                     (f"one/{ids[2]}@0", "temporal split"),
                                                     (f"one/{ids[2]}@10", "temporal split"),
                                                     (f"one/{ids[2]}@20", "temporal split")]
    assert clips[0].database_names == [ids[1]]


@pytest.mark.parametrize("sets,fragment", [
    ({"w1": ["x"]}, "compare.subjects.w1': 'w1' is the name of a subset"),
    ({"walk": ["x"]}, "compare.subjects.walk': 'walk' is the name of a subset or re-sequencing clip"),
    ({"s99": ["99_01"]}, r"compare.subjects.s99': trial\(s\) '99_01' have no record in 'trials'.*mapping keyed"),
    ({"mix": ["syn35_16", "syn16_34"]}, r"compare.subjects.mix': mixes trials of 2 subjects \(subject syn35: "
                                       r"syn35_16; subject syn16: syn16_34\)"),
])
def test_a_subject_set_with_a_taken_name_an_unknown_trial_or_two_subjects_is_refused(sets, fragment):
    cfg = copy.deepcopy(_config())
    cfg["compare"]["subjects"] = sets
    with pytest.raises(ConfigError, match=fragment):
        settings.check(cfg)


def test_the_runner_gives_the_held_out_future_to_a_generator_whose_query_is_it(walks, cfg, monkeypatch):
    """``motion_matching_traj`` (``query = "future_trajectory"``) is passed the clip's held-out frames after the
    start, by its query attribute, not its name; a generator of the default query gets nothing more."""
    from animsynth.compare.generators.motionmatching import MotionMatchingTrajectory
    from animsynth.generator import Generator

    trials = {f"t{i}": w for i, w in enumerate(walks)}
    cc = {k: cfg[k] for k in settings.CLIP_KEYS}
    clips = protocol.prepare_clips(trials, {"w1": ["t0", "t1", "t2"]}, {}, dict(cc, length=20))
    seen = []
    real = MotionMatchingTrajectory.generate

    def spy(self, start, length, seed, trajectory=None, native_start=None):
        seen.append(trajectory)
        return real(self, start, length, seed, trajectory=trajectory)

    monkeypatch.setattr(MotionMatchingTrajectory, "generate", spy)
    metrics, _, _ = runner.run_generator(clips, "motion_matching_traj", cfg, 7)
    assert len(seen) == len(clips) * cfg["seeds"] and (metrics["note"] == "").all()
    assert (metrics["seed_diversity_m"] == 0).all()
    for i, c in enumerate(clips):
        got = seen[i * cfg["seeds"]]
        assert np.array_equal(got.values, c.held_out.values[c.context:])
        assert np.array_equal(got.values[:c.length], c.truth.values)
    assert Generator.query == "start" and runner.generation_query(G.make_generator("motion_matching", cfg), clips[0]) == {}

    class Odd(Generator):
        query = "the answer"

    with pytest.raises(ValueError, match="unknown query"):
        runner.generation_query(Odd(), clips[0])


def test_the_runner_records_transitions_kept_from_the_generators_run_notes(walks, cfg, monkeypatch):
    """The ``transitions_kept`` column is what :meth:`Generator.run_notes` gives (NaN where it gives none), for
    every generator: no generator's own attribute is read."""
    from animsynth.compare.generators.motiongraph import MotionGraph
    from animsynth.compare.generators.references import Concat
    from animsynth.generator import Generator

    assert Generator().run_notes() == {}
    trials = {f"t{i}": w for i, w in enumerate(walks)}
    cc = {k: cfg[k] for k in settings.CLIP_KEYS}
    clips = protocol.prepare_clips(trials, {"w1": ["t0", "t1", "t2"]}, {}, dict(cc, length=20))[:1]
    metrics, _, _ = runner.run_generator(clips, "concat", cfg, 7)
    assert metrics["transitions_kept"].isna().all()
    monkeypatch.setattr(Concat, "run_notes", lambda self: {"transitions_kept": 3})
    metrics, _, _ = runner.run_generator(clips, "concat", cfg, 7)
    assert (metrics["transitions_kept"] == 3.0).all()
    kept = []
    real = MotionGraph.run_notes

    def spy(self):
        kept.append(self.n_below_threshold_)
        return real(self)

    monkeypatch.setattr(MotionGraph, "run_notes", spy)
    metrics, _, _ = runner.run_generator(clips, "motion_graph", cfg, 7)
    assert kept and (metrics["transitions_kept"] == float(kept[0])).all()
    monkeypatch.setattr(MotionGraph, "n_below_threshold_", -5, raising=False)  # the class's attribute, not read
    monkeypatch.setattr(MotionGraph, "run_notes", lambda self: {})
    metrics, _, _ = runner.run_generator(clips, "motion_graph", cfg, 7)
    assert metrics["transitions_kept"].isna().all()
