"""BVH files laid out as cgspeed's CMU conversions are, written here (no shared data): the MotionBuilder-friendly
release (ROOT Hips, zero-offset LHipJoint, LeftUpLeg ... LeftToeBase, LeftShoulder as the clavicle, a T-pose frame
0, lengths in the ASF unit, most lines CRLF and a few LF) and the 3ds Max-friendly one (LeftHip, LeftKnee,
LeftAnkle, LeftToe, LeftCollar as the clavicle and LeftShoulder as the upper arm)."""

import logging

import numpy as np
import pytest

from animsynth.data import load_trial
from animsynth.errors import MotionFormatError
from animsynth.io.bvh import read_bvh
from animsynth.joints import ROLES, JointRoleError, resolve_role, resolve_roles

#: (name, parent, offset in CMU ASF units) of a cgspeed MotionBuilder-friendly skeleton (left side; the right
#: side mirrors it), and an End Site on the leaves
LEFT = [("LHipJoint", "Hips", (0, 0, 0)), ("LeftUpLeg", "LHipJoint", (1.2, -1.8, 0.7)),
        ("LeftLeg", "LeftUpLeg", (2.5, -6.9, 0)), ("LeftFoot", "LeftLeg", (2.9, -7.9, 0)),
        ("LeftToeBase", "LeftFoot", (0.2, -0.6, 2.1))]
SPINE = [("LowerBack", "Hips", (0, 0, 0)), ("Spine", "LowerBack", (0, 2.0, 0)), ("Spine1", "Spine", (0, 2.0, 0)),
         ("Neck", "Spine1", (0, 2.0, 0)), ("Neck1", "Neck", (0, 1.5, 0)), ("Head", "Neck1", (0, 1.5, 0))]
ARM = [("LeftShoulder", "Spine1", (0.5, 2.0, 0)), ("LeftArm", "LeftShoulder", (3.0, 0, 0)),
       ("LeftForeArm", "LeftArm", (5.0, 0, 0)), ("LeftHand", "LeftForeArm", (4.5, 0, 0))]
ENDS = {"LeftToeBase": (0, 0, 1.1), "Head": (0, 1.8, 0), "LeftHand": (1.0, 0, 0)}
#: the 3ds Max-friendly release's names for the same joints
MAX_NAMES = {"LeftUpLeg": "LeftHip", "LeftLeg": "LeftKnee", "LeftFoot": "LeftAnkle", "LeftToeBase": "LeftToe",
             "LowerBack": "lowerback", "Spine": "Chest", "Spine1": "Chest2", "Neck": "lowerneck", "Neck1": "Neck",
             "LeftShoulder": "LeftCollar", "LeftArm": "LeftShoulder", "LeftForeArm": "LeftElbow",
             "LeftHand": "LeftWrist"}
#: the metres of the ASF unit (length 0.45: 1/0.45 inch)
CMU_UNIT_M = 0.0564444


def _mirror(name: str) -> str:
    return name.replace("Left", "Right").replace("LHip", "RHip")


def _joints(names: dict) -> list:
    """[(name, parent, offset, end)] in file order: legs, spine, arms; ``names`` renames (3ds Max)."""
    ends = {names.get(n, n): e for n, e in ENDS.items()}

    def side(rows):
        left = [(names.get(n, n), names.get(p, p), o) for n, p, o in rows]
        return left + [(_mirror(n), _mirror(p), (-o[0], o[1], o[2])) for n, p, o in left]

    rows = [("Hips", None, (0, 0, 0))] + side(LEFT) + [(names.get(n, n), names.get(p, p), o) for n, p, o in SPINE]
    out = []
    for n, p, o in rows + side(ARM):
        e = ends.get(n.replace("Right", "Left"))
        out.append((n, p, o, None if e is None else ((-e[0] if n.startswith("Right") else e[0]), e[1], e[2])))
    return out


def _frames(joints, n: int, upper_arm: str = "LeftArm") -> np.ndarray:
    """Frame 0 a T-pose (zero rotations, the root at hip height); then the arms hang (the upper arms turned 80
    degrees about z), the root walks forward 1.2 m/s along z."""
    data = np.zeros((n, 6 + 3 * (len(joints) - 1)))
    data[:, 1] = 17.5
    data[1:, 2] = np.arange(1, n) * (1.2 / 120 / CMU_UNIT_M)
    for k, (name, *_rest) in enumerate(joints[1:]):
        if name in (upper_arm, _mirror(upper_arm)):
            data[1:, 6 + 3 * k] = -80.0 if name.startswith("Left") else 80.0  # Zrotation, the first channel
    return data


def _bvh_text(joints, data, lf_lines=()) -> str:
    """A BVH file whose lines end in CRLF except the 1-based lines ``lf_lines`` (LF), as cgspeed's files are."""
    kids: dict = {}
    for n, p, *_ in joints:
        kids.setdefault(p, []).append(n)
    info = {n: (o, e) for n, _, o, e in joints}
    lines = ["HIERARCHY"]

    def emit(name, depth):
        ind = "\t" * depth
        o, e = info[name]
        lines.append(f"{ind}{'ROOT' if depth == 0 else 'JOINT'} {name}")
        lines.append(f"{ind}{{")
        lines.append(f"{ind}\tOFFSET {o[0]:.5f} {o[1]:.5f} {o[2]:.5f}")
        chans = "6 Xposition Yposition Zposition Zrotation Yrotation Xrotation " if depth == 0 else \
            "3 Zrotation Yrotation Xrotation"
        lines.append(f"{ind}\tCHANNELS {chans}")
        for k in kids.get(name, []):
            emit(k, depth + 1)
        if e is not None:
            lines.extend([f"{ind}\tEnd Site", f"{ind}\t{{", f"{ind}\t\tOFFSET {e[0]:.5f} {e[1]:.5f} {e[2]:.5f}",
                          f"{ind}\t}}"])
        lines.append(f"{ind}}}")

    emit(joints[0][0], 0)
    lines += ["MOTION", f"Frames: {len(data)}", "Frame Time: .0083333"]
    lines += [" ".join(f"{x:.4f}" for x in row) for row in data]
    return "".join(line + ("\n" if i in lf_lines else "\r\n") for i, line in enumerate(lines, 1))


@pytest.fixture(scope="module")
def mb_joints():
    return _joints({})


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_bytes(text.encode())
    return p


def test_mixed_crlf_and_lf_lines_read_as_lf_lines(tmp_path, mb_joints):
    """Most lines CRLF, a few LF (the ROOT line, the frame count, some frames): the same skeleton and values as
    the all-LF file, 120 fps, and an error still names the right line."""
    data = _frames(mb_joints, 30)
    n_head = _bvh_text(mb_joints, data).count("\r\n") - len(data)
    mixed = _bvh_text(mb_joints, data, lf_lines={2, n_head - 1, n_head + 3, n_head + 7})
    lf = mixed.replace("\r\n", "\n")
    assert "\r\n" in mixed and mixed.count("\r\n") < mixed.count("\n")
    a, b = read_bvh(_write(tmp_path, "mixed.bvh", mixed)), read_bvh(_write(tmp_path, "lf.bvh", lf))
    assert a.skeleton.names == b.skeleton.names and np.array_equal(a.values, b.values)
    assert a.fps == 120.0 and a.n_frames == 30
    assert all(np.array_equal(x.offset, y.offset) for x, y in zip(a.skeleton.joints, b.skeleton.joints))
    lines = mixed.split("\n")
    bad_line = n_head + 5  # 1-based: a frame row
    lines[bad_line - 1] = lines[bad_line - 1].replace("17.5000", "x17", 1)
    with pytest.raises(MotionFormatError, match=rf"bad.bvh:{bad_line}: non-numeric"):
        read_bvh(_write(tmp_path, "bad.bvh", "\n".join(lines)))


def test_a_motionbuilder_file_in_the_asf_unit_loads_without_a_warning(tmp_path, mb_joints, caplog):
    """first_frame 1 drops the T-pose frame; with the ASF unit the figure stands a human height on the floor,
    every role resolves by name and nothing is warned."""
    path = _write(tmp_path, "26_01.bvh", _bvh_text(mb_joints, _frames(mb_joints, 40), lf_lines={2}))
    with caplog.at_level(logging.WARNING):
        m = load_trial(bvh=path, bvh_length_to_m=CMU_UNIT_M, first_frame=1)
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING] == []
    assert m.n_frames == 39
    assert resolve_roles(m.skeleton, ["left_shoulder", "left_hip", "left_toe", "spine", "chest"]) == \
        ["LeftArm", "LeftUpLeg", "LeftToeBase", "LowerBack", "Spine1"]
    from animsynth.axes import standing_height

    assert 1.4 < standing_height(m.skeleton, m.values, "+y") * CMU_UNIT_M < 1.7


def test_3ds_max_names_resolve_with_the_shoulders_named(tmp_path, caplog):
    """LeftHip, LeftKnee, LeftAnkle, LeftToe, LeftElbow, LeftWrist resolve by name; LeftShoulder (the upper arm
    here) needs joint_roles, and with it the file loads without a warning."""
    joints = _joints(MAX_NAMES)
    path = _write(tmp_path, "131_01.bvh", _bvh_text(joints, _frames(joints, 20, "LeftShoulder")[1:]))
    m = read_bvh(path)
    assert resolve_roles(m.skeleton, ["left_hip", "left_knee", "left_ankle", "left_toe", "left_elbow", "left_wrist",
                                      "right_toe", "neck", "chest"]) == \
        ["LeftHip", "LeftKnee", "LeftAnkle", "LeftToe", "LeftElbow", "LeftWrist", "RightToe", "lowerneck", "Chest"]
    with pytest.raises(JointRoleError, match="joint_roles.left_shoulder"):
        resolve_role(m.skeleton, "left_shoulder")
    roles = {"left_shoulder": "LeftShoulder", "right_shoulder": "RightShoulder"}
    with caplog.at_level(logging.WARNING):
        m = load_trial(bvh=path, bvh_length_to_m=CMU_UNIT_M, joint_roles=roles)
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING] == []
    assert {r: resolve_role(m.skeleton, r) for r in ROLES}["left_shoulder"] == "LeftShoulder"


def test_a_daz_shoulder_name_is_the_shoulder_role():
    """cgspeed's ROOT hip release (subjects 06 and 10) names the upper arm lShldr / rShldr, the clavicle lCollar."""
    names = ["hip", "abdomen", "chest", "neck", "head", "lCollar", "lShldr", "lForeArm", "lHand", "rCollar",
             "rShldr", "rForeArm", "rHand", "lThigh", "lShin", "lFoot", "rThigh", "rShin", "rFoot"]
    assert resolve_roles(names, ["left_shoulder", "right_shoulder", "left_elbow", "left_wrist"]) == \
        ["lShldr", "rShldr", "lForeArm", "lHand"]
