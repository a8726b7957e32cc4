"""The command line's BVH options and previews: a per-file option naming no input, a bad --role named as the
option, a joint given two roles, the log's pointer to the docs, and previews titled by their input and played
in real time (or evenly subsampled at a stated speed-up)."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest

from animsynth.cli import main
from animsynth.data import load_trial
from animsynth.io.bvh import read_bvh, write_bvh
from animsynth.motion import Motion
from bvh_classes import BIP_ROLES
from test_bvh_wild import DATA

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("option, value, says", [
    ("--length-to-m", "walk.bvh=0.01", "'walk.bvh', which is not one of the input files"),
    ("--up-axis", "walk.bvh=+z", "'walk.bvh', which is not one of the input files"),
    ("--role", "walk.bvh:head=Head", "'walk.bvh', which is not one of the input files"),
    ("--length-to-m", "bandai.bvh=", "gives 'bandai.bvh' no value"),
    ("--up-axis", "bandai.bvh=", "gives 'bandai.bvh' no value"),
])
def test_a_per_file_option_naming_no_input_is_refused(tmp_path, capsys, option, value, says):
    gif = tmp_path / "p.gif"
    assert main(["preview", str(DATA / "bandai.bvh"), str(gif), option, value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"argument {option}" in err[0] and says in err[0], err
    assert not gif.exists()
    # the file's own name or path is accepted
    assert main(["preview", str(DATA / "bandai.bvh"), str(gif), "--length-to-m", "bandai.bvh=0.01"]) == 0


def test_a_bad_role_names_the_command_line_option(tmp_path, capsys):
    assert main(["preview", str(DATA / "bandai.bvh"), str(tmp_path / "p.gif"), "--role", "left_knee=Nope"]) == 2
    err = capsys.readouterr().err.strip()
    assert "argument --role: left_knee=Nope: the skeleton has no joint 'Nope'" in err and "config key" not in err
    assert main(["preview", str(DATA / "bandai.bvh"), str(tmp_path / "p.gif"), "--role", "knie=UpperLeg_L"]) == 2
    assert "argument --role: knie=UpperLeg_L: unknown joint role" in capsys.readouterr().err
    # the workflow still names its config key
    with pytest.raises(ValueError, match=r"config key joint_roles.left_knee: the skeleton has no joint 'Nope'"):
        load_trial(bvh=DATA / "bandai.bvh", joint_roles={"left_knee": "Nope"})


def test_a_joint_given_two_roles_is_warned(caplog):
    with caplog.at_level(logging.WARNING, logger="animsynth"):
        load_trial(bvh=DATA / "bandai.bvh", bvh_length_to_m=0.01,
                   joint_roles={"left_hip": "UpperLeg_L", "right_hip": "UpperLeg_L"})
    w = [r.getMessage() for r in caplog.records if "plays 2 roles" in r.getMessage()]
    assert len(w) == 1 and "'UpperLeg_L'" in w[0] and "left_hip, right_hip" in w[0] and "bandai.bvh" in w[0]
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="animsynth"):
        load_trial(bvh=DATA / "bandai.bvh", bvh_length_to_m=0.01)
    assert not [r for r in caplog.records if "roles" in r.getMessage()]


def test_the_log_points_to_a_page_that_says_how_translation_is_used(caplog):
    with caplog.at_level(logging.INFO, logger="animsynth"):
        load_trial(bvh=DATA / "every6_bip.bvh", bvh_length_to_m=0.01, joint_roles=BIP_ROLES)
    line = next(r.getMessage() for r in caplog.records if "their translation is part of the pose" in r.getMessage())
    assert "config/README.md" in line and "docs/data.md" not in line
    page = (ROOT / "config" / "README.md").read_text()
    assert "How each family uses a non-root joint's translation" in page


def _gif(path):
    from PIL import Image

    im = Image.open(path)
    durations = []
    for k in range(im.n_frames):
        im.seek(k)
        durations.append(im.info["duration"])
    return durations


def test_a_preview_is_titled_by_its_input_and_a_long_clip_is_not_a_slideshow(tmp_path, monkeypatch, capsys):
    import animsynth.viz as viz

    seen = []
    real = viz.skeleton_gif
    monkeypatch.setattr(viz, "skeleton_gif", lambda *a, **k: (seen.append((a, k)), real(*a, **k))[1])
    m = read_bvh(DATA / "bandai.bvh")  # 24 frames at 120 fps
    short = tmp_path / "short.gif"
    assert main(["preview", str(DATA / "bandai.bvh"), str(short), "--length-to-m", "0.01"]) == 0
    assert seen[-1][0][3] == ["bandai.bvh"]
    assert "bandai.bvh stands 1.6 m tall" in capsys.readouterr().out  # the height, to check the unit by
    d = _gif(short)
    assert len(d) == 6 and sum(d) / 1000 == pytest.approx(24 / 120, abs=0.03)  # real time
    # 40 s at 120 fps: too long for real time within the preview's frames: evenly subsampled, played at about
    # 30 GIF frames per second (so faster), the speed-up in the title; not 2.5 frames per second
    long = tmp_path / "long.bvh"
    write_bvh(long, Motion(np.tile(m.values, (200, 1)), m.skeleton, m.fps, "long"))
    gif = tmp_path / "long.gif"
    assert main(["preview", str(long), str(gif), "--length-to-m", "0.01"]) == 0
    assert seen[-1][0][3] == ["long.bvh"]
    d = _gif(gif)
    assert 500 <= len(d) <= 600 and max(d) <= 40
    from animsynth.viz import gif_timing

    assert gif_timing(4800, 30.0, 4, 600, 120.0) == (8, 30.0, 2.0)  # 40 s: every 8th frame, 30 fps, x2 speed
    assert gif_timing(2400, 30.0, 4, 600, 120.0) == (4, 30.0, 1.0)  # 20 s: real time
    assert gif_timing(4800, 30.0, 4, 150, 120.0) == (32, 30.0, 8.0)  # the workflow's previews: x8, not 3.75 fps


def _without_toes(m: Motion) -> Motion:
    """``m`` on its skeleton without the toe joints (the foot ends its chain, as in cgspeed's CMU BVH files)."""
    import dataclasses

    from animsynth.skeleton import Skeleton

    sk = m.skeleton
    keep = [i for i, j in enumerate(sk.joints) if j.name not in ("ltoes", "rtoes")]
    new = {old: k for k, old in enumerate(keep)}
    joints = [dataclasses.replace(sk.joints[i], parent=new.get(sk.joints[i].parent, -1)) for i in keep]
    cols = [c for c in sk.columns() if c.split(".")[0] not in ("ltoes", "rtoes")]
    values = m.values[:, [sk.columns().index(c) for c in cols]]
    return Motion(values, Skeleton(joints, length_to_m=sk.length_to_m), m.fps, m.name)


def test_the_documented_toe_roles_of_a_skeleton_without_toes_are_not_warned(tmp_path, caplog):
    """config/cmu.yaml's setting for cgspeed's BVH files (left_toe: the foot joint, which ends its chain) is the
    documented one, not a mistake: an info line, no warning; the same roles on a skeleton with toe joints, and a
    joint given two roles of different limbs, are still warned."""
    from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

    walk = generate_motion("walk_straight", 24, 0, cmu_like_skeleton("t", 1))
    write_bvh(tmp_path / "toeless.bvh", _without_toes(walk))
    write_bvh(tmp_path / "toes.bvh", walk)
    roles = {"left_toe": "lfoot", "right_toe": "rfoot"}
    with caplog.at_level(logging.INFO, logger="animsynth"):
        load_trial(bvh=tmp_path / "toeless.bvh", bvh_length_to_m=0.05644, joint_roles=roles)
    said = [r for r in caplog.records if "'lfoot'" in r.getMessage() or "'rfoot'" in r.getMessage()]
    assert [r.levelname for r in said] == ["INFO", "INFO"] and "no toe joint below it" in said[0].getMessage()
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="animsynth"):
        load_trial(bvh=tmp_path / "toes.bvh", bvh_length_to_m=0.05644, joint_roles=roles)
        load_trial(bvh=tmp_path / "toeless.bvh", bvh_length_to_m=0.05644, joint_roles={"left_toe": "rfoot"})
    w = [r.getMessage() for r in caplog.records if "plays 2 roles" in r.getMessage()]
    assert len(w) == 3 and "'rfoot' plays 2 roles (right_ankle, left_toe" in w[2], w


def test_3ds_max_biped_names_need_no_role_option(tmp_path, capsys):
    """``Bip01_L_Thigh``, ``Bip01 L Calf`` ...: the role map drops Biped's prefix, so ``score`` (which needs the
    feet, the hips and the head) runs on a Biped file without one --role."""
    out = tmp_path / "s.csv"
    f = str(DATA / "every6_bip.bvh")
    assert main(["score", f, "--reference", f, "--database", f, "--length-to-m", "0.01", "--out", str(out)]) == 0, \
        capsys.readouterr().err
    import pandas as pd

    row = pd.read_csv(out).iloc[0]
    assert np.isfinite(row["skate_share"])
