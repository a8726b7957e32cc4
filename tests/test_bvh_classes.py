"""The classes of BVH file found in the wild (tests/data/bvh/, written by make_bvh.py from
tests/bvh_classes.py): read in the canonical frame with no false unit warning, facing from the hips
within 10 degrees of the facing computed here from the file's own joint positions; per-trial settings and
resequencing_trials subsets of the config."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from animsynth.config import ConfigError, check_config, normalise_resequencing_trials, trial_setting
from animsynth.data import load_trial
from animsynth.io.bvh import read_bvh
from animsynth.axes import standing_height
from animsynth.kinematics import facing, forward_kinematics
from bvh_classes import BIP_ROLES
from test_bvh_wild import DATA, _independent_fk

# file -> (metres per unit, up axis of the file, left and right hip joints, joint_roles of the trial)
CLASSES = {
    "bandai": (0.01, "+y", "UpperLeg_L", "UpperLeg_R", None),
    "every6_bip": (0.01, "+y", "Bip01_L_Thigh", "Bip01_R_Thigh", BIP_ROLES),
    "rest_along_x": (0.01, "+y", "LeftUpLeg", "RightUpLeg", None),
    "z_up": (1.0, "+z", "LeftUpLeg", "RightUpLeg", None),
    "mixed_orders": (0.01, "+y", "LeftUpLeg", "RightUpLeg", None),
}


def _to_canonical(v, up):
    """File-frame vectors (..., 3) in the canonical frame (+y up; a Z-up file's -y forward becomes +z)."""
    if up == "+y":
        return v
    assert up == "+z"
    return np.stack([v[..., 0], v[..., 2], -v[..., 1]], axis=-1)


def _angle(f):
    return np.degrees(np.arctan2(f[:, 0], f[:, 1]))


@pytest.mark.parametrize("stem", sorted(CLASSES))
def test_class_reads_upright_with_hip_facing_and_no_false_unit_warning(stem, caplog):
    unit, up, lh, rh, roles = CLASSES[stem]
    path = DATA / f"{stem}.bvh"
    with caplog.at_level(logging.INFO, logger="animsynth"):
        m = load_trial(bvh=path, bvh_length_to_m=unit, joint_roles=roles)
    warnings = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert not warnings, warnings
    assert any(f"up axis {up}" in r.getMessage() for r in caplog.records)
    names, pos, _ = _independent_fk(path)
    pos = _to_canonical(pos, up)
    # upright, a plausible human height in metres, the head above the feet
    h = standing_height(m.skeleton, m.values) * m.skeleton.length_to_m
    assert 1.0 < h < 2.5
    ours = forward_kinematics(m.skeleton, m.values, ends=False)
    k = {n: i for i, n in enumerate(m.skeleton.names)}
    np.testing.assert_allclose(ours[:, k[lh]], pos[:, names.index(lh)], atol=1e-4 * h / unit)
    # facing: from the hips of the file's own positions
    across = pos[:, names.index(lh)] - pos[:, names.index(rh)]
    ref = np.cross(across, [0.0, 1.0, 0.0])[:, [0, 2]]
    d = np.abs((_angle(facing(m.skeleton, m.values)) - _angle(ref) + 180.0) % 360.0 - 180.0)
    assert np.median(d) < 10.0 and d.max() < 1e-3


def test_dummy_root_merged_into_its_child_without_loss(caplog):
    path = DATA / "bandai.bvh"
    with caplog.at_level(logging.INFO, logger="animsynth.io"):
        m = read_bvh(path)
    assert m.skeleton.joints[0].name == "Hips" and "joint_Root" not in m.skeleton.names
    assert any("'joint_Root' has a constant rotation" in r.getMessage() and "merged" in r.getMessage()
               for r in caplog.records)
    names, pos, _ = _independent_fk(path)
    np.testing.assert_allclose(forward_kinematics(m.skeleton, m.values, ends=False), pos[:, 1:], atol=1e-9)


def test_moving_joints_keep_their_translation():
    m = read_bvh(DATA / "every6_bip.bvh")
    moving = {j.name for j in m.skeleton.joints[1:] if "tx" in j.dofs}
    assert moving == {"Bip01_Spine", "Bip01_L_Clavicle", "Bip01_R_Clavicle"}
    names, pos, _ = _independent_fk(DATA / "every6_bip.bvh")
    c = names.index("Bip01_L_Clavicle")
    moved = np.linalg.norm(pos[:, c] - pos[:, names.index("Bip01_Spine2")], axis=1)
    assert np.ptp(moved) > 1.0  # centimetres: the clavicle really moves against its parent


def test_wrong_unit_is_warned_along_the_up_axis(caplog):
    with caplog.at_level(logging.WARNING, logger="animsynth"):
        load_trial(bvh=DATA / "z_up.bvh", bvh_length_to_m=0.01)
    assert any("stands 0.016" in r.getMessage() and "0.05644" in r.getMessage() for r in caplog.records)


def test_given_axes_override_the_detection(caplog):
    with caplog.at_level(logging.INFO, logger="animsynth"):
        m = load_trial(bvh=DATA / "z_up.bvh", up_axis="+z", forward_axis="+x")
    assert any("up axis +z (given), forward axis +x (given)" in r.getMessage() for r in caplog.records)
    names, pos, _ = _independent_fk(DATA / "z_up.bvh")
    ours = forward_kinematics(m.skeleton, m.values, ends=False)
    # +x forward -> +z, +z up -> +y, so +y becomes -x... checked through the head's height above the hips
    assert np.allclose(ours[:, :, 1], pos[:, :, 2], atol=1e-5)
    with pytest.raises(ValueError, match="perpendicular"):
        load_trial(bvh=DATA / "z_up.bvh", up_axis="+z", forward_axis="-z")


def _cfg(**reseq):
    return {"mocap_source": "user", "data_dir": "d", "trials": [{"id": "a", "subject": "s", "kind": "walk_straight",
                                                                  "bvh": "a.bvh"}],
            "subsets": {"w1": ["a"]}, "resequencing_trials": reseq,
            "resequencing": {"datasets": ["walk", "run", "dance"]}}


def test_resequencing_trials_take_any_subset():
    cfg = _cfg(walk="a", run=None, dance="syn05_02")
    notes = normalise_resequencing_trials(cfg, {"walk": "syn35_01", "run": "syn35_20", "dance": "syn05_02"})
    assert cfg["resequencing_trials"] == {"walk": "a"} and cfg["resequencing"]["datasets"] == ["walk"]
    assert any("'resequencing_trials.run' is null" in n for n in notes)
    assert any("'resequencing_trials.dance' is not set" in n for n in notes)
    check_config(cfg)
    # an id the user set that is not a trial stays an error naming the key
    cfg = _cfg(walk="typo")
    normalise_resequencing_trials(cfg, {"walk": "syn35_01"})
    with pytest.raises(ConfigError, match="resequencing_trials.walk': trial 'typo' has no record in 'trials'"):
        check_config(cfg)


def test_per_trial_settings_override_the_top_level():
    cfg = {"bvh_length_to_m": 0.05644, "joint_roles": {"head": "Head", "neck": "Neck"}, "up_axis": "auto"}
    trial = {"id": "t", "bvh_length_to_m": 0.01, "joint_roles": {"head": "Kopf"}, "up_axis": "+z"}
    assert trial_setting(cfg, trial, "bvh_length_to_m") == 0.01
    assert trial_setting(cfg, {"id": "u"}, "bvh_length_to_m") == 0.05644
    assert trial_setting(cfg, trial, "joint_roles") == {"head": "Kopf", "neck": "Neck"}
    assert trial_setting(cfg, trial, "up_axis") == "+z" and trial_setting(cfg, {}, "up_axis") == "auto"


def test_command_line_takes_bvh_files(tmp_path, capsys):
    from animsynth.cli import main

    gif = tmp_path / "walk.gif"
    assert main(["preview", str(DATA / "bandai.bvh"), str(gif), "--length-to-m", "0.01"]) == 0 and gif.stat().st_size
    out = tmp_path / "gen.bvh"
    assert main(["generate", str(DATA / "bandai.bvh"), str(DATA / "bandai.bvh"), str(out), "--steps", "12", "--k", "4",
                 "--method", "knn"]) == 0
    g = read_bvh(out)
    assert g.n_frames == 13 and g.skeleton.joints[0].name == "Hips" and g.fps == 120.0
    out = tmp_path / "re.bvh"
    rc = main(["resequence", str(DATA / "every6_bip.bvh"), "--start", "2", "--end", "20", str(out),
               "--length-to-m", "every6_bip.bvh=0.01", "--role", "every6_bip.bvh:left_hip=Bip01_L_Thigh"])
    assert rc == 0, capsys.readouterr().err
    assert read_bvh(out).skeleton.joints[0].name == "Bip01_Pelvis"
    # a Z-up file comes out Y up
    out = tmp_path / "z.bvh"
    assert main(["resequence", str(DATA / "z_up.bvh"), "--start", "0", "--end", "20", "--out", str(out)]) == 0
    m = read_bvh(out)
    pos = forward_kinematics(m.skeleton, m.values)
    assert np.ptp(pos[:, :, 1], axis=1).min() > np.ptp(pos[:, :, 2], axis=1).min()
    # bad combinations name the argument
    assert main(["preview", str(DATA / "bandai.bvh"), str(DATA / "z_up.bvh"), str(gif)]) == 2
    assert "expected one .bvh file or an .asf and an .amc file" in capsys.readouterr().err
    assert main(["preview", str(DATA / "bandai.bvh"), str(gif), "--up-axis", "up"]) == 2
    assert "argument --up-axis" in capsys.readouterr().err


def test_dummy_root_with_a_constant_turn_is_merged_without_loss(tmp_path):
    from test_bvh_wild import _perturb_column

    text = (DATA / "bandai.bvh").read_text()
    for col, deg in ((3, 12.0), (4, 30.0), (5, -7.0)):  # joint_Root: Zrotation Yrotation Xrotation, constant
        text = _perturb_column(text, col, lambda f, v, deg=deg: deg)
    p = tmp_path / "turned.bvh"
    p.write_text(text)
    m = read_bvh(p)
    assert m.skeleton.joints[0].name == "Hips"
    names, pos, endpos = _independent_fk(p)
    np.testing.assert_allclose(forward_kinematics(m.skeleton, m.values, ends=False), pos[:, 1:], atol=1e-6)
    # a root whose rotation varies is a real joint: kept
    text = _perturb_column(text, 4, lambda f, v: 30.0 + f)
    p.write_text(text)
    m = read_bvh(p)
    assert m.skeleton.joints[0].name == "joint_Root" and m.skeleton["Hips"].dofs[:3] == ["tx", "ty", "tz"]
    names, pos, endpos = _independent_fk(p)
    np.testing.assert_allclose(forward_kinematics(m.skeleton, m.values, ends=False), pos, atol=1e-9)


@pytest.mark.workflow
def test_no_resequencing_trial_leaves_the_family_out(tmp_path):
    from conftest import copy_workflow, run_snakemake

    wd = copy_workflow(tmp_path / "wf")
    (wd / "config" / "none.yaml").write_text("resequencing_trials: {walk: null, run: null, dance: null}\n")
    res = run_snakemake(wd, "-n", "--configfile", "config/test.yaml", "config/none.yaml")
    assert res.returncode == 0, (res.stdout + res.stderr)[-3000:]
    out = res.stdout + res.stderr
    assert "skipping resequencing" in out and "no trial in resequencing_trials" in out
    assert "resequencing_analyse" not in out
