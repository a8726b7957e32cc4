"""BVH files as they exist elsewhere: the conventions of tests/data/bvh/ (see
make_bvh.py there), read, written back, and checked against a forward
kinematics written here independently of animsynth; and the malformed files
that used to be read silently wrong."""

import math
import re
from pathlib import Path

import numpy as np
import pytest

from animsynth.cli import main
from animsynth.io import MotionFormatError, read_amc, read_asf
from animsynth.io.bvh import read_bvh, write_bvh
from animsynth.kinematics import forward_kinematics

DATA = Path(__file__).resolve().parent / "data" / "bvh"
FILES = sorted(DATA.glob("*.bvh"))
EXPECTED_FPS = {"cmu_converted": 120.0, "hips_xyz": 120.0, "hips_zxy": 30.0, "blender": 24.0, "bandai": 120.0,
                "every6_bip": 120.0, "rest_along_x": 120.0, "z_up": 120.0, "mixed_orders": 120.0}
#: files whose first joint is a dummy root that the reader merges into its child
MERGED_ROOT = {"bandai"}


def test_folder_has_the_conventions():
    assert {f.stem for f in FILES} == set(EXPECTED_FPS)


# --- an independent reader + forward kinematics (4x4 matrices) ---------------

def _elementary(axis: str, deg: float) -> np.ndarray:
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    if axis == "X":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "Y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _parse(path):
    """(joints [(name, parent, offset, channels)], end sites {joint: offset}, data rows)."""
    tokens = Path(path).read_text().split()
    i = tokens.index("HIERARCHY") + 1
    joints, ends, stack = [], {}, []
    while tokens[i] != "MOTION":
        t = tokens[i]
        if t in ("ROOT", "JOINT"):
            joints.append([tokens[i + 1], stack[-1] if stack else -1, None, []])
            stack.append(len(joints) - 1)
            i += 3
        elif t == "OFFSET":
            joints[stack[-1]][2] = np.array(list(map(float, tokens[i + 1:i + 4])))
            i += 4
        elif t == "CHANNELS":
            k = int(tokens[i + 1])
            joints[stack[-1]][3] = tokens[i + 2:i + 2 + k]
            i += 2 + k
        elif t == "End":
            ends[stack[-1]] = np.array(list(map(float, tokens[i + 4:i + 7])))
            i += 8
        elif t == "}":
            stack.pop()
            i += 1
        else:
            raise AssertionError(t)
    n = int(tokens[i + 2])
    ncol = sum(len(j[3]) for j in joints)
    data = np.array(list(map(float, tokens[i + 6:]))).reshape(n, ncol)
    return joints, ends, data


def _independent_fk(path):
    """World joint positions (frames, joints, 3) and leaf end-site positions {joint: (frames, 3)}."""
    joints, ends, data = _parse(path)
    n = data.shape[0]
    pos = np.zeros((n, len(joints), 3))
    endpos = {j: np.zeros((n, 3)) for j in ends}
    for f in range(n):
        col = 0
        G = [None] * len(joints)
        for k, (name, parent, off, chans) in enumerate(joints):
            R = np.eye(3)
            t = off.copy()
            for c in chans:
                v = data[f, col]
                col += 1
                if c.endswith("position"):
                    t["XYZ".index(c[0])] = v  # root positions are absolute
                else:
                    R = R @ _elementary(c[0], v)
            M = np.eye(4)
            M[:3, :3], M[:3, 3] = R, t
            G[k] = M if parent < 0 else G[parent] @ M
            pos[f, k] = G[k][:3, 3]
            if k in ends:
                endpos[k][f] = (G[k] @ np.append(ends[k], 1.0))[:3]
    return [j[0] for j in joints], pos, endpos


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_joint_positions_match_an_independent_forward_kinematics(path):
    m = read_bvh(path)
    names, pos, endpos = _independent_fk(path)
    if path.stem in MERGED_ROOT:  # the dummy root is gone, every other joint where it was
        names, pos = names[1:], pos[:, 1:]
        endpos = {k - 1: v for k, v in endpos.items()}
    assert m.skeleton.names == names
    assert m.fps == EXPECTED_FPS[path.stem]
    ours = forward_kinematics(m.skeleton, m.values, ends=False)
    np.testing.assert_allclose(ours, pos, atol=1e-9)
    tips = forward_kinematics(m.skeleton, m.values, ends=True)
    for k, p in endpos.items():
        np.testing.assert_allclose(tips[:, k], p, atol=1e-9)


def _as_written_back(joints, ends, data):
    """What a write-back of the read holds: position channels of a non-root joint that are the same in every
    frame become its OFFSET, the joint keeps its rotation channels; moving ones stay channels (these files
    have no position channel between the two); every other channel is unchanged."""
    joints = [list(j) for j in joints]
    keep, col = [], 0
    for k, j in enumerate(joints):
        off = j[2].copy()
        pcols = [col + i for i, c in enumerate(j[3]) if c.endswith("position")]
        fold = k > 0 and all(np.all(data[:, c] == data[0, c]) for c in pcols)
        for c in j[3]:
            if fold and c.endswith("position"):
                off["XYZ".index(c[0])] = data[0, col]
            else:
                keep.append(col)
            col += 1
        j[2] = off
        if fold:
            j[3] = [c for c in j[3] if not c.endswith("position")]
    return joints, ends, data[:, keep]


def test_blender_file_has_position_channels_on_unconnected_bones():
    joints, _, _ = _parse(DATA / "blender.bvh")
    six = {j[0] for j in joints[1:] if len(j[3]) == 6}
    assert six == {"thigh.L", "thigh.R", "shoulder.L", "shoulder.R", "upper_arm.L", "upper_arm.R"}
    assert "\tOFFSET" in (DATA / "blender.bvh").read_text()


@pytest.mark.parametrize("path", [f for f in FILES if f.stem not in MERGED_ROOT], ids=lambda p: p.stem)
def test_read_write_read_reproduces_every_channel(path, tmp_path):
    m = read_bvh(path)
    out = tmp_path / path.name
    write_bvh(out, m)
    j0, e0, d0 = _as_written_back(*_parse(path))
    j1, e1, d1 = _parse(out)
    assert [(a[0], a[1], a[3]) for a in j0] == [(a[0], a[1], a[3]) for a in j1]  # names, tree, channel orders
    for a, b in zip(j0, j1):
        np.testing.assert_array_equal(a[2], b[2])
    assert e0.keys() == e1.keys() and all(np.array_equal(e0[k], e1[k]) for k in e0)
    np.testing.assert_allclose(d1, d0, atol=0.5e-6, rtol=0)  # printed with 6 decimals
    back = read_bvh(out)
    assert back.fps == m.fps
    np.testing.assert_allclose(forward_kinematics(back.skeleton, back.values),
                               forward_kinematics(m.skeleton, m.values), atol=1e-5)


# --- the defects ------------------------------------------------------------

@pytest.fixture(params=["Hips", "root"])
def base_text(request):
    """hips_xyz.bvh, with its root renamed ``root`` too (so the defects show
    on a reader that only knew roots called ``root``)."""
    return (DATA / "hips_xyz.bvh").read_text().replace("ROOT Hips", f"ROOT {request.param}")


def _write(tmp_path, text, name="x.bvh"):
    p = tmp_path / name
    p.write_text(text)
    return p


def _line_of(text, needle, nth=0):
    hits = [k for k, ln in enumerate(text.split("\n"), start=1) if needle in ln]
    return hits[nth]


def test_root_not_called_root_is_read(tmp_path):
    m = read_bvh(DATA / "hips_xyz.bvh")
    assert m.skeleton.joints[0].name == "Hips" and m.n_frames == 24
    assert m.skeleton.joints[0].dofs == ["tx", "ty", "tz", "rz", "ry", "rx"]


def test_repeated_rotation_axis_is_refused(tmp_path, base_text):
    text = base_text.replace("CHANNELS 3 Xrotation Yrotation Zrotation", "CHANNELS 3 Xrotation Xrotation Xrotation", 1)
    p = _write(tmp_path, text)
    with pytest.raises(MotionFormatError, match="repeat an axis") as ei:
        read_bvh(p)
    assert ei.value.line == _line_of(text, "Xrotation Xrotation Xrotation")


def test_duplicate_joint_names_are_refused(tmp_path, base_text):
    text = base_text.replace("JOINT RightUpLeg", "JOINT LeftUpLeg")
    p = _write(tmp_path, text)
    with pytest.raises(MotionFormatError, match="duplicate joint name 'LeftUpLeg'") as ei:
        read_bvh(p)
    assert ei.value.line == _line_of(text, "JOINT LeftUpLeg", 1)


@pytest.mark.parametrize("extra,msg", [("ROOT Other\n{\n  OFFSET 0 0 0\n  CHANNELS 0\n}\n", "second ROOT"),
                                       ("}\n", "'}' after the root")])
def test_content_after_the_root_is_refused(tmp_path, extra, msg, base_text):
    text = base_text.replace("MOTION\n", extra + "MOTION\n")
    p = _write(tmp_path, text)
    with pytest.raises(MotionFormatError, match=msg) as ei:
        read_bvh(p)
    assert ei.value.line == _line_of(text, "MOTION") - extra.count("\n")


@pytest.mark.parametrize("ft", ["1e-320", "1e300", "1e-7", "3600"])
def test_frame_time_out_of_bounds_is_refused(tmp_path, ft, base_text):
    text = re.sub(r"Frame Time: .*", f"Frame Time: {ft}", base_text)
    p = _write(tmp_path, text)
    with pytest.raises(MotionFormatError, match="frame time .* is outside") as ei:
        read_bvh(p)
    assert ei.value.line == _line_of(text, "Frame Time:")


def _perturb_column(text, col, fn):
    """``text`` with frame-row column ``col`` replaced by ``fn(frame, value)``."""
    head, body = text.split("Frame Time:")
    first, *rows = body.split("\n")
    out = []
    for f, row in enumerate(rows):
        parts = row.split()
        if parts:
            parts[col] = f"{fn(f, float(parts[col])):.6f}"
        out.append(" ".join(parts))
    return head + "Frame Time:" + "\n".join([first] + out)


def _column_of(path, joint, channel):
    joints, _, _ = _parse(path)
    col = 0
    for j in joints:
        if j[0] == joint:
            return col + j[3].index(channel)
        col += len(j[3])
    raise AssertionError(joint)


def test_constant_child_positions_are_read_as_offsets(caplog):
    with caplog.at_level("INFO", logger="animsynth.io"):
        m = read_bvh(DATA / "blender.bvh")
    thigh = m.skeleton.joints[m.skeleton.index("thigh.L")]
    assert thigh.dofs == ["rz", "rx", "ry"]  # rotations only; the positions became the offset
    np.testing.assert_array_equal(thigh.offset, [9.0, -6.0, 0.0])
    msgs = [r.getMessage() for r in caplog.records if "non-root" in r.getMessage()]
    assert len(msgs) == 1 and "thigh.L" in msgs[0] and "upper_arm.R" in msgs[0]


def test_child_positions_within_the_tolerance_are_read(tmp_path):
    text = (DATA / "blender.bvh").read_text()
    col = _column_of(DATA / "blender.bvh", "thigh.L", "Yposition")
    p = _write(tmp_path, _perturb_column(text, col, lambda f, v: v + 1e-6 * (f % 3 - 1)))  # float32-like noise
    names, pos, _ = _independent_fk(p)
    m = read_bvh(p)
    np.testing.assert_allclose(forward_kinematics(m.skeleton, m.values, ends=False), pos, atol=1e-5)


def test_varying_child_positions_are_read_as_translation(tmp_path, caplog):
    text = (DATA / "blender.bvh").read_text()
    col = _column_of(DATA / "blender.bvh", "upper_arm.R", "Xposition")
    p = _write(tmp_path, _perturb_column(text, col, lambda f, v: v + 0.5 * f))  # a stretching arm
    with caplog.at_level("INFO", logger="animsynth.io"):
        m = read_bvh(p)
    assert m.skeleton["upper_arm.R"].dofs[:3] == ["tx", "ty", "tz"]
    assert any("upper_arm.R (5.75)" in r.getMessage() and "translation DOF" in r.getMessage()
               for r in caplog.records)
    names, pos, endpos = _independent_fk(p)
    np.testing.assert_allclose(forward_kinematics(m.skeleton, m.values, ends=False), pos, atol=1e-9)
    write_bvh(tmp_path / "o.bvh", m)
    back = read_bvh(tmp_path / "o.bvh")
    np.testing.assert_allclose(forward_kinematics(back.skeleton, back.values, ends=False), pos, atol=1e-5)


def _under_dummy_root(text, offset="1.5 -2.0 3.0"):
    """``text``'s skeleton as the single child of a ``ROOT __0`` without channels."""
    head, motion = text.split("MOTION\n")
    body = head.split("HIERARCHY\n", 1)[1].replace("ROOT ", "JOINT ", 1)
    body = "".join("\t" + ln + "\n" for ln in body.splitlines())
    return f"HIERARCHY\nROOT __0\n{{\n\tOFFSET {offset}\n\tCHANNELS 0\n{body}}}\nMOTION\n{motion}"


def test_a_dummy_root_with_one_child_is_collapsed(tmp_path, caplog):
    p = _write(tmp_path, _under_dummy_root((DATA / "blender.bvh").read_text()))
    with caplog.at_level("INFO", logger="animsynth.io"):
        m = read_bvh(p)
    names, pos, endpos = _independent_fk(p)
    assert names[0] == "__0" and m.skeleton.names == names[1:]
    np.testing.assert_allclose(m.skeleton.joints[0].offset, [1.5, -2.0, 3.0])
    np.testing.assert_allclose(forward_kinematics(m.skeleton, m.values, ends=False), pos[:, 1:], atol=1e-9)
    assert any("'__0'" in r.getMessage() and "'hips' is the root" in r.getMessage() for r in caplog.records)
    write_bvh(tmp_path / "o.bvh", m)
    back = read_bvh(tmp_path / "o.bvh")
    assert back.skeleton.names == names[1:]
    np.testing.assert_allclose(forward_kinematics(back.skeleton, back.values, ends=False), pos[:, 1:], atol=1e-5)


def test_a_dummy_root_with_several_children_is_refused():
    p = DATA / "multiroot" / "blender_two_roots.bvh"
    with pytest.raises(MotionFormatError, match=r"root joint '__0' has no channels and 2 children \('hips', 'prop'\)"
                       ) as ei:
        read_bvh(p)
    assert "blender_two_roots.bvh" in str(ei.value) and ei.value.line == 2


@pytest.mark.parametrize("fps", [120.0, 30.0, 24.0, 60.0, 29.97, 100.0])
def test_frame_rate_survives_a_write(tmp_path, fps, base_text):
    m = read_bvh(_write(tmp_path, base_text, "in.bvh"))
    m.fps = fps
    write_bvh(tmp_path / "o.bvh", m)
    assert read_bvh(tmp_path / "o.bvh").fps == fps


@pytest.fixture(scope="module")
def asf_amc(tmp_path_factory):
    from conftest import write_small_trial

    return write_small_trial(tmp_path_factory.mktemp("amc2bvh"), 30)


def test_amc2bvh_120_fps_reads_back_as_120(asf_amc, tmp_path):
    assert main(["amc2bvh", str(asf_amc / "c.asf"), str(asf_amc / "c.amc"), str(tmp_path / "o.bvh")]) == 0
    assert read_bvh(tmp_path / "o.bvh").fps == 120.0


def test_amc2bvh_refuses_an_unreadable_frame_rate(asf_amc, tmp_path, capsys):
    out = tmp_path / "o.bvh"
    assert main(["amc2bvh", str(asf_amc / "c.asf"), str(asf_amc / "c.amc"), str(out), "--fps", "1e308"]) == 2
    err = capsys.readouterr().err
    assert "--fps" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_amc2bvh_refuses_a_tiny_asf_length_unit(asf_amc, tmp_path, capsys):
    text = (asf_amc / "c.asf").read_text()
    text = re.sub(r"(?m)^(\s*length\s+)\S+", r"\g<1>1e-320", text, count=1)
    (tmp_path / "t.asf").write_text(text)
    out = tmp_path / "o.bvh"
    assert main(["amc2bvh", str(tmp_path / "t.asf"), str(asf_amc / "c.amc"), str(out), "--metres"]) == 2
    err = capsys.readouterr().err
    assert "t.asf" in err and "length" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_asf_in_radians_with_an_amc_without_unit_flag(asf_amc, tmp_path, caplog):
    sk = read_asf(asf_amc / "c.asf")
    deg = read_amc(asf_amc / "c.amc", sk)
    text = (asf_amc / "c.asf").read_text()
    text = re.sub(r"(?m)^(\s*angle\s+)deg", r"\g<1>rad", text)
    # axis angles are written in degrees: convert them so the skeleton is the same
    def to_rad(mt):
        return mt.group(1) + " ".join(f"{math.radians(float(v)):.12f}" for v in mt.group(2).split()) + mt.group(3)
    text = re.sub(r"(?m)^(\s*axis\s+)([-\d.eE+ ]+?)(\s+[XYZ]{3}\s*)$", to_rad, text)
    text = re.sub(r"(?m)^(\s*orientation\s+)([-\d.eE+ ]+?)(\s*)$", to_rad, text)
    (tmp_path / "r.asf").write_text(text)
    amc = "\n".join(ln for ln in (asf_amc / "c.amc").read_text().split("\n") if ln.strip().upper() != ":DEGREES")
    vals = deg.values.copy()
    rot = [k for k, c in enumerate(sk.columns()) if c.split(".")[1].startswith("r")]
    vals[:, rot] = np.radians(vals[:, rot])
    lines = []
    body = iter(vals)
    for ln in amc.split("\n"):
        tok = ln.split()
        if len(tok) == 1 and tok[0].isdigit():
            row = next(body)
            lines.append(ln)
            continue
        if tok and tok[0] in sk.names:
            s = sk.dof_slices()[tok[0]]
            lines.append(tok[0] + " " + " ".join(f"{v:.12f}" for v in row[s]))
        else:
            lines.append(ln)
    (tmp_path / "r.amc").write_text("\n".join(lines))
    rsk = read_asf(tmp_path / "r.asf")
    with caplog.at_level("INFO", logger="animsynth.io"):
        got = read_amc(tmp_path / "r.amc", rsk)
    np.testing.assert_allclose(got.values, deg.values, atol=1e-6)
    assert any("radians" in r.getMessage() for r in caplog.records)
