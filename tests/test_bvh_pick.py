"""BVH files as users bring them: two characters in one file (one picked by its root joint's name), joint names
in Shift-JIS (an encoding hint, not just "not UTF-8"), and a negative axis given as ``--forward-axis -y``."""

from __future__ import annotations

import re

import numpy as np
import pytest

from animsynth.cli import main
from animsynth.data import load_trial
from animsynth.errors import MotionFormatError
from animsynth.io.bvh import read_bvh
from animsynth.kinematics import forward_kinematics
from test_bvh_wild import DATA

ONE = DATA / "cmu_converted.bvh"


@pytest.fixture(scope="module")
def two(tmp_path_factory):
    """cmu_converted.bvh and a second character (every joint in the namespace ``Char2:``, standing 100 units to
    the side) in one file: two ROOT blocks, each frame's values the first's then the second's."""
    head, motion = ONE.read_text().split("MOTION\n")
    hier = head.split("HIERARCHY\n")[1]
    lines = motion.splitlines()
    rows = [r + " " + " ".join(f"{float(v) + (100.0 if i == 0 else 0.0):.6f}" for i, v in enumerate(r.split()))
            for r in lines[2:]]
    path = tmp_path_factory.mktemp("two") / "two.bvh"
    path.write_text("HIERARCHY\n" + hier + re.sub(r"(ROOT|JOINT) (\S+)", r"\1 Char2:\2", hier) + "MOTION\n"
                    + "\n".join(lines[:2] + rows) + "\n")
    return path


def test_a_file_of_two_characters_names_them_and_reads_the_one_picked(two):
    with pytest.raises(MotionFormatError) as exc:
        read_bvh(two)
    assert "a second ROOT 'Char2:Hips': the file holds 2 skeletons ('Hips', 'Char2:Hips'); name one with root=" \
        in str(exc.value) and "--root NAME" in str(exc.value)
    one = read_bvh(ONE)
    first, second = read_bvh(two, root="Hips"), read_bvh(two, root="Char2:Hips")
    assert first.skeleton.names == one.skeleton.names and np.array_equal(first.values, one.values)
    assert second.skeleton.names == [f"Char2:{n}" for n in one.skeleton.names]
    moved = forward_kinematics(second.skeleton, second.values) - forward_kinematics(one.skeleton, one.values)
    np.testing.assert_allclose(moved, np.broadcast_to([100.0, 0.0, 0.0], moved.shape), atol=1e-6)
    with pytest.raises(MotionFormatError, match=r"root='Nobody' is none of the file's skeletons"):
        read_bvh(two, root="Nobody")
    # the workflow's reader takes it from the trial record (bvh_root), its roles found through the namespace
    m = load_trial(bvh=two, bvh_root="Char2:Hips", bvh_length_to_m=0.01)
    assert m.skeleton.names[0] == "Char2:Hips"


def test_a_root_bone_under_blenders_dummy_root_is_picked_too():
    p = DATA / "multiroot" / "blender_two_roots.bvh"
    assert read_bvh(p, root="prop").skeleton.names == ["prop"]
    assert read_bvh(p, root="hips").skeleton.names == ["hips"]


def test_the_command_line_picks_a_character_and_takes_a_negative_axis(two, tmp_path, capsys):
    gif = tmp_path / "p.gif"
    assert main(["preview", str(two), str(gif), "--length-to-m", "0.01"]) == 2
    assert "the file holds 2 skeletons" in capsys.readouterr().err and not gif.exists()
    assert main(["preview", str(two), str(gif), "--length-to-m", "0.01", "--root", "Char2:Hips",
                 "--up-axis", "+y", "--forward-axis", "-z"]) == 0, capsys.readouterr().err
    assert gif.is_file()
    assert main(["preview", str(two), str(gif), "--root", "two.bvh=Char2:Hips", "--forward-axis", "-x",
                 "--length-to-m", "0.01"]) == 0, capsys.readouterr().err
    assert main(["preview", str(two), str(gif), "--root", "other.bvh=Hips"]) == 2
    assert "argument --root: 'other.bvh=Hips' names 'other.bvh', which is not one of the input files" \
        in capsys.readouterr().err


def test_shift_jis_joint_names_get_an_encoding_hint(tmp_path):
    text = ONE.read_text().replace("JOINT LeftUpLeg", "JOINT 左太もも").replace("JOINT Head", "JOINT 頭")
    kana = ONE.read_text().replace("JOINT Head", "JOINT アタマ")  # trail bytes in the ASCII range (0x83 0x41)
    p = tmp_path / "sjis.bvh"
    p.write_bytes(text.encode("cp932"))
    with pytest.raises(MotionFormatError) as exc:
        read_bvh(p)
    msg = str(exc.value)
    assert msg.startswith(f"{p}:18: not UTF-8 text (byte b'\\x93'); it reads as Shift-JIS (Japanese; Windows code "
                          "page 932), e.g. 'JOINT 頭'") and "iconv -f CP932 -t UTF-8" in msg
    (tmp_path / "utf8.bvh").write_bytes(text.encode("utf-8"))  # what the hint says to do: then it reads
    assert "頭" in read_bvh(tmp_path / "utf8.bvh").skeleton.names
    (tmp_path / "latin.bvh").write_bytes(ONE.read_text().replace("JOINT Head", "JOINT Tête").encode("cp1252"))
    with pytest.raises(MotionFormatError, match="it reads as Windows-1252"):
        read_bvh(tmp_path / "latin.bvh")
    (tmp_path / "kana.bvh").write_bytes(kana.encode("cp932"))
    with pytest.raises(MotionFormatError, match="it reads as Shift-JIS .*'JOINT アタマ'"):
        read_bvh(tmp_path / "kana.bvh")
