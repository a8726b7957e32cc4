"""ASF/AMC parsing, forward kinematics, rotations, BVH round trip, malformed files."""

import numpy as np
import pytest

from animsynth.io import MotionFormatError, read_amc, read_asf, write_amc, write_asf
from animsynth.io.bvh import motion_from_bvh_on, read_bvh, write_bvh
from animsynth.kinematics import bone_lengths, exponential_maps, forward_kinematics, quaternions
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

CMU_62 = 62


def angle_diff(a, b):
    return np.abs((a - b + 180.0) % 360.0 - 180.0)


@pytest.fixture(scope="module")
def synth_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("synth")
    sk = cmu_like_skeleton("s1", 3)
    m = generate_motion("walk_straight", 60, 5, sk)
    write_asf(d / "s1.asf", sk, length_unit=0.45)
    write_amc(d / "s1_01.amc", m)
    return d, sk, m


def test_real_cmu_asf_amc(cmu_dir):
    sk = read_asf(cmu_dir / "35" / "35.asf")
    assert sk.n_dof == CMU_62
    assert sk.columns()[:6] == ["root.tx", "root.ty", "root.tz", "root.rx", "root.ry", "root.rz"]
    assert sk.columns()[6:9] == ["lowerback.rx", "lowerback.ry", "lowerback.rz"]
    assert abs(sk.length_to_m - 2.54 / 100 / 0.45) < 1e-12
    femur = sk["lfemur"]
    assert femur.dofs == ["rx", "ry", "rz"] and femur.limits[0] == (-160.0, 20.0)
    assert np.allclose(femur.axis, [0, 0, 20])
    m = read_amc(cmu_dir / "35" / "35_01.amc", sk)  # CRLF file
    assert m.values.shape == (358, CMU_62)
    assert m.without_root().shape == (358, 56)
    # first frame, root line of the file: 4.40047 17.8934 -21.0986 -0.943965 -8.37963 -7.42612
    assert np.allclose(m.values[0, :6], [4.40047, 17.8934, -21.0986, -0.943965, -8.37963, -7.42612])
    assert m.values[0, sk.columns().index("ltoes.rx")] == pytest.approx(1.09177)


def test_bone_lengths_constant_over_real_trial(cmu_dir):
    sk = read_asf(cmu_dir / "35" / "35.asf")
    m = read_amc(cmu_dir / "35" / "35_01.amc", sk)
    bl = bone_lengths(sk, m.values)
    expected = np.array([np.linalg.norm(j.tail) for j in sk.joints[1:]])
    assert np.allclose(bl, expected[None, :], atol=1e-9)
    pos = forward_kinematics(sk, m.values) * sk.length_to_m
    head = pos[:, sk.index("head"), 1]
    toes = pos[:, [sk.index("ltoes"), sk.index("rtoes")], 1]
    assert 1.4 < head.mean() < 1.9  # a standing adult, metres, Y up
    assert toes.min() > -0.1 and toes.min() < 0.1


def test_fk_toy_two_bones():
    from animsynth.skeleton import Joint, Skeleton

    sk = Skeleton([
        Joint("root", -1, np.zeros(3), np.zeros(3), ["tx", "ty", "tz", "rx", "ry", "rz"]),
        Joint("a", 0, np.zeros(3), np.array([1.0, 0, 0]), ["rz"], direction=np.array([1.0, 0, 0]), length=1.0),
        Joint("b", 1, np.array([1.0, 0, 0]), np.array([1.0, 0, 0]), ["rz"], direction=np.array([1.0, 0, 0]), length=1.0),
    ])
    v = np.array([[0, 0, 0, 0, 0, 0, 90, 0], [1, 2, 3, 0, 0, 0, 0, 90]], float)
    p = forward_kinematics(sk, v)
    assert np.allclose(p[0, 1], [0, 1, 0]) and np.allclose(p[0, 2], [0, 2, 0])
    assert np.allclose(p[1, 1], [2, 2, 3]) and np.allclose(p[1, 2], [2, 3, 3])


def test_quaternions_and_expmaps_agree(synth_files):
    _, sk, m = synth_files
    q = quaternions(sk, m.values)
    e = exponential_maps(sk, m.values)
    assert q.shape == (60, len(sk.joints), 4) and e.shape == (60, len(sk.joints), 3)
    assert np.allclose(np.linalg.norm(q, axis=-1), 1.0)
    from scipy.spatial.transform import Rotation
    r1 = Rotation.from_quat(q.reshape(-1, 4))
    r2 = Rotation.from_rotvec(e.reshape(-1, 3))
    assert np.allclose((r1.inv() * r2).magnitude(), 0.0, atol=1e-9)
    assert np.all(np.sum(q[1:] * q[:-1], axis=-1) >= 0)  # sign-continuous


def test_synthetic_files_roundtrip(synth_files):
    d, sk, m = synth_files
    sk2 = read_asf(d / "s1.asf")
    assert sk2.columns() == sk.columns()
    for a, b in zip(sk.joints, sk2.joints):
        assert np.allclose(a.tail, b.tail, atol=1e-6) and np.allclose(a.axis, b.axis)
    m2 = read_amc(d / "s1_01.amc", sk2)
    assert np.allclose(m2.values, m.values, atol=1e-5)


@pytest.mark.parametrize("source", ["synthetic", "real"])
def test_bvh_round_trip(tmp_path, synth_files, source, request):
    if source == "real":
        cmu = request.getfixturevalue("cmu_dir")
        sk = read_asf(cmu / "16" / "16.asf")
        m = read_amc(cmu / "16" / "16_18.amc", sk)
    else:
        _, sk, m = synth_files
    write_bvh(tmp_path / "x.bvh", m)
    b = read_bvh(tmp_path / "x.bvh")
    assert b.n_frames == m.n_frames and b.fps == pytest.approx(m.fps)
    back = motion_from_bvh_on(b, sk)
    assert np.allclose(back.values[:, :3], m.values[:, :3], atol=1e-5)
    # angles agree modulo 360 (gimbal-free for these motions)
    assert angle_diff(back.values[:, 3:], m.values[:, 3:]).max() < 1e-3
    # and the BVH skeleton puts every joint where the ASF skeleton does
    pa = forward_kinematics(sk, m.values, ends=False)
    pb = forward_kinematics(b.skeleton, b.values, ends=False)
    assert np.abs(pa - pb).max() < 1e-4


GOOD_AMC_HEAD = ":FULLY-SPECIFIED\n:DEGREES\n"


def _amc_frame(sk, k, values=None, skip=None, extra=None, bad=None):
    lines = [str(k)]
    for j in sk.joints:
        if not j.dofs or j.name == skip:
            continue
        vals = ["0.0"] * len(j.dofs)
        if bad and j.name == bad[0]:
            vals[0] = bad[1]
        lines.append(j.name + " " + " ".join(vals))
    if extra:
        lines.append(extra)
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    "case,message",
    [
        ("truncated", "missing bones"),
        ("unknown_bone", "unknown bone 'tail'"),
        ("wrong_count", "has 2 values, skeleton says 3 DOF"),
        ("non_numeric", "non-numeric"),
        ("nan", "non-finite"),
        ("frame_gap", "frame number 3 follows 1"),
        ("empty", "no frames"),
    ],
)
def test_malformed_amc_names_file_and_line(tmp_path, synth_files, case, message):
    _, sk, _ = synth_files
    body = GOOD_AMC_HEAD + _amc_frame(sk, 1)
    if case == "truncated":
        body += "\n".join(_amc_frame(sk, 2).splitlines()[:5]) + "\n"
    elif case == "unknown_bone":
        body += _amc_frame(sk, 2, extra="tail 1 2 3")
    elif case == "wrong_count":
        body += _amc_frame(sk, 2).replace("lowerback 0.0 0.0 0.0", "lowerback 0.0 0.0")
    elif case == "non_numeric":
        body += _amc_frame(sk, 2, bad=("head", "abc"))
    elif case == "nan":
        body += _amc_frame(sk, 2, bad=("head", "nan"))
    elif case == "frame_gap":
        body += _amc_frame(sk, 3)
    elif case == "empty":
        body = GOOD_AMC_HEAD
    p = tmp_path / "bad.amc"
    p.write_text(body)
    with pytest.raises(MotionFormatError) as ei:
        read_amc(p, sk)
    msg = str(ei.value)
    assert message in msg
    assert str(p) in msg
    if case in ("unknown_bone", "wrong_count", "non_numeric", "nan", "frame_gap"):
        # the line number points at the offending line
        line_no = int(msg.split(str(p) + ":")[1].split(":")[0])
        assert message.split()[0] in msg
        assert body.splitlines()[line_no - 1].split()[0] in ("tail", "lowerback", "head", "3")


def test_malformed_asf(tmp_path, synth_files):
    d, _, _ = synth_files
    text = (d / "s1.asf").read_text()
    bad = text.replace("  end\n:hierarchy", "  end\n  begin\n     name broken\n:hierarchy")
    p = tmp_path / "b.asf"
    p.write_text(bad)
    with pytest.raises(MotionFormatError, match=r"b\.asf:\d+: bone block not closed"):
        read_asf(p)
    p.write_text(text.replace("lfemur ltibia", "lfemur lshin"))
    with pytest.raises(MotionFormatError, match=r"b\.asf:\d+: hierarchy names unknown bone 'lshin'"):
        read_asf(p)
    p.write_text(text.replace("length ", "length x", 1))
    with pytest.raises(MotionFormatError, match="non-numeric length"):
        read_asf(p)


def test_malformed_bvh(tmp_path, synth_files):
    _, _, m = synth_files
    write_bvh(tmp_path / "ok.bvh", m)
    lines = (tmp_path / "ok.bvh").read_text().splitlines()
    (tmp_path / "trunc.bvh").write_text("\n".join(lines[:-3]) + "\n")
    with pytest.raises(MotionFormatError, match="truncated"):
        read_bvh(tmp_path / "trunc.bvh")
    lines[-1] = lines[-1] + " 1.0"
    (tmp_path / "cols.bvh").write_text("\n".join(lines) + "\n")
    with pytest.raises(MotionFormatError, match=r"cols\.bvh:\d+: .* values, hierarchy declares"):
        read_bvh(tmp_path / "cols.bvh")


def test_nan_motion_is_rejected_everywhere(tmp_path, synth_files):
    _, sk, m = synth_files
    v = m.values.copy()
    v[7, 10] = np.nan
    with pytest.raises(ValueError, match="frame 7"):
        forward_kinematics(sk, v)
    from animsynth.motion import Motion
    with pytest.raises(ValueError, match="frame 8"):
        write_amc(tmp_path / "x.amc", Motion(v, sk))
    assert not (tmp_path / "x.amc").exists()
