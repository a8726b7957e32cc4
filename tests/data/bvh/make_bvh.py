"""Write the small BVH files of this folder (run: python tests/data/bvh/make_bvh.py).

Each file follows one convention seen in BVH files from elsewhere; all are
made up here (smooth sinusoidal joint angles, a root walking forward) and do
not come from any other project:

* ``cmu_converted.bvh``: CMU-to-BVH conversion names (``Hips``, ``LHipJoint``,
  ``LeftUpLeg``, ``LowerBack``, ``LeftToeBase`` ...), root ``Zrotation
  Yrotation Xrotation``, joints ``Zrotation Yrotation Xrotation``, frame time
  printed as ``.0083333`` (120 fps), space indentation.
* ``hips_xyz.bvh``: ``ROOT Hips``, ``Xrotation Yrotation Zrotation``
  everywhere, 120 fps printed as ``0.008333``.
* ``hips_zxy.bvh``: Mixamo-style ``mixamorig:`` names, ``Zrotation
  Xrotation Yrotation``, 30 fps, a root OFFSET that is not zero.
* ``blender.bvh``: what Blender's BVH exporter writes (default
  ``root_transform_only=False``) for an armature with one root bone: tab
  indentation, rigify-style lower-case ``thigh.L`` names, ``Yrotation
  Xrotation Zrotation``, 24 fps printed as ``0.041667``, an ``End Site`` on
  every leaf, and ``CHANNELS 6 Xposition Yposition Zposition ...`` on every
  bone not connected to its parent (thighs, shoulders, upper arms) whose
  positions are constant, equal to the bone's ``OFFSET``.
* the classes of tests/bvh_classes.py (made from the project's synthetic
  mocap, a 24-frame walk, by the project's writer): ``bandai.bvh`` (a
  6-channel dummy root over a 6-channel Hips, cm), ``every6_bip.bvh`` (6
  channels on every joint, Bip01 names, joints that move, cm),
  ``rest_along_x.bvh`` (the rest pose lying along +X, cm), ``z_up.bvh`` (Z
  up, -Y forward, metres), ``mixed_orders.bvh`` (a different rotation order
  on every joint, cm).
* ``creatures/`` (a folder of its own: the files above are all bipeds),
  bodies that are not bipeds (tests/bvh_classes.py, metres, +y up):
  ``quadruped.bvh`` (four legs, a long horizontal body, a head in front and a
  trunk, 2 m tall and 3.4 m long; biped joint names on its legs) and
  ``crab.bvh`` (a wide flat body on eight splayed legs, two claws).
* ``multiroot/blender_two_roots.bvh`` (a folder of its own: it is refused, the
  files above are read): what the exporter writes for an armature with two
  root bones, a dummy ``ROOT __0`` with ``OFFSET 0.0 0.0 0.0`` and
  ``CHANNELS 0`` holding both as ``JOINT`` with six channels.
"""

from __future__ import annotations

import math
from pathlib import Path

HERE = Path(__file__).resolve().parent
FRAMES = 24

# (role name, parent role, offset) of a generic biped, Y up, lengths in cm
BODY = [
    ("hips", None, (0.0, 0.0, 0.0)),
    ("spine", "hips", (0.0, 10.0, 0.5)),
    ("chest", "spine", (0.0, 12.0, 0.0)),
    ("neck", "chest", (0.0, 20.0, -1.0)),
    ("head", "neck", (0.0, 8.0, 1.0)),
    ("lshoulder", "chest", (3.0, 17.0, -1.0)),
    ("larm", "lshoulder", (12.0, 0.0, 0.0)),
    ("lforearm", "larm", (27.0, 0.0, 0.0)),
    ("lhand", "lforearm", (25.0, 0.0, 0.0)),
    ("rshoulder", "chest", (-3.0, 17.0, -1.0)),
    ("rarm", "rshoulder", (-12.0, 0.0, 0.0)),
    ("rforearm", "rarm", (-27.0, 0.0, 0.0)),
    ("rhand", "rforearm", (-25.0, 0.0, 0.0)),
    ("lupleg", "hips", (9.0, -6.0, 0.0)),
    ("lleg", "lupleg", (0.0, -42.0, 0.5)),
    ("lfoot", "lleg", (0.0, -41.0, -2.0)),
    ("ltoe", "lfoot", (0.0, -6.0, 12.0)),
    ("rupleg", "hips", (-9.0, -6.0, 0.0)),
    ("rleg", "rupleg", (0.0, -42.0, 0.5)),
    ("rfoot", "rleg", (0.0, -41.0, -2.0)),
    ("rtoe", "rfoot", (0.0, -6.0, 12.0)),
]
END_SITES = {"head": (0.0, 10.0, 0.0), "lhand": (8.0, 0.0, 0.0), "rhand": (-8.0, 0.0, 0.0),
             "ltoe": (0.0, 0.0, 5.0), "rtoe": (0.0, 0.0, 5.0)}


def angles(k: int, t: int, fps: float) -> tuple[float, float, float]:
    """Smooth made-up angles (degrees) of joint k at frame t, about X, Y, Z."""
    s = 2.0 * math.pi * 1.1 * t / fps
    a = 25.0 * math.sin(s + 0.7 * k) + 3.0 * k % 7
    b = 12.0 * math.sin(0.5 * s + 1.3 * k)
    c = 8.0 * math.cos(s + 0.4 * k) - 2.0
    return a, b, c


def write(name: str, names: dict, root_order: str, order: str, fps: float, frame_time: str, indent: str = "  ",
          root_offset=(0.0, 0.0, 0.0), extra=(), skip=(), unconnected=()) -> None:
    body = [b for b in BODY if b[0] not in skip] + list(extra)
    kids = {}
    for role, parent, _ in body:
        kids.setdefault(parent, []).append(role)
    off = {role: o for role, _, o in body}
    lines = ["HIERARCHY"]
    chan_order = []

    def emit(role, depth):
        ind = indent * depth
        lines.append(f"{ind}{'ROOT' if depth == 0 else 'JOINT'} {names[role]}")
        lines.append(f"{ind}{{")
        o = root_offset if depth == 0 else off[role]
        lines.append(f"{ind}{indent}OFFSET {o[0]:.6f} {o[1]:.6f} {o[2]:.6f}")
        ro = root_order if depth == 0 else order
        rot = " ".join(f"{a}rotation" for a in ro)
        six = depth == 0 or role in unconnected
        if six:
            lines.append(f"{ind}{indent}CHANNELS 6 Xposition Yposition Zposition {rot}")
        else:
            lines.append(f"{ind}{indent}CHANNELS 3 {rot}")
        chan_order.append((role, depth == 0, six, ro))
        for c in kids.get(role, []):
            emit(c, depth + 1)
        if role not in kids:
            e = END_SITES.get(role, (0.0, 5.0, 0.0))
            lines.append(f"{ind}{indent}End Site")
            lines.append(f"{ind}{indent}{{")
            lines.append(f"{ind}{indent}{indent}OFFSET {e[0]:.6f} {e[1]:.6f} {e[2]:.6f}")
            lines.append(f"{ind}{indent}}}")
        lines.append(f"{ind}}}")

    emit("hips", 0)
    lines += ["MOTION", f"Frames: {FRAMES}", f"Frame Time: {frame_time}"]
    for t in range(FRAMES):
        row = []
        for k, (role, is_root, six, ro) in enumerate(chan_order):
            if is_root:
                row += [1.5 * t, 95.0 + 2.0 * math.sin(t / 3.0), 0.3 * t]
            elif six:
                row += list(off[role])  # an unanimated translation: the OFFSET in every frame
            a = dict(zip("XYZ", angles(k, t, fps)))
            row += [a[ax] for ax in ro]
        lines.append(" ".join(f"{v:.6f}" for v in row))
    (HERE / name).write_text("\n".join(lines) + "\n")


def main():
    cmu = {"hips": "Hips", "spine": "LowerBack", "chest": "Spine1", "neck": "Neck", "head": "Head",
           "lshoulder": "LeftShoulder", "larm": "LeftArm", "lforearm": "LeftForeArm", "lhand": "LeftHand",
           "rshoulder": "RightShoulder", "rarm": "RightArm", "rforearm": "RightForeArm", "rhand": "RightHand",
           "lhip": "LHipJoint", "lupleg": "LeftUpLeg", "lleg": "LeftLeg", "lfoot": "LeftFoot", "ltoe": "LeftToeBase",
           "rhip": "RHipJoint", "rupleg": "RightUpLeg", "rleg": "RightLeg", "rfoot": "RightFoot",
           "rtoe": "RightToeBase"}
    # the CMU conversions put a hip joint between the root and each thigh
    global BODY
    saved = BODY
    BODY = [b if b[0] not in ("lupleg", "rupleg") else (b[0], "lhip" if b[0] == "lupleg" else "rhip", (3.0, -4.0, 0.0)
                                                        if b[0] == "lupleg" else (-3.0, -4.0, 0.0)) for b in BODY]
    BODY.insert(13, ("lhip", "hips", (6.0, -2.0, 0.0)))
    BODY.insert(18, ("rhip", "hips", (-6.0, -2.0, 0.0)))
    write("cmu_converted.bvh", cmu, "ZYX", "ZYX", 120.0, ".0083333")
    BODY = saved
    plain = {"hips": "Hips", "spine": "Spine", "chest": "Spine1", "neck": "Neck", "head": "Head",
             "lshoulder": "LeftShoulder", "larm": "LeftArm", "lforearm": "LeftForeArm", "lhand": "LeftHand",
             "rshoulder": "RightShoulder", "rarm": "RightArm", "rforearm": "RightForeArm", "rhand": "RightHand",
             "lupleg": "LeftUpLeg", "lleg": "LeftLeg", "lfoot": "LeftFoot", "ltoe": "LeftToeBase",
             "rupleg": "RightUpLeg", "rleg": "RightLeg", "rfoot": "RightFoot", "rtoe": "RightToeBase"}
    write("hips_xyz.bvh", plain, "XYZ", "XYZ", 120.0, "0.008333")
    mixamo = {k: "mixamorig:" + v for k, v in plain.items()}
    write("hips_zxy.bvh", mixamo, "ZXY", "ZXY", 30.0, "0.0333333", root_offset=(0.0, 2.5, 0.0))
    blender = {"hips": "hips", "spine": "spine", "chest": "chest", "neck": "neck", "head": "head",
               "lshoulder": "shoulder.L", "larm": "upper_arm.L", "lforearm": "forearm.L", "lhand": "hand.L",
               "rshoulder": "shoulder.R", "rarm": "upper_arm.R", "rforearm": "forearm.R", "rhand": "hand.R",
               "lupleg": "thigh.L", "lleg": "shin.L", "lfoot": "foot.L", "ltoe": "toe.L",
               "rupleg": "thigh.R", "rleg": "shin.R", "rfoot": "foot.R", "rtoe": "toe.R"}
    write("blender.bvh", blender, "YXZ", "YXZ", 24.0, "0.041667", indent="\t",
          unconnected=("lupleg", "rupleg", "lshoulder", "rshoulder", "larm", "rarm"))
    write_two_roots()
    write_classes()
    write_creatures()


#: file name -> class of tests/bvh_classes.py
CLASS_FILES = {"bandai.bvh": "bandai", "every6_bip.bvh": "every6", "rest_along_x.bvh": "rest_x",
               "z_up.bvh": "zup", "mixed_orders.bvh": "mixed"}


def write_classes() -> None:
    """The files of the classes found in the wild, from a synthetic walk (tests/bvh_classes.py)."""
    import sys

    sys.path[:0] = [str(HERE.parents[1]), str(HERE.parents[2] / "src")]
    from bvh_classes import write_class
    from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

    walk = generate_motion("walk_turn", FRAMES, 3, cmu_like_skeleton("wild", 0), name="walk")
    for name, cls in CLASS_FILES.items():
        write_class(walk, cls, HERE / name)


def write_creatures() -> None:
    """Bodies that are not bipeds, in metres, +y up (tests/bvh_classes.py): a four-legged animal and a crab."""
    import sys

    sys.path[:0] = [str(HERE.parents[1]), str(HERE.parents[2] / "src")]
    from bvh_classes import CRAB, QUADRUPED, creature
    from animsynth.io.bvh import write_bvh

    (HERE / "creatures").mkdir(exist_ok=True)
    write_bvh(HERE / "creatures" / "quadruped.bvh", creature(QUADRUPED, name="quadruped"))
    write_bvh(HERE / "creatures" / "crab.bvh", creature(CRAB, swing=8.0, name="crab"))


def write_two_roots() -> None:
    """Blender's layout for an armature with two root bones (a body and a prop)."""
    lines = ["HIERARCHY", "ROOT __0", "{", "\tOFFSET 0.0 0.0 0.0", "\tCHANNELS 0"]
    for name, off, tip in (("hips", (0.0, 95.0, 0.0), (0.0, 10.0, 0.0)), ("prop", (40.0, 80.0, 5.0), (0.0, 0.0, 30.0))):
        lines += [f"\tJOINT {name}", "\t{", f"\t\tOFFSET {off[0]:.6f} {off[1]:.6f} {off[2]:.6f}",
                  "\t\tCHANNELS 6 Xposition Yposition Zposition Yrotation Xrotation Zrotation",
                  "\t\tEnd Site", "\t\t{", f"\t\t\tOFFSET {tip[0]:.6f} {tip[1]:.6f} {tip[2]:.6f}", "\t\t}", "\t}"]
    lines += ["}", "MOTION", "Frames: 3", "Frame Time: 0.041667"]
    for t in range(3):
        lines.append(" ".join(f"{v:.6f}" for v in (1.5 * t, 95.0, 0.3 * t, *angles(0, t, 24.0),
                                                   40.0, 80.0 + t, 5.0, *angles(1, t, 24.0))))
    (HERE / "multiroot").mkdir(exist_ok=True)
    (HERE / "multiroot" / "blender_two_roots.bvh").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
