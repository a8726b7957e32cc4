"""Acclaim ASF skeleton reader and writer (the CMU mocap skeleton format).

The reader understands ``:units`` (``length``, ``angle``, ``mass``), ``:root``
(``order``, ``axis``, ``position``, ``orientation``), ``:bonedata`` (``id``,
``name``, ``direction``, ``length``, ``axis``, ``dof``, ``limits``) and
``:hierarchy``. Lengths are kept in file units; ``Skeleton.length_to_m`` holds
the CMU conversion ``(1 / length) * 2.54 / 100`` (file units -> inches -> m).

Bones are reordered so that the skeleton's joint order is the CMU AMC order
(:data:`animsynth.skeleton.CMU_BONE_ORDER`) for the bones it contains, then any
other bones in breadth-first order; this fixes the column order of motions.
"""

from __future__ import annotations

import os

import numpy as np

from ..skeleton import CMU_BONE_ORDER, Joint, Skeleton
from ..atomic import atomic_write_text
from ..errors import MotionFormatError, parse_float, read_text_lines

_AXES = {"X", "Y", "Z"}


#: Bounds of ``:units length`` (file units per inch): beyond them lengths in
#: metres overflow or vanish.
MIN_LENGTH_UNIT, MAX_LENGTH_UNIT = 1e-6, 1e6


def read_asf(path) -> Skeleton:
    """Parse an ASF file into a :class:`~animsynth.skeleton.Skeleton`.

    Raises
    ------
    MotionFormatError
        On any malformed line (message names file and line), a file that is
        not UTF-8 text, a ``:units length`` that is not positive or lies outside
        [:data:`MIN_LENGTH_UNIT`, :data:`MAX_LENGTH_UNIT`], or a missing
        ``:root`` section. A leading UTF-8 byte-order mark is ignored.
    """
    lines = read_text_lines(path)
    reader = _AsfReader(path)
    for ln, raw in enumerate(lines, start=1):
        line = raw.split("#", 1)[0].strip()
        if line:
            reader.read_line(ln, line, line.split())
    return reader.skeleton(len(lines))


class _AsfReader:
    """The state of one ASF file read line by line: the current section, the bone block being read, and what the
    sections gave so far (units, root, bones, hierarchy). One method per section; each raises
    :class:`MotionFormatError` naming the file and line."""

    def __init__(self, path):
        self.path = path
        self.units = {"length": 1.0, "angle": "deg", "mass": 1.0}
        self.root = {"order": ["tx", "ty", "tz", "rx", "ry", "rz"], "axis": "XYZ",
                     "position": np.zeros(3), "orientation": np.zeros(3)}
        self.bones: dict[str, dict] = {}
        self.children: dict[str, list[str]] = {}
        self.name = os.path.splitext(os.path.basename(os.fspath(path)))[0]
        self.section = None
        self.root_line = None
        self.bone = None
        self.limits_pending = 0

    def read_line(self, ln: int, line: str, tok: list[str]) -> None:
        """One non-empty line without its comment, split into tokens."""
        if tok[0].startswith(":"):
            self._start_section(ln, tok)
        elif self.section == "units":
            self._units(ln, line, tok)
        elif self.section == "root":
            self._root(ln, line, tok)
        elif self.section == "bonedata":
            self._bonedata(ln, line, tok)
        elif self.section == "hierarchy":
            self._hierarchy(ln, tok)
        # other sections (version, documentation, name, or unknown ones such as :skin) are skipped, as Acclaim
        # readers do

    def _start_section(self, ln: int, tok: list[str]) -> None:
        if self.bone is not None:
            raise MotionFormatError(self.path, self.bone["line"], f"bone block not closed with 'end' before {tok[0]}")
        self.section = tok[0][1:].lower()
        if self.section == "root":
            self.root_line = ln
        if self.section == "name" and len(tok) > 1:
            self.name = tok[1]
        self.limits_pending = 0

    def _units(self, ln: int, line: str, tok: list[str]) -> None:
        path, units = self.path, self.units
        if len(tok) != 2:
            raise MotionFormatError(path, ln, f"bad units line {line!r}")
        key = tok[0].lower()
        if key == "angle":
            if tok[1].lower() not in ("deg", "rad"):
                raise MotionFormatError(path, ln, f"unknown angle unit {tok[1]!r}")
            units["angle"] = tok[1].lower()
            return
        units[key] = parse_float(tok[1], path, ln, f"{key} unit")
        if key == "length" and units[key] <= 0:
            raise MotionFormatError(path, ln, f"length unit must be positive, got {tok[1]!r}")
        if key == "length" and not MIN_LENGTH_UNIT <= units[key] <= MAX_LENGTH_UNIT:
            raise MotionFormatError(path, ln, f"length unit {tok[1]!r} is outside [{MIN_LENGTH_UNIT:g}, "
                                              f"{MAX_LENGTH_UNIT:g}] (CMU files use 0.45)")

    def _root(self, ln: int, line: str, tok: list[str]) -> None:
        path, key = self.path, tok[0].lower()
        if key == "order":
            order = [t.lower() for t in tok[1:]]
            if sorted(order) != sorted(["tx", "ty", "tz", "rx", "ry", "rz"]):
                raise MotionFormatError(path, ln, f"root order must be a permutation of TX TY TZ RX RY RZ, got {tok[1:]}")
            self.root["order"] = order
        elif key == "axis":
            if len(tok) != 2 or set(tok[1].upper()) != _AXES or len(tok[1]) != 3:
                raise MotionFormatError(path, ln, f"bad root axis {line!r}")
            self.root["axis"] = tok[1].upper()
        elif key in ("position", "orientation"):
            if len(tok) != 4:
                raise MotionFormatError(path, ln, f"root {key} needs 3 numbers")
            self.root[key] = np.array([parse_float(t, path, ln, key) for t in tok[1:]])
        else:
            raise MotionFormatError(path, ln, f"unknown root field {tok[0]!r}")

    def _limit_pairs(self, text: str, ln: int, line: str) -> None:
        """Append the ``(lo hi)`` pairs of ``text`` to the bone's limits."""
        for pair in text.replace(")", ") ").split(")"):
            pair = pair.strip().lstrip("(").strip()
            if not pair:
                continue
            parts = pair.split()
            if len(parts) != 2:
                raise MotionFormatError(self.path, ln, f"bad limits {line!r}")
            self.bone["limits"].append(tuple(_limit(p, self.path, ln) for p in parts))
            self.limits_pending -= 1

    def _bonedata(self, ln: int, line: str, tok: list[str]) -> None:
        key = tok[0].lower()
        if self.limits_pending and (line.startswith("(") or key == "limits"):  # limits continued on this line
            self._limit_pairs(line[len("limits"):] if key == "limits" else line, ln, line)
        elif key == "begin":
            self.bone = {"line": ln, "axis": np.zeros(3), "axis_order": "XYZ", "dof": [], "limits": []}
        elif self.bone is None:
            raise MotionFormatError(self.path, ln, f"{tok[0]!r} outside begin/end")
        elif key == "end":
            self._end_bone(ln)
        elif key == "limits":
            self.limits_pending = len(self.bone["dof"])
            self._limit_pairs(line[len(tok[0]):].strip(), ln, line)
        elif key not in ("bodymass", "cofmass"):
            self._bone_field(ln, line, tok, key)

    def _end_bone(self, ln: int) -> None:
        path, bone = self.path, self.bone
        for req in ("name", "direction", "length"):
            if req not in bone:
                raise MotionFormatError(path, bone["line"], f"bone without {req}")
        if bone["dof"] and len(bone["limits"]) not in (0, len(bone["dof"])):
            raise MotionFormatError(
                path, ln, f"bone {bone['name']!r}: {len(bone['dof'])} dof but {len(bone['limits'])} limits")
        if bone["name"] in self.bones:
            raise MotionFormatError(path, bone["line"], f"duplicate bone {bone['name']!r}")
        self.bones[bone["name"]] = bone
        self.bone = None

    def _bone_field(self, ln: int, line: str, tok: list[str], key: str) -> None:
        path, bone = self.path, self.bone
        if key == "id":
            bone["id"] = tok[1] if len(tok) > 1 else None
        elif key == "name":
            if len(tok) != 2:
                raise MotionFormatError(path, ln, "bone name must be one word")
            bone["name"] = tok[1]
        elif key == "direction":
            if len(tok) != 4:
                raise MotionFormatError(path, ln, "direction needs 3 numbers")
            d = np.array([parse_float(t, path, ln, "direction") for t in tok[1:]])
            n = np.linalg.norm(d)
            bone["direction"] = d / n if n > 0 else d
        elif key == "length":
            if len(tok) != 2:
                raise MotionFormatError(path, ln, "length needs 1 number")
            bone["length"] = parse_float(tok[1], path, ln, "length")
            if bone["length"] < 0:
                raise MotionFormatError(path, ln, "negative bone length")
        elif key == "axis":
            if len(tok) != 5 or len(tok[4]) != 3 or set(tok[4].upper()) != _AXES:
                raise MotionFormatError(path, ln, f"axis needs 3 numbers and an order, got {line!r}")
            bone["axis"] = np.array([parse_float(t, path, ln, "axis") for t in tok[1:4]])
            bone["axis_order"] = tok[4].upper()
        elif key == "dof":
            dofs = [t.lower() for t in tok[1:]]
            bad = [d for d in dofs if d not in ("rx", "ry", "rz", "tx", "ty", "tz", "l")]
            if bad or not dofs or len(set(dofs)) != len(dofs):
                raise MotionFormatError(path, ln, f"bad dof list {tok[1:]}")
            if "l" in dofs:
                raise MotionFormatError(path, ln, "length DOF 'l' is not supported")
            bone["dof"] = dofs
        else:
            raise MotionFormatError(path, ln, f"unknown bone field {tok[0]!r}")

    def _hierarchy(self, ln: int, tok: list[str]) -> None:
        if tok[0].lower() in ("begin", "end"):
            return
        parent, kids = tok[0], tok[1:]
        if parent != "root" and parent not in self.bones:
            raise MotionFormatError(self.path, ln, f"hierarchy names unknown bone {parent!r}")
        for k in kids:
            if k not in self.bones:
                raise MotionFormatError(self.path, ln, f"hierarchy names unknown bone {k!r}")
            if any(k in v for v in self.children.values()):
                raise MotionFormatError(self.path, ln, f"bone {k!r} has two parents")
        self.children.setdefault(parent, []).extend(kids)

    def skeleton(self, n_lines: int) -> Skeleton:
        """The skeleton read, once every line is in (``n_lines``: the file's line count, for a truncated file)."""
        path = self.path
        if self.bone is not None:
            raise MotionFormatError(path, n_lines, "file ends inside a bone's begin/end block (truncated?)")
        if self.root_line is None:
            raise MotionFormatError(path, None, "no :root section (the root's DOF order, axis and position)")
        if not self.bones:
            raise MotionFormatError(path, None, "no :bonedata bones found")
        if "root" not in self.children:
            raise MotionFormatError(path, None, "no :hierarchy (or root has no children)")
        return _build_skeleton(path, self.name, self.units, self.root, self.bones, self.children)


def _limit(tok: str, path, ln: int) -> float:
    t = tok.strip().lower()
    if t in ("inf", "+inf"):
        return float("inf")
    if t == "-inf":
        return float("-inf")
    return parse_float(t, path, ln, "limit")


def _build_skeleton(path, name, units, root, bones, children) -> Skeleton:
    # breadth-first order from root, then re-sort by CMU order where known
    parent_of: dict[str, str] = {}
    order, queue = [], ["root"]
    while queue:
        b = queue.pop(0)
        order.append(b)
        for k in children.get(b, []):
            parent_of[k] = b
            queue.append(k)
    missing = set(bones) - set(order)
    if missing:
        raise MotionFormatError(path, None, f"bones not reachable from root in :hierarchy: {sorted(missing)}")
    rank = {b: i for i, b in enumerate(CMU_BONE_ORDER)}
    # topological order compatible with CMU ranks: repeatedly take the
    # available bone (parent placed) with the smallest (cmu rank, bfs index)
    bfs_index = {b: i for i, b in enumerate(order)}
    placed, final = {"root"}, ["root"]
    pending = [b for b in order if b != "root"]
    while pending:
        avail = [b for b in pending if parent_of[b] in placed]
        b = min(avail, key=lambda x: (rank.get(x, len(rank)), bfs_index[x]))
        final.append(b)
        placed.add(b)
        pending.remove(b)
    index = {b: i for i, b in enumerate(final)}
    rot_to_deg = 1.0 if units["angle"] == "deg" else np.rad2deg(1.0)
    joints = [
        Joint(
            name="root",
            parent=-1,
            offset=np.asarray(root["position"], float),
            tail=np.zeros(3),
            dofs=list(root["order"]),
            axis=np.asarray(root["orientation"], float) * rot_to_deg,
            axis_order=root["axis"],
        )
    ]
    for b in final[1:]:
        info = bones[b]
        p = parent_of[b]
        poff = np.zeros(3) if p == "root" else bones[p]["direction"] * bones[p]["length"]
        joints.append(
            Joint(
                name=b,
                parent=index[p],
                offset=poff,
                tail=info["direction"] * info["length"],
                dofs=list(info["dof"]),
                axis=info["axis"] * rot_to_deg,
                axis_order=info["axis_order"],
                limits=[tuple(x) for x in info["limits"]],
                direction=info["direction"],
                length=info["length"],
            )
        )
    length_to_m = (1.0 / units["length"]) * 2.54 / 100.0
    return Skeleton(joints, length_to_m=length_to_m, angle_unit="deg", name=name, file_angle_unit=units["angle"])


def write_asf(path, skeleton: Skeleton, length_unit: float | None = None) -> None:
    """Write an ASF file (degrees). ``length_unit`` is the ``:units length``
    value; by default it is derived from ``skeleton.length_to_m``."""
    if length_unit is None:
        length_unit = 2.54 / 100.0 / skeleton.length_to_m
    r = skeleton.joints[0]
    out = [
        "# ASF written by animsynth",
        ":version 1.10",
        f":name {skeleton.name}",
        ":units",
        "  mass 1.0",
        f"  length {length_unit:.6g}",
        "  angle deg",
        ":documentation",
        "   written by animsynth",
        ":root",
        "   order " + " ".join(d.upper() for d in r.dofs),
        f"   axis {r.axis_order}",
        "   position " + " ".join(f"{v:.6g}" for v in r.offset),
        "   orientation " + " ".join(f"{v:.6g}" for v in r.axis),
        ":bonedata",
    ]
    for i, j in enumerate(skeleton.joints[1:], start=1):
        length = float(np.linalg.norm(j.tail)) if j.length is None else j.length
        direction = j.direction if j.direction is not None else (j.tail / length if length > 0 else np.array([0.0, 1.0, 0.0]))
        out += [
            "  begin",
            f"     id {i}",
            f"     name {j.name}",
            "     direction " + " ".join(f"{v:.9g}" for v in direction),
            f"     length {length:.9g}",
            "     axis " + " ".join(f"{v:.9g}" for v in j.axis) + f" {j.axis_order}",
        ]
        if j.dofs:
            out.append("    dof " + " ".join(j.dofs))
            lims = j.limits or [(-180.0, 180.0)] * len(j.dofs)
            out.append("    limits " + "\n           ".join(f"({lo:.6g} {hi:.6g})" for lo, hi in lims))
        out.append("  end")
    out += [":hierarchy", "  begin"]
    for i, j in enumerate(skeleton.joints):
        kids = skeleton.children(i)
        if kids:
            out.append("    " + " ".join([j.name] + [skeleton.joints[k].name for k in kids]))
    out.append("  end")
    atomic_write_text(path, "\n".join(out) + "\n")
