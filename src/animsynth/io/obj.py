"""Wavefront OBJ meshes and mesh sequences (one OBJ per frame, one topology).

The layout is the one of the public performance-capture datasets (Vlasic et
al. 2008: ``mesh_0000.obj ... mesh_0174.obj``): a folder of frames that share
their connectivity. Frames may be plain ``.obj`` or gzipped ``.obj.gz``.
Only ``v`` and ``f`` records are used (``vt``/``vn``/``g``/``o``/``s``/``usemtl``
and comments are skipped); polygons are triangulated as fans; ``f`` tokens may
be ``i``, ``i/t``, ``i//n`` or ``i/t/n`` and negative (relative) indices are
accepted.

:class:`MeshSequence` is cached between workflow rules as ``.npz``.
"""

from __future__ import annotations

import gzip
import os
import re
import zlib
from dataclasses import dataclass, field

import numpy as np

from ..atomic import atomic_path, atomic_write_bytes
from ..errors import MotionFormatError, parse_float

__all__ = ["MeshSequence", "read_obj", "write_obj", "read_obj_sequence", "write_obj_sequence", "list_obj_frames",
           "is_frame_name", "frame_stem"]


def _read_text(path) -> str:
    p = os.fspath(path)
    try:
        if p.lower().endswith(".gz"):
            with gzip.open(p, "rb") as fh:
                data = fh.read()
        else:
            with open(p, "rb") as fh:
                data = fh.read()
    except (OSError, EOFError, zlib.error) as exc:
        # gzip raises EOFError for a truncated stream, zlib.error for corrupt
        # data and BadGzipFile (an OSError) for a file that is not gzip at all
        what = "truncated or corrupt gzip data" if isinstance(exc, (EOFError, zlib.error, gzip.BadGzipFile)) \
            else "cannot read"
        raise MotionFormatError(path, None, f"{what}: {exc}") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def _slow_parse(path, lines):
    """Line-by-line parser: exact errors with line numbers (used when the fast path fails)."""
    verts, faces = [], []
    for ln, raw in enumerate(lines, start=1):
        tok = raw.split()
        if not tok or tok[0].startswith("#"):
            continue
        if tok[0] == "v":
            if len(tok) < 4:
                raise MotionFormatError(path, ln, f"vertex record needs 3 coordinates, got {len(tok) - 1}")
            verts.append([parse_float(t, path, ln, "vertex coordinate") for t in tok[1:4]])
        elif tok[0] == "f":
            if len(tok) < 4:
                raise MotionFormatError(path, ln, f"face record needs at least 3 vertices, got {len(tok) - 1}")
            idx = []
            for t in tok[1:]:
                head = t.split("/")[0]
                try:
                    i = int(head)
                except ValueError:
                    raise MotionFormatError(path, ln, f"non-integer face index {t[:40]!r}") from None
                if i == 0:
                    raise MotionFormatError(path, ln, "face index 0 (OBJ indices are 1-based)")
                i = i - 1 if i > 0 else len(verts) + i
                if i < 0 or i >= len(verts):
                    raise MotionFormatError(path, ln, f"face index {t[:40]!r} refers to a vertex not defined before it")
                idx.append(i)
            for k in range(1, len(idx) - 1):
                faces.append([idx[0], idx[k], idx[k + 1]])
    return verts, faces


def _fast_parse(lines):
    """Vectorised parse of a plain triangle OBJ, or None to use :func:`_slow_parse`.

    It accepts exactly the files whose every ``v`` record has 3 numbers and
    every ``f`` record 3 positive plain indices to vertices defined before
    it, with finite coordinates. On anything else (polygons, ``i/t/n``
    tokens, negative indices, ``w`` coordinates, junk) it returns None, so
    the careful parser either reads the file or refuses it with file and
    line: the two parsers never disagree on a file.
    """
    vrec: list[list[str]] = []
    frec: list[list[str]] = []
    defined: list[int] = []  # vertices defined before each face
    for raw in lines:
        tok = raw.split()
        if not tok:
            continue
        if tok[0] == "v":
            if len(tok) != 4:
                return None
            vrec.append(tok[1:])
        elif tok[0] == "f":
            if len(tok) != 4 or "/" in raw:
                return None
            frec.append(tok[1:])
            defined.append(len(vrec))
    try:
        verts = np.array(vrec, dtype=float).reshape(-1, 3)
        faces = np.array(frec, dtype=np.int64).reshape(-1, 3)
    except (ValueError, OverflowError):  # an index past int64: the careful parser names file and line
        return None
    if not np.all(np.isfinite(verts)):
        return None
    if faces.size and (faces.min() < 1 or np.any(faces.max(axis=1) > np.array(defined))):
        return None
    return verts, faces - 1


def read_obj(path) -> tuple[np.ndarray, np.ndarray]:
    """Read one OBJ (or OBJ.gz) file.

    Returns
    -------
    vertices : ndarray (V, 3) float64
    faces : ndarray (T, 3) int64, 0-based triangle indices

    Raises
    ------
    MotionFormatError
        Unreadable file, malformed ``v``/``f`` record, non-finite coordinate,
        out-of-range face index, or a file without vertices; names file and line.
    """
    text = _read_text(path)
    lines = text.splitlines()
    fast = _fast_parse(lines)
    if fast is None:
        v, f = _slow_parse(path, lines)
        verts = np.array(v, float).reshape(-1, 3)
        faces = np.array(f, np.int64).reshape(-1, 3)
    else:
        verts, faces = fast
    if len(verts) == 0:
        raise MotionFormatError(path, None, "no vertices ('v' records)")
    return verts, faces


def write_obj(path, vertices, faces, precision: int = 6) -> None:
    """Write a triangle mesh as OBJ (gzipped when ``path`` ends in ``.gz``), atomically."""
    v = np.asarray(vertices, float)
    f = np.asarray(faces, np.int64)
    if not np.all(np.isfinite(v)):
        bad = int(np.argwhere(~np.isfinite(v))[0, 0])
        raise ValueError(f"refusing to write {path}: vertex {bad} is not finite")
    fmt = f"%.{precision}g"
    parts = ["# OBJ written by animsynth\n"]
    parts.append("".join("v " + " ".join(fmt % c for c in row) + "\n" for row in v))
    parts.append("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in f))
    data = "".join(parts).encode()
    if os.fspath(path).endswith(".gz"):
        data = gzip.compress(data, compresslevel=6, mtime=0)
    atomic_write_bytes(path, data)


def _natural_key(s: str):
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", s)]


_FRAME_RX = re.compile(r"\.obj(\.gz)?$", re.IGNORECASE)
#: Folders whose content is never frames: macOS Finder's resource forks.
JUNK_FOLDERS = ("__MACOSX",)


def is_frame_name(path) -> bool:
    """Does ``path`` (a file path, relative or not) name a mesh frame?

    The one rule shared by the reader, the fetch and the checksum check: the
    file name ends in ``.obj`` or ``.obj.gz`` in any letter case; hidden files
    (``.``-prefixed, e.g. macOS ``._mesh_0001.obj`` companions) and anything
    inside a hidden folder or a ``__MACOSX`` folder are not frames.
    """
    parts = [p for p in re.split(r"[\\/]+", os.fspath(path)) if p not in ("", ".")]
    if not parts or not _FRAME_RX.search(parts[-1]):
        return False
    return not any(p.startswith(".") or p in JUNK_FOLDERS for p in parts)


def frame_stem(name: str) -> str:
    """The frame name without ``.obj`` / ``.obj.gz`` (any case)."""
    return _FRAME_RX.sub("", os.path.basename(name))


def list_obj_frames(folder) -> list[str]:
    """Frame files directly in a mesh sequence folder (:func:`is_frame_name`), in natural order."""
    folder = os.fspath(folder)
    if not os.path.isdir(folder):
        raise FileNotFoundError(f"mesh sequence folder {folder!r} does not exist")
    files = [os.path.join(folder, f) for f in os.listdir(folder)
             if is_frame_name(f) and os.path.isfile(os.path.join(folder, f))]
    stems = {}
    for f in files:
        stem = frame_stem(f)
        if stem in stems:
            raise MotionFormatError(f, None, f"frame {stem!r} exists twice (as {os.path.basename(stems[stem])!r} too)")
        stems[stem] = f
    return [stems[s] for s in sorted(stems, key=_natural_key)]


@dataclass
class MeshSequence:
    """A mesh animation with one topology.

    Attributes
    ----------
    vertices : ndarray (frames, V, 3)
    faces : ndarray (T, 3) int, 0-based
    names : list of str, one frame name per frame
    fps : float
    meta : dict of str -> str (free-form, stored in the npz)
    """

    vertices: np.ndarray
    faces: np.ndarray
    names: list[str] = field(default_factory=list)
    fps: float = 30.0
    meta: dict = field(default_factory=dict)

    @property
    def n_frames(self) -> int:
        return int(self.vertices.shape[0])

    @property
    def n_vertices(self) -> int:
        return int(self.vertices.shape[1])

    def save_npz(self, path) -> None:
        import json

        with atomic_path(path, suffix=".npz") as tmp:
            np.savez_compressed(tmp, vertices=self.vertices.astype(np.float64), faces=self.faces.astype(np.int64),
                                names=np.array(self.names), fps=np.float64(self.fps),
                                meta=np.array(json.dumps(self.meta, sort_keys=True)))

    @classmethod
    def load_npz(cls, path) -> "MeshSequence":
        import json

        with np.load(path, allow_pickle=False) as z:
            return cls(np.array(z["vertices"]), np.array(z["faces"]), [str(n) for n in z["names"]],
                       float(z["fps"]), json.loads(str(z["meta"])))


def read_obj_sequence(folder, cache=None, fps: float = 30.0, max_frames: int | None = None) -> MeshSequence:
    """Read a folder of OBJ / OBJ.gz frames that share one topology.

    Parameters
    ----------
    folder : path
    cache : path or None
        ``.npz`` cache; read from it when it exists and is newer than every
        frame, otherwise written after parsing.
    fps : float
        Frame rate to record (OBJ files carry none).
    max_frames : int or None
        Read only the first frames.

    Raises
    ------
    MotionFormatError
        An unreadable or malformed frame, or a frame whose vertex count or
        connectivity differs from the first frame (the message names the frame).
    FileNotFoundError
        Missing folder or a folder without frames.
    """
    files = list_obj_frames(folder)
    if not files:
        raise FileNotFoundError(f"no .obj or .obj.gz frames in {os.fspath(folder)!r}")
    if max_frames is not None:
        files = files[: int(max_frames)]
    if cache is not None and os.path.exists(cache):
        newest = max(os.path.getmtime(f) for f in files)
        if os.path.getmtime(cache) >= newest:
            seq = MeshSequence.load_npz(cache)
            names = [os.path.basename(f) for f in files]
            if seq.names == names:
                return seq
    verts, faces0 = [], None
    for f in files:
        v, fc = read_obj(f)
        if faces0 is None:
            faces0 = fc
            n0 = len(v)
        else:
            if len(v) != n0:
                raise MotionFormatError(f, None, f"topology mismatch: frame has {len(v)} vertices, first frame "
                                                 f"{os.path.basename(files[0])} has {n0}")
            if fc.shape != faces0.shape or not np.array_equal(fc, faces0):
                k = "a different number of faces" if fc.shape != faces0.shape else \
                    f"different connectivity (first differing face {int(np.argwhere(np.any(fc != faces0, axis=1))[0, 0])})"
                raise MotionFormatError(f, None, f"topology mismatch: frame has {k} than first frame "
                                                 f"{os.path.basename(files[0])}")
        verts.append(v)
    seq = MeshSequence(np.stack(verts), faces0, [os.path.basename(f) for f in files], fps,
                       {"source": os.path.abspath(os.fspath(folder))})
    if cache is not None:
        seq.save_npz(cache)
    return seq


def write_obj_sequence(folder, seq: MeshSequence, prefix: str = "mesh_", gz: bool = False) -> list[str]:
    """Write every frame as ``<folder>/<prefix>NNNN.obj[.gz]``; return the paths."""
    os.makedirs(folder, exist_ok=True)
    ext = ".obj.gz" if gz else ".obj"
    paths = []
    for t in range(seq.n_frames):
        p = os.path.join(folder, f"{prefix}{t:04d}{ext}")
        write_obj(p, seq.vertices[t], seq.faces)
        paths.append(p)
    return paths
