"""BVH (Biovision hierarchy) writer and reader.

Reading (:func:`read_bvh`) accepts BVH as it exists in the wild: any root name
(``ROOT Hips``, ``ROOT root``, ``ROOT mixamorig:Hips``), any rotation-channel
order per joint, lengths in whatever unit the file uses. It is strict where a
silent misreading would follow; each of these is a
:class:`~animsynth.errors.MotionFormatError` naming file and line:

* a joint's rotation (or position) channels must name distinct axes
  (``Xrotation Xrotation Xrotation`` is refused);
* position channels may sit on any joint (in BVH they replace the joint's
  ``OFFSET`` in every frame, as Blender's importer reads them). Those of a
  non-root joint that are constant over the frames, to within
  :data:`CHILD_POSITION_REL_TOL` of the skeleton's size (the sum of its bone
  lengths) plus the printed precision (Blender's exporter writes them on
  every bone not connected to its parent), are read as the joint's
  ``OFFSET`` (their mean; one log line names the joints). Varying ones (game
  and research rigs with 6 channels on every joint) become translation DOF
  of that joint (``tx ty tz``: the channel minus the ``OFFSET``, as for the
  root), logged with the largest movement;
* a root with no channels (``CHANNELS 0``, Blender's dummy ``ROOT __0``) and
  exactly one child is dropped: the child becomes the root, the dummy's
  ``OFFSET`` added to the child's offset and positions (logged). With several
  children (an armature with several root bones) it is refused: one skeleton
  with one root translation per file is supported;
* a *dummy root with channels* (the Bandai-Namco layout: ``joint_Root`` with
  6 channels whose rotation is constant, usually zero, over one child
  ``Hips`` that has position channels and carries the motion) is merged into
  its child without loss: the child becomes the root, its world translation
  ``root position + R0 (child position)`` and its rotation ``R0 R_child``
  (``R0`` the constant root rotation; with ``R0`` the identity the child's
  rotation channels are kept as they are). Every joint's world position is
  unchanged (logged);
* joint names must be unique; joints may nest at most
  :data:`MAX_JOINT_DEPTH` deep;
* nothing may follow the root joint's closing brace before ``MOTION`` (a
  second ``ROOT``, a stray ``}``);
* the frame time must lie in [:data:`MIN_FRAME_TIME`, :data:`MAX_FRAME_TIME`]
  seconds (100 kHz down to one frame a minute); the frame count must match
  the rows.

The file becomes a generic :class:`Skeleton` (axis = identity; each joint's DOF
are its position channels, then its rotation channels in reverse order, since
a BVH rotation ``CHANNELS ... Zrotation Xrotation Yrotation`` is the intrinsic
Z-X-Y rotation, i.e. the *extrinsic* ``ry rx rz`` of
:mod:`animsynth.skeleton`) and a :class:`Motion` whose values are the file's
channel values (root positions minus the root ``OFFSET``). The frame rate is
``1 / Frame Time``, except that when an integer rate is consistent with the
printed frame time (``0.008333`` -> 120, ``0.0333333`` -> 30), or a rate with
a few decimals is (29.97), that rate is used: a frame time is a rounded print
of ``1 / fps``.

Writing (:func:`write_bvh`): one BVH joint per skeleton joint, ``OFFSET`` =
where the joint starts relative to its parent, an ``End Site`` at the tip of
every leaf. A joint that came from a BVH file (no ASF axis frame) is written
with its own channels in its own order, so reading a BVH and writing it back
reproduces every channel value to the printed precision (6 decimals), except
that constant position channels of a non-root joint are written back as that
joint's ``OFFSET`` (the joint positions are the same, the joint has its
rotation channels only) and a merged dummy root is written as its child.
Varying position channels on any joint are written back as they were read. An ASF
joint with rotational DOF gets ``Zrotation Yrotation Xrotation`` (the local
rotation ``L = C M C^-1`` of :mod:`animsynth.kinematics` as intrinsic Z-Y-X
Euler angles, degrees); an ASF joint without DOF (e.g. CMU ``lhipjoint``) gets
no channels. The root's positions are absolute (its translation plus its
``OFFSET``). The frame time is written with 17 significant digits, so
``1 / Frame Time`` gives back the frame rate. Lengths stay in skeleton units
unless ``scale`` is given (e.g. ``skeleton.length_to_m`` for metres).

:func:`motion_from_bvh_on` maps a BVH written by us back onto the original ASF
skeleton's DOF (the round trip).
"""

from __future__ import annotations

import logging
import math
import os

import numpy as np
from scipy.spatial.transform import Rotation

from ..kinematics import dof_values_from_local, joint_translations, local_rotations, root_translation
from ..motion import Motion
from ..skeleton import ROT_DOFS, TRANS_DOFS, Joint, Skeleton
from ..atomic import atomic_write_text
from ..errors import MotionFormatError, parse_float, read_text_lines

_CH = {"Xposition": "tx", "Yposition": "ty", "Zposition": "tz",
       "Xrotation": "rx", "Yrotation": "ry", "Zrotation": "rz"}
_CH_NAME = {v: k for k, v in _CH.items()}

log = logging.getLogger("animsynth.io")

#: Position channels of a non-root joint count as constant when every value
#: lies within this fraction of the skeleton's size (sum of its bone lengths),
#: plus half the printed precision, of the channel's mean.
CHILD_POSITION_REL_TOL = 1e-5

#: Shortest frame time accepted (seconds): 100,000 frames per second.
MIN_FRAME_TIME = 1e-5
#: Longest frame time accepted (seconds): one frame a minute.
MAX_FRAME_TIME = 60.0
#: Deepest joint chain accepted (a hand's finger tip in a full-body rig is about
#: 30 joints below the root); deeper nesting is refused naming file and line,
#: before the recursive parser and the forward kinematics run out of stack.
MAX_JOINT_DEPTH = 256
#: Values of the channels and offsets are written with this many decimals.
DECIMALS = 6


def _native(j: Joint) -> bool:
    """Is ``j`` written with its own channels (a BVH joint: no ASF axis frame)?"""
    return j.direction is None and not np.any(np.asarray(j.axis, float))


def _check_frame_time(ftime: float, where: str) -> None:
    if not MIN_FRAME_TIME <= ftime <= MAX_FRAME_TIME:
        raise ValueError(f"{where}: frame time {ftime:g} s is outside [{MIN_FRAME_TIME:g}, {MAX_FRAME_TIME:g}] s "
                         f"(frame rate {1 / MAX_FRAME_TIME:g} to {1 / MIN_FRAME_TIME:g} fps)")


def write_bvh(path, motion: Motion, scale: float = 1.0) -> None:
    """Write ``motion`` as BVH (see module docstring).

    Raises
    ------
    ValueError
        Non-finite values, a non-finite or non-positive ``scale``, offsets or
        positions that are not finite after scaling, or a frame rate whose
        frame time is outside [:data:`MIN_FRAME_TIME`, :data:`MAX_FRAME_TIME`]
        (such a file could not be read back). Nothing is written then.
    """
    sk = motion.skeleton
    values = np.asarray(motion.values, float)
    if not np.all(np.isfinite(values)):
        raise ValueError(f"refusing to write {path}: motion has non-finite values")
    scale = float(scale)
    if not math.isfinite(scale) or scale <= 0:
        raise ValueError(f"refusing to write {path}: length scale {scale!r} must be finite and > 0")
    fps = float(motion.fps)
    if not math.isfinite(fps) or fps <= 0:
        raise ValueError(f"refusing to write {path}: frame rate {fps!r} must be finite and > 0")
    _check_frame_time(1.0 / fps, f"refusing to write {path}")
    L = local_rotations(sk, values)
    root_t = root_translation(sk, values) * scale
    T = joint_translations(sk, values) * scale
    sl = sk.dof_slices()
    n = values.shape[0]
    lines = ["HIERARCHY"]
    blocks = []

    def num(v) -> str:
        return f"{v:.{DECIMALS}f}"

    def emit(i: int, depth: int):
        j = sk.joints[i]
        ind = "  " * depth
        lines.append(f"{ind}{'ROOT' if i == 0 else 'JOINT'} {j.name}")
        lines.append(f"{ind}{{")
        off = np.asarray(j.offset, float) * scale
        if not np.all(np.isfinite(off)):
            raise ValueError(f"refusing to write {path}: joint {j.name!r} has a non-finite offset after scaling")
        lines.append(f"{ind}  OFFSET {num(off[0])} {num(off[1])} {num(off[2])}")
        chans: list[str] = []
        if _native(j):
            trans = [d for d in j.dofs if d in TRANS_DOFS]
            rots = [d for d in j.dofs if d in ROT_DOFS][::-1]  # extrinsic DOF order -> intrinsic channel order
            cols = values[:, sl[j.name]]
            for d in trans:  # position channels replace the OFFSET: offset + translation DOF
                blocks.append(T[:, i, TRANS_DOFS.index(d)][:, None])
            for d in rots:
                blocks.append(cols[:, [j.dofs.index(d)]])
            chans = [_CH_NAME[d] for d in trans + rots]
        else:
            if i == 0:
                chans = ["Xposition", "Yposition", "Zposition"]
                blocks.append(root_t)
            if j.rot_dofs or i == 0:
                chans += ["Zrotation", "Yrotation", "Xrotation"]
                blocks.append(L[i].as_euler("ZYX", degrees=True))
        lines.append(f"{ind}  CHANNELS {len(chans)}" + "".join(" " + c for c in chans))
        kids = sk.children(i)
        for k in kids:
            emit(k, depth + 1)
        if not kids:
            tail = np.asarray(j.tail, float) * scale
            if not np.all(np.isfinite(tail)):
                raise ValueError(f"refusing to write {path}: joint {j.name!r} has a non-finite tail after scaling")
            lines.append(f"{ind}  End Site")
            lines.append(f"{ind}  {{")
            lines.append(f"{ind}    OFFSET {num(tail[0])} {num(tail[1])} {num(tail[2])}")
            lines.append(f"{ind}  }}")
        lines.append(f"{ind}}}")

    emit(0, 0)
    data = np.hstack(blocks) if blocks else np.zeros((n, 0))
    if not np.all(np.isfinite(data)):
        raise ValueError(f"refusing to write {path}: a channel value is not finite after scaling")
    lines += ["MOTION", f"Frames: {n}", f"Frame Time: {1.0 / fps:.17g}"]
    lines += [" ".join(num(v) for v in row) for row in data]
    atomic_write_text(path, "\n".join(lines) + "\n")


def _frame_rate(ft_s: str, ftime: float) -> float:
    """``1 / ftime``, or the shortest decimal rate that the printed frame time is a rounding of."""
    fps = 1.0 / ftime
    low = ft_s.strip().lower()
    mant, _, exp = low.partition("e")
    decimals = len(mant.split(".", 1)[1]) if "." in mant else 0
    half_ulp = 0.5 * 10.0 ** ((int(exp) if exp else 0) - decimals)
    for d in range(7):
        cand = round(fps, d)
        if cand > 0 and abs(1.0 / cand - ftime) <= half_ulp * (1 + 1e-9):
            return float(cand)
    return fps


def bvh_frame_rate(path) -> float:
    """The frame rate of a BVH file from its ``Frame Time:`` line, without reading the motion.

    The file is read line by line up to that line (the hierarchy and two header lines), so a long capture
    costs no more than a short one. The rate is the one :func:`read_bvh` gives (a printed frame time such as
    ``0.0333333`` is read as 30 fps).

    Raises
    ------
    OSError
        the file cannot be read
    MotionFormatError
        no ``Frame Time:`` line, or a frame time that is not a positive number in the accepted range
    """
    with open(path, encoding="utf-8-sig", errors="replace") as fh:
        for ln, line in enumerate(fh, 1):
            text = line.strip()
            if text.startswith("Frame Time:"):
                ft_s = text.split(":", 1)[1].strip()
                return _frame_rate(ft_s, _parse_frame_time(ft_s, path, ln))
    raise MotionFormatError(path, None, "no 'Frame Time:' line")


def _parse_frame_time(ft_s: str, path, line: int) -> float:
    """The ``Frame Time:`` value ``ft_s`` (seconds per frame) of ``path`` at ``line``, checked: a positive number
    in the accepted range, else :class:`MotionFormatError` naming the file and line."""
    ftime = parse_float(ft_s, path, line, "frame time")
    if ftime <= 0:
        raise MotionFormatError(path, line, f"frame time must be positive (seconds per frame), got {ft_s!r}")
    try:
        _check_frame_time(ftime, "frame time")
    except ValueError as exc:
        raise MotionFormatError(path, line, str(exc).replace("frame time: ", "")) from None
    return ftime


def read_bvh(path, fps: float | None = None, root: str | None = None) -> Motion:
    """Read a BVH file into a generic skeleton and motion (see module docstring).

    Parameters
    ----------
    path : path
    fps : float, optional
        Override the frame rate given by the file's frame time.
    root : str, optional
        The skeleton to read from a file that holds several (two characters, a character and a prop): the name
        of one of its ``ROOT`` joints, or of a root bone under a dummy root without channels (Blender's armature
        with several root bones). Not needed for a file of one skeleton.

    Returns
    -------
    Motion
        ``values`` (frames, n_dof) in file order of joints; angles in degrees,
        lengths in file units (``skeleton.length_to_m`` is 1).

    Raises
    ------
    MotionFormatError
        Malformed input (file and line): see the module docstring, plus bytes
        that are not UTF-8, a frame count below 1, rows that do not match the
        channels. A leading UTF-8 byte-order mark is ignored.
    """
    raw = read_text_lines(path)
    toks, motion_line = _hierarchy_tokens(path, raw)
    joints = _HierarchyReader(path, toks, motion_line).read()
    ft_s, ftime, data = _read_motion(path, raw, motion_line, sum(len(r["channels"]) for r in joints))
    joints, data = _pick_skeleton(path, joints, data, root)
    joints, data = _drop_dummy_root(path, joints, data)
    joints, data = _merge_dummy_root(path, joints, data)
    data = _constant_child_positions(path, joints, data)
    sk, cols = _generic_skeleton(path, joints)
    values = _positions_as_translations(sk, data[:, cols] if cols else np.zeros((data.shape[0], 0)))
    return Motion(values, sk, float(fps) if fps is not None else _frame_rate(ft_s, ftime), sk.name)


def _hierarchy_tokens(path, raw: list[str]) -> tuple[list[tuple[str, int]], int]:
    """The tokens ``(text, line)`` of the lines before the ``MOTION`` line, and that line's number."""
    toks: list[tuple[str, int]] = []
    for ln, line in enumerate(raw, start=1):
        if line.strip().upper() == "MOTION":
            return toks, ln
        toks += [(t, ln) for t in line.split()]
    raise MotionFormatError(path, len(raw), "no MOTION section")


class _HierarchyReader:
    """The ``HIERARCHY`` section read token by token into joint records, in file order (a parent before its
    children): dicts of ``name``, ``parent`` (index, -1 for a root), ``offset``, ``channels`` (BVH channel names),
    ``end`` (the End Site's offset or None), ``line`` (of its ``ROOT``/``JOINT``) and ``chan_line``.

    Hand-written recursive descent rather than a parser library: the grammar is a handful of keywords, and
    every error has to name the file and line of the token at fault.
    """

    def __init__(self, path, toks: list[tuple[str, int]], motion_line: int):
        self.path, self.toks, self.motion_line = path, toks, motion_line
        self.pos = 0
        self.joints: list[dict] = []
        self.seen: dict[str, int] = {}

    def next(self) -> tuple[str, int]:
        """The next token and its line; the hierarchy may not end before every joint is closed."""
        if self.pos >= len(self.toks):
            raise MotionFormatError(self.path, self.motion_line, "hierarchy ends early (a joint is not closed)")
        self.pos += 1
        return self.toks[self.pos - 1]

    def read(self) -> list[dict]:
        """``HIERARCHY``, then one ``ROOT`` block or several (characters, props), and nothing after them."""
        t, ln = self.next()
        if t != "HIERARCHY":
            raise MotionFormatError(self.path, ln, f"expected HIERARCHY, got {t!r}")
        kw, ln = self.next()
        if kw != "ROOT":
            raise MotionFormatError(self.path, ln, f"expected ROOT, got {kw!r}")
        self.joint(-1, kw, ln)
        while self.pos < len(self.toks) and self.toks[self.pos][0] == "ROOT":  # another character (or prop)
            kw, ln = self.next()
            self.joint(-1, kw, ln)
        if self.pos < len(self.toks):
            t, ln = self.toks[self.pos]
            raise MotionFormatError(self.path, ln, f"{t!r} after the root joint's closing brace")
        return self.joints

    def joint(self, parent: int, kw: str, ln0: int, depth: int = 1) -> int:
        """One ``ROOT`` or ``JOINT`` block (keyword ``kw`` on line ``ln0``) with its children; returns its index."""
        rec = self._open(parent, kw, ln0, depth)
        idx, name = len(self.joints) - 1, rec["name"]
        while True:
            t, ln = self.next()
            if t == "OFFSET":
                if rec["offset"] is not None:
                    raise MotionFormatError(self.path, ln, f"joint {name!r} has a second OFFSET")
                rec["offset"] = self._xyz(ln)
            elif t == "CHANNELS":
                if rec["channels"] is not None:
                    raise MotionFormatError(self.path, ln, f"joint {name!r} has a second CHANNELS line")
                rec["channels"], rec["chan_line"] = self._channels(name)
            elif t == "JOINT":
                self.joint(idx, t, ln, depth + 1)
            elif t == "End":
                rec["end"] = self._end_site()
            elif t == "}":
                break
            else:
                raise MotionFormatError(self.path, ln, f"unexpected token {t!r} in joint {name!r}")
        if rec["offset"] is None:
            raise MotionFormatError(self.path, ln0, f"joint {name!r} has no OFFSET")
        if rec["channels"] is None:
            rec["channels"] = []
        return idx

    def _open(self, parent: int, kw: str, ln0: int, depth: int) -> dict:
        """A joint's head, ``NAME {`` after its keyword: checked (depth, a unique name) and its record appended."""
        if depth > MAX_JOINT_DEPTH:
            raise MotionFormatError(self.path, ln0, f"joints nested more than {MAX_JOINT_DEPTH} deep (a skeleton "
                                                    "chain this long is a broken or hostile file)")
        name, lnn = self.next()
        if name in ("{", "}"):
            raise MotionFormatError(self.path, lnn, f"{kw} without a name")
        if name in self.seen:
            raise MotionFormatError(self.path, lnn, f"duplicate joint name {name!r} (first on line {self.seen[name]})")
        self.seen[name] = lnn
        b, lnb = self.next()
        if b != "{":
            raise MotionFormatError(self.path, lnb, f"expected '{{' after {kw} {name}")
        rec = {"name": name, "parent": parent, "offset": None, "channels": None, "end": None, "line": ln0,
               "chan_line": ln0}
        self.joints.append(rec)
        return rec

    def _xyz(self, line: int) -> np.ndarray:
        """The three numbers of an ``OFFSET`` on ``line``."""
        return np.array([parse_float(self.next()[0], self.path, line, "offset") for _ in range(3)])

    def _channels(self, name: str) -> tuple[list[str], int]:
        """A ``CHANNELS`` line's names after its keyword, checked (count 0 to 6, known names, each axis once per
        kind), and the line of its count."""
        c, lnc = self.next()
        try:
            k = int(c)
        except ValueError:
            raise MotionFormatError(self.path, lnc, f"bad channel count {c!r}") from None
        if not 0 <= k <= 6:
            raise MotionFormatError(self.path, lnc, f"channel count must be 0 to 6, got {c!r}")
        chans = [self.next() for _ in range(k)]
        bad = [c for c, _ in chans if c not in _CH]
        if bad:
            raise MotionFormatError(self.path, chans[[c for c, _ in chans].index(bad[0])][1],
                                    f"unknown channel {bad[0]!r} (expected {', '.join(_CH)})")
        names = [c for c, _ in chans]
        for suffix in ("rotation", "position"):
            axes = [c[0] for c in names if c.endswith(suffix)]
            if len(set(axes)) != len(axes):
                raise MotionFormatError(self.path, lnc, f"joint {name!r}: {suffix} channels repeat an axis "
                                                        f"({' '.join(c for c in names if c.endswith(suffix))}); "
                                                        "each axis may appear once")
        return names, lnc

    def _end_site(self) -> np.ndarray:
        """An ``End Site { OFFSET x y z }`` block after its ``End``: the offset."""
        s, lns = self.next()
        b2, _ = self.next()
        o, lno = self.next()
        if s != "Site" or b2 != "{" or o != "OFFSET":
            raise MotionFormatError(self.path, lns, "malformed End Site")
        end = self._xyz(lno)
        e, lne = self.next()
        if e != "}":
            raise MotionFormatError(self.path, lne, "End Site block not closed")
        return end


def _read_motion(path, raw: list[str], motion_line: int, ncols: int) -> tuple[str, float, np.ndarray]:
    """The ``MOTION`` section after line ``motion_line``: the frame time as printed and as a number, and the
    frame rows (frames, ncols), as many as ``Frames:`` declares."""
    nf_s, lnf = _header_value(path, raw, motion_line, "Frames:")
    ft_s, lnt = _header_value(path, raw, lnf, "Frame Time:")
    try:
        nframes = int(nf_s)
    except ValueError:
        raise MotionFormatError(path, lnf, f"bad frame count {nf_s!r}") from None
    if nframes < 1:
        raise MotionFormatError(path, lnf, f"frame count must be at least 1, got {nframes}")
    ftime = _parse_frame_time(ft_s, path, lnt)
    rows = []
    for k in range(lnt, len(raw)):
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
    return ft_s, ftime, np.array(rows, float).reshape(nframes, ncols)


def _header_value(path, raw: list[str], i: int, prefix: str) -> tuple[str, int]:
    """The value after ``prefix:`` on the first non-blank line from index ``i``, and that line's number (the
    index of the line after it)."""
    while i < len(raw) and not raw[i].strip():
        i += 1
    if i >= len(raw) or not raw[i].strip().startswith(prefix):
        raise MotionFormatError(path, i + 1, f"expected '{prefix}'")
    return raw[i].split(":", 1)[1].strip(), i + 1


def _generic_skeleton(path, joints: list[dict]) -> tuple[Skeleton, list[int]]:
    """The skeleton of the joint records, named after the file, and the data column of each of its DOF: a joint's
    DOF are its position channels, then its rotation channels reversed (intrinsic channel order -> extrinsic DOF
    order)."""
    sk_joints, cols, col = [], [], 0
    for idx, rec in enumerate(joints):
        chans = rec["channels"]
        order = {c: col + k for k, c in enumerate(chans)}
        col += len(chans)
        trans = [c for c in chans if c.endswith("position")]
        rots = [c for c in chans if c.endswith("rotation")][::-1]
        kids = [k for k, r in enumerate(joints) if r["parent"] == idx]
        tail = rec["end"] if rec["end"] is not None else (joints[kids[0]]["offset"] if kids else np.zeros(3))
        sk_joints.append(Joint(rec["name"], rec["parent"], np.asarray(rec["offset"], float),
                               np.asarray(tail, float), [_CH[c] for c in trans + rots]))
        cols += [order[c] for c in trans + rots]
    return Skeleton(sk_joints, name=os.path.splitext(os.path.basename(os.fspath(path)))[0]), cols


def _positions_as_translations(sk: Skeleton, values: np.ndarray) -> np.ndarray:
    """``values`` with each position channel (root: absolute; other joints: from the parent), which replaces the
    joint's OFFSET, made our translation DOF, which add to it: the channel minus the OFFSET (in place)."""
    slices = sk.dof_slices()
    for j in sk.joints:
        for k, d in enumerate(j.dofs):
            if d in TRANS_DOFS:
                values[:, slices[j.name].start + k] -= j.offset[TRANS_DOFS.index(d)]
    return values


def _pick_skeleton(path, joints: list[dict], data: np.ndarray, root: str | None):
    """The joints and columns of the one skeleton ``root`` names, from a file that may hold several (``ROOT``
    blocks, or root bones under a dummy root without channels); a file of several and no ``root`` is refused,
    naming them and how to pick one."""
    tops = [k for k, r in enumerate(joints) if r["parent"] == -1]
    bones = {k: [c for c, r in enumerate(joints) if r["parent"] == k] for k in tops}
    picks = [c for k in tops for c in (bones[k] if not joints[k]["channels"] and len(bones[k]) > 1 else [k])]
    names = [joints[k]["name"] for k in picks]
    how = "name one with root= (command line: --root NAME; config: bvh_root on the trial)"
    if root is None:
        if len(tops) > 1:
            raise MotionFormatError(path, joints[tops[1]]["line"], f"a second ROOT {joints[tops[1]]['name']!r}: the "
                                    f"file holds {len(tops)} skeletons ({', '.join(map(repr, names))}); {how}")
        return joints, data
    if root not in names:
        raise MotionFormatError(path, joints[0]["line"], f"root={root!r} is none of the file's skeletons "
                                f"({', '.join(map(repr, names))})")
    pick = picks[names.index(root)]
    top = pick if joints[pick]["parent"] == -1 else joints[pick]["parent"]
    keep = []
    for k, r in enumerate(joints):  # file order: a parent comes before its children
        if k in (top, pick) or (r["parent"] in keep and (r["parent"] != top or top == pick)):
            keep.append(k)
    start = np.cumsum([0] + [len(r["channels"]) for r in joints])
    cols = [c for k in keep for c in range(start[k], start[k + 1])]
    new = {k: i for i, k in enumerate(keep)}
    out = [dict(joints[k], parent=new.get(joints[k]["parent"], -1)) for k in keep]
    log.info("%s: skeleton %r read (root=%r) of the %d in the file: %s", os.fspath(path), root, root, len(names),
             ", ".join(names))
    return out, data[:, cols]


def _drop_dummy_root(path, joints: list[dict], data: np.ndarray):
    """Drop a root without channels that has one child (see module docstring)."""
    root = joints[0]
    if root["channels"]:
        return joints, data
    kids = [k for k, r in enumerate(joints) if r["parent"] == 0]
    if len(kids) > 1:
        names = ", ".join(repr(joints[k]["name"]) for k in kids)
        raise MotionFormatError(path, root["line"],
                                f"root joint {root['name']!r} has no channels and {len(kids)} children ({names}): "
                                "an armature with several root bones (Blender writes them under a dummy root); "
                                "read one with root=NAME (command line: --root NAME; config: bvh_root on the "
                                "trial), or export one root bone")
    if not kids:
        return joints, data
    child = joints[1]  # the only child comes first in file order
    shift = np.asarray(root["offset"], float)
    child["offset"] = np.asarray(child["offset"], float) + shift
    data = data.copy()
    for k, c in enumerate(child["channels"]):  # the dummy has no columns: the child's start at 0
        if c.endswith("position"):
            data[:, k] += shift["XYZ".index(c[0])]
    out = [dict(r, parent=r["parent"] - 1) for r in joints[1:]]
    log.info("%s: root %r has no channels and one child; %r is the root", os.fspath(path), root["name"],
             child["name"])
    return out, data


def _constant_child_positions(path, joints: list[dict], data: np.ndarray) -> np.ndarray:
    """Read constant position channels of non-root joints as their OFFSET; keep varying ones.

    Changes ``joints`` in place (offset replaced, constant position channels
    removed) and returns ``data`` without those columns. A joint with a
    varying position channel keeps all its position channels (they become its
    translation DOF); one log line names those joints and their largest
    movement.
    """
    start, col = [], 0
    for r in joints:
        start.append(col)
        col += len(r["channels"])
    moved = [k for k, r in enumerate(joints) if k > 0 and any(c.endswith("position") for c in r["channels"])]
    if not moved:
        return data
    size = sum(float(np.linalg.norm(r["offset"])) for r in joints[1:])
    size += sum(float(np.linalg.norm(r["end"])) for r in joints if r["end"] is not None)
    tol = CHILD_POSITION_REL_TOL * size + 0.5 * 10.0 ** -DECIMALS
    drop, const, varying = [], [], []
    for k in moved:
        r = joints[k]
        cols = [(i, c) for i, c in enumerate(r["channels"]) if c.endswith("position")]
        devs = {c: float(np.max(np.abs(data[:, start[k] + i] - data[:, start[k] + i].mean()))) for i, c in cols}
        if max(devs.values()) > tol:
            varying.append(f"{r['name']} ({max(devs.values()):.6g})")
            continue
        off = np.asarray(r["offset"], float).copy()
        for i, c in cols:
            off["XYZ".index(c[0])] = data[:, start[k] + i].mean()
            drop.append(start[k] + i)
        r["offset"] = off
        r["channels"] = [c for c in r["channels"] if not c.endswith("position")]
        const.append(r["name"])
    if const:
        log.info("%s: position channels of non-root joint(s) %s are constant (within %g file units); read as their "
                 "OFFSET", os.fspath(path), ", ".join(const), tol)
    if varying:
        log.info("%s: non-root joint(s) with translation over the frames (largest movement from the mean, file "
                 "units): %s; read as translation DOF of those joints", os.fspath(path), ", ".join(varying))
    return np.delete(data, drop, axis=1)


#: A channelled root's rotation counts as constant (a dummy root) when no frame's rotation differs from the
#: first frame's by more than this many degrees (the printed precision of the angles is 1e-6 degrees).
DUMMY_ROOT_ROTATION_TOL_DEG = 1e-5


def _joint_translation(rec: dict, data: np.ndarray, first: int) -> np.ndarray:
    """(frames, 3): a joint's OFFSET with its position channels (columns from ``first``) replacing it."""
    t = np.tile(np.asarray(rec["offset"], float), (data.shape[0], 1))
    for i, c in enumerate(rec["channels"]):
        if c.endswith("position"):
            t[:, "XYZ".index(c[0])] = data[:, first + i]
    return t


def _joint_rotation(rec: dict, data: np.ndarray, first: int) -> Rotation:
    """A joint's local rotation per frame from its rotation channels (intrinsic, in channel order)."""
    idx = [i for i, c in enumerate(rec["channels"]) if c.endswith("rotation")]
    if not idx:
        return Rotation.identity(data.shape[0])
    seq = "".join(rec["channels"][i][0] for i in idx)
    return Rotation.from_euler(seq, data[:, [first + i for i in idx]], degrees=True)


def _merge_dummy_root(path, joints: list[dict], data: np.ndarray):
    """Merge a channelled root with constant rotation into its only child that has position channels
    (see module docstring)."""
    root = joints[0]
    kids = [k for k, r in enumerate(joints) if r["parent"] == 0]
    if not root["channels"] or len(kids) != 1 or root["end"] is not None:
        return joints, data
    child = joints[1]
    if not any(c.endswith("position") for c in child["channels"]):
        return joints, data
    R_root = _joint_rotation(root, data, 0)
    R0 = R_root[0]
    if data.shape[0] > 1 and np.degrees((R0.inv() * R_root).magnitude()).max() > DUMMY_ROOT_ROTATION_TOL_DEG:
        return joints, data
    nr, nc = len(root["channels"]), len(child["channels"])
    t = _joint_translation(root, data, 0) + R0.apply(_joint_translation(child, data, nr))
    rot_ch = [c for c in child["channels"] if c.endswith("rotation")]
    if np.degrees(R0.magnitude()) <= DUMMY_ROOT_ROTATION_TOL_DEG:
        rot = data[:, [nr + i for i, c in enumerate(child["channels"]) if c.endswith("rotation")]]
    else:
        if len(rot_ch) < 3:
            rot_ch = ["Zrotation", "Yrotation", "Xrotation"]
        R = R0 * _joint_rotation(child, data, nr)
        rot = R.as_euler("".join(c[0] for c in rot_ch), degrees=True)
    new = dict(child, parent=-1, channels=["Xposition", "Yposition", "Zposition"] + rot_ch,
               offset=np.asarray(root["offset"], float) + R0.apply(np.asarray(child["offset"], float)))
    out = [new] + [dict(r, parent=r["parent"] - 1) for r in joints[2:]]
    data = np.concatenate([t, rot, data[:, nr + nc:]], axis=1)
    log.info("%s: root %r has a constant rotation (%.6g degrees) and one child %r with position channels, which "
             "carries the motion; merged: %r is the root (every joint's world position unchanged)", os.fspath(path),
             root["name"], float(np.degrees(R0.magnitude())), child["name"], child["name"])
    return out, data


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
