"""BVH files of the classes found in the wild, made here from the project's synthetic mocap.

Each converter takes a motion on the CMU-like synthetic skeleton
(:func:`animsynth.synth.mocap.generate_motion`) and returns the same motion
(the same world joint positions, up to the stated change of frame) in one
class's layout, written with the project's writer. Nothing comes from a
third-party file:

* ``bandai``: a 6-channel dummy root ``joint_Root`` (zero rotation, forward-only
  translation) over a 6-channel ``Hips`` that carries the motion; Bandai-Namco
  names (``UpperLeg_L`` ...), centimetres.
* ``every6``: 6 channels on every joint (Truebones / 3ds Max ``Bip01_`` names,
  found by the role map since it drops Biped's prefix; the trials still name
  their roles, the spine's as the Biped's Spine2 for the chest); the
  spine's positions wobble by 0.1 mm, the clavicles really move (2.5 cm).
* ``rest_x``: the rest pose lies along +X (LAFAN1): every offset turned by a
  fixed rotation, the joint rotations compensating, so the motion is Y up.
* ``zup``: Z up, -Y forward (a Blender export): the whole motion turned.
* ``mixed``: a different rotation-channel order on every joint.
* ``cmu_units``: cgspeed's CMU conversions: ``Hips`` names with the
  ``LHipJoint`` joints, the ASF length unit (0.05644 m).
"""

from __future__ import annotations

import copy

import numpy as np
from scipy.spatial.transform import Rotation

from animsynth.io.bvh import write_bvh
from animsynth.kinematics import dof_values_from_local, joint_translations, local_rotations, root_translation
from animsynth.motion import Motion
from animsynth.skeleton import Joint, Skeleton

HIPS_NAMES = {"root": "Hips", "lowerback": "Spine", "upperback": "Spine1", "thorax": "Spine2", "lowerneck": "Neck",
              "upperneck": "Neck1", "head": "Head", "lclavicle": "LeftShoulder", "lhumerus": "LeftArm",
              "lradius": "LeftForeArm", "lwrist": "LeftHand", "rclavicle": "RightShoulder", "rhumerus": "RightArm",
              "rradius": "RightForeArm", "rwrist": "RightHand", "lfemur": "LeftUpLeg", "ltibia": "LeftLeg",
              "lfoot": "LeftFoot", "ltoes": "LeftToeBase", "rfemur": "RightUpLeg", "rtibia": "RightLeg",
              "rfoot": "RightFoot", "rtoes": "RightToeBase"}
CMU_CONVERSION_NAMES = dict(HIPS_NAMES, lhipjoint="LHipJoint", rhipjoint="RHipJoint", lowerback="LowerBack",
                            upperback="Spine", thorax="Spine1")
BANDAI_NAMES = {"Hips": "Hips", "Spine": "Spine", "Spine1": "Chest", "Spine2": "Chest2", "Neck": "Neck",
                "Neck1": "Neck1", "Head": "Head", "LeftShoulder": "Shoulder_L", "LeftArm": "UpperArm_L",
                "LeftForeArm": "LowerArm_L", "LeftHand": "Hand_L", "RightShoulder": "Shoulder_R",
                "RightArm": "UpperArm_R", "RightForeArm": "LowerArm_R", "RightHand": "Hand_R",
                "LeftUpLeg": "UpperLeg_L", "LeftLeg": "LowerLeg_L", "LeftFoot": "Foot_L", "LeftToeBase": "Toes_L",
                "RightUpLeg": "UpperLeg_R", "RightLeg": "LowerLeg_R", "RightFoot": "Foot_R", "RightToeBase": "Toes_R"}
BIP_NAMES = {"Hips": "Bip01_Pelvis", "Spine": "Bip01_Spine", "Spine1": "Bip01_Spine1", "Spine2": "Bip01_Spine2",
             "Neck": "Bip01_Neck", "Neck1": "Bip01_Neck1", "Head": "Bip01_Head", "LeftShoulder": "Bip01_L_Clavicle",
             "LeftArm": "Bip01_L_UpperArm", "LeftForeArm": "Bip01_L_Forearm", "LeftHand": "Bip01_L_Hand",
             "RightShoulder": "Bip01_R_Clavicle", "RightArm": "Bip01_R_UpperArm", "RightForeArm": "Bip01_R_Forearm",
             "RightHand": "Bip01_R_Hand", "LeftUpLeg": "Bip01_L_Thigh", "LeftLeg": "Bip01_L_Calf",
             "LeftFoot": "Bip01_L_Foot", "LeftToeBase": "Bip01_L_Toe0", "RightUpLeg": "Bip01_R_Thigh",
             "RightLeg": "Bip01_R_Calf", "RightFoot": "Bip01_R_Foot", "RightToeBase": "Bip01_R_Toe0"}
#: The roles a Bip01 skeleton has to name (config joint_roles of its trial).
BIP_ROLES = {"pelvis": "Bip01_Pelvis", "spine": "Bip01_Spine", "chest": "Bip01_Spine2", "neck": "Bip01_Neck",
             "head": "Bip01_Head", "left_hip": "Bip01_L_Thigh", "right_hip": "Bip01_R_Thigh",
             "left_knee": "Bip01_L_Calf", "right_knee": "Bip01_R_Calf", "left_ankle": "Bip01_L_Foot",
             "right_ankle": "Bip01_R_Foot", "left_toe": "Bip01_L_Toe0", "right_toe": "Bip01_R_Toe0",
             "left_shoulder": "Bip01_L_UpperArm", "right_shoulder": "Bip01_R_UpperArm",
             "left_elbow": "Bip01_L_Forearm", "right_elbow": "Bip01_R_Forearm", "left_wrist": "Bip01_L_Hand",
             "right_wrist": "Bip01_R_Hand"}
#: metres per file unit of each class as written by :func:`write_class`
UNITS = {"bandai": 0.01, "every6": 0.01, "rest_x": 0.01, "zup": 1.0, "mixed": 0.01, "cmu_units": None}
CLASSES = tuple(UNITS)
ORDERS = ("zyx", "xyz", "yxz", "zxy", "yzx", "xzy")


def _rebuild(sk: Skeleton, rots, trans, fps, name) -> Motion:
    values = dof_values_from_local(sk, rots, trans[:, 0], trans)
    return Motion(values, sk, fps, name)


def hips_motion(motion: Motion, names: dict = HIPS_NAMES) -> Motion:
    """``motion`` (CMU-like ASF skeleton) on a BVH-style skeleton: ``names`` joints only (joints left out
    are merged into their child's offset), root ``tx ty tz`` + 3 rotations, others 3 rotations, extrinsic
    y x z (channels Z X Y)."""
    sk = motion.skeleton
    L = local_rotations(sk, motion.values)
    keep = [i for i, j in enumerate(sk.joints) if j.name in names]
    new_index, joints, rots = {}, [], []
    for i in keep:
        j = sk.joints[i]
        p, off = j.parent, np.asarray(j.offset, float)
        while p >= 0 and sk.joints[p].name not in names:
            off = off + np.asarray(sk.joints[p].offset, float)
            p = sk.joints[p].parent
        kids = [k for k in keep if sk.joints[k].parent == i]
        tail = np.asarray(j.tail, float) if not kids or p < 0 else np.asarray(sk.joints[kids[0]].offset, float)
        dofs = (["tx", "ty", "tz"] if p < 0 else []) + ["ry", "rx", "rz"]
        joints.append(Joint(names[j.name], -1 if p < 0 else new_index[p], off if p >= 0 else np.zeros(3), tail, dofs))
        new_index[i] = len(joints) - 1
        rots.append(L[i])
    new = Skeleton(joints, length_to_m=sk.length_to_m, name=motion.name)
    root_t = root_translation(sk, motion.values)
    trans = np.stack([root_t] + [np.tile(j.offset, (len(root_t), 1)) for j in joints[1:]], axis=1)
    return _rebuild(new, rots, trans, motion.fps, motion.name)


def renamed(m: Motion, names: dict) -> Motion:
    sk = copy.deepcopy(m.skeleton)
    for j in sk.joints:
        j.name = names.get(j.name, j.name)
    sk.__post_init__()
    return Motion(m.values.copy(), sk, m.fps, m.name)


def mixed_orders(m: Motion) -> Motion:
    """Every joint with its own rotation order (cycling through the six)."""
    sk = copy.deepcopy(m.skeleton)
    rots = local_rotations(m.skeleton, m.values)
    for k, j in enumerate(sk.joints):
        j.dofs = [d for d in j.dofs if d[0] == "t"] + ["r" + a for a in ORDERS[k % 6]]
    sk.__post_init__()
    return _rebuild(sk, rots, joint_translations(m.skeleton, m.values), m.fps, m.name)


def turned_rest(m: Motion, Q: Rotation) -> Motion:
    """The same world motion with every offset and tail turned by ``Q`` (the rest pose turned), the
    rotations compensating: ``L_root' = L_root Q^-1``, ``L_j' = Q L_j Q^-1``."""
    sk = copy.deepcopy(m.skeleton)
    rots = local_rotations(m.skeleton, m.values)
    trans = joint_translations(m.skeleton, m.values)
    for k, j in enumerate(sk.joints):
        j.tail = Q.apply(j.tail)
        if k:
            j.offset = Q.apply(j.offset)
    trans[:, 1:] = Q.apply(trans[:, 1:].reshape(-1, 3)).reshape(trans[:, 1:].shape)
    rots = [rots[0] * Q.inv()] + [Q * r * Q.inv() for r in rots[1:]]
    return _rebuild(sk, rots, trans, m.fps, m.name)


def turned_world(m: Motion, P: Rotation) -> Motion:
    """The motion with every world position ``p`` moved to ``P p`` (the rest pose turned too)."""
    sk = copy.deepcopy(m.skeleton)
    rots = [P * r * P.inv() for r in local_rotations(m.skeleton, m.values)]
    trans = joint_translations(m.skeleton, m.values)
    trans = P.apply(trans.reshape(-1, 3)).reshape(trans.shape)
    for j in sk.joints:
        j.offset, j.tail = P.apply(j.offset), P.apply(j.tail)
    return _rebuild(sk, rots, trans, m.fps, m.name)


def bandai(m: Motion) -> Motion:
    """A dummy ``joint_Root`` (6 channels, zero rotation, forward-only translation) over a 6-channel Hips."""
    src = renamed(m, BANDAI_NAMES)
    sk0 = src.skeleton
    root_t = root_translation(sk0, src.values)
    fwd = np.zeros_like(root_t)
    fwd[:, 2] = root_t[:, 2]  # the dummy root carries the forward translation only
    joints = [Joint("joint_Root", -1, np.zeros(3), np.zeros(3), ["tx", "ty", "tz", "rx", "ry", "rz"])]
    for j in sk0.joints:
        j = copy.deepcopy(j)
        if j.parent < 0:
            j.offset = np.array([0.0, float(root_t[0, 1]), 0.0])
            j.dofs = ["tx", "ty", "tz"] + j.dofs[-3:]
        j.parent += 1
        joints.append(j)
    sk = Skeleton(joints, length_to_m=sk0.length_to_m, name=m.name)
    rots = [Rotation.identity(len(root_t))] + local_rotations(sk0, src.values)
    t0 = joint_translations(sk0, src.values)
    trans = np.concatenate([fwd[:, None], (root_t - fwd)[:, None], t0[:, 1:]], axis=1)
    return _rebuild(sk, rots, trans, m.fps, m.name)


def every_six(m: Motion) -> Motion:
    """6 channels on every joint; Bip01 names; the spine wobbles by 2e-4 units, the clavicles move 2.5 cm."""
    src = renamed(m, BIP_NAMES)
    sk = copy.deepcopy(src.skeleton)
    trans = joint_translations(src.skeleton, src.values)
    n = len(trans)
    t = np.arange(n)
    for k, j in enumerate(sk.joints):
        if k:
            j.dofs = ["tx", "ty", "tz"] + [d for d in j.dofs if d[0] == "r"]
        if j.name == "Bip01_Spine":  # a wobble just above the reader's tolerance for constant channels
            trans[:, k, 0] += 0.0001 / sk.length_to_m * np.sin(t / 5.0)
        if j.name.endswith("_Clavicle"):
            trans[:, k, 1] += 0.025 / sk.length_to_m * 0.5 * (1 - np.cos(2 * np.pi * t / max(n, 2)))
    sk.__post_init__()
    return _rebuild(sk, local_rotations(src.skeleton, src.values), trans, m.fps, m.name)


#: the rest pose turned so that the body lies along +X (LAFAN1-like): +Y -> +X, +Z -> -Y
REST_ALONG_X = Rotation.from_euler("x", 90, degrees=True) * Rotation.from_euler("z", -90, degrees=True)
#: Y up, Z forward -> Z up, -Y forward (Blender)
Z_UP = Rotation.from_euler("x", 90, degrees=True)


def convert(motion: Motion, cls: str) -> Motion:
    """``motion`` (CMU-like synthetic skeleton) in class ``cls`` (lengths still in skeleton units)."""
    if cls == "cmu_units":
        return hips_motion(motion, CMU_CONVERSION_NAMES)
    h = hips_motion(motion)
    return {"bandai": bandai, "every6": every_six, "rest_x": lambda x: turned_rest(x, REST_ALONG_X),
            "zup": lambda x: turned_world(x, Z_UP), "mixed": mixed_orders}[cls](h)


def write_class(motion: Motion, cls: str, path) -> float:
    """Write ``motion`` as class ``cls``; return the file's metres per unit (its ``bvh_length_to_m``)."""
    m = convert(motion, cls)
    unit = UNITS[cls]
    if unit is None:
        write_bvh(path, m)
        return float(m.skeleton.length_to_m)
    write_bvh(path, m, scale=m.skeleton.length_to_m / unit)
    return unit


# ---------------------------------------------------------------------------------------------------------------
# bodies that are not bipeds (made here: offsets in metres, +y up, +z forward, sinusoidal joint angles)
# ---------------------------------------------------------------------------------------------------------------
#: (name, parent, offset, tail) of a four-legged animal about 2 m tall and 3.4 m long (an elephant's
#: proportions): the hind legs carry the biped leg names and the front legs the arm names, so the role map finds
#: a head and two feet (as on animal rigs made from a biped template) but the legs number four.
QUADRUPED = [
    ("Hips", None, (0.0, 1.25, 0.0), (0.0, 0.0, 0.5)),
    ("Spine", "Hips", (0.0, 0.05, 0.5), (0.0, 0.0, 0.6)),
    ("Chest", "Spine", (0.0, 0.0, 0.6), (0.0, 0.1, 0.4)),
    ("Neck", "Chest", (0.0, 0.1, 0.4), (0.0, 0.2, 0.2)),
    ("Head", "Neck", (0.0, 0.2, 0.2), (0.0, 0.35, 0.3)),
    ("Trunk", "Head", (0.0, 0.0, 0.35), (0.0, -0.4, 0.2)),
    ("TrunkTip", "Trunk", (0.0, -0.4, 0.2), (0.0, -0.3, 0.05)),
    ("Tail", "Hips", (0.0, -0.05, -0.3), (0.0, -0.3, -0.3)),
    ("TailTip", "Tail", (0.0, -0.3, -0.3), (0.0, -0.3, -0.1)),
]
for _side, _x in (("Left", 0.35), ("Right", -0.35)):
    QUADRUPED += [
        (f"{_side}UpLeg", "Hips", (_x, -0.1, 0.0), (0.0, -0.55, 0.0)),
        (f"{_side}Leg", f"{_side}UpLeg", (0.0, -0.55, 0.0), (0.0, -0.5, 0.0)),
        (f"{_side}Foot", f"{_side}Leg", (0.0, -0.5, 0.0), (0.0, -0.1, 0.08)),
        (f"{_side}Arm", "Chest", (_x, -0.15, 0.1), (0.0, -0.55, 0.0)),
        (f"{_side}ForeArm", f"{_side}Arm", (0.0, -0.55, 0.0), (0.0, -0.5, 0.0)),
        (f"{_side}Hand", f"{_side}ForeArm", (0.0, -0.5, 0.0), (0.0, -0.15, 0.08)),
    ]
#: a crab: a wide flat body (0.7 m across, 0.6 m front to back with the claws, 0.2 m tall), eight legs
#: fanned out sideways and down, two claws forward, two eye stalks; no joint name the role map knows
CRAB = [("Carapace", None, (0.0, 0.12, 0.0), (0.0, 0.02, 0.1)),
        ("EyeL", "Carapace", (0.03, 0.03, 0.1), (0.0, 0.06, 0.0)), ("EyeR", "Carapace", (-0.03, 0.03, 0.1),
                                                                    (0.0, 0.06, 0.0))]
for _side, _s in (("L", 1.0), ("R", -1.0)):
    for _k, _deg in enumerate((-35.0, -12.0, 12.0, 35.0)):
        _c, _z = np.cos(np.radians(_deg)), np.sin(np.radians(_deg))
        CRAB += [(f"Leg{_side}{_k}a", "Carapace", (_s * 0.08, 0.0, 0.03 * (_k - 1.5)), (_s * 0.12 * _c, 0.04, 0.12 * _z)),
                 (f"Leg{_side}{_k}b", f"Leg{_side}{_k}a", (_s * 0.12 * _c, 0.04, 0.12 * _z),
                  (_s * 0.1 * _c, -0.06, 0.1 * _z)),
                 (f"Leg{_side}{_k}c", f"Leg{_side}{_k}b", (_s * 0.1 * _c, -0.06, 0.1 * _z),
                  (_s * 0.04 * _c, -0.1, 0.04 * _z))]
    CRAB += [(f"Claw{_side}a", "Carapace", (_s * 0.06, 0.02, 0.1), (_s * 0.03, 0.01, 0.1)),
             (f"Claw{_side}b", f"Claw{_side}a", (_s * 0.03, 0.01, 0.1), (0.0, 0.0, 0.12))]


def creature(parts, frames: int = 48, fps: float = 30.0, swing: float = 12.0, name: str = "creature") -> Motion:
    """A body of ``parts`` ((name, parent, offset, tail), metres, +y up) walking forward along +z for
    ``frames`` frames: every joint below the root swings by up to ``swing`` degrees about the axis across its
    segment, with its own phase; the root sways by 2 degrees."""
    index = {p[0]: i for i, p in enumerate(parts)}
    joints = [Joint(n, -1 if par is None else index[par], np.asarray(off if par is not None else (0.0, 0.0, 0.0),
                                                                    float),
                    np.asarray(tail, float), (["tx", "ty", "tz"] if par is None else []) + ["rz", "rx", "ry"])
              for n, par, off, tail in parts]
    sk = Skeleton(joints, length_to_m=1.0, name=name)
    t = np.arange(frames) / fps
    rots, trans = [], []
    for k, j in enumerate(joints):
        seg = j.tail / max(np.linalg.norm(j.tail), 1e-9)
        across = np.cross(seg, [0.0, 0.0, 1.0]) if abs(seg[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        across /= np.linalg.norm(across)
        amp = 2.0 if k == 0 else swing
        ang = np.radians(amp * np.sin(2 * np.pi * 1.0 * t + 1.7 * k))
        rots.append(Rotation.from_rotvec(ang[:, None] * across[None, :]))
        trans.append(np.tile(j.offset, (frames, 1)))
    root = np.tile(np.asarray(parts[0][2], float), (frames, 1))
    root[:, 2] += 0.8 * t
    trans[0] = root
    return _rebuild(sk, rots, np.stack(trans, axis=1), fps, name)


def turned_joint_frames(m: Motion, names, Q: Rotation) -> Motion:
    """The same world motion with the local frame of each joint in ``names`` turned by ``Q`` (a rig whose
    bones rest turned, as Bandai-Namco's upper legs): ``L_j' = L_j Q``, its children's offsets, translations
    and its tail ``Q^-1 x``, its children's rotations ``Q^-1 L_c`` (``Q^-1 L_c Q`` when turned too)."""
    sk = copy.deepcopy(m.skeleton)
    rots = local_rotations(m.skeleton, m.values)
    trans = joint_translations(m.skeleton, m.values)
    turned = {sk.index(n) for n in names}
    for i, j in enumerate(sk.joints):
        if i in turned:
            rots[i] = rots[i] * Q
            j.tail = Q.inv().apply(j.tail)
        if j.parent in turned:
            j.offset = Q.inv().apply(j.offset)
            trans[:, i] = Q.inv().apply(trans[:, i])
            rots[i] = Q.inv() * rots[i]
    return _rebuild(sk, rots, trans, m.fps, m.name)


#: the joints whose frames :func:`bandai_with_wraps` turns (names of :func:`hips_motion`)
WRAP_JOINTS = ("LeftUpLeg", "RightUpLeg", "LeftArm", "RightArm")


def bandai_with_wraps(motion: Motion) -> Motion:
    """The ``bandai`` class with the upper legs' and upper arms' frames turned 180 degrees about +y: their
    ``Yrotation`` channels swing about +-180 degrees, so the file's angles wrap from +180 to -180 as a walk's
    legs swing (a Bandai-Namco walk's wraps). The world motion is the same."""
    h = turned_joint_frames(hips_motion(motion), WRAP_JOINTS, Rotation.from_euler("y", 180, degrees=True))
    return bandai(h)
