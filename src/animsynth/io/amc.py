"""Acclaim AMC motion reader and writer.

:func:`read_amc` returns a :class:`~animsynth.motion.Motion`: a
``(frames, n_dof)`` float array in degrees whose columns are
``skeleton.columns()`` (for CMU: 62 columns, the 6 root DOF first, then the 56
joint angles in CMU AMC bone order).
"""

from __future__ import annotations

import logging
import os

import numpy as np

from ..motion import Motion
from ..skeleton import Skeleton
from ..atomic import atomic_write_text
from ..errors import MotionFormatError, parse_float, read_text_lines

log = logging.getLogger("animsynth.io")


#: Longest frame number read (digits); a longer one is refused naming file and line.
MAX_FRAME_NUMBER_DIGITS = 12


def read_amc(path, skeleton: Skeleton, fps: float = 120.0) -> Motion:
    """Parse an AMC file against ``skeleton``.

    Every frame must list every bone that has DOF, each with exactly its DOF
    count of finite numbers. Frame numbers must be consecutive from the first.
    Angles are in the unit the header declares (``:DEGREES`` or ``:RADIANS``);
    a file with neither uses the ASF's ``:units angle``
    (``skeleton.file_angle_unit``, logged when that is radians). The returned
    values are always degrees.

    Raises
    ------
    MotionFormatError
        Truncated file, unknown bone, wrong DOF count, non-numeric value, NaN,
        missing bone in a frame, out-of-sequence frame number, or bytes that
        are not UTF-8; the message names file and line. A leading UTF-8
        byte-order mark is ignored.
    """
    frames, degrees_flag = _read_frames(path, skeleton)
    values = np.vstack(frames)
    if degrees_flag is None:
        degrees_flag = skeleton.file_angle_unit != "rad"
        if not degrees_flag:
            log.info("%s: no :DEGREES or :RADIANS header; angles read in radians, as the ASF's ':units angle rad' "
                     "declares", os.fspath(path))
    if not degrees_flag:
        rot_cols = [i for i, c in enumerate(skeleton.columns()) if c.split(".")[1].startswith("r")]
        values[:, rot_cols] *= np.rad2deg(1.0)
    name = os.path.splitext(os.path.basename(os.fspath(path)))[0]
    return Motion(values, skeleton, fps, name)


def _read_frames(path, skeleton: Skeleton) -> tuple[list[np.ndarray], bool | None]:
    """The frames of an AMC file (each ``(n_dof,)``, in the file's angle unit) and its header's angle flag (True
    for ``:DEGREES``, False for ``:RADIANS``, None without either); the checks of :func:`read_amc`."""
    slices = skeleton.dof_slices()
    ndof = {j.name: len(j.dofs) for j in skeleton.joints}
    expected = {n for n, k in ndof.items() if k > 0}
    frames: list[np.ndarray] = []
    cur: np.ndarray | None = None
    seen: set[str] = set()
    cur_line = 0
    frame_no = None
    degrees_flag = None  # AMC header :DEGREES or :RADIANS; without one, the ASF's angle unit
    for ln, raw in enumerate(read_text_lines(path), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith(":"):
            if line.upper().startswith(":RADIANS"):
                degrees_flag = False
            elif line.upper().startswith(":DEGREES"):
                degrees_flag = True
            continue
        tok = line.split()
        if len(tok) == 1 and tok[0].isascii() and tok[0].isdigit():
            if len(tok[0]) > MAX_FRAME_NUMBER_DIGITS:
                raise MotionFormatError(path, ln, f"frame number of {len(tok[0])} digits (at most "
                                                  f"{MAX_FRAME_NUMBER_DIGITS} are read)")
            _finish_frame(path, cur, expected - seen, cur_line, frame_no, frames)
            n = int(tok[0])
            if frame_no is not None and n != frame_no + 1:
                raise MotionFormatError(path, ln, f"frame number {n} follows {frame_no}")
            frame_no, cur, seen, cur_line = n, np.empty(skeleton.n_dof), set(), ln
            continue
        if cur is None:
            raise MotionFormatError(path, ln, f"expected a frame number, got {line[:40]!r}")
        _read_bone_line(path, ln, tok, skeleton, slices, ndof, seen, frame_no, cur)
    _finish_frame(path, cur, expected - seen, cur_line, frame_no, frames)
    if not frames:
        raise MotionFormatError(path, None, "no frames")
    return frames, degrees_flag


def _finish_frame(path, cur, missing: set, cur_line: int, frame_no, frames: list) -> None:
    """Append the frame ``cur`` (None: no frame yet) to ``frames`` unless bones are ``missing`` from it."""
    if cur is None:
        return
    if missing:
        raise MotionFormatError(path, cur_line, f"frame {frame_no} is missing bones {sorted(missing)} (truncated file?)")
    frames.append(cur)


def _read_bone_line(path, ln: int, tok: list[str], skeleton: Skeleton, slices: dict, ndof: dict, seen: set,
                    frame_no, cur: np.ndarray) -> None:
    """Write one bone's values (the line's tokens ``tok``) into the frame ``cur`` and add the bone to ``seen``."""
    bone = tok[0]
    if bone not in slices:
        raise MotionFormatError(path, ln, f"unknown bone {bone!r} (not in skeleton {skeleton.name!r})")
    if bone in seen:
        raise MotionFormatError(path, ln, f"bone {bone!r} appears twice in frame {frame_no}")
    if len(tok) - 1 != ndof[bone]:
        raise MotionFormatError(path, ln, f"bone {bone!r} has {len(tok) - 1} values, skeleton says {ndof[bone]} DOF")
    cur[slices[bone]] = [parse_float(t, path, ln, f"{bone} value") for t in tok[1:]]
    seen.add(bone)


def write_amc(path, motion: Motion) -> None:
    """Write ``motion`` as a fully specified AMC file in degrees."""
    if not np.all(np.isfinite(motion.values)):
        bad = int(np.argwhere(~np.isfinite(motion.values))[0, 0])
        raise ValueError(f"refusing to write {path}: frame {bad + 1} has a non-finite value")
    sk = motion.skeleton
    slices = sk.dof_slices()
    lines = ["# AMC written by animsynth", ":FULLY-SPECIFIED", ":DEGREES"]
    for f, row in enumerate(motion.values, start=1):
        lines.append(str(f))
        for j in sk.joints:
            if j.dofs:
                lines.append(j.name + " " + " ".join(f"{v:.6f}" for v in row[slices[j.name]]))
    atomic_write_text(path, "\n".join(lines) + "\n")
