"""Known-answer tests of the compare family's metrics (animsynth.compare.measures)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.spatial.transform import Rotation

from animsynth.compare import measures as M
from animsynth.joints import JointRoleError
from animsynth.kinematics import forward_kinematics
from animsynth.motion import Motion
from animsynth.skeleton import Joint, Skeleton
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

FPS = 120.0


@pytest.fixture(scope="module")
def cmu():
    sk = cmu_like_skeleton("metrics", 0)
    clips = [generate_motion(k, 180, s, sk, fps=FPS) for s, k in enumerate(("walk_straight", "run_turn", "dance"))]
    pos = [M.positions(m) for m in clips]
    fwd = [M.facing(m) for m in clips]
    return sk, clips, pos, fwd


def _yaw(deg):
    return Rotation.from_euler("y", deg, degrees=True)


# ---------------------------------------------------------------------------------------------------------------
# positions, roles, facing, features
# ---------------------------------------------------------------------------------------------------------------
def test_positions_are_metres_of_segment_ends():
    sk = Skeleton([Joint("root", -1, np.zeros(3), np.zeros(3), ["tx", "ty", "tz"]),
                   Joint("stick", 0, np.zeros(3), np.array([0.0, 10.0, 0.0]))], length_to_m=0.01)
    m = Motion(np.array([[0.0, 0.0, 0.0], [100.0, 0.0, -50.0]]), sk, FPS)
    p = M.positions(m)
    assert p.shape == (2, 2, 3)
    np.testing.assert_allclose(p[:, 1], [[0.0, 0.1, 0.0], [1.0, 0.1, -0.5]], atol=1e-12)


def test_foot_indices_by_role_and_override(cmu):
    sk = cmu[0]
    assert [sk.joints[i].name for i in M.foot_indices(sk)] == ["lfoot", "ltoes", "rfoot", "rtoes"]
    assert sk.joints[M.foot_indices(sk, {"left_toe": "lfoot"})[1]].name == "lfoot"
    with pytest.raises(JointRoleError, match="left_toe"):
        M.foot_indices(sk, {"left_toe": "nosuchjoint"})


def test_facing_of_the_zero_pose_and_a_quarter_turn(cmu):
    sk = cmu[0]
    v = np.zeros((2, sk.n_dof))
    v[1, sk.columns().index("root.ry")] = 90.0  # root axis is identity: a pure yaw
    f = M.facing(Motion(v, sk, FPS))
    np.testing.assert_allclose(f, [[0.0, 1.0], [1.0, 0.0]], atol=1e-12)  # +z, then +z turned 90 deg about y: +x


def test_facing_follows_the_walking_direction(cmu):
    _, _, pos, fwd = cmu
    travel = pos[0][-1, 0, M.HORIZONTAL] - pos[0][0, 0, M.HORIZONTAL]
    assert np.dot(fwd[0].mean(axis=0), travel / np.linalg.norm(travel)) > 0.95


def test_pose_features_ignore_where_the_body_stands_and_faces(cmu):
    _, _, pos, fwd = cmu
    R = _yaw(73.0)
    moved = R.apply(pos[2].reshape(-1, 3)).reshape(pos[2].shape) + np.array([4.0, 0.0, -7.0])
    fwd3 = np.c_[fwd[2][:, 0], np.zeros(len(fwd[2])), fwd[2][:, 1]]
    moved_fwd = R.apply(fwd3)[:, M.HORIZONTAL]
    np.testing.assert_allclose(M.pose_features(moved, moved_fwd), M.pose_features(pos[2], fwd[2]), atol=1e-9)
    # a body raised by h is h away (RMS joint distance) from itself
    raised = pos[2] + np.array([0.0, 0.3, 0.0])
    d = np.linalg.norm(M.pose_features(raised, fwd[2]) - M.pose_features(pos[2], fwd[2]), axis=1)
    np.testing.assert_allclose(d, 0.3, rtol=1e-12)


def test_global_quaternions_are_the_world_rotations_and_continuous(cmu):
    sk, clips, _, _ = cmu
    q = M.global_quaternions(clips[2])
    _, W = forward_kinematics(sk, clips[2].values, world_rotations=True)
    for j in (0, 5, 17):
        ang = (Rotation.from_quat(q[:, j]).inv() * W[j]).magnitude()
        assert np.max(ang) < 1e-9
    assert np.all(np.sum(q[1:] * q[:-1], axis=-1) >= 0)


# ---------------------------------------------------------------------------------------------------------------
# foot skating
# ---------------------------------------------------------------------------------------------------------------
def _sliding_foot(speed, height, frames=60, direction=(0.6, 0.8)):
    t = np.arange(frames) / FPS
    pos = np.zeros((frames, 2, 3))
    pos[:, 0] = [0.0, 1.0, 0.0]  # a hip that never touches the floor
    pos[:, 1, 0] = direction[0] * speed * t
    pos[:, 1, 2] = direction[1] * speed * t
    pos[:, 1, 1] = height
    return pos


def test_a_foot_sliding_at_floor_height_skates_every_frame_at_its_speed():
    speed = 0.9
    r = M.foot_skating(_sliding_foot(speed, 0.0), FPS, [1], height_m=0.02, speed_m_s=0.1, floor_m=0.0)
    assert r["contact_share"] == 1.0
    assert r["skate_share"] == 1.0
    assert r["skate_m_per_contact_frame"] == pytest.approx(speed / FPS, rel=1e-12)


def test_a_slow_foot_is_in_contact_without_skating():
    r = M.foot_skating(_sliding_foot(0.05, 0.01), FPS, [1], height_m=0.02, speed_m_s=0.1, floor_m=0.0)
    assert r == {"contact_share": 1.0, "skate_share": 0.0, "skate_m_per_contact_frame": 0.0}


def test_a_lifted_foot_has_no_contact():
    r = M.foot_skating(_sliding_foot(0.9, 0.03), FPS, [1], height_m=0.02, speed_m_s=0.1, floor_m=0.0)
    assert r["contact_share"] == 0.0
    assert np.isnan(r["skate_share"]) and np.isnan(r["skate_m_per_contact_frame"])


def test_contact_share_counts_foot_joint_frames_and_the_floor_defaults_to_the_lowest_foot():
    pos = _sliding_foot(0.9, 0.5)
    pos[30:, 1, 1] = 0.6  # second half 10 cm higher
    # own floor = 0.5: frames 1..29 in contact (29 of 59 steps)
    r = M.foot_skating(pos, FPS, [1], height_m=0.02, speed_m_s=0.1)
    assert r["contact_share"] == pytest.approx(29 / 59)
    assert M.foot_skating(pos, FPS, [1], 0.02, 0.1, floor_m=0.0)["contact_share"] == 0.0
    assert M.floor_height([pos, pos - 0.2], [1]) == pytest.approx(0.3)
    # two foot joints, one lifted: half the joint-frames
    two = np.concatenate([_sliding_foot(0.9, 0.0), _sliding_foot(0.9, 0.5)[:, 1:]], axis=1)
    assert M.foot_skating(two, FPS, [1, 2], 0.02, 0.1, floor_m=0.0)["contact_share"] == 0.5


# ---------------------------------------------------------------------------------------------------------------
# seams
# ---------------------------------------------------------------------------------------------------------------
def _reference(c=0.05, n=100):
    """One point whose velocity changes by c, 2c, ..., n*c (m/s) at successive frames."""
    v = np.concatenate([[0.0], np.cumsum(c * np.arange(1, n + 1))])
    x = np.concatenate([[0.0], np.cumsum(v) / FPS])
    pos = np.zeros((x.size, 1, 3))
    pos[:, 0, 0] = x
    return pos


def _seam_motion(v1, v2, seam=20, frames=40):
    pos = np.zeros((frames, 1, 3))
    for t in range(1, frames):
        pos[t, 0] = pos[t - 1, 0] + (np.asarray(v1) if t < seam else np.asarray(v2)) / FPS
    return pos


def test_reference_distribution_is_the_capture_jumps():
    ref = M.jump_reference([_reference()], FPS)
    np.testing.assert_allclose(ref.velocity, 0.05 * np.arange(1, 101), rtol=1e-9)
    np.testing.assert_allclose(ref.accel, 0.05 * FPS, rtol=1e-6)  # the velocity increment grows by c per frame


def test_a_seam_with_a_known_velocity_jump():
    v1, v2 = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 2.0])
    r = M.seam_jumps(_seam_motion(v1, v2), FPS, [20], [_reference()])
    jump = np.sqrt(5.0)
    assert r["n_seams"] == 1
    assert r["velocity_jump"] == pytest.approx(jump, rel=1e-9)
    assert r["velocity_jump_ratio"] == pytest.approx(jump / (50.5 * 0.05), rel=1e-9)  # reference median 2.525
    assert r["velocity_jump_pct"] == pytest.approx(44.0)  # 0.05 .. 2.20 of 0.05 .. 5.00 lie at or below 2.236
    assert r["accel_jump"] == pytest.approx(jump * FPS, rel=1e-9)
    assert r["accel_jump_ratio"] == pytest.approx(jump / 0.05, rel=1e-6)
    assert r["accel_jump_pct"] == 100.0


def test_a_position_jump_at_a_seam_reads_as_offset_times_fps():
    pos = _seam_motion([1.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    pos[20:, 0, 1] += 0.02
    r = M.seam_jumps(pos, FPS, np.array([20]), M.jump_reference([_reference()], FPS))
    assert r["velocity_jump"] == pytest.approx(0.02 * FPS, rel=1e-9)


def test_no_seams_is_nan_and_bad_seams_are_refused():
    pos = _seam_motion([1.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    r = M.seam_jumps(pos, FPS, np.zeros(0, dtype=int), [_reference()])
    assert r["n_seams"] == 0 and all(np.isnan(r[k]) for k in r if k != "n_seams")
    r = M.seam_jumps(pos, FPS, [2], [_reference()])  # too early for the acceleration stencil
    assert r["velocity_jump"] == pytest.approx(0.0) and np.isnan(r["accel_jump"])
    with pytest.raises(ValueError, match="seams must lie in 1..39"):
        M.seam_jumps(pos, FPS, [40], [_reference()])


# ---------------------------------------------------------------------------------------------------------------
# smoothness
# ---------------------------------------------------------------------------------------------------------------
def _min_jerk_speed(amplitude, duration, fps):
    tau = np.arange(round(duration * fps) + 1) / fps / duration
    return 30.0 * amplitude / duration * tau ** 2 * (1.0 - tau) ** 2


def test_ldlj_of_a_minimum_jerk_movement_is_minus_log_204_8():
    # v = 30 A/D tau^2 (1-tau)^2: v_peak = 15 A / 8D, int (v'')^2 dt = 720 A^2 / D^5, so
    # D^3 / v_peak^2 * int = 720 * 64 / 225 = 204.8 whatever A and D (sampled finely: the finite differences
    # are off by about 5 / (D fps))
    for amplitude, duration, fps in ((0.4, 1.0, 10000.0), (2.0, 3.0, 4000.0)):
        assert M.ldlj(_min_jerk_speed(amplitude, duration, fps), fps) == pytest.approx(-np.log(204.8), abs=1e-3)


def test_two_submovements_are_less_smooth_than_one_and_noise_hurts_ldlj_not_sparc():
    v = _min_jerk_speed(1.0, 2.0, FPS)
    two = np.zeros(v.size + 120)
    two[:v.size] += v
    two[120:] += v  # a second movement starting one second later
    assert M.ldlj(two, FPS) < M.ldlj(v, FPS) - 0.5
    assert M.sparc(two, FPS) < M.sparc(v, FPS) - 0.1
    # white noise of 5 % of the peak: the jerk explodes; SPARC's amplitude threshold keeps it out
    noisy = v + np.random.default_rng(3).normal(0.0, 0.05 * v.max(), v.size)
    assert M.ldlj(noisy, FPS) < M.ldlj(v, FPS) - 5.0
    assert M.sparc(noisy, FPS) == pytest.approx(M.sparc(v, FPS), abs=0.01)


def test_sparc_of_a_gaussian_speed_profile_and_its_scale_invariance():
    # |FFT| of exp(-t^2 / 2 s^2) is exp(-2 pi^2 s^2 f^2): with f normalised by the 0.05 cut-off this is
    # exp(-ln(20) u^2) on u in [0, 1] whatever s; SPARC is minus its arc length
    a = np.log(20.0)
    exact = -quad(lambda u: np.sqrt(1.0 + (2.0 * a * u * np.exp(-a * u * u)) ** 2), 0.0, 1.0)[0]
    for sigma in (0.1, 0.2):
        t = np.arange(-8 * sigma, 8 * sigma + 1e-12, 1.0 / 200.0)
        v = np.exp(-t ** 2 / (2 * sigma ** 2))
        assert M.sparc(v, 200.0) == pytest.approx(exact, abs=2e-3)
        assert M.sparc(3.7 * v, 200.0) == pytest.approx(M.sparc(v, 200.0), rel=1e-12)
        assert M.ldlj(3.7 * v, 200.0) == pytest.approx(M.ldlj(v, 200.0), rel=1e-12)


def test_smoothness_from_positions_uses_the_mean_joint_speed(cmu):
    pos = cmu[2][0]
    v = M.speed_profile(pos, FPS)
    assert v.shape == (pos.shape[0] - 1,)
    assert M.ldlj(pos, FPS) == M.ldlj(v, FPS) and M.sparc(pos, FPS) == M.sparc(v, FPS)


# ---------------------------------------------------------------------------------------------------------------
# against a ground truth
# ---------------------------------------------------------------------------------------------------------------
def test_l2p_is_zero_for_identical_motion_and_known_for_an_offset(cmu):
    gt = cmu[2][1]
    std = np.random.default_rng(0).uniform(0.1, 0.5, gt.shape[1:])
    assert M.l2p(gt, gt, std) == 0.0
    d = 0.07
    gen = gt + np.array([d, 0.0, 0.0])
    assert M.l2p(gen, gt, std) == pytest.approx(d * np.sqrt(np.sum(1.0 / std[:, 0] ** 2)), rel=1e-12)
    assert M.l2p(gen, gt, None) == pytest.approx(d * np.sqrt(gt.shape[1]), rel=1e-12)
    # statistics aligned to a ground truth facing +x: a world-x error is a forward (z) error there
    assert M.l2p(gen, gt, std, forward=[1.0, 0.0]) == pytest.approx(d * np.sqrt(np.sum(1.0 / std[:, 2] ** 2)),
                                                                   rel=1e-12)


def test_position_stats_do_not_depend_on_where_the_clips_are(cmu):
    _, _, pos, fwd = cmu
    mean, std = M.position_stats(pos, fwd, window=50, stride=20, context=10)
    assert mean.shape == std.shape == (pos[0].shape[1], 3) and np.all(std > 0)
    R = _yaw(-121.0)
    moved = [R.apply(p.reshape(-1, 3)).reshape(p.shape) + [30.0, 0.0, 2.0] for p in pos]
    moved_fwd = [R.apply(np.c_[f[:, 0], np.zeros(len(f)), f[:, 1]])[:, M.HORIZONTAL] for f in fwd]
    mean2, std2 = M.position_stats(moved, moved_fwd, window=50, stride=20, context=10)
    np.testing.assert_allclose(mean2, mean, atol=1e-9)
    np.testing.assert_allclose(std2, std, atol=1e-9)


def test_l2q_is_zero_for_identical_or_sign_flipped_and_known_for_a_rotation():
    q = Rotation.random(40 * 5, random_state=1).as_quat().reshape(40, 5, 4)
    assert M.l2q(q, q) == 0.0
    flips = np.where(np.random.default_rng(2).random((40, 5, 1)) < 0.5, -1.0, 1.0)
    assert M.l2q(q * flips, q) == pytest.approx(0.0, abs=1e-12)
    theta = 0.6
    turned = (_yaw(np.degrees(theta)) * Rotation.from_quat(q.reshape(-1, 4))).as_quat().reshape(q.shape)
    assert M.l2q(turned, q) == pytest.approx(np.sqrt(5) * 2 * np.sin(theta / 4), rel=1e-9)


def test_npss_known_values():
    T = 64
    t = np.arange(T)
    gt = np.cos(2 * np.pi * 3 * t / T)[:, None]
    assert M.npss(gt, gt) == 0.0
    # the power of cos(2 pi k t / T) sits at bins k and T-k, half each: the EMD between bins k1 and k2 is |k1-k2|
    assert M.npss(np.cos(2 * np.pi * 5 * t / T)[:, None], gt) == pytest.approx(2.0, rel=1e-9)
    # a circular time shift: the power spectrum does not see it, the real part of the FFT does
    walk = np.c_[np.cos(2 * np.pi * 2 * t / T) + 0.5 * np.cos(2 * np.pi * 7 * t / T + 0.3), np.sin(t / 5.0)]
    shifted = np.roll(walk, 9, axis=0)
    assert M.npss(shifted, walk, spectrum="power") == pytest.approx(0.0, abs=1e-9)
    assert M.npss(shifted, walk, spectrum="real") > 0.1
    with pytest.raises(ValueError, match="spectrum"):
        M.npss(walk, walk, spectrum="abs")


def test_npss_of_quaternions_ignores_their_sign(cmu):
    q = M.global_quaternions(cmu[1][1])
    flips = np.where(np.random.default_rng(4).random(q.shape[:2] + (1,)) < 0.3, -1.0, 1.0)
    assert M.npss(q * flips, q, quaternions=True) == pytest.approx(0.0, abs=1e-12)
    assert M.npss(q * flips, q) > 0.0


# ---------------------------------------------------------------------------------------------------------------
# against the database
# ---------------------------------------------------------------------------------------------------------------
def test_window_nearest_matches_brute_force():
    rng = np.random.default_rng(5)
    a = [rng.normal(size=(23, 4)), rng.normal(size=(9, 4))]
    b = [rng.normal(size=(31, 4)), rng.normal(size=(12, 4))]
    L = 6
    a_min, b_min = M.window_nearest(a, b, L, block=7)

    def cost(x, i, y, k):
        return np.mean(np.linalg.norm(x[i:i + L] - y[k:k + L], axis=1))

    for x, got in zip(a, a_min):
        want = [min(cost(x, i, y, k) for y in b for k in range(len(y) - L + 1)) for i in range(len(x) - L + 1)]
        np.testing.assert_allclose(got, want, rtol=1e-12)
    for y, got in zip(b, b_min):
        want = [min(cost(x, i, y, k) for x in a for i in range(len(x) - L + 1)) for k in range(len(y) - L + 1)]
        np.testing.assert_allclose(got, want, rtol=1e-12)


def test_coverage_of_the_database_itself_and_of_a_far_away_motion(cmu):
    _, _, pos, fwd = cmu
    db = [M.pose_features(p, f) for p, f in zip(pos, fwd)]
    r = M.window_scores(db, db, length=30, threshold_m=0.05)
    assert r == {"coverage": 1.0, "local_diversity": 0.0}
    far = [x + 10.0 for x in db]
    assert M.coverage(far, db, 30, 0.05) == 0.0
    assert M.local_diversity(far, db, 30) > 5.0
    # one clip of three (the other two far from it): its own windows, and only those, are covered
    apart = [db[0], db[1] + 10.0, db[2] + 20.0]
    n = [len(x) - 30 + 1 for x in apart]
    assert M.coverage(db[0], apart, 30, 0.05) == pytest.approx(n[0] / sum(n))


def test_novelty_of_a_replayed_clip_is_zero_and_of_a_lifted_one_its_lift(cmu):
    _, _, pos, fwd = cmu
    db = [M.pose_features(p, f) for p, f in zip(pos, fwd)]
    assert M.novelty(db[1][40:120], db, tolerance_m=1e-6) == {"novelty_median_m": 0.0, "copy_share": 1.0}
    lifted = M.pose_features(pos[1] + np.array([0.0, 1e-4, 0.0]), fwd[1])
    r = M.novelty(lifted, db, tolerance_m=1e-5)
    assert r["copy_share"] == 0.0
    assert r["novelty_median_m"] == pytest.approx(1e-4, rel=1e-6)
    assert M.novelty(lifted, db, tolerance_m=1e-3)["copy_share"] == 1.0


def test_seed_diversity(cmu):
    _, _, pos, fwd = cmu
    f = M.pose_features(pos[0], fwd[0])
    assert M.seed_diversity([f, f, f]) == 0.0
    raised = M.pose_features(pos[0] + np.array([0.0, 0.2, 0.0]), fwd[0])
    # pairs (f, f) 0, (f, raised) 0.2 twice
    assert M.seed_diversity([f, f, raised]) == pytest.approx(0.4 / 3, rel=1e-12)
    assert np.isnan(M.seed_diversity([f]))


# ---------------------------------------------------------------------------------------------------------------
# per-frame jumps, GMD's skating ratio, the robust floor, LDLJ's duration
# ---------------------------------------------------------------------------------------------------------------
def test_per_frame_jumps_find_a_discontinuity_between_reported_seams():
    # constant velocity, a reported seam at 10 where nothing happens, a hidden 3 cm step at 30
    pos = _seam_motion([1.0, 0.0, 0.0], [1.0, 0.0, 0.0], frames=60)
    pos[30:, 0, 2] += 0.03
    capture = _seam_motion([1.0, 0.0, 0.0], [1.2, 0.0, 0.0], seam=20, frames=40)  # its largest jump: 0.2 m/s
    cmax = M.capture_max_jumps(capture, FPS)
    assert cmax[0] == pytest.approx(0.2, rel=1e-9)
    at_seams = M.seam_jumps(pos, FPS, [10], M.jump_reference([capture], FPS))
    assert at_seams["velocity_jump"] == pytest.approx(0.0, abs=1e-9)  # the seams say: smooth
    r = M.frame_jumps(pos, FPS, 2, cmax)
    assert r["velocity_jump_max"] == pytest.approx(0.03 * FPS, rel=1e-9)  # the step in, then out
    assert r["velocity_jump_over_capture"] == pytest.approx(2 / 58)  # frames 30 and 31 of 2..59
    assert r["velocity_jump_p95"] == pytest.approx(0.0, abs=1e-9)
    assert r["accel_jump_over_capture"] > 0
    # measured from the first generated frame on
    assert M.frame_jumps(pos, FPS, 40, cmax)["velocity_jump_max"] == pytest.approx(0.0, abs=1e-9)


def test_gmd_skating_ratio_counts_frame_steps_where_either_foot_skates_over_all_frame_steps():
    # GMD's definition: a frame step skates when either foot skates on it; the ratio is over all T - 1 steps
    slide, lifted = _sliding_foot(0.9, 0.0)[:, 1:], _sliding_foot(0.9, 0.5)[:, 1:]
    T = slide.shape[0]
    assert T == 60
    # one foot skates on every step (the zero-padded 5-step mean at the ends is 0.9 * 3/5 = 0.54 > 0.5), the
    # other is lifted and never does: every frame step skates (joint-steps over all joint-steps would give 1/2)
    one_skates = np.concatenate([slide, lifted], axis=1)
    assert M.skating_ratio(one_skates, FPS, [0, 1], height_m=0.02, speed_m_s=0.5, floor_m=0.0, window=5) == 1.0
    # both feet skating on the same steps count once
    assert M.skating_ratio(np.concatenate([slide, slide], axis=1), FPS, [0, 1], 0.02, 0.5, 0.0) == 1.0
    # the feet take turns: foot 0 on the floor in frames 0..29, foot 1 in frames 30..59, both sliding. Foot 0 is
    # in contact (both frames of the step) on steps 0..28, foot 1 on steps 30..58; step 29 has neither, and
    # counts in the denominator: 58 of 59 frame steps (joint-steps: 58 of 118; contact steps only: 58 of 58)
    turns = np.concatenate([slide, slide], axis=1)
    turns[30:, 0, 1] = 0.5
    turns[:30, 1, 1] = 0.5
    assert M.skating_ratio(turns, FPS, [0, 1], 0.02, 0.5, 0.0) == pytest.approx(58 / 59, rel=1e-12)
    # a foot in contact in one frame only of a step does not skate there
    one = slide.copy()
    one[::2, 0, 1] = 0.05
    assert M.skating_ratio(one, FPS, [0], 0.02, 0.5, 0.0) == 0.0
    # a short burst of speed is removed by the 5-step mean
    burst = _sliding_foot(0.0, 0.0)[:, 1:].copy()
    burst[31:, 0, 0] += 0.6 / FPS  # one step at 0.6 m/s
    assert M.foot_skating(burst, FPS, [0], 0.02, 0.5, 0.0)["skate_share"] > 0
    assert M.skating_ratio(burst, FPS, [0], 0.02, 0.5, 0.0) == 0.0
    # a slide on the floor from frame 40 on skates on steps 40..58 (the 5-step mean there is at least
    # 0.9 * 3/5), the other foot lifted: 19 of 59 frame steps (joint-steps: 19 of 118)
    late = _sliding_foot(0.0, 0.0)[:, 1:].copy()
    late[41:, 0, 0] += 0.9 / FPS * np.arange(1, T - 40)
    assert M.skating_ratio(np.concatenate([late, lifted], axis=1), FPS, [0, 1], 0.02, 0.5, 0.0) == \
        pytest.approx(19 / 59, rel=1e-12)


def test_the_robust_floor_ignores_a_few_frames_through_the_floor():
    pos = _sliding_foot(0.9, 0.1)
    pos[5, 1, 1] = -0.3  # one frame through the floor
    assert M.floor_height([pos], [1]) == pytest.approx(-0.3)
    assert M.floor_height([pos], [1], percentile=5) == pytest.approx(0.1)


def test_ldlj_takes_the_duration_as_n_over_fs():
    v = np.array([0.0, 1.0, 3.0, 2.0, 0.5, 0.0])
    fps = 10.0
    integral = np.sum((np.diff(v, 2) * fps * fps) ** 2) / fps
    assert M.ldlj(v, fps) == pytest.approx(-np.log((6 / fps) ** 3 / 3.0 ** 2 * integral), rel=1e-12)
