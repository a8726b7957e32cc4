"""The pose math of :mod:`animsynth.kinematics`, each written once: heading, Euler angles and DOF values,
quaternions, springs, and the tree forward kinematics the skinning rig shares."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from animsynth import skinning
from animsynth.kinematics import (continuous_euler, continuous_sign, dof_values_from_local, forward_kinematics,
                                  from_rot6d, ground_heading, heading, hip_forward, joint_euler, joint_starts,
                                  local_rotations, matrix_to_xyz_euler, nearest_euler, other_euler_branch, qexp, qinv,
                                  qlog, qmul, rest_forward, root_rotation, root_translation, rot6d, set_root,
                                  rotation_heading, tree_forward, tree_local, wrap_degrees, xyz_euler_rotation,
                                  xyz_euler_to_matrix, yaw_rotation)
from animsynth.springs import decay_spring, halflife_to_damping, spring_angle
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion


@pytest.fixture(scope="module")
def walk():
    return generate_motion("walk_turn", 60, 2, cmu_like_skeleton("pose", 1))


def _same_rotation(a: Rotation, b: Rotation, atol: float = 1e-9) -> bool:
    return bool(np.allclose((a * b.inv()).magnitude(), 0.0, atol=atol))


# ----------------------------------------------------------------------------- heading


def test_yaw_rotation_turns_plus_z_to_sin_cos():
    a = np.array([-2.5, 0.0, 0.3, 3.0])
    f = yaw_rotation(a).apply([0.0, 0.0, 1.0])
    assert np.allclose(f, np.c_[np.sin(a), np.zeros(4), np.cos(a)])
    assert len(yaw_rotation(0.7)) == 1  # a scalar gives one rotation


def test_rotation_heading_of_a_known_rotation_and_of_a_given_forward():
    a = np.array([-3.0, -1.0, 0.0, 0.5, 3.1])
    assert np.allclose(rotation_heading(yaw_rotation(a)), a)
    # the heading of +x turned by a yaw a is a + 90 degrees
    assert np.allclose(wrap_degrees(np.rad2deg(rotation_heading(yaw_rotation(a), np.array([1.0, 0.0, 0.0]))
                                               - a - np.pi / 2) + 1e-9), 1e-9, atol=1e-7)


def test_rotation_heading_holds_the_frame_before_where_the_forward_turns_vertical():
    R = Rotation.from_euler("YX", [[0.4, 0.0], [0.9, -np.pi / 2], [1.2, 0.0]])  # frame 1: +z turned straight up
    held = rotation_heading(R, np.array([0.0, 0.0, 1.0]), hold_vertical=True)
    assert held[0] == pytest.approx(0.4) and held[1] == held[0] and held[2] == pytest.approx(1.2)
    free = rotation_heading(R)
    assert free[0] == held[0] and free[2] == held[2]
    first = rotation_heading(R[1:], np.array([0.0, 0.0, 1.0]), hold_vertical=True)
    assert first[0] == 0.0  # no frame before: 0


def test_rest_forward_is_the_unit_floor_projection_of_the_zero_pose_hips(walk):
    sk = walk.skeleton
    f = rest_forward(sk)
    assert f.shape == (3,) and f[1] == 0.0 and np.linalg.norm(f) == pytest.approx(1.0)
    zero = np.zeros((1, sk.n_dof))
    h = hip_forward(sk, zero)[0]
    assert np.allclose(f, np.array([h[0], 0.0, h[2]]) / np.hypot(h[0], h[2]))
    # a pure yaw of the root turns the hips' facing and the rest forward's heading alike
    v = set_root(sk, np.zeros((5, sk.n_dof)), yaw_rotation(np.linspace(-2.0, 2.0, 5)), np.zeros((5, 3)))
    assert np.allclose(rotation_heading(root_rotation(sk, v), f), heading(sk, v), atol=1e-9)


# ----------------------------------------------------------------------------- Euler angles


def _euler_path(n: int = 200) -> np.ndarray:
    """An extrinsic-xyz path whose middle angle crosses 90 degrees and whose outer angles wrap past 180."""
    t = np.linspace(0.0, 1.0, n)
    return np.c_[-150.0 + 400.0 * t, 40.0 + 80.0 * np.sin(np.pi * t), 170.0 + 60.0 * t]


def test_other_euler_branch_is_the_same_rotation():
    ang = np.array([[10.0, 20.0, 30.0], [-170.0, 85.0, 120.0]])
    alt = other_euler_branch(ang)
    assert np.allclose(alt, [[190.0, 160.0, 210.0], [10.0, 95.0, 300.0]])
    assert _same_rotation(Rotation.from_euler("xyz", alt, degrees=True), Rotation.from_euler("xyz", ang, degrees=True))


def test_continuous_euler_round_trip_across_the_gimbal_branch_and_wraps():
    path = _euler_path()
    R = Rotation.from_euler("xyz", path, degrees=True)
    raw = R.as_euler("xyz", degrees=True)
    assert np.abs(np.diff(raw, axis=0)).max() > 90.0  # scipy's branch jumps where the middle angle crosses 90
    out = continuous_euler(raw)
    assert np.abs(wrap_degrees(np.diff(out, axis=0))).max() < 10.0  # continuous up to the wrap
    assert out.min() >= -180.0 and out.max() < 180.0
    assert _same_rotation(Rotation.from_euler("xyz", out, degrees=True), R)
    # anchored to the frame before the first: the branch and the turns carry on, the path comes back unwrapped
    back = continuous_euler(raw[1:], path[0])
    assert np.allclose(back, path[1:], atol=1e-8)


def test_anchored_continuous_euler_is_nearest_euler_frame_after_frame():
    raw = Rotation.from_euler("xyz", _euler_path(60), degrees=True).as_euler("xyz", degrees=True)
    anchor = np.array([-150.0, 40.0, 170.0])
    seq = continuous_euler(raw, anchor)
    prev = anchor[None, :]
    for t in range(len(raw)):
        prev = nearest_euler(raw[t:t + 1], prev)
        assert np.array_equal(prev[0], seq[t])


def test_dof_values_from_local_round_trip_with_an_anchor_keeps_unwrapped_angles(walk):
    sk = walk.skeleton
    v = np.array(walk.values, float, copy=True)
    # the first angle of every three-DOF joint and the angle of every one-DOF joint turns past 180 degrees (a
    # two-DOF joint past 90 in its middle angle has no Euler pair on its own axes)
    sl, cols = sk.dof_slices(), []
    for j in sk.joints[1:]:
        rot = [sl[j.name].start + k for k, d in enumerate(j.dofs) if d in ("rx", "ry", "rz")]
        if len(rot) in (1, 3):
            cols.append(rot[0])
    v[:, cols] += np.linspace(0.0, 300.0, len(v))[:, None]
    L = local_rotations(sk, v)
    out = dof_values_from_local(sk, [r[1:] for r in L], root_translation(sk, v[1:]), anchor=v[0])
    assert np.allclose(out, v[1:], atol=1e-6)
    plain = dof_values_from_local(sk, L, root_translation(sk, v))  # without: every angle on scipy's range
    assert np.allclose(forward_kinematics(sk, plain), forward_kinematics(sk, v), atol=1e-9)
    assert np.abs(plain[:, cols]).max() <= 180.0 < np.abs(v[:, cols]).max()


def test_joint_euler_drops_the_axes_a_joint_lacks(walk):
    sk = walk.skeleton
    j = next(j for j in sk.joints if sum(d in ("rx", "ry", "rz") for d in j.dofs) == 1)
    axis = next(d[1] for d in j.dofs if d in ("rx", "ry", "rz"))
    C = j.axis_rotation()
    L = C * Rotation.from_euler(axis, np.array([[10.0], [-35.0]]), degrees=True) * C.inv()
    assert np.allclose(joint_euler(j, L), [[10.0], [-35.0]])


# ----------------------------------------------------------------------------- quaternions


def test_quaternion_helpers_agree_with_scipy():
    rng = np.random.default_rng(3)
    a, b = Rotation.random(20, random_state=rng), Rotation.random(20, random_state=rng)
    ab = Rotation.from_quat(qmul(a.as_quat(), b.as_quat()))
    assert _same_rotation(ab, a * b)
    assert _same_rotation(Rotation.from_quat(qinv(a.as_quat())), a.inv())
    assert np.allclose(np.linalg.norm(qlog(a.as_quat()), axis=-1), a.magnitude())
    assert _same_rotation(Rotation.from_quat(qexp(qlog(a.as_quat()))), a)
    assert np.allclose(qexp(np.zeros((2, 3))), [[0, 0, 0, 1], [0, 0, 0, 1]])
    assert _same_rotation(Rotation.from_quat(from_rot6d(rot6d(a.as_quat()))), a)
    q = a.as_quat()
    q[1::2] *= -1.0
    c = continuous_sign(q)
    assert np.all(np.sum(c[1:] * c[:-1], axis=-1) >= 0) and _same_rotation(Rotation.from_quat(c), a)


# ----------------------------------------------------------------------------- springs


def test_decay_spring_halflife_contract():
    h = 0.2
    y = halflife_to_damping(h) / 2.0
    assert y == 2.0 * np.log(2.0) / h  # the damping the foot locking and the inertialization share
    # from rest: (1 + 2 ln 2) / 4 of the offset after one half-life; with the velocity that cancels the
    # linear term the offset follows the envelope e^(-y t), a half after half a half-life
    x, _ = decay_spring(1.0, 0.0, h, h)
    assert x == pytest.approx((1.0 + 2.0 * np.log(2.0)) / 4.0, abs=1e-12)
    x, v = decay_spring(1.0, -y, h, h / 2.0)
    assert x == pytest.approx(0.5, abs=1e-12) and v == pytest.approx(-y / 2.0, abs=1e-12)
    # exact: two steps of half a half-life land where one step does; arrays decay elementwise
    x1, v1 = decay_spring(np.array([1.0, -2.0]), np.array([0.5, 0.0]), h, h)
    x2, v2 = decay_spring(*decay_spring(np.array([1.0, -2.0]), np.array([0.5, 0.0]), h, h / 2.0), h, h / 2.0)
    assert np.allclose(x1, x2, atol=1e-12) and np.allclose(v1, v2, atol=1e-12)


# ----------------------------------------------------------------------------- forward kinematics


def test_skinning_forward_is_kinematics_forward_kinematics_on_the_rig():
    rig = skinning.default_rig()
    rng = np.random.default_rng(0)
    F = 7
    angles = rng.uniform(-1.5, 1.5, (F, rig.n_joints, 3))
    root_t = rng.normal(size=(F, 3))
    W, S = skinning.forward(rig, root_t, angles)
    sk = rig.to_skeleton()
    pos, Wk = forward_kinematics(sk, rig.motion_values(root_t, angles), ends=False, world_rotations=True)
    assert np.allclose(S, pos, atol=1e-12)
    assert np.allclose(W, np.stack([w.as_matrix() for w in Wk], axis=1), atol=1e-12)
    # rotation matrices or Euler angles: the same transforms
    W2, S2 = skinning.forward(rig, root_t, xyz_euler_to_matrix(angles))
    assert np.array_equal(W, W2) and np.array_equal(S, S2)


def test_tree_forward_on_matrices_and_rotations_and_on_a_chain_only():
    parents = [-1, 0, 1, 0]
    rng = np.random.default_rng(1)
    L = [Rotation.random(4, random_state=rng) for _ in parents]
    T = [rng.normal(size=(4, 3)) for _ in parents]
    W, S = tree_forward(parents, L, T)
    Wm, Sm = tree_forward(parents, [r.as_matrix() for r in L], T)
    for i in range(4):
        assert np.allclose(W[i].as_matrix(), Wm[i], atol=1e-12) and np.allclose(S[i], Sm[i], atol=1e-12)
    assert np.allclose(S[2], T[0] + L[0].apply(T[1]) + (L[0] * L[1]).apply(T[2]))
    Wc, Sc = tree_forward(parents, L, T, [0, 1, 2])
    assert Wc[3] is None and Sc[3] is None and np.array_equal(Sc[2], S[2])


def test_joint_starts_is_forward_kinematics_along_a_chain(walk):
    sk, v = walk.skeleton, walk.values
    idx = [sk.index("ltoes"), sk.index("head")]
    assert np.array_equal(joint_starts(sk, v, idx), forward_kinematics(sk, v, ends=False)[:, idx])


def test_tree_local_inverts_tree_forward_on_the_rig():
    rig = skinning.default_rig()
    angles = np.random.default_rng(2).uniform(-1.0, 1.0, (4, rig.n_joints, 3))
    W, _ = skinning.forward(rig, np.zeros((4, 3)), angles)
    assert np.allclose(tree_local(rig.parents, W), xyz_euler_to_matrix(angles), atol=1e-12)


def test_ground_heading_is_the_angle_from_plus_z_towards_plus_x():
    assert ground_heading(np.array([1.0, 0.0])) == pytest.approx(np.pi / 2)
    v = np.array([[0.0, 1.0], [0.0, -1.0], [-1.0, 0.0], [1.0, 1.0]])
    assert np.allclose(ground_heading(v), [0.0, np.pi, -np.pi / 2, np.pi / 4])
    a = np.linspace(-3.0, 3.0, 7)
    assert np.allclose(ground_heading(yaw_rotation(a).apply([0.0, 0.0, 1.0])[:, [0, 2]]), a)


def test_spring_angle_takes_the_short_way_round_across_pi():
    a = spring_angle(3.0, 0.0, -3.0, 0.27, np.array([0.0, 0.1, 5.0]))
    assert a[0] == 3.0 and 3.0 < a[1] < a[2]  # from 3 up through pi, not down through 0
    assert np.cos(a[2] + 3.0) == pytest.approx(1.0, abs=1e-9)
    assert spring_angle(-3.0, 0.0, 3.0, 0.27, 0.1) < -3.0


def test_xyz_euler_is_the_extrinsic_rz_ry_rx_product_and_inverts():
    a = np.random.default_rng(3).uniform(-1.2, 1.2, (2, 5, 3))
    M = xyz_euler_to_matrix(a)
    assert M.shape == (2, 5, 3, 3)
    rx, ry, rz = (Rotation.from_rotvec(np.outer(a[..., k].ravel(), e)).as_matrix()
                  for k, e in enumerate(np.eye(3)))
    assert np.allclose(M.reshape(-1, 3, 3), rz @ ry @ rx, atol=1e-12)
    assert np.allclose(matrix_to_xyz_euler(M), a, atol=1e-12)
    assert np.array_equal(xyz_euler_rotation(a).as_matrix(), M.reshape(-1, 3, 3))
