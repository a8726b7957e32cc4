"""Euler angles that wrap past 180 degrees, and skeletons that share joint names but not rest offsets.

Every file is written here from the project's synthetic walk (tests/bvh_classes.py):

* a Bandai-Namco-like walk whose upper legs and upper arms rest turned 180 degrees about +y, so their
  ``Yrotation`` channels wrap between +180 and -180 as the limbs swing (the real file's wraps sit in a few
  columns holding most of the angle variance; so do these);
* the same walk written Y up and re-exported Z up with every offset turned (as Blender writes it);
* the walk on a skeleton with other bone lengths, and on one whose arms rest in another pose.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from animsynth.cli import main
from animsynth.data import load_trial
from animsynth.io.bvh import read_bvh, write_bvh
from animsynth.kinematics import forward_kinematics
from animsynth.motion import Motion
from animsynth.simplicial import generate_from_trials
from animsynth.retarget import (align_angle_branches, continuous_clips, retarget, rotation_columns, unwrap_angles,
                                wrap_count)
from animsynth.skeleton import SAME_SKELETON_TOL_M, compare_skeletons
from animsynth.synth.mocap import generate_motion
from bvh_classes import Z_UP, bandai_with_wraps, hips_motion, turned_world

CM = 0.01


def _write(path, motion, unit=CM):
    write_bvh(path, motion, scale=motion.skeleton.length_to_m / unit)
    return path


def _largest_step_m(m: Motion) -> float:
    """The largest distance any joint moves between two consecutive frames, metres (forward kinematics)."""
    p = forward_kinematics(m.skeleton, m.values, ends=False) * m.skeleton.length_to_m
    return float(np.linalg.norm(np.diff(p, axis=0), axis=-1).max())


@pytest.fixture(scope="module")
def walk():
    return generate_motion("walk_straight", 360, 1, name="walk")


@pytest.fixture(scope="module")
def wraps(walk, tmp_path_factory):
    return _write(tmp_path_factory.mktemp("wraps") / "bandai_wraps.bvh", bandai_with_wraps(walk))


# --------------------------------------------------------------------------------------------- angle wraps


def test_the_mimic_wraps_like_the_real_file(wraps):
    """The file's own angles jump by about 360 degrees in a few columns holding most of the angle variance."""
    raw = read_bvh(wraps)
    cols = rotation_columns(raw.skeleton, root=False)
    jumps = np.abs(np.diff(raw.values[:, cols], axis=0)) > 180
    hit = jumps.any(axis=0)
    var = raw.values[:, cols].var(axis=0)
    assert jumps.sum() >= 10 and 2 <= hit.sum() <= 6
    assert var[hit].sum() / var.sum() > 0.9


def test_loading_unwraps_each_rotation_channel_and_keeps_the_rotations(wraps, caplog):
    raw = read_bvh(wraps)
    with caplog.at_level(logging.INFO, logger="animsynth"):
        m = load_trial(bvh=wraps, bvh_length_to_m=CM)
    assert wrap_count(m.skeleton, m.values) == 0
    assert any("read as wraps of the Euler angle and unwrapped" in r.getMessage() for r in caplog.records)
    # the same rotations: every joint where the file puts it; every angle moved by whole turns
    pa = forward_kinematics(raw.skeleton, raw.values, ends=False)
    pb = forward_kinematics(m.skeleton, m.values, ends=False)
    np.testing.assert_allclose(pb, pa, atol=1e-6)
    cols = rotation_columns(m.skeleton)
    turns = (m.values[:, cols] - raw.values[:, cols]) / 360.0
    np.testing.assert_allclose(turns, np.round(turns), atol=1e-9)
    # translations untouched
    t = [k for k, c in enumerate(m.columns) if c.split(".")[1].startswith("t")]
    np.testing.assert_array_equal(m.values[:, t], raw.values[:, t])


def test_only_wrapping_columns_change(walk):
    """No wrap, no arithmetic: a column that does not wrap keeps its values bit for bit (the synthetic walks'
    joint angles, all of CMU's trials), a motion without a wrap is returned as it is (so is an unwrapped one),
    and a clip already on the first clip's branch is not moved. (The synthetic root's Euler angles do wrap.)"""
    cols = rotation_columns(walk.skeleton, root=False)
    assert np.all(np.abs(np.diff(walk.values[:, cols], axis=0)) <= 180)
    out = unwrap_angles(walk)
    assert out.values[:, 6:].tobytes() == walk.values[:, 6:].tobytes()
    assert out.values[:, :3].tobytes() == walk.values[:, :3].tobytes()  # root translation
    assert unwrap_angles(out) is out
    other = Motion(walk.values[100:].copy(), walk.skeleton, walk.fps, "b")
    clips = continuous_clips([out, other])
    assert clips[0] is out
    assert clips[1].values[:, cols].tobytes() == other.values[:, cols].tobytes()


def test_generated_walk_moves_no_joint_further_per_frame_than_the_capture(wraps, tmp_path):
    """The acceptance criterion: on the mimic of a Bandai walk with wraps, ``animsynth generate``'s walk has its
    largest joint step per frame within the capture's own largest step. On the file's raw angles (what PCA got
    before) the same generation jumps far beyond it."""
    out = tmp_path / "out.bvh"
    assert main(["generate", str(wraps), str(out), "--steps", "120", "--length-to-m", str(CM)]) == 0
    capture = load_trial(bvh=wraps, bvh_length_to_m=CM)
    held = Motion(capture.values.copy(), capture.skeleton, capture.fps, "in place")
    n_root = len(capture.skeleton.joints[0].dofs)
    held.values[:, :n_root] = capture.values[0, :n_root]  # the generated walk's root is held: compare in place too
    gen = load_trial(bvh=out, bvh_length_to_m=CM)
    assert _largest_step_m(gen) <= _largest_step_m(held) <= _largest_step_m(capture)
    # the output keeps the file's channels, continuous (not wrapped back to (-180, 180])
    raw_out = read_bvh(out)
    assert raw_out.columns == read_bvh(wraps).columns
    assert wrap_count(raw_out.skeleton, raw_out.values) == 0
    # the criterion discriminates: the raw, wrapping angles give a jump beyond the capture's
    raw = read_bvh(wraps)
    raw.skeleton.length_to_m = CM
    angles, _ = generate_from_trials([raw.without_root()], steps=120)
    values = np.tile(raw.values[0], (len(angles), 1))
    values[:, n_root:] = angles
    assert _largest_step_m(Motion(values, raw.skeleton, raw.fps)) > 2 * _largest_step_m(capture)


def test_clips_are_put_on_the_branch_of_the_first(walk):
    """The same pose gets the same value across clips: a clip whose joint angles sit one turn away is moved
    back by whole turns (the root's heading is left as it is)."""
    a = Motion(walk.values[:120].copy(), walk.skeleton, walk.fps, "a")
    b = Motion(walk.values[120:].copy(), walk.skeleton, walk.fps, "b")
    cols = rotation_columns(walk.skeleton, root=False)
    root = rotation_columns(walk.skeleton)[:3]
    b.values[:, cols[:5]] += 360.0
    b.values[:, cols[5:9]] -= 720.0
    b.values[:, root] += 360.0
    out = align_angle_branches(b, a)
    np.testing.assert_allclose(out.values[:, cols], walk.values[120:, cols], atol=1e-9)
    np.testing.assert_array_equal(out.values[:, root], b.values[:, root])
    assert align_angle_branches(out, a) is out


# --------------------------------------------------------------------------------------------- rest offsets


@pytest.fixture(scope="module")
def pair(walk, tmp_path_factory):
    """The walk Y up (the capture) and the same walk re-exported Z up with its offsets turned (Blender)."""
    d = tmp_path_factory.mktemp("zup")
    h = hips_motion(walk)
    return _write(d / "walk.bvh", h), _write(d / "walk_blender.bvh", turned_world(h, Z_UP))


def _score(tmp_path, generated, reference, *extra):
    out = tmp_path / "s.csv"
    code = main(["score", str(generated), "--reference", str(reference), "--database", str(reference),
                 "--length-to-m", str(CM), "--out", str(out), *map(str, extra)])
    return code, (pd.read_csv(out) if code == 0 else None)


def test_a_walk_scored_against_its_z_up_re_export_scores_zero(pair, tmp_path, caplog):
    """Equal joint names and channels, offsets turned: the same skeleton, read onto the capture's rest pose
    (L2P below 0.05, the acceptance criterion; here it is 0 to the printed precision)."""
    y, z = pair
    a, b = load_trial(bvh=y, bvh_length_to_m=CM), load_trial(bvh=z, bvh_length_to_m=CM)
    assert a.columns == b.columns
    diff = compare_skeletons(b.skeleton, a.skeleton)
    assert diff.same and abs(diff.turn_deg - 90) < 1e-6
    with caplog.at_level(logging.INFO, logger="animsynth"):
        code, table = _score(tmp_path, z, y)
    assert code == 0
    assert table["l2p"].iloc[0] < 0.05 and table["l2p_m"].iloc[0] < 1e-4
    assert table["npss"].iloc[0] < 1e-3
    assert any("with its rest pose turned by 90 degrees" in r.getMessage() for r in caplog.records)


def _other_lengths(m: Motion, factor=1.15) -> Motion:
    sk = m.skeleton.__class__.from_dict(m.skeleton.to_dict())
    for j in sk.joints:
        if "Leg" in j.name or "Foot" in j.name:
            j.offset, j.tail = j.offset * factor, j.tail * factor
    return Motion(m.values.copy(), sk, m.fps, m.name)


def test_other_bone_lengths_are_retargeted_with_a_line_naming_both(walk, pair, tmp_path, caplog):
    y, _ = pair
    long = _write(tmp_path / "long_legs.bvh", _other_lengths(hips_motion(walk)))
    with caplog.at_level(logging.WARNING, logger="animsynth"):
        code, table = _score(tmp_path, long, y)
    assert code == 0 and np.isfinite(table["l2p"].iloc[0])
    lines = [r.getMessage() for r in caplog.records if "retargeted onto" in r.getMessage()]
    assert lines and "long_legs.bvh" in lines[0] and "walk.bvh" in lines[0] and " mm (joint " in lines[0]
    # retargeted: the capture's offsets, the file's rotations (its joints where the capture's are, at rest lengths)
    a, b = load_trial(bvh=y, bvh_length_to_m=CM), load_trial(bvh=long, bvh_length_to_m=CM)
    r = retarget(b, a.skeleton, "long_legs.bvh", "walk.bvh")
    assert r.skeleton is a.skeleton
    np.testing.assert_allclose(forward_kinematics(r.skeleton, r.values), forward_kinematics(a.skeleton, a.values),
                               atol=1e-4)


def test_another_rest_pose_is_refused_naming_both_files(walk, pair, tmp_path, capsys):
    y, _ = pair
    h = hips_motion(walk)
    sk = h.skeleton.__class__.from_dict(h.skeleton.to_dict())
    down = Rotation.from_euler("z", -60, degrees=True)
    for j in sk.joints:  # arms rest 60 degrees lower (an A pose against a T pose)
        if j.name.startswith(("LeftArm", "LeftFore", "LeftHand")):
            j.offset, j.tail = down.apply(j.offset), down.apply(j.tail)
    other = _write(tmp_path / "a_pose.bvh", Motion(h.values.copy(), sk, h.fps, "a"))
    capsys.readouterr()
    code, _ = _score(tmp_path, other, y)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert "a_pose.bvh" in err[0] and "walk.bvh" in err[0] and "mm at joint" in err[0], err
    assert not (tmp_path / "s.csv").exists()


def test_the_tolerance_is_one_millimetre(walk):
    h = hips_motion(walk)
    for shift, same in ((0.5 * SAME_SKELETON_TOL_M, True), (2 * SAME_SKELETON_TOL_M, False)):
        sk = h.skeleton.__class__.from_dict(h.skeleton.to_dict())
        sk["LeftLeg"].offset = sk["LeftLeg"].offset + np.array([shift / sk.length_to_m, 0, 0])
        d = compare_skeletons(sk, h.skeleton)
        assert d.same is same and d.joint == "LeftLeg" and abs(d.largest_m - shift) < 1e-9


def test_multi_file_generate_reads_a_z_up_copy_onto_the_first_skeleton(pair, tmp_path, caplog):
    y, z = pair
    out = tmp_path / "g.bvh"
    with caplog.at_level(logging.INFO, logger="animsynth"):
        assert main(["generate", str(y), str(z), str(out), "--steps", "20", "--length-to-m", str(CM)]) == 0
    lines = [r.getMessage() for r in caplog.records if "with its rest pose turned by 90 degrees" in r.getMessage()]
    assert lines and lines[0].split(": the skeleton of ")[0].endswith("walk_blender.bvh")
    assert read_bvh(out).columns == read_bvh(y).columns


def test_compare_databases_and_simplicial_subsets_share_one_skeleton(pair, tmp_path):
    """A database trial re-exported Z up is read onto the held-out trial's rest pose (its joint positions
    unchanged); the simplicial subset's trials onto the first trial's."""
    from animsynth.compare.protocol import prepare_clips
    from animsynth.simplicial.jobs import load_trials

    y, z = pair
    a, b = load_trial(bvh=y, bvh_length_to_m=CM, name="a"), load_trial(bvh=z, bvh_length_to_m=CM, name="b")
    cfg = {"fps": 30.0, "context": 4, "length": 20, "min_length": 5, "holdout_fraction": 0.3}
    clips = prepare_clips({"a": a, "b": b}, {"s": ["a", "b"]}, {}, cfg)
    held_a = next(c for c in clips if c.trial == "a")
    db = held_a.database[0]
    assert db.skeleton is held_a.held_out.skeleton
    np.testing.assert_allclose(db.values, held_a.held_out.values, atol=1e-5)
    a.save_npz(tmp_path / "a.npz"), b.save_npz(tmp_path / "b.npz")
    angles, motions = load_trials([tmp_path / "a.npz", tmp_path / "b.npz"], ["a", "b"])
    np.testing.assert_allclose(angles["b"], angles["a"], atol=1e-5)
