"""Motion matching and GenMM: known answers, the interface, determinism (small synthetic databases)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from animsynth.compare.generators import registry as G
from animsynth.compare import protocol
from animsynth.compare.generators.footlock import contact_points, hip_knee_ankle, lock_contacts, place_feet, two_bone_ik
from animsynth.compare.generators.genmm import GenMM, extract_patches, make_genmm, match_patches, vote
from animsynth.compare.generators.motionmatching import MotionMatching, make_motion_matching
from animsynth.springs import decay_spring, spring_angle, spring_position
from animsynth.compare.generators.poses import decode, encode
from animsynth.compare.generators.references import Replay
from animsynth.kinematics import bone_lengths, forward_kinematics, root_translation
from animsynth.motion import Motion
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

INF = float("inf")
DATA = Path(__file__).parent / "data"


# the fixture walks (the synthetic database) lives in conftest.py


def _cut(m: Motion, a: int, b: int, name: str = "part") -> Motion:
    return Motion(np.asarray(m.values[a:b], float).copy(), m.skeleton, m.fps, name)


def _angle_diff(a, b) -> float:
    """Largest difference of DOF values, angles compared modulo 360 degrees."""
    return float(np.abs((np.asarray(a) - np.asarray(b) + 180.0) % 360.0 - 180.0).max())


# ----------------------------------------------------------------------------- the shared pose representation


def test_encode_then_decode_from_the_frame_before_gives_the_motion_back(walks):
    m = walks[1]
    tr = encode(m)
    c = 5
    back = decode(m.skeleton, tr.rotations[c:], tr.tilt[c:], tr.height[c:], tr.step[c:], tr.turn[c:], m.values[c - 1])
    assert _angle_diff(back, m.values[c:]) < 1e-8


def test_decode_holds_the_anchors_translation_on_joints_with_position_channels():
    """A BVH with position channels on every joint (3ds Max Biped): the pose encoding keeps no translation of a
    non-root joint, so decoding holds each at the anchor's, not at the root's position; the angles come back."""
    from pathlib import Path

    from animsynth.io.bvh import read_bvh
    from animsynth.skeleton import TRANS_DOFS

    m = read_bvh(Path(__file__).parent / "data" / "bvh" / "every6_bip.bvh")
    sk = m.skeleton
    sl = sk.dof_slices()
    cols = np.concatenate([np.arange(sl[j.name].start, sl[j.name].stop)[[d in TRANS_DOFS for d in j.dofs]]
                           for j in sk.joints[1:]])
    assert cols.size  # the file has position channels below the root
    fwd = np.array([0.0, 0.0, 1.0])  # the forward given (not found from the roles)
    tr = encode(m, fwd)
    c = 5
    back = decode(sk, tr.rotations[c:], tr.tilt[c:], tr.height[c:], tr.step[c:], tr.turn[c:], m.values[c - 1], fwd)
    np.testing.assert_allclose(back[:, cols], np.broadcast_to(m.values[c - 1, cols], back[:, cols].shape), atol=1e-9)
    root = np.arange(sl[sk.joints[0].name].start, sl[sk.joints[0].name].stop)
    others = np.setdiff1d(np.arange(sk.n_dof), np.concatenate([cols, root]))
    assert _angle_diff(back[:, others], m.values[c:, others]) < 1e-6  # the joints' angles come back


# ----------------------------------------------------------------------------- motion matching


def test_inertialization_offset_after_one_half_life_is_0597_of_the_start():
    x, v = decay_spring(1.0, 0.0, 0.1, 0.1)
    assert x == pytest.approx((1.0 + 2.0 * np.log(2.0)) / 4.0, abs=1e-12)
    assert round(float(x), 3) == 0.597
    # the exact spring: three steps of a third of a half-life land where one step does
    y, w = 1.0, 0.0
    for _ in range(3):
        y, w = decay_spring(y, w, 0.1, 0.1 / 3.0)
    assert (y, w) == pytest.approx((float(x), float(v)), abs=1e-12)
    assert float(v) < 0.0  # moving back towards zero


def test_gamepad_springs_hold_a_steady_velocity_and_turn_to_the_goal():
    dt = np.array([1 / 3, 2 / 3, 1.0])
    p = spring_position(np.array([1.0, 2.0]), np.array([0.5, -1.0]), np.zeros(2), np.array([0.5, -1.0]), 0.27,
                        dt[:, None])
    assert np.allclose(p, [1.0, 2.0] + dt[:, None] * [0.5, -1.0])  # already at the goal velocity: a straight line
    a = spring_angle(3.0, 0.0, -3.0, 0.27, np.array([0.0, 5.0]))  # the short way round through pi
    assert a[0] == pytest.approx(3.0) and np.cos(a[1] + 3.0) == pytest.approx(1.0, abs=1e-6)
    assert a[1] > 3.0  # it crossed pi instead of turning back through 0


def test_gamepad_below_the_deadzone_asks_to_stand(walks):
    mm = MotionMatching().fit(walks[1:])
    still = np.zeros((8, 2))
    still[:, 0] = np.linspace(0.0, 0.03, 8)  # 0.13 m/s
    v, yaw = mm._gamepad(still, 0.7, 30.0)
    assert np.array_equal(v, [0.0, 0.0]) and yaw == 0.7
    moving = still * 3.0  # 0.39 m/s (0.09 m in 7 frames)
    v, yaw = mm._gamepad(moving, 0.7, 30.0)
    assert v == pytest.approx([0.09 * 30 / 7, 0.0]) and yaw == pytest.approx(np.pi / 2)


def test_motion_matching_on_a_clip_of_its_database_with_the_true_trajectory_is_the_replay(walks):
    db = walks
    clip, c, length = walks[2], 8, 40
    # the matching and blending; the reference's foot clean-up (below) then edits only the legs
    mm = MotionMatching(foot_lock=False).fit(db)
    start, truth = _cut(clip, 0, c, "start"), _cut(clip, c, clip.n_frames, "truth")
    m = mm.generate(start, length, 0, trajectory=truth)
    costs = m.meta["costs"]
    assert costs[0] < 1e-12  # the start's last frame is found at cost 0 ...
    assert tuple(m.meta["source_frames"][0]) == (2, c)  # ... so its next frame plays first
    assert np.all(costs < 1e-12) and m.meta["seams"].size == 0 and m.meta["switches"] == 1  # the entry only
    assert np.array_equal(m.meta["source_frames"][:, 1], np.arange(c, c + length))
    replay = Replay().fit(db).generate(start, length, 0, trajectory=truth)
    assert _angle_diff(m.values, replay.values) < 1e-8
    locked = MotionMatching().fit(db).generate(start, length, 0, trajectory=truth)
    assert np.array_equal(locked.meta["source_frames"], m.meta["source_frames"])
    sk = clip.skeleton
    sl = sk.dof_slices()
    legs = {sk.joints[j].name for j in hip_knee_ankle(sk).ravel()}
    other = [c for j in sk.joints if j.name not in legs for c in range(sl[j.name].start, sl[j.name].stop)]
    assert _angle_diff(locked.values[:, other], replay.values[:, other]) < 1e-8


def test_motion_matching_is_deterministic_and_keeps_the_interface(walks):
    mm = MotionMatching().fit(walks[1:])
    start, length = _cut(walks[0], 0, 8), 45
    a = mm.generate(start, length, 5)
    b = mm.generate(start, length, 6)  # the seed is not used: seed diversity 0 (the rollout is kept ...)
    assert np.array_equal(a.values, b.values)
    b.values[:] = 0.0  # ... and handed out as copies
    assert np.array_equal(mm.generate(start, length, 7).values, a.values)
    assert np.array_equal(MotionMatching().fit(walks[1:]).generate(start, length, 5).values, a.values)
    assert a.values.shape == (length, walks[0].skeleton.n_dof) and np.all(np.isfinite(a.values))
    assert a.fps == 30.0 and a.skeleton.columns() == walks[0].skeleton.columns()
    src, seams = a.meta["source_frames"], a.meta["seams"]
    assert src.shape == (length, 2) and (src >= 0).all()
    follows = (src[1:, 0] == src[:-1, 0]) & (src[1:, 1] == src[:-1, 1] + 1)
    assert set(np.flatnonzero(~follows) + 1) == set(seams.tolist())
    # each match lies outside its clip's last 1/3 s (10 frames) and 1/3 s away from the frame it left
    n = np.array([w.n_frames for w in walks[1:]])
    for t in seams:
        clip_j, j = src[t, 0], src[t, 1] - 1
        assert j < n[clip_j] - mm.exclude_frames_
        if clip_j == src[t - 1, 0]:
            assert abs(j - src[t - 1, 1]) >= mm.exclude_frames_
    # searches every 0.1 s (3 frames) unless a clip ends in between
    assert np.all(np.diff(a.meta["search_frames"]) <= 3)
    # the output continues the start where it stands
    gap = np.linalg.norm(root_translation(a.skeleton, a.values[:1])[0, [0, 2]]
                         - root_translation(start.skeleton, start.values[-1:])[0, [0, 2]])
    step = np.linalg.norm(np.diff(root_translation(start.skeleton, walks[0].values)[:, [0, 2]], axis=0), axis=1)
    assert gap < 2 * step.max()


def test_motion_matching_without_trajectory_weights_matches_on_the_pose_only(walks):
    full = MotionMatching().fit(walks[1:])
    pose = make_motion_matching({}, trajectory_weight=0.0, name="motion_matching_pose").fit(walks[1:])
    assert pose.generate(_cut(walks[0], 0, 8), 5, 0).name == "motion_matching_pose"
    assert np.all(pose.features_[:, 15:] == 0.0) and np.any(full.features_[:, 15:] != 0.0)
    assert np.array_equal(pose.features_[:, :15], full.features_[:, :15])
    with pytest.raises(ValueError, match="trajectory_weight"):
        MotionMatching(trajectory_weight=-1).fit(walks[1:])


# ----------------------------------------------------------------------------- foot locking and leg IK


def _hip_and_ball(sk, values, chain, effector="ball"):
    starts = forward_kinematics(sk, values, ends=False) * sk.length_to_m
    if effector == "heel":
        return starts[:, chain[0]], starts[:, chain[2]]
    return starts[:, chain[0]], contact_points(sk, values, hip_knee_ankle(sk))[:, list(hip_knee_ankle(sk)[:, 0]).index(
        chain[0])]


def _cols(sk, joints):
    sl = sk.dof_slices()
    return {c for j in joints for c in range(sl[sk.joints[j].name].start, sl[sk.joints[j].name].stop)}


@pytest.mark.parametrize("effector", ["ball", "heel"])
def test_two_bone_ik_reaches_a_reachable_target_exactly_and_keeps_bone_lengths(walks, effector):
    m = walks[1]
    sk, values = m.skeleton, np.asarray(m.values[:12], float)
    legs = hip_knee_ankle(sk)
    for f, chain in enumerate(legs):
        hip, ball = _hip_and_ball(sk, values, chain, effector)
        # nearer the hip and off to the side: inside the leg's reach, not on its current circle
        targets = hip + 0.85 * (ball - hip) + np.array([0.04, 0.03, -0.05])
        out = two_bone_ik(sk, values, chain, targets, effector=effector)
        _, got = _hip_and_ball(sk, out, chain, effector)
        assert np.abs(got - targets).max() < 1e-6  # metres
        assert np.abs(got - ball).max() > 0.05  # it did move
        assert np.allclose(bone_lengths(sk, out), bone_lengths(sk, values), atol=1e-9)
        changed = np.flatnonzero(np.any(out != values, axis=0))
        assert set(changed.tolist()) <= _cols(sk, chain[:2])  # only the hip and the knee turn


def test_placing_a_foot_keeps_its_world_orientation(walks):
    m = walks[1]
    sk, values = m.skeleton, np.asarray(m.values[:12], float)
    chain = hip_knee_ankle(sk)[0]
    hip, ball = _hip_and_ball(sk, values, chain)
    targets = hip + 0.85 * (ball - hip) + np.array([0.04, 0.03, -0.05])
    out = place_feet(sk, values, chain, targets)
    _, W0 = forward_kinematics(sk, values, ends=False, world_rotations=True)
    _, W1 = forward_kinematics(sk, out, ends=False, world_rotations=True)
    # the heel lands exactly where the animation's foot vector puts the contact point on the target ...
    _, heel = _hip_and_ball(sk, out, chain, "heel")
    foot = W0[chain[2]].apply(sk.joints[chain[2]].tail) * sk.length_to_m
    assert np.abs(heel + foot - targets).max() < 1e-6
    # ... and the foot keeps its world orientation but for the ankle's missing DOF (CMU's lfoot: rx rz), so the
    # contact point lands within millimetres of the target
    _, got = _hip_and_ball(sk, out, chain)
    assert np.abs(got - targets).max() < 0.005
    tip0 = W0[chain[2]].apply(sk.joints[chain[2]].tail)
    tip1 = W1[chain[2]].apply(sk.joints[chain[2]].tail)
    assert np.abs(tip1 - tip0).max() * sk.length_to_m < 0.005
    assert set(np.flatnonzero(np.any(out != values, axis=0)).tolist()) <= _cols(sk, chain)
    assert np.allclose(bone_lengths(sk, out), bone_lengths(sk, values), atol=1e-9)


@pytest.mark.parametrize("buffer_m", [0.0, 0.015])
def test_two_bone_ik_stretches_the_leg_towards_an_unreachable_target(walks, buffer_m):
    m = walks[1]
    sk, values = m.skeleton, np.asarray(m.values[3:4], float)
    chain = hip_knee_ankle(sk)[0]
    hip, ball = _hip_and_ball(sk, values, chain)
    target = hip + np.array([[0.6, -2.5, 0.9]])  # metres away: out of reach
    out = two_bone_ik(sk, values, chain, target, max_length_buffer_m=buffer_m)
    _, got = _hip_and_ball(sk, out, chain)
    d_got = got - hip
    u = (target - hip) / np.linalg.norm(target - hip)
    assert float(np.sum(d_got * u) / np.linalg.norm(d_got)) > 1.0 - 1e-12  # pointing at it
    # fully stretched: the largest hip-to-ball distance any knee angle gives (a sweep of the knee's DOF)
    knee = sk.joints[chain[1]]
    col = sk.dof_slices()[knee.name].start
    sweep = np.repeat(values, 7201, axis=0)
    sweep[:, col] = np.linspace(-180.0, 180.0, 7201)
    h, b = _hip_and_ball(sk, sweep, chain)
    reach = float(np.linalg.norm(b - h, axis=1).max())
    assert float(np.linalg.norm(d_got)) == pytest.approx(reach - buffer_m, abs=1e-5)
    assert np.allclose(bone_lengths(sk, out), bone_lengths(sk, values), atol=1e-9)


def test_a_locked_contact_stays_put_and_releases_beyond_the_unlock_radius():
    fps, h = 30.0, 0.03
    T = 40
    x = np.zeros((T, 1, 3))
    x[:, 0, 1] = h
    x[9:, 0, 0] = 0.05 * np.arange(1, T - 8)  # at rest until frame 8, then sliding 1.5 m/s under the lock
    states = np.zeros((T, 1), bool)
    states[5:] = True  # in contact from frame 5 on
    tg, locked = lock_contacts(x, states, fps, x[0], np.array([h]), unlock_radius_m=0.2,
                               halflife_s=0.1)
    assert np.array_equal(tg[:6], x[:6])  # free: the animation itself
    assert not locked[:6].any() and locked[6:14].all() and not locked[14:].any()
    # locked from frame 6: constant while the animation slides, up to 0.25 m away at frame 13
    assert np.abs(tg[6:14] - x[5]).max() < 1e-6
    assert np.linalg.norm(x[13, 0] - x[5, 0]) > 0.2 >= np.linalg.norm(x[12, 0] - x[5, 0])  # released only beyond
    # released: blends back to the animation (no jump), the offset decaying with the half-life
    assert np.linalg.norm(tg[14, 0] - tg[13, 0]) < 0.1
    gap = np.linalg.norm(tg[:, 0] - x[:, 0], axis=1)
    assert gap[-1] < 0.05 * gap[14] and np.all(np.diff(gap[16:]) < 0)
    # the contact starting above its height: locked at the contact height, horizontally in place at once
    y = x.copy()
    y[:, 0, 1] = h + 0.02
    tg2, _ = lock_contacts(y, states, fps, y[0], np.array([h]))
    # (released a frame earlier: the distance is 3-D, and 0.2 m along the floor is beyond the radius at 2 cm up)
    assert np.abs(tg2[6:13, 0, [0, 2]] - y[5, 0, [0, 2]]).max() < 1e-6
    assert tg2[12, 0, 1] < tg2[6, 0, 1] < h + 0.02


def test_motion_matching_without_foot_lock_is_unchanged(walks):
    """The ablation row (foot_lock=False) is the motion matching of before foot locking
    (tests/data/motion_matching_without_foot_lock.npz: generated by that code on these walks, on an AMD CPU).

    Not bit for bit: the file was saved on another machine, and BLAS / libm kernels differ between CPUs in
    the last bits (on an Intel Xeon the values differ by up to 6e-13 degrees). Motion matching does not
    amplify such differences: its output is database frames plus inertialisation offsets that decay
    linearly, so a last-bit change of the input stays a last-bit change. A different match (the only way
    the method could diverge) moves a joint by degrees. Hence a tolerance of 1e-9 degrees: over a thousand
    times the cross-CPU gap, a billionth of any changed match."""
    ref = np.load(DATA / "motion_matching_without_foot_lock.npz")
    start = _cut(walks[0], 0, 8)
    a = make_motion_matching({}, foot_lock=False).fit(walks[1:]).generate(start, 45, 0)
    b = make_motion_matching({}, trajectory_weight=0.0, foot_lock=False).fit(walks[1:]).generate(start, 45, 0)
    for got, name in ((a, "motion_matching"), (b, "motion_matching_pose")):
        assert got.values.shape == ref[name].shape
        np.testing.assert_allclose(got.values, ref[name], rtol=0.0, atol=1e-9, err_msg=name)
    assert "contact_targets" not in a.meta


def test_motion_matching_locks_the_feet_by_default_with_the_leg_ik(walks):
    assert MotionMatching().foot_lock is True and make_motion_matching({}).foot_lock is True
    start = _cut(walks[0], 0, 8)
    free = make_motion_matching({}, foot_lock=False).fit(walks[1:]).generate(start, 45, 0)
    mm = MotionMatching().fit(walks[1:])
    assert mm.contacts_.shape == (sum(w.n_frames for w in walks[1:]), 2) and mm.contacts_.any()
    mm.contacts_[:] = True  # every frame in contact: both feet lock at the first frame
    m = mm.generate(start, 45, 0)
    assert np.array_equal(m.meta["source_frames"], free.meta["source_frames"])  # the same matches ...
    sk = walks[0].skeleton
    legs = mm.legs_
    other = np.setdiff1d(np.arange(sk.n_dof), sorted(_cols(sk, legs.ravel())))
    assert np.array_equal(m.values[:, other], free.values[:, other])  # ... only hips, knees and ankles differ
    locked, tg = m.meta["contact_locked"], m.meta["contact_targets"]
    assert locked[1:].any()
    # the heel goes for the lock less the animation's (``free``'s) foot vector: on locked frames it lies on the
    # ray from the hip to that point (at it, or the leg stretched towards it)
    s_free, W_free = forward_kinematics(sk, free.values, ends=False, world_rotations=True)
    s_lock = forward_kinematics(sk, m.values, ends=False) * sk.length_to_m
    reached = 0
    for f in range(2):
        h, _k, a = legs[f]
        foot = W_free[a].apply(sk.joints[a].tail) * sk.length_to_m
        for t in np.flatnonzero(locked[:, f]):
            d, want = s_lock[t, a] - s_lock[t, h], tg[t, f] - foot[t] - s_lock[t, h]
            assert float(d @ want) / (np.linalg.norm(d) * np.linalg.norm(want)) > 1.0 - 1e-9
            assert np.linalg.norm(d) <= np.linalg.norm(want) + 1e-6
            reached += int(np.linalg.norm(d - want) < 1e-6)
    assert reached > 0
    miss = np.linalg.norm(contact_points(sk, m.values, legs) - tg, axis=-1)[locked]
    miss_free = np.linalg.norm(contact_points(sk, free.values, legs) - tg, axis=-1)[locked]
    assert miss.mean() < 0.5 * miss_free.mean()  # the locked feet are much nearer their locks


# ----------------------------------------------------------------------------- GenMM


def test_patch_votes_of_a_sequences_own_patches_give_it_back():
    x = np.random.default_rng(0).normal(size=(20, 3))
    p = extract_patches(x, 5)
    assert p.shape == (16, 15) and np.array_equal(p[3].reshape(5, 3), x[3:8])
    assert np.allclose(vote(p, 5, 20), x)


def test_completeness_sends_the_second_patch_to_the_unused_target():
    keys = np.array([[0.0, 0.0], [1.0, 1.0]])  # two target patches
    queries = np.array([[0.0, 0.0], [0.4, 0.4]])  # both nearer the first
    nn, _ = match_patches(queries, keys, INF)
    assert nn.tolist() == [0, 0]  # plain nearest neighbours: the second target is never used
    nn, dist = match_patches(queries, keys, 0.01)
    assert nn.tolist() == [0, 1]  # completeness: the second query takes the unused target
    assert dist == pytest.approx([0.0, 0.36])


def test_genmm_without_noise_from_a_database_segment_returns_that_segment(walks):
    clip, a, c, length = walks[1], 10, 8, 35
    g = GenMM(noise_sigma=0.0, alpha=INF, coarse_patches=100, min_levels=1).fit(walks[1:])  # one level: the full rate
    assert g.scales_ == [1.0]
    segment = _cut(clip, a, a + c + length, "segment")
    m = g.generate(_cut(clip, a, a + c, "start"), length, 0, initial=segment)
    # every patch is the segment's own; only the start's first frame (its step from the frame before it is
    # not in the start) differs a little from the database's
    assert m.meta["match_distance"] < 1e-6
    assert _angle_diff(m.values, clip.values[a + c:a + c + length]) < 1e-8
    # with noise the same start gives something else
    n = GenMM(alpha=INF, coarse_patches=100, min_levels=1).fit(walks[1:]).generate(_cut(clip, a, a + c), length, 0,
                                                                     initial=segment)
    assert _angle_diff(n.values, clip.values[a + c:a + c + length]) > 1.0


@pytest.mark.parametrize("root", ["local", "world"])
def test_genmm_keeps_the_interface_and_is_seeded(walks, root):
    g = make_genmm({}, root=root).fit(walks[1:])
    assert g.scales_[-1] == 1.0 and np.all(np.diff(g.scales_) > 0) and len(g.scales_) > 1
    # 60-frame clips: the 5-patch rule gives 2 levels, so the coarsest is the floor, 3 patches of the longest clip,
    # and the 7 levels of min_levels run from it to the full rate
    assert g.scales_[0] == pytest.approx(3 * 11 / max(w.n_frames for w in walks[1:])) and len(g.scales_) == 7
    assert make_genmm({}, min_levels=1).fit(walks[1:]).scales_[0] == pytest.approx(5 * 11 / 60)
    start, length = _cut(walks[0], 0, 8), 40
    a = g.generate(start, length, 5)
    assert a.values.shape == (length, walks[0].skeleton.n_dof) and np.all(np.isfinite(a.values))
    assert a.meta["seams"].size == 0 and (a.meta["source_frames"] == -1).all()
    assert a.meta["levels"][-1] == 8 + length and np.all(np.diff(a.meta["levels"]) > 0)
    b = g.generate(start, length, 5)
    assert np.array_equal(a.values, b.values)
    assert not np.array_equal(a.values, g.generate(start, length, 6).values)
    gap = np.linalg.norm(root_translation(a.skeleton, a.values[:1])[0, [0, 2]]
                         - root_translation(start.skeleton, start.values[-1:])[0, [0, 2]])
    step = np.linalg.norm(np.diff(root_translation(start.skeleton, walks[0].values)[:, [0, 2]], axis=0), axis=1)
    assert gap < 3 * step.max()


def test_genmm_refuses_bad_parameters(walks):
    for kw, key in (({"root": "up"}, "root"), ({"patch_size": 10}, "patch_size"), ({"pyramid_factor": 1.2},
                                                                                    "pyramid_factor"),
                    ({"alpha": 0.0}, "alpha")):
        with pytest.raises(ValueError, match=key):
            GenMM(**kw).fit(walks[1:])
    with pytest.raises(ValueError, match="shorter than a patch"):
        GenMM().fit(walks[1:]).generate(_cut(walks[0], 0, 2), 3, 0)


def test_genmm_patches_never_cross_clips(walks):
    db = [walks[1], _cut(walks[2], 0, 20, "short"), _cut(walks[3], 0, 9, "shorter than a patch")]
    g = GenMM(coarse_patches=100).fit(db)
    keys = g.keys_[-1]
    assert keys.shape[0] == (60 - 10) + (20 - 10) + 0  # every 11-frame window inside one clip, none across
    rows = g.frames_
    assert np.array_equal(keys[50], extract_patches(rows[1], 11)[0])  # the second clip's first patch
    joined = extract_patches(np.vstack(rows[:2]), 11)
    crossing = joined[50:60]  # windows that would start in the first clip and end in the second
    assert not any(np.any(np.all(np.isclose(keys, c), axis=1)) for c in crossing)


def test_genmm_keeps_a_pyramid_on_a_short_database(walks):
    """A 40-frame database is shorter than the 5-patch rule's coarsest level (55 frames): it still gets the 7 levels
    of ``min_levels``, the coarsest the floor of 3 patches, the levels between spaced by a larger factor (the floor
    binds below 185 frames); above that the pyramid factor spaces them; the rule alone (``min_levels=1``) gives one
    level, and a long database keeps the rule's levels."""
    from animsynth.compare.generators.genmm import level_scales, pyramid_note

    db = [_cut(w, 0, 40, f"short{i}") for i, w in enumerate(walks[1:])]
    g = make_genmm({}).fit(db)
    assert len(g.scales_) == 7 and g.scales_[-1] == 1.0
    frames = [int(round(40 * s)) for s in g.scales_]
    assert frames == [33, 34, 35, 36, 38, 39, 40] and min(frames) >= 3 * g.patch_size
    ratio = np.array(g.scales_[1:]) / g.scales_[:-1]
    assert np.allclose(ratio, (40 / 33) ** (1 / 6))  # one factor from the floor to the full rate
    longer = level_scales(100, 11, 5.0, 0.75, 7, 3.0)  # the floor binds: 7 levels from 33 frames, spaced evenly
    assert [int(round(100 * s)) for s in longer] == [33, 40, 48, 57, 69, 83, 100]
    long = level_scales(200, 11, 5.0, 0.75, 7, 3.0)  # above 185 frames: 0.75^6 is above the floor
    assert long[0] == pytest.approx(0.75 ** 6) and np.allclose(np.array(long[1:-1]) / long[:-2], 1 / 0.75)
    # at or under the floor itself (33 frames): one level, and the note says so
    assert level_scales(33, 11, 5.0, 0.75, 7, 3.0) == [1.0] and level_scales(21, 11, 5.0, 0.75, 7, 3.0) == [1.0]
    assert "21 frames, not above the pyramid floor of 33" in pyramid_note(21, 11, 3.0, 7)
    assert pyramid_note(34, 11, 3.0, 7) == "" and pyramid_note(21, 11, 3.0, 1) == ""
    assert all(k.shape[0] > 0 for k in g.keys_)  # a patch at every level
    m = g.generate(_cut(walks[0], 0, 8), 30, 1)
    assert m.meta["levels"].size == len(g.scales_) and np.all(m.meta["levels"] >= g.patch_size)
    assert np.all(np.isfinite(m.values))
    assert make_genmm({}, min_levels=1).fit(db).scales_ == [1.0]
    assert len(level_scales(200, 11, 5.0, 0.75, 7, 3.0)) == 7 and len(level_scales(200, 11, 5.0, 0.75, 1)) == 6
    # a floor of one patch: the levels go down to the patch itself
    assert [int(round(40 * s)) for s in level_scales(40, 11, 5.0, 0.75, 7, 1.0)] == [11, 14, 17, 21, 26, 32, 40]
    assert level_scales(400, 11, 5.0, 0.75, 7) == level_scales(400, 11, 5.0, 0.75, 1)  # 8 levels by the rule
    with pytest.raises(ValueError, match="min_levels"):
        make_genmm({}, min_levels=0).fit(db)
    with pytest.raises(ValueError, match="min_coarse_patches"):
        make_genmm({}, min_coarse_patches=0.5).fit(db)
    # the seed still matters on the short database (its 7 close levels refine more: two of six seeds may meet)
    outs = {g.generate(_cut(walks[0], 0, 8), 30, s).values.tobytes() for s in range(6)}
    assert len(outs) >= 5


def test_motion_matching_traj_follows_the_held_out_path_closer_than_the_gamepad():
    """A turning held-out walk: the row whose query trajectory is the held-out future (``motion_matching_traj``)
    follows the capture's root path closer than the steady gamepad from the start (``motion_matching``), which
    walks on in the start's direction; without the future it refuses to run."""
    sk = cmu_like_skeleton("cmp", 3)
    db = [protocol.resample(generate_motion(k, 480, s, sk, name=f"{k}{s}"), 30.0)
          for k, s in (("walk_straight", 1), ("walk_turn", 2), ("walk_turn", 3), ("walk_straight", 4))]
    held = protocol.resample(generate_motion("walk_turn", 480, 9, sk, name="held"), 30.0)
    c, length = 10, 90
    start, future = _cut(held, 0, c, "start"), _cut(held, c, held.n_frames, "future")
    truth = root_translation(sk, held.values[c:c + length])[:, [0, 2]]
    # the capture turns: its heading at the end differs from the start's straight line
    chord, step = truth[-1] - truth[0], truth[5] - truth[0]
    assert np.degrees(np.arccos(chord @ step / np.linalg.norm(chord) / np.linalg.norm(step))) > 10
    err = {}
    for name in ("motion_matching", "motion_matching_traj"):
        g = G.make_generator(name, {"motion_matching": {}})
        assert g.name == name and g.query == ("future_trajectory" if name.endswith("traj") else "start")
        g.fit(db)
        kw = {"trajectory": future} if g.query == "future_trajectory" else {}
        m = g.generate(start, length, 0, **kw)
        err[name] = np.linalg.norm(root_translation(sk, m.values)[:, [0, 2]] - truth, axis=1).mean() * sk.length_to_m
    assert err["motion_matching_traj"] < 0.6 * err["motion_matching"], err
    with pytest.raises(ValueError, match="future trajectory"):
        g.generate(start, length, 0)
