"""What the ``animsynth`` commands read: the argument types (checked by argparse), the input files (a BVH file
read as the workflow reads a trial, or an ASF/AMC pair) and the per-file options (``--length-to-m``, ``--role``,
``--up-axis``, ``--forward-axis``, ``--root``, ``--encoding``). Each failure is a :class:`UsageError` naming the
argument, or a :class:`~animsynth.errors.MotionFormatError` naming the file and line."""

from __future__ import annotations

import argparse
import math
import os

class UsageError(ValueError):
    """An argument is invalid for the data it applies to (e.g. a frame past the end)."""

    def __init__(self, option: str, message: str):
        self.option = option
        super().__init__(f"argument {option}: {message}")


def _finite(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def positive_float(text: str) -> float:
    """argparse type: a finite number > 0 (frame rates)."""
    value = _finite(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text!r}")
    return value


def fps_float(text: str) -> float:
    """argparse type: a frame rate whose frame time a BVH file can hold (1/60 to 100,000 fps)."""
    from .io.bvh import MAX_FRAME_TIME, MIN_FRAME_TIME

    value = positive_float(text)
    # 1 / 1e-5 is 99999.99999999999 in floating point: the stated ends are accepted as printed
    if not 1.0 / MAX_FRAME_TIME * (1 - 1e-12) <= value <= 1.0 / MIN_FRAME_TIME * (1 + 1e-12):
        raise argparse.ArgumentTypeError(f"must be between {1.0 / MAX_FRAME_TIME:g} and {1.0 / MIN_FRAME_TIME:g} "
                                         f"frames per second, got {text!r}")
    return value


def _int(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1 (counts)."""
    value = _int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {text!r}")
    return value


def index_int(text: str) -> int:
    """argparse type: an integer >= 0 (0-based frame or file index)."""
    value = _int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0 (0-based index), got {text!r}")
    return value


def seed_int(text: str) -> int:
    """argparse type: a seed for numpy, 0 <= seed < 2**32."""
    value = _int(text)
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"must be in [0, 2**32), got {text!r}")
    return value


def _out_with(suffixes: tuple[str, ...]):
    def check(text: str) -> str:
        if not text.lower().endswith(suffixes):
            raise argparse.ArgumentTypeError(f"use a {', '.join(suffixes[:-1])} or {suffixes[-1]} file name, got {text!r}"
                                             if len(suffixes) > 1 else f"use a {suffixes[0]} file name, got {text!r}")
        folder = os.path.dirname(os.path.abspath(text))
        if os.path.exists(folder) and not os.path.isdir(folder):
            raise argparse.ArgumentTypeError(f"{folder!r} is not a folder")
        return text
    return check


def _existing_file(text: str) -> str:
    if not os.path.isfile(text):
        raise argparse.ArgumentTypeError(f"no such file {text!r}")
    return text


def _existing_dir(text: str) -> str:
    if not os.path.isdir(text):
        raise argparse.ArgumentTypeError(f"no such folder {text!r}")
    return text


def _load(asf: str, amc: str, fps: float):
    from .io import read_amc, read_asf

    return read_amc(amc, read_asf(asf), fps=fps)


def _per_file(values, path: str, option: str, sep: str = "="):
    """The value of a per-file option for ``path``: ``FILE=VALUE`` entries for this file win over plain ones."""
    plain, own = None, None
    for v in values or []:
        head, found, tail = v.partition(sep)
        if found and (os.path.normpath(head) == os.path.normpath(path) or os.path.basename(path) == head):
            own = tail
        elif found and head.lower().endswith(".bvh"):
            continue
        else:
            plain = v
    return own if own is not None else plain


def _roles_for(values, path: str) -> dict:
    roles = {}
    for v in values or []:
        cut = v.lower().find(".bvh:")  # FILE.bvh:ROLE=JOINT (a joint name may hold ':', mixamorig:LeftArm)
        file, rest = (v[:cut + 4], v[cut + 5:]) if cut >= 0 else ("", v)
        if file and os.path.normpath(file) != os.path.normpath(path) and os.path.basename(path) != file:
            continue
        role, found, joint = rest.partition("=")
        if not found or not role or not joint:
            raise UsageError("--role", f"expected ROLE=JOINT or FILE.bvh:ROLE=JOINT, got {v!r}")
        roles[role] = joint
    return roles


def _load_bvh(a, path: str):
    """A BVH file as the workflow reads a trial, with this file's --length-to-m, --role and axes."""
    from .data import load_trial
    from .kinematics import AXES

    unit = _per_file(a.length_to_m, path, "--length-to-m")
    try:
        unit = 1.0 if unit is None else positive_float(unit)
    except argparse.ArgumentTypeError as exc:
        raise UsageError("--length-to-m", str(exc)) from None
    axes = {}
    for opt, key in (("--up-axis", "up_axis"), ("--forward-axis", "forward_axis")):
        v = _per_file(getattr(a, key), path, opt) or "auto"
        if v != "auto" and v.lower() not in AXES and "+" + v.lower() not in AXES:
            raise UsageError(opt, f"expected auto or one of {', '.join(AXES)}, got {v!r}")
        axes[key] = v
    return load_trial(bvh=path, joint_roles=_roles_for(a.role, path), bvh_length_to_m=unit,
                      name=os.path.splitext(os.path.basename(path))[0], setting_names=CLI_SETTING_NAMES,
                      bvh_root=_per_file(getattr(a, "root", None), path, "--root"), **axes)


#: How :func:`animsynth.data.load_trial` names its settings in errors and warnings from the command line.
CLI_SETTING_NAMES = {"joint_roles": "argument --role", "up_axis": "--up-axis (e.g. --up-axis FILE=+y)",
                     "bvh_length_to_m": "--length-to-m"}
#: The per-file options (``FILE=VALUE``; ``--role FILE.bvh:ROLE=JOINT``) of the commands that read BVH files.
PER_FILE_OPTIONS = (("--length-to-m", "length_to_m"), ("--up-axis", "up_axis"), ("--forward-axis", "forward_axis"),
                    ("--role", "role"), ("--root", "root"))


def _check_per_file_options(a) -> None:
    """Refuse a per-file option that names no input file, or gives a file no value (``walk.bvh=``).

    A ``FILE=VALUE`` entry (``FILE.bvh:ROLE=JOINT`` for ``--role``) whose ``FILE`` is none of the command's
    input files, by path or by file name, would be ignored: a typo would silently leave that file at the
    default. Entries without a file part apply to every file and are checked where they are used.
    """
    inputs = [f for f in _inputs(a) if f.lower().endswith(".bvh")]
    for option, key in PER_FILE_OPTIONS:
        for v in getattr(a, key, None) or []:
            if key == "role":
                cut = v.lower().find(".bvh:")
                if cut < 0:
                    continue
                head, value = v[:cut + 4], v[cut + 5:]
            else:
                head, found, value = v.partition("=")
                if not found or not head.lower().endswith(".bvh"):
                    continue
            if not any(os.path.normpath(head) == os.path.normpath(f) or os.path.basename(f) == head
                       for f in inputs):
                raise UsageError(option, f"{v!r} names {head!r}, which is not one of the input files "
                                         f"({', '.join(inputs) or 'none is a .bvh file'})")
            if not value.strip():
                raise UsageError(option, f"{v!r} gives {head!r} no value")


def _split_motion_args(files: list[str], out: str | None, outputs: tuple[str, ...]):
    """``(inputs, out)`` from positional files: the output is ``--out`` or the last file with an output suffix."""
    files = list(files)
    if out is None:
        if len(files) >= 2 and files[-1].lower().endswith(outputs):
            out = files.pop()
        else:
            raise UsageError("out", f"give the output file last (a {', '.join(outputs)} file name) or with --out")
    for f in files:
        if not os.path.isfile(f):
            raise UsageError("input", f"no such file {f!r}")
    try:
        _out_with(outputs)(out)
    except argparse.ArgumentTypeError as exc:
        raise UsageError("out", str(exc)) from None
    return files, out


def _load_any(a, files: list[str]):
    """One motion from ``files``: a .bvh file, or an .asf and an .amc file (either order)."""
    low = [f.lower() for f in files]
    if len(files) == 1 and low[0].endswith(".bvh"):
        return _load_bvh(a, files[0]), files[0]
    if len(files) == 2 and sorted(os.path.splitext(f)[1] for f in low) == [".amc", ".asf"]:
        asf, amc = (files[0], files[1]) if low[0].endswith(".asf") else (files[1], files[0])
        return _load(asf, amc, a.fps), amc
    raise UsageError("input", f"expected one .bvh file or an .asf and an .amc file, got {' '.join(files)}")


def _inputs(a) -> list[str]:
    """The input files a command was given: ``--asf``/``amc``, the training files or the positional files."""
    names = [getattr(a, k, None) for k in ("asf", "amc")]
    names += list(getattr(a, "train", None) or []) + list(getattr(a, "files", None) or [])
    names += list(getattr(a, "generated", None) or []) + [getattr(a, "reference", None)]
    names += list(getattr(a, "database", None) or [])
    return [n for n in dict.fromkeys(names) if n]


