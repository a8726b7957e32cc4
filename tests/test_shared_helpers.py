"""The low-layer helpers every family shares: root write-back, heading, angle wrapping, foot roles, ST-Isomap
parameters."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from animsynth.joints import FOOT_ROLES, resolve_roles
from animsynth.kinematics import (heading, root_rotation, root_translation, rotation_heading, set_root,
                                  wrap_degrees, wrap_radians)
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion


@pytest.fixture(scope="module")
def walk():
    return generate_motion("walk_turn", 60, 2, cmu_like_skeleton("shared", 1))


def test_set_root_writes_back_the_root_it_is_given(walk):
    sk, v = walk.skeleton, walk.values
    R, p = root_rotation(sk, v), root_translation(sk, v)
    turn = Rotation.from_euler("y", np.linspace(0.0, 2.0, len(v))[:, None])
    out = set_root(sk, v, turn * R, p + [1.0, 0.5, -2.0])
    assert np.allclose(root_translation(sk, out), p + [1.0, 0.5, -2.0])
    assert np.allclose((root_rotation(sk, out) * (turn * R).inv()).magnitude(), 0.0, atol=1e-9)
    n_root = len(sk.joints[0].dofs)
    assert np.array_equal(out[:, n_root:], v[:, n_root:])  # the other joints untouched
    assert not np.shares_memory(out, v)


def test_set_root_refuses_a_root_with_two_rotational_dof(walk):
    import copy

    sk = copy.deepcopy(walk.skeleton)
    root = sk.joints[0]
    root.dofs = [d for d in root.dofs if d != "rz"]
    v = np.zeros((3, sk.n_dof))
    with pytest.raises(ValueError, match="three rotational DOF"):
        set_root(sk, v, Rotation.identity(3), np.zeros((3, 3)))


def test_rotation_heading_reads_the_turn_about_up():
    a = np.array([-3.0, -1.0, 0.0, 0.5, 3.1])
    assert np.allclose(rotation_heading(Rotation.from_euler("y", a[:, None])), a)
    # a tilt about x does not change the heading
    tilt = Rotation.from_euler("YX", np.c_[a, np.full(a.size, 0.4)])
    assert np.allclose(rotation_heading(tilt), a)


def test_heading_falls_back_to_the_root_axis_without_hips(walk):
    sk, v = walk.skeleton, walk.values
    no_hips = heading(sk, v, overrides={"left_hip": "no_such_joint"})  # the role does not resolve
    assert np.array_equal(no_hips, rotation_heading(root_rotation(sk, v)))
    assert not np.array_equal(heading(sk, v), no_hips)  # with hips: the body's facing


@pytest.mark.parametrize("wrap, full", [(wrap_degrees, 360.0), (wrap_radians, 2 * np.pi)])
def test_wrapping_lands_in_half_open_range_and_keeps_the_angle(wrap, full):
    a = np.array([-3.2, -1.5, -0.5, 0.0, 0.49, 0.5, 1.7, 7.25]) * full
    w = wrap(a)
    assert np.all(w >= -full / 2) and np.all(w < full / 2)
    k = (w - a) / full
    assert np.allclose(k, np.round(k), atol=1e-12)  # the same angle, whole turns apart
    assert wrap(np.array([full / 2]))[0] == -full / 2


def test_foot_roles_resolve_on_cmu_names():
    sk = cmu_like_skeleton("feet", 0)
    assert FOOT_ROLES == ("left_ankle", "left_toe", "right_ankle", "right_toe")
    assert resolve_roles(sk, FOOT_ROLES) == ["lfoot", "ltoes", "rfoot", "rtoes"]


def test_st_parameters_turn_seconds_into_frames():
    from animsynth.resequencing.settings import st_parameters

    st = {"temporal_window": 2, "c_atn": 10, "c_ctn": 5, "ctn_neighbors": 4, "ctn_min_gap_s": 0.25,
          "ctn_tolerance": 2, "ctn_reach_s": 0.01}
    p = st_parameters(st, 120.0)
    assert p == {"temporal_window": 2, "c_atn": 10.0, "c_ctn": 5.0, "ctn_neighbors": 4, "ctn_min_gap": 30,
                 "ctn_tolerance": 2, "ctn_reach": 1}
    assert st_parameters(st, 4.0)["ctn_min_gap"] == 2  # never below the temporal window
