"""The capture check on constructed motions with known flagged frames, and the generic-figure check."""

import numpy as np
import pytest

from animsynth.capture_check import BODY_PARTS, CaptureCheck, check_capture, checks_table
from animsynth.config import ConfigError
from animsynth.motion import Motion
from animsynth.skeleton import figure_kinds, shared_figure_pairs, shared_figures
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

#: the schema's defaults (config/schema.yaml, capture_check)
CFG = {"max_joint_speed_m_s": 15.0, "tpose_arm_deg": 60.0, "zero_tol_deg": 1.0e-6, "frozen_min_s": 0.05}


@pytest.fixture(scope="module")
def walk():
    """A clean synthetic walk of a CMU-like skeleton: 480 frames at 120 fps."""
    return generate_motion("walk_straight", 480, 5, cmu_like_skeleton("cap", 1), name="w")


def _with(motion, values):
    return Motion(values, motion.skeleton, motion.fps, motion.name)


def _upper_body_columns(sk):
    """Rotation columns of every joint above the root except the legs (the ASF rest pose holds the arms out)."""
    legs = {"rhipjoint", "rfemur", "rtibia", "rfoot", "rtoes", "lhipjoint", "lfemur", "ltibia", "lfoot", "ltoes"}
    sl = sk.dof_slices()
    return [sl[j.name].start + k for j in sk.joints[1:] if j.name not in legs for k in range(len(j.dofs))]


def _flags(check):
    return [(f.kind, f.first, f.last) for f in check.flags]


def test_a_clean_walk_and_run_have_no_flag(walk):
    run = generate_motion("run_straight", 480, 6, walk.skeleton, name="r")
    for m in (walk, run):
        c = check_capture(m, m.name, CFG)
        assert c.flags == [] and c.usable.all() and c.usable.shape == (m.n_frames,)


def test_a_t_pose_start_is_flagged_through_the_frame_its_jump_lands_on(walk):
    """Frames 0-2 hold the ASF rest pose (arms straight out, 90 degrees from hanging), frame 3 is the walk: the
    arms drop at far over 15 m/s between frames 2 and 3, so frames 0-3 are the T-pose settling."""
    v = np.array(walk.values, float)
    rest = v[3].copy()
    rest[6:] = 0.0  # every joint at its rest pose, the root where the walk starts
    v[:3] = rest
    c = check_capture(_with(walk, v), "t", CFG)
    assert _flags(c) == [("tpose_settling", 0, 3)]
    assert not c.usable[:4].any() and c.usable[4:].all()
    assert "T-pose" in c.flags[0].note and "frames 0-3" in c.flags[0].note


def test_a_blended_t_pose_start_is_flagged_by_speed_alone(walk):
    """A converter's blend from its T-pose (frame 0 dropped by first_frame) whose first kept frame has the arms
    below the T-pose limit: the too-fast steps from frame 0 are the settling; the note gives the file's frames."""
    v = np.array(walk.values, float)
    rest = v[4].copy()
    rest[6:] = 0.0
    for i, w in enumerate((0.6, 0.4, 0.2, 0.0)):  # steps of a fifth of the way, each far over 15 m/s
        v[i] = w * rest + (1 - w) * v[4]
    c = check_capture(_with(walk, v), "b", dict(CFG, tpose_arm_deg=80.0), first_frame=1)
    assert _flags(c) == [("tpose_settling", 0, 3)] and c.usable[4:].all()
    assert "file frames 1-4" in c.flags[0].note and "moving faster than a body can" in c.flags[0].note


def test_an_upper_body_at_exactly_zero_is_flagged_with_the_jumps_it_makes(walk):
    """Frames 100-149 with every upper-body DOF at exactly zero (a gap filled with zeros): one zero_part flag for
    the upper body (not again for each arm), and the arms' jumps in and out of it."""
    v = np.array(walk.values, float)
    v[100:150, _upper_body_columns(walk.skeleton)] = 0.0
    c = check_capture(_with(walk, v), "z", CFG)
    assert _flags(c) == [("jump", 99, 100), ("zero_part", 100, 149), ("jump", 149, 150)]
    assert "upper body" in c.flags[1].note and "z: frames 100-149 (50 frames at 120 fps)" in c.flags[1].note
    assert not c.usable[99:151].any() and c.usable[:99].all() and c.usable[151:].all()


def test_a_single_frame_spike_is_one_jump(walk):
    v = np.array(walk.values, float)
    v[240, 1] += 9.0  # the root 9 ASF units (0.5 m) up on one frame
    c = check_capture(_with(walk, v), "j", CFG)
    assert _flags(c) == [("jump", 239, 241)]
    assert "between frames 239 and 240" in c.flags[0].note or "between frames 240 and 241" in c.flags[0].note


def test_the_speed_limit_is_the_key(walk):
    """The same walk with the limit below its fastest joint: every step over it is flagged (the limit is read)."""
    c = check_capture(walk, "w", dict(CFG, max_joint_speed_m_s=3.0))
    assert any(f.kind == "jump" for f in c.flags)


def test_a_held_pose_is_frozen_and_one_repeated_frame_is_not(walk):
    v = np.array(walk.values, float)
    v[301:311] = v[300]  # 10 copies (0.083 s at 120 fps): frozen
    v[401] = v[400]  # one copy (0.008 s): a duplicated frame, kept
    c = check_capture(_with(walk, v), "f", CFG)
    assert [(k, a, b) for k, a, b in _flags(c) if k == "frozen"] == [("frozen", 301, 310)]
    assert c.usable[401] and c.usable[300] and not c.usable[301:311].any()


def test_usable_every_keeps_no_flagged_step_between_two_usable_frames():
    usable = np.ones(40, bool)
    usable[13] = False
    c = CaptureCheck("u", 120.0, usable)
    every = c.usable_every(4)  # frames 0, 4, ..., 36
    assert every.shape == (10,)
    assert list(np.flatnonzero(~every)) == [3, 4]  # frames 12 and 16 are within 3 frames of 13
    assert c.usable_stretches() == [(0, 13), (14, 40)] and c.usable_stretches(min_frames=14) == [(14, 40)]
    with pytest.raises(ValueError, match="step"):
        c.usable_every(0)


def test_checks_table_has_a_row_per_flag_and_one_per_clean_trial(walk):
    v = np.array(walk.values, float)
    v[240, 1] += 9.0
    table = checks_table([check_capture(walk, "clean", CFG), check_capture(_with(walk, v), "spiky", CFG, 2)])
    assert list(table.kind) == ["none", "jump"] and list(table.trial) == ["clean", "spiky"]
    row = table.iloc[1]
    assert (row.first_frame, row.last_frame, row.flagged_frames, row.file_first_frame) == (239, 241, 3, 241)
    assert row.usable_frames == 477 and table.iloc[0].usable_frames == 480 and table.first_frame.isna().iloc[0]


def test_a_missing_or_bad_key_names_it(walk):
    with pytest.raises(ConfigError, match=r"capture_check\.frozen_min_s"):
        check_capture(walk, "w", {k: v for k, v in CFG.items() if k != "frozen_min_s"})
    with pytest.raises(ConfigError, match=r"capture_check\.max_joint_speed_m_s"):
        check_capture(walk, "w", dict(CFG, max_joint_speed_m_s=float("nan")))


def test_body_parts_are_roles():
    from animsynth.joints import ROLES

    assert all(r in ROLES for roles in BODY_PARTS.values() for r in roles)


# --- one figure for several subjects -----------------------------------------------------------------------

def test_two_subjects_on_one_figure_are_flagged_and_own_skeletons_are_not():
    """Subjects a and b share one skeleton (a generic figure, as two copies of it); c and d have their own; c has
    two trials on its skeleton (one subject's trials are never flagged)."""
    generic = cmu_like_skeleton("generic", 0)
    skeletons = {"a_1": generic, "b_1": cmu_like_skeleton("generic", 0), "c_1": cmu_like_skeleton("c", 1),
                 "c_2": cmu_like_skeleton("c", 1), "d_1": cmu_like_skeleton("d", 2)}
    subjects = {"a_1": "a", "b_1": "b", "c_1": "c", "c_2": "c", "d_1": "d"}
    pairs = shared_figure_pairs(skeletons, subjects)
    assert [(a, b) for a, b, _ in pairs] == [("a_1", "b_1")] and pairs[0][2] == 0.0
    shared = shared_figures(skeletons, subjects)
    assert shared == {"a": ["b"], "b": ["a"], "c": [], "d": []}
    assert figure_kinds(shared) == {"a": "generic", "b": "generic", "c": "own", "d": "own"}


def test_a_figure_is_shared_within_the_tolerance_only():
    """A copy with one bone 0.5 mm longer is the same figure; 5 mm longer is another (tolerance 1 mm)."""
    base = cmu_like_skeleton("generic", 0)
    m = base.length_to_m
    near, far = cmu_like_skeleton("generic", 0), cmu_like_skeleton("generic", 0)
    k = near.index("ltibia")
    for sk, metres in ((near, 0.0005), (far, 0.005)):
        t = np.asarray(sk.joints[k].tail, float)
        sk.joints[k].tail = t * (1 + metres / (np.linalg.norm(t) * m))
    subjects = {"x": "1", "near": "2", "far": "3"}
    assert shared_figures({"x": base, "near": near, "far": far}, subjects) == {"1": ["2"], "2": ["1"], "3": []}
    with pytest.raises(KeyError, match="no subject"):
        shared_figures({"x": base}, {})
