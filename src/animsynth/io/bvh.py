"""BVH (Biovision hierarchy) writer and reader.

:func:`write_bvh` writes any :class:`~animsynth.motion.Motion` so that it opens
in Blender: one BVH joint per skeleton joint (ASF bone), ``OFFSET`` = where
the joint starts relative to its parent (the parent bone's direction x
length), an ``End Site`` at the tip of every leaf, root channels
``Xposition Yposition Zposition Zrotation Yrotation Xrotation`` and
``Zrotation Yrotation Xrotation`` for every other joint with rotational DOF.
Joints without DOF (e.g. CMU ``lhipjoint``) get no channels. BVH rotations
are the local rotations ``L = C M C^-1`` of :mod:`animsynth.kinematics`,
written as intrinsic Z-Y-X Euler angles in degrees. Lengths stay in skeleton
units unless ``scale`` is given (e.g. ``skeleton.length_to_m`` for metres).

:func:`read_bvh` reads a BVH file into a generic :class:`Skeleton` (axis =
identity, DOF = the file's rotation channels turned into the equivalent
extrinsic order) and :class:`Motion`. :func:`motion_from_bvh_on` maps a BVH
written by us back onto the original ASF skeleton's DOF (the round trip).
"""

from __future__ import annotations

import os

import numpy as np
from scipy.spatial.transform import Rotation

from ..kinematics import dof_values_from_local, local_rotations, root_translation
from ..motion import Motion
from ..skeleton import Joint, Skeleton
from .atomic import atomic_write_text
from .errors import MotionFormatError, parse_float, read_text_lines

_CH = {"Xposition": "tx", "Yposition": "ty", "Zposition": "tz",
       "Xrotation": "rx", "Yrotation": "ry", "Zrotation": "rz"}


def write_bvh(path, motion: Motion, scale: float = 1.0) -> None:
    """Write ``motion`` as BVH (see module docstring)."""
    sk = motion.skeleton
    values = np.asarray(motion.values, float)
    if not np.all(np.isfinite(values)):
        raise ValueError(f"refusing to write {path}: motion has non-finite values")
    L = local_rotations(sk, values)
    root_t = root_translation(sk, values) * scale
    has_rot = [bool(j.rot_dofs) or i == 0 for i, j in enumerate(sk.joints)]
    lines = ["HIERARCHY"]

    def emit(i: int, depth: int):
        j = sk.joints[i]
        ind = "  " * depth
        head = "ROOT" if i == 0 else "JOINT"
        lines.append(f"{ind}{head} {j.name}")
        lines.append(f"{ind}{{")
        off = np.zeros(3) if i == 0 else np.asarray(j.offset) * scale
        lines.append(f"{ind}  OFFSET {off[0]:.6f} {off[1]:.6f} {off[2]:.6f}")
        if i == 0:
            lines.append(f"{ind}  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation")
        elif has_rot[i]:
            lines.append(f"{ind}  CHANNELS 3 Zrotation Yrotation Xrotation")
        else:
            lines.append(f"{ind}  CHANNELS 0")
        kids = sk.children(i)
        for k in kids:
            emit(k, depth + 1)
        if not kids:
            tail = np.asarray(j.tail) * scale
            lines.append(f"{ind}  End Site")
            lines.append(f"{ind}  {{")
            lines.append(f"{ind}    OFFSET {tail[0]:.6f} {tail[1]:.6f} {tail[2]:.6f}")
            lines.append(f"{ind}  }}")
        lines.append(f"{ind}}}")

    emit(0, 0)
    n = values.shape[0]
    lines += ["MOTION", f"Frames: {n}", f"Frame Time: {1.0 / motion.fps:.9f}"]
    blocks = [root_t]
    for i, r in enumerate(L):
        if has_rot[i]:
            blocks.append(r.as_euler("ZYX", degrees=True))
    data = np.hstack(blocks)
    lines += [" ".join(f"{v:.6f}" for v in row) for row in data]
    atomic_write_text(path, "\n".join(lines) + "\n")


def read_bvh(path, fps: float | None = None) -> Motion:
    """Read a BVH file into a generic skeleton and motion.

    Raises :class:`MotionFormatError` (file and line) on malformed input,
    including bytes that are not UTF-8, a frame count below 1 and a frame time
    that is not positive. A leading UTF-8 byte-order mark is ignored.
    """
    raw = read_text_lines(path)
    toks: list[tuple[str, int]] = []
    motion_line = None
    for ln, line in enumerate(raw, start=1):
        if line.strip().upper() == "MOTION":
            motion_line = ln
            break
        toks += [(t, ln) for t in line.split()]
    if motion_line is None:
        raise MotionFormatError(path, len(raw), "no MOTION section")
    pos = 0

    def nxt():
        nonlocal pos
        if pos >= len(toks):
            raise MotionFormatError(path, motion_line, "hierarchy ends early")
        pos += 1
        return toks[pos - 1]

    t, ln = nxt()
    if t != "HIERARCHY":
        raise MotionFormatError(path, ln, f"expected HIERARCHY, got {t!r}")
    joints: list[dict] = []
    channels: list[tuple[int, list[str]]] = []

    def parse_joint(parent: int):
        kw, ln0 = nxt()
        name, _ = nxt()
        b, lnb = nxt()
        if b != "{":
            raise MotionFormatError(path, lnb, f"expected '{{' after {kw} {name}")
        rec = {"name": name, "parent": parent, "offset": None, "channels": [], "end": None, "kids": []}
        idx = len(joints)
        joints.append(rec)
        while True:
            t, ln = nxt()
            if t == "OFFSET":
                rec["offset"] = np.array([parse_float(nxt()[0], path, ln, "offset") for _ in range(3)])
            elif t == "CHANNELS":
                c, lnc = nxt()
                try:
                    k = int(c)
                except ValueError:
                    raise MotionFormatError(path, lnc, f"bad channel count {c!r}") from None
                if k < 0:
                    raise MotionFormatError(path, lnc, f"negative channel count {c!r}")
                chans = [nxt()[0] for _ in range(k)]
                bad = [c for c in chans if c not in _CH]
                if bad:
                    raise MotionFormatError(path, lnc, f"unknown channel(s) {bad}")
                rec["channels"] = chans
                channels.append((idx, chans))
            elif t in ("JOINT",):
                pos_back()
                rec["kids"].append(parse_joint(idx))
            elif t == "End":
                s, lns = nxt()
                b2, _ = nxt()
                o, lno = nxt()
                if s != "Site" or b2 != "{" or o != "OFFSET":
                    raise MotionFormatError(path, lns, "malformed End Site")
                rec["end"] = np.array([parse_float(nxt()[0], path, lno, "offset") for _ in range(3)])
                e, lne = nxt()
                if e != "}":
                    raise MotionFormatError(path, lne, "End Site block not closed")
            elif t == "}":
                break
            else:
                raise MotionFormatError(path, ln, f"unexpected token {t!r}")
        if rec["offset"] is None:
            raise MotionFormatError(path, ln0, f"joint {name!r} has no OFFSET")
        return idx

    def pos_back():
        nonlocal pos
        pos -= 1

    parse_joint(-1)
    # motion header
    i = motion_line
    def header(prefix):
        nonlocal i
        while i < len(raw) and not raw[i].strip():
            i += 1
        if i >= len(raw) or not raw[i].strip().startswith(prefix):
            raise MotionFormatError(path, i + 1, f"expected '{prefix}'")
        val = raw[i].split(":", 1)[1].strip()
        i += 1
        return val, i
    nf_s, lnf = header("Frames:")
    ft_s, lnt = header("Frame Time:")
    try:
        nframes = int(nf_s)
    except ValueError:
        raise MotionFormatError(path, lnf, f"bad frame count {nf_s!r}") from None
    if nframes < 1:
        raise MotionFormatError(path, lnf, f"frame count must be at least 1, got {nframes}")
    ftime = parse_float(ft_s, path, lnt, "frame time")
    if ftime <= 0:
        raise MotionFormatError(path, lnt, f"frame time must be positive (seconds per frame), got {ft_s!r}")
    ncols = sum(len(c) for _, c in channels)
    rows = []
    for k in range(i, len(raw)):
        if not raw[k].strip():
            continue
        parts = raw[k].split()
        if len(rows) == nframes:
            raise MotionFormatError(path, k + 1, f"more frame rows than the {nframes} the header declares")
        if len(parts) != ncols:
            raise MotionFormatError(path, k + 1, f"{len(parts)} values, hierarchy declares {ncols} channels")
        rows.append([parse_float(p, path, k + 1) for p in parts])
    if len(rows) != nframes:
        raise MotionFormatError(path, len(raw), f"header says {nframes} frames, file has {len(rows)} (truncated?)")
    data = np.array(rows, float).reshape(nframes, ncols)
    # build the generic skeleton: DOF are the channels, rotations in
    # extrinsic order = reversed intrinsic channel order
    sk_joints = []
    cols = []
    col = 0
    chan_of = dict(channels)
    for idx, rec in enumerate(joints):
        chans = chan_of.get(idx, [])
        trans = [_CH[c] for c in chans if c.endswith("position")]
        rots = [_CH[c] for c in chans if c.endswith("rotation")]
        dofs = trans + rots[::-1]
        kids = [k for k, r in enumerate(joints) if r["parent"] == idx]
        tail = rec["end"] if rec["end"] is not None else (joints[kids[0]]["offset"] if kids else np.zeros(3))
        sk_joints.append(Joint(rec["name"], rec["parent"], rec["offset"] if idx else np.zeros(3), np.asarray(tail, float), dofs))
        # columns of this joint in file order
        order = {c: col + k for k, c in enumerate(chans)}
        col += len(chans)
        file_cols = [order[c] for c in chans if c.endswith("position")] + [order[c] for c in chans if c.endswith("rotation")][::-1]
        cols += file_cols
    values = data[:, cols] if cols else np.zeros((nframes, 0))
    root_off = joints[0]["offset"]
    sk = Skeleton(sk_joints, name=os.path.splitext(os.path.basename(os.fspath(path)))[0])
    sk.joints[0].offset = np.asarray(root_off, float)
    # root positions in BVH are absolute; our root translation adds the offset
    sl = sk.dof_slices()["root"]
    for k, d in enumerate(sk.joints[0].dofs):
        if d.startswith("t"):
            values[:, sl.start + k] -= root_off["xyz".index(d[1])]
    return Motion(values, sk, fps if fps is not None else round(1.0 / ftime, 6), sk.name)


def motion_from_bvh_on(bvh_motion: Motion, skeleton: Skeleton) -> Motion:
    """Map a BVH motion (joint names matching ``skeleton``) onto ``skeleton``'s DOF.

    Used for the AMC -> BVH -> angles round trip: the BVH local rotations are
    converted back to the ASF joint's DOF through its axis frame C.
    """
    bsk = bvh_motion.skeleton
    L_bvh = local_rotations(bsk, bvh_motion.values)
    n = bvh_motion.n_frames
    rots = []
    for j in skeleton.joints:
        if j.name in bsk.names:
            rots.append(L_bvh[bsk.index(j.name)])
        else:
            rots.append(Rotation.identity(n))
    root_t = root_translation(bsk, bvh_motion.values)
    values = dof_values_from_local(skeleton, rots, root_t)
    return Motion(values, skeleton, bvh_motion.fps, bvh_motion.name)
