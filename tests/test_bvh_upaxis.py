"""Up-axis detection on bodies that are not bipeds (tests/data/bvh/creatures/, written by make_bvh.py from
tests/bvh_classes.py) and the warning for a given up axis that lays a biped down: read upright or kept as the
file has it, never turned without a warning that names the file and the override."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from animsynth.data import load_trial
from animsynth.io.bvh import read_bvh, write_bvh
from animsynth.axes import detect_up_axis, standing_height
from animsynth.kinematics import forward_kinematics
from bvh_classes import Z_UP, turned_world
from test_bvh_wild import DATA, _independent_fk

CREATURES = DATA / "creatures"


def _true_height(path, axis=1):
    """Median over frames of the extent along ``axis`` of the file's own joint and end-site positions."""
    _names, pos, ends = _independent_fk(path)
    allpos = np.concatenate([pos] + [e[:, None] for e in ends.values()], axis=1)
    return float(np.median(np.ptp(allpos[:, :, axis], axis=1)))


def _load(path, caplog, **kw):
    with caplog.at_level(logging.INFO, logger="animsynth"):
        m = load_trial(bvh=path, **kw)
    msgs = [r.getMessage() for r in caplog.records]
    warns = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    return m, msgs, warns


def test_quadruped_stays_y_up_with_a_warning_and_its_true_height(caplog):
    path = CREATURES / "quadruped.bvh"
    m, msgs, warns = _load(path, caplog)
    assert any("up axis +y (detected" in s for s in msgs)
    w = [s for s in warns if "not a biped" in s]
    assert len(w) == 1 and str(path) in w[0] and "up_axis" in w[0] and "4 leg-like chains" in w[0], warns
    true = _true_height(path)
    assert 1.5 < true < 2.1  # about 2 m tall: the body is longer (3.4 m) than it is tall
    assert standing_height(m.skeleton, m.values) == pytest.approx(true, rel=1e-3)
    assert any(f"stands {true:.3g} m tall" in s for s in msgs)
    # the old rule (tallest axis) would have turned it: it is longest along z
    ext = detect_up_axis(read_bvh(path).skeleton, read_bvh(path).values)[1]["extent"]
    assert ext[2] > ext[1]
    # upright: the feet below the hips, the head above them
    pos = forward_kinematics(m.skeleton, m.values, ends=False)
    k = {n: i for i, n in enumerate(m.skeleton.names)}
    assert np.all(pos[:, k["LeftFoot"], 1] < pos[:, k["Hips"], 1]) and np.all(pos[:, k["Head"], 1] > pos[:, k["Hips"], 1])


def test_quadruped_written_z_up_is_found_from_its_legs(tmp_path, caplog):
    path = tmp_path / "quadruped_zup.bvh"
    write_bvh(path, turned_world(read_bvh(CREATURES / "quadruped.bvh"), Z_UP))
    m, msgs, warns = _load(path, caplog)
    assert any("up axis +z (detected" in s and "4 legs stand on the floor along +z" in s for s in msgs)
    assert any("not a biped" in s and "up axis +z from its legs" in s for s in warns)
    assert standing_height(m.skeleton, m.values) == pytest.approx(_true_height(CREATURES / "quadruped.bvh"),
                                                                  rel=1e-3)


def test_crab_is_kept_as_it_is_warned_and_not_tipped_over(caplog):
    path = CREATURES / "crab.bvh"
    raw = read_bvh(path)
    ext = detect_up_axis(raw.skeleton, raw.values)[1]["extent"]
    assert ext[1] < 0.5 * min(ext[0], ext[2])  # wide and flat: the tallest-axis rule would tip it over
    m, msgs, warns = _load(path, caplog)
    assert any("up axis +y" in s for s in msgs)
    assert any("not a biped" in s and str(path) in s and "up_axis" in s for s in warns), warns
    np.testing.assert_allclose(forward_kinematics(m.skeleton, m.values), forward_kinematics(raw.skeleton, raw.values),
                               atol=1e-9)  # the file's own axes: nothing turned
    assert standing_height(m.skeleton, m.values) == pytest.approx(_true_height(path), rel=1e-3)


def test_ambiguous_body_that_is_not_a_biped_keeps_the_files_axes(tmp_path, caplog):
    """No head or feet by role (joint names the role map does not know, no joint_roles) and no clear legs: +y
    kept, warned."""
    from bvh_classes import renamed

    bip = read_bvh(DATA / "every6_bip.bvh")
    path = tmp_path / "unnamed.bvh"
    write_bvh(path, renamed(bip, {j.name: f"part{k}" for k, j in enumerate(bip.skeleton.joints)}))
    raw = read_bvh(path)
    axis, info = detect_up_axis(raw.skeleton, raw.values)
    assert axis == "+y" and not info["biped"] and info["ambiguous"] and info["sign_from"] == "file"
    m, msgs, warns = _load(path, caplog, bvh_length_to_m=0.01)
    assert any("ambiguous: the file's own axes are kept" in s and str(path) in s and "up_axis" in s for s in warns)
    # the 3ds Max Biped names themselves are known (Bip01_L_Thigh ...): a biped, up from its roles
    axis, info = detect_up_axis(bip.skeleton, bip.values)
    assert axis == "+y" and info["biped"] and info["sign_from"] == "roles"
    # the same file on its side is kept as it is too (nothing tells which way is up without roles or legs)
    from scipy.spatial.transform import Rotation

    on_side = turned_world(raw, Rotation.from_euler("z", 90, degrees=True))
    axis, info = detect_up_axis(on_side.skeleton, on_side.values)
    assert axis == "+y" and info["ambiguous"]


def test_biped_z_up_is_still_found_by_its_roles():
    m = read_bvh(DATA / "z_up.bvh")
    axis, info = detect_up_axis(m.skeleton, m.values)
    assert axis == "+z" and info["biped"] and not info["ambiguous"] and info["sign_from"] == "roles"


@pytest.mark.parametrize("stem, given, says", [
    ("z_up", "+y", "lies down"),        # a Z-up biped read Y up: it lies on its back
    ("bandai", "-y", "its head is not above its feet"),
    ("bandai", "+z", "lies down"),
    ("creatures/quadruped", "+z", "its legs stand along +y"),
])
def test_a_wrong_given_up_axis_is_warned(stem, given, says, caplog):
    path = DATA / f"{stem}.bvh"
    _m, msgs, warns = _load(path, caplog, up_axis=given, bvh_length_to_m=0.01)
    w = [s for s in warns if "with the given up axis" in s]
    assert len(w) == 1 and str(path) in w[0] and "up_axis" in w[0] and says in w[0], warns


def test_a_right_given_up_axis_is_not_warned(caplog):
    _m, _msgs, warns = _load(DATA / "z_up.bvh", caplog, up_axis="+z")
    assert not [s for s in warns if "given up axis" in s]


def test_cli_names_the_up_axis_option(tmp_path, capsys, caplog):
    from animsynth.cli import main

    with caplog.at_level(logging.WARNING, logger="animsynth"):
        assert main(["resequence", str(DATA / "z_up.bvh"), "--start", "0", "--end", "10", "--up-axis", "+y",
                     "--out", str(tmp_path / "r.bvh")]) == 0
    w = [r.getMessage() for r in caplog.records if "given up axis" in r.getMessage()]
    assert w and "--up-axis" in w[0] and "z_up.bvh" in w[0]


#: a two-legged bird whose joint names the role map does not know: two leg-like chains are too few to tell its up
#: axis (the file's own axes are kept), yet a given up axis along which no leg stands is wrong
BIRD = [("Body", None, (0.0, 0.6, 0.0), (0.0, 0.05, 0.3)),
        ("NeckB", "Body", (0.0, 0.05, 0.3), (0.0, 0.25, 0.1)), ("Beak", "NeckB", (0.0, 0.25, 0.1), (0.0, 0.0, 0.12)),
        ("TailB", "Body", (0.0, 0.0, -0.1), (0.0, 0.05, -0.3))]
for _side, _x in (("A", 0.12), ("B", -0.12)):
    BIRD += [(f"Thigh{_side}", "Body", (_x, -0.05, 0.05), (0.0, -0.3, 0.05)),
             (f"Shank{_side}", f"Thigh{_side}", (0.0, -0.3, 0.05), (0.0, -0.25, -0.03)),
             (f"Wing{_side}", "Body", (_x, 0.05, 0.1), (_x * 2, 0.0, -0.1))]


@pytest.mark.parametrize("given, says", [("+x", "0 leg-like chains end on the floor along +x, 2 along +y"),
                                         ("-y", "1 leg-like chains end on the floor along -y, 2 along +y"),  # the neck points up
                                         ("+y", None)])
def test_a_wrong_given_up_axis_on_an_animal_whose_axis_is_ambiguous_is_warned(tmp_path, caplog, given, says):
    from bvh_classes import creature

    path = tmp_path / "bird.bvh"
    write_bvh(path, creature(BIRD, swing=6.0))
    raw = read_bvh(path)
    axis, info = detect_up_axis(raw.skeleton, raw.values)
    assert axis == "+y" and not info["biped"] and info["ambiguous"] and info["leg_counts"]["+y"] == 2
    _m, _msgs, warns = _load(path, caplog, up_axis=given)
    w = [s for s in warns if "with the given up axis" in s]
    assert (w == []) if says is None else (len(w) == 1 and says in w[0] and str(path) in w[0]), warns


def _leaning_take(tmp_path, lean_deg: float):
    """A LAFAN1-like file (rest pose along +X, Hips names) of a walk leaning ``lean_deg`` forward throughout."""
    from scipy.spatial.transform import Rotation

    from animsynth.kinematics import root_rotation, root_translation, set_root
    from animsynth.motion import Motion
    from animsynth.synth.mocap import cmu_like_skeleton, generate_motion
    from bvh_classes import convert

    m = convert(generate_motion("walk_straight", 120, 0, cmu_like_skeleton("lafan", 1)), "rest_x")
    sk = m.skeleton
    values = set_root(sk, m.values, Rotation.from_euler("x", lean_deg, degrees=True) * root_rotation(sk, m.values),
                      root_translation(sk, m.values))
    path = tmp_path / f"lean{lean_deg:g}.bvh"
    write_bvh(path, Motion(values, sk, m.fps, "take"))
    return path


def test_the_roles_decide_a_leaning_bipeds_up_axis_without_an_ambiguity_warning(tmp_path, caplog):
    """A crouched walk leaning 38 degrees: the head-to-feet vector's forward part is over 0.7 of its upward part
    (once "ambiguous"), but the head is above the feet along +y in every frame and the legs stand along +y: the
    roles decide, no warning. Leaning 50 degrees, the head-to-feet vector points forward: still ambiguous."""
    path = _leaning_take(tmp_path, 38.0)
    raw = read_bvh(path)
    axis, info = detect_up_axis(raw.skeleton, raw.values)
    assert axis == "+y" and info["biped"] and not info["ambiguous"]
    _m, _msgs, warns = _load(path, caplog, bvh_length_to_m=0.05644)
    assert not [w for w in warns if "ambiguous" in w], warns
    raw = read_bvh(_leaning_take(tmp_path, 50.0))
    axis, info = detect_up_axis(raw.skeleton, raw.values)
    assert info["ambiguous"] and "lies between two axes" in info["why"]
