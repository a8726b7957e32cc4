"""The fixed 18-joint rig of the mesh family and the synthetic character: its joint names, their parents and the
CMU (ASF) bone that drives each. Plain data in a module of its own, so that config checks can name the joints
without loading :mod:`animsynth.skinning` and its numerical imports."""

#: The 18 joints, parents before children.
JOINTS = (
    "hips", "spine", "spine1", "chest", "neck", "head",
    "l_upperarm", "l_forearm", "l_hand", "r_upperarm", "r_forearm", "r_hand",
    "l_thigh", "l_shin", "l_foot", "r_thigh", "r_shin", "r_foot",
)
PARENTS = (-1, 0, 1, 2, 3, 4, 3, 6, 7, 3, 9, 10, 0, 12, 13, 0, 15, 16)
#: Which CMU (ASF) bone drives each of the 18 joints.
CMU_MAP = {
    "hips": "root", "spine": "lowerback", "spine1": "upperback", "chest": "thorax",
    "neck": "lowerneck", "head": "head",
    "l_upperarm": "lhumerus", "l_forearm": "lradius", "l_hand": "lwrist",
    "r_upperarm": "rhumerus", "r_forearm": "rradius", "r_hand": "rwrist",
    "l_thigh": "lfemur", "l_shin": "ltibia", "l_foot": "lfoot",
    "r_thigh": "rfemur", "r_shin": "rtibia", "r_foot": "rfoot",
}
