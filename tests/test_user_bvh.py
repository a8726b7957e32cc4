"""The library on a BVH skeleton that is not CMU's: ``ROOT Hips``, Mixamo-style names, no hip joints, fingers or
thumbs, ``Zrotation Xrotation Yrotation`` everywhere, centimetres; body parts found by joint role
(animsynth.joints). The workflow's own-data route on Hips-named skeletons (simplicial, re-sequencing and compare,
each class of BVH file found in the wild) is tests/test_user_bvh_classes.py."""

from __future__ import annotations

import numpy as np
import pytest

from animsynth.io.bvh import read_bvh, write_bvh
from animsynth.joints import JointRoleError, resolve_role
from animsynth.kinematics import forward_kinematics, local_rotations, root_translation
from animsynth.motion import Motion
from animsynth.resequencing.distances import PAPER_WEIGHTS, joint_weights
from animsynth.resequencing.features import motion_features
from animsynth.resequencing.metrics import foot_ground
from animsynth.skeleton import Joint, Skeleton
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

NAMES = {"root": "Hips", "lowerback": "Spine", "upperback": "Spine1", "thorax": "Spine2", "lowerneck": "Neck",
         "upperneck": "Neck1", "head": "Head", "lclavicle": "LeftShoulder", "lhumerus": "LeftArm",
         "lradius": "LeftForeArm", "lwrist": "LeftHand", "rclavicle": "RightShoulder", "rhumerus": "RightArm",
         "rradius": "RightForeArm", "rwrist": "RightHand", "lfemur": "LeftUpLeg", "ltibia": "LeftLeg",
         "lfoot": "LeftFoot", "ltoes": "LeftToeBase", "rfemur": "RightUpLeg", "rtibia": "RightLeg",
         "rfoot": "RightFoot", "rtoes": "RightToeBase"}
DROPPED_NO_DOF = ("lhipjoint", "rhipjoint")  # merged into the thigh's offset


def to_hips_bvh(motion: Motion, path, prefix: str = "") -> None:
    """Write ``motion`` (CMU-like skeleton) as a Hips-rooted BVH in cm, channels Z X Y."""
    sk = motion.skeleton
    L = local_rotations(sk, motion.values)
    keep = [i for i, j in enumerate(sk.joints) if j.name in NAMES]
    new_index, joints, cols = {}, [], []
    for i in keep:
        j = sk.joints[i]
        p, off = j.parent, np.asarray(j.offset, float)
        while p >= 0 and sk.joints[p].name in DROPPED_NO_DOF:
            off = off + np.asarray(sk.joints[p].offset, float)
            p = sk.joints[p].parent
        dofs = (["tx", "ty", "tz"] if p < 0 else []) + ["ry", "rx", "rz"]  # extrinsic y x z = channels Z X Y
        kids = [k for k in keep if sk.joints[k].parent == i]
        tail = np.asarray(j.tail, float) if not kids or p < 0 else np.asarray(sk.joints[kids[0]].offset, float)
        joints.append(Joint(prefix + NAMES[j.name], -1 if p < 0 else new_index[p], off if p >= 0 else np.zeros(3),
                            tail, dofs))
        new_index[i] = len(joints) - 1
        block = L[i].as_euler("yxz", degrees=True)
        if p < 0:
            block = np.hstack([root_translation(sk, motion.values), block])
        cols.append(block)
    new = Skeleton(joints, length_to_m=sk.length_to_m, name="hips")
    write_bvh(path, Motion(np.hstack(cols), new, motion.fps, motion.name), scale=sk.length_to_m * 100.0)


def test_conversion_keeps_the_pose(tmp_path):
    sk = cmu_like_skeleton("s", 1)
    m = generate_motion("walk_straight", 30, 0, sk)
    to_hips_bvh(m, tmp_path / "w.bvh")
    b = read_bvh(tmp_path / "w.bvh")
    assert b.skeleton.joints[0].name == "Hips" and "lhipjoint" not in b.skeleton.names
    assert b.skeleton["LeftLeg"].dofs == ["ry", "rx", "rz"]
    ours = forward_kinematics(b.skeleton, b.values) / 100.0
    ref = forward_kinematics(sk, m.values) * sk.length_to_m
    for cmu, name in (("ltoes", "LeftToeBase"), ("rfoot", "RightFoot"), ("head", "Head"), ("lwrist", "LeftHand")):
        np.testing.assert_allclose(ours[:, b.skeleton.index(name)], ref[:, sk.index(cmu)], atol=2e-5)


def test_roles_find_the_body_parts_of_a_hips_skeleton(tmp_path):
    sk = cmu_like_skeleton("s", 1)
    to_hips_bvh(generate_motion("walk_straight", 30, 0, sk), tmp_path / "w.bvh", prefix="mixamorig:")
    b = read_bvh(tmp_path / "w.bvh")
    f = motion_features(b)
    w = joint_weights(f.joint_names, PAPER_WEIGHTS)
    assert {f.joint_names[k] for k in np.flatnonzero(w)} == {
        "mixamorig:" + n for n in ("LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg", "LeftArm", "RightArm",
                                   "LeftForeArm", "RightForeArm")}
    assert w[f.joint_names.index("mixamorig:LeftArm")] == PAPER_WEIGHTS["shoulders"]
    assert np.all(np.isfinite(foot_ground(b)))


def test_unresolvable_role_names_the_role_and_the_joints(tmp_path):
    sk = cmu_like_skeleton("s", 1)
    to_hips_bvh(generate_motion("walk_straight", 30, 0, sk), tmp_path / "w.bvh")
    text = (tmp_path / "w.bvh").read_text().replace("LeftLeg", "Knee_L_custom")
    (tmp_path / "x.bvh").write_text(text)
    b = read_bvh(tmp_path / "x.bvh")
    with pytest.raises(JointRoleError, match="role 'left_knee'.*joints available: Spine, Spine1") as ei:
        joint_weights(motion_features(b).joint_names, PAPER_WEIGHTS)
    assert "joint_roles.left_knee" in str(ei.value) and "Knee_L_custom" in str(ei.value)
    b.skeleton.roles = {"left_knee": "Knee_L_custom"}
    assert resolve_role(b.skeleton, "left_knee") == "Knee_L_custom"
    assert joint_weights(motion_features(b).joint_names, PAPER_WEIGHTS, b.skeleton.roles).sum() > 0
