"""Where real data come from: is a source reachable, and getting a mesh sequence.

Two jobs, both used by the workflow before any experiment runs:

* :func:`probe_source` answers, quickly and without raising, whether a data
  source (a local folder, or a URL) can be read right now. The paper run uses
  it to skip a family whose real data are unavailable, with one clear line,
  instead of failing half-way through a download.
* :func:`fetch_mesh_frames` and :func:`verify_mesh_frames` turn ``mesh_dir``
  (a folder, a ``.zip`` / ``.tar.gz`` archive, or a URL of one) into a folder
  of OBJ frames checked against a SHA-256 list (``sha256sum`` format, hashes of
  the *uncompressed* OBJ files, so ``.obj.gz`` frames are hashed after
  decompression). A mismatch names the frame.

The standard library does all of this (``urllib``, ``zipfile``, ``tarfile``,
``hashlib``); nothing here knows any animation method.
"""

from __future__ import annotations

import gzip
import hashlib
import logging
import os
import re
import shutil
import tarfile
import tempfile
import urllib.error
import urllib.request
import zipfile
from pathlib import Path

import pandas as pd

from .io.obj import frame_stem, is_frame_name

log = logging.getLogger("animsynth.sources")

ARCHIVE_SUFFIXES = (".zip", ".tar.gz", ".tgz", ".tar")
#: Default cap (MB, 10**6 bytes) on the total unpacked size of a mesh archive.
DEFAULT_MAX_UNPACKED_MB = 8000.0


class MeshSourceError(RuntimeError):
    """A mesh source could not be read, unpacked or verified (the message names the file or frame)."""


def is_url(s: str) -> bool:
    return str(s).startswith(("http://", "https://", "ftp://", "file://"))


def is_archive(s: str) -> bool:
    return str(s).lower().endswith(ARCHIVE_SUFFIXES)


def mesh_source_name(source: str) -> str:
    """A folder name for an archive or URL: its file name without the archive suffix."""
    name = str(source).rstrip("/").rsplit("/", 1)[-1]
    for suf in ARCHIVE_SUFFIXES:
        if name.lower().endswith(suf):
            name = name[: -len(suf)]
            break
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "mesh"


def probe_source(source: str | os.PathLike | None, probe: str | None = None, timeout: float = 5.0) -> tuple[bool, str]:
    """Can ``source`` be read now?

    Parameters
    ----------
    source : str or path or None
        A local folder or file, or a URL.
    probe : str, optional
        A path below ``source`` that must exist (for a folder) or answer (for
        a URL), e.g. the first trial's AMC file. Without it a URL is asked for
        itself.
    timeout : float
        Seconds to wait for a URL.

    Returns
    -------
    ok : bool
    reason : str
        Empty when ``ok``; otherwise one line saying what is missing.
    """
    if not source:
        return False, "no source configured"
    s = str(source)
    if is_url(s):
        url = s.rstrip("/") + ("/" + probe.lstrip("/") if probe else "")
        req = urllib.request.Request(url, method="HEAD")
        try:
            with urllib.request.urlopen(req, timeout=timeout):
                return True, ""
        except urllib.error.HTTPError as e:  # the server answered: reachable unless the file is missing
            if e.code in (403, 405, 501):  # HEAD refused: the host is up
                return True, ""
            return False, f"{url} answered HTTP {e.code}"
        except (urllib.error.URLError, OSError, ValueError) as e:
            reason = getattr(e, "reason", e)
            return False, f"{url} is not reachable ({reason})"
    p = Path(s)
    if not p.exists():
        return False, f"{p} does not exist"
    if probe and not p.is_dir():  # a mirror (files below it) that is a file
        return False, f"{p} is a file, not a folder"
    if probe and not (p / probe).is_file():
        return False, f"{p / probe} does not exist" if not (p / probe).exists() else f"{p / probe} is not a file"
    return True, ""


def missing_below(source: str | os.PathLike | None, paths) -> list[str]:
    """The ``paths`` (relative) that are not readable files below the local folder ``source``, in order; none for a
    URL or no source (a URL is probed once, by :func:`probe_source`: asking it for every file would take minutes).

    A symbolic link to a readable file counts as that file (a mirror may be a folder of links).
    """
    if not source or is_url(str(source)):
        return []
    root = Path(source)
    return [p for p in paths if not (root / p).is_file() or not os.access(root / p, os.R_OK)]


def list_frames(folder: str | os.PathLike) -> list[Path]:
    """Frame files directly in ``folder`` (:func:`animsynth.io.obj.is_frame_name`), sorted by name."""
    return sorted(p for p in Path(folder).iterdir() if p.is_file() and is_frame_name(p.name))


def _frames_folder(root: Path, source) -> Path:
    """The one folder below ``root`` holding frames (archives often nest one level).

    Hidden and ``__MACOSX`` folders never hold frames; frames in two folders
    are refused, naming both, since which one is meant cannot be guessed.
    """
    found = [d for d in [root, *sorted(p for p in root.rglob("*") if p.is_dir())]
             if is_frame_name(d.relative_to(root) / "x.obj") and list_frames(d)]
    if not found:
        raise MeshSourceError(f"{source}: no .obj or .obj.gz frames found")
    if len(found) > 1:
        a, b = (str(d.relative_to(root)) or "." for d in found[:2])
        raise MeshSourceError(f"{source}: frames in more than one folder ({a!r} with {len(list_frames(found[0]))}, "
                              f"{b!r} with {len(list_frames(found[1]))}); keep one sequence per archive")
    return found[0]


def _extract(archive: Path, dest: Path, max_unpacked_mb: float = DEFAULT_MAX_UNPACKED_MB) -> None:
    """Unpack ``archive`` into ``dest``, refusing members that would land outside it
    and archives whose members add up to more than ``max_unpacked_mb`` MB."""
    dest = dest.resolve()
    name = archive.name.lower()
    cap = float(max_unpacked_mb) * 1e6

    def check_size(total: float) -> None:
        if total > cap:
            raise MeshSourceError(f"{archive}: unpacks to {total / 1e6:.6g} MB, over the {max_unpacked_mb:g} MB cap "
                                  "(config key meshdetail.max_unpacked_mb)")
    try:
        if name.endswith(".zip"):
            with zipfile.ZipFile(archive) as z:
                check_size(sum(i.file_size for i in z.infolist()))
                for m in z.namelist():
                    target = (dest / m).resolve()
                    if not str(target).startswith(str(dest) + os.sep) and target != dest:
                        raise MeshSourceError(f"{archive}: member {m!r} would be written outside the target folder")
                z.extractall(dest)
        else:
            with tarfile.open(archive, "r:*") as t:
                check_size(sum(m.size for m in t.getmembers() if m.isfile()))
                t.extractall(dest, filter="data")  # refuses absolute paths, '..' and links out of dest
    except (zipfile.BadZipFile, tarfile.TarError, EOFError, OSError) as e:
        if isinstance(e, MeshSourceError):
            raise
        raise MeshSourceError(f"{archive}: cannot unpack ({e})") from e


def _download(url: str, dest: Path, timeout: float, max_mb: float) -> None:
    """Copy ``url`` to ``dest``, stopping with :class:`MeshSourceError` once it passes ``max_mb`` MB.

    A declared ``Content-Length`` over the cap is refused before the copy;
    either way the partial file is removed.
    """
    cap = float(max_mb) * 1e6

    def over(size: str) -> MeshSourceError:
        return MeshSourceError(f"{url}: download is {size} MB, over the {max_mb:g} MB cap "
                               "(config key meshdetail.max_unpacked_mb); stopped, nothing kept")
    total = 0
    try:
        with urllib.request.urlopen(url, timeout=timeout) as r:
            declared = r.headers.get("Content-Length")
            if declared and declared.strip().isdigit() and int(declared) > cap:
                raise over(f"{int(declared) / 1e6:.6g}")
            with open(dest, "wb") as f:
                for chunk in iter(lambda: r.read(1 << 20), b""):
                    total += len(chunk)
                    if total > cap:
                        raise over(f"more than {cap / 1e6:.6g}")
                    f.write(chunk)
    except (urllib.error.URLError, OSError, ValueError) as e:
        dest.unlink(missing_ok=True)
        raise MeshSourceError(f"{url}: download failed ({getattr(e, 'reason', e)})") from e
    except MeshSourceError:
        dest.unlink(missing_ok=True)
        raise


def fetch_mesh_frames(source: str, dest: str | os.PathLike, timeout: float = 120.0, sums: dict | None = None,
                      max_unpacked_mb: float = DEFAULT_MAX_UNPACKED_MB) -> list[Path]:
    """Put the OBJ frames of ``source`` (an archive file, or a URL of one) into ``dest``.

    The frames are copied flat into ``dest`` (created; must not hold frames
    already). Everything is first unpacked in a temporary folder next to
    ``dest`` and, when ``sums`` (``{frame: sha256}``) is given, checked there
    (:func:`verify_mesh_frames`), so a failed or interrupted fetch leaves
    neither ``dest`` nor the temporary folder behind. What counts as a frame
    is :func:`animsynth.io.obj.is_frame_name` (macOS ``__MACOSX`` / ``._``
    companions are ignored); frames in two folders of the archive are refused.
    An archive unpacking to more than ``max_unpacked_mb`` MB is refused before
    anything is written; so is a download that passes ``max_unpacked_mb`` MB
    (the copy stops there: an archive is at most about as large as what it
    unpacks to).

    Returns
    -------
    frames : list of Path
        The frame files in ``dest``, sorted by name.
    """
    dest = Path(dest)
    dest.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=dest.parent, prefix=".mesh-fetch-") as tmp:
        tmp = Path(tmp)
        if is_url(source):
            fname = source.rstrip("/").rsplit("/", 1)[-1] or "mesh_archive"
            archive = tmp / fname
            log.info("downloading %s", source)
            _download(source, archive, timeout, max_unpacked_mb)
        else:
            archive = Path(source)
            if not archive.is_file():
                raise MeshSourceError(f"{archive}: no such archive")
        if not is_archive(archive.name):
            raise MeshSourceError(f"{source}: not an archive ({', '.join(ARCHIVE_SUFFIXES)}) nor a folder")
        unpacked = tmp / "unpacked"
        unpacked.mkdir()
        _extract(archive, unpacked, max_unpacked_mb)
        folder = _frames_folder(unpacked, source)
        staged = tmp / "frames"
        staged.mkdir()
        for f in list_frames(folder):
            shutil.move(str(f), staged / f.name)
        if sums is not None:
            verify_mesh_frames(staged, sums)
        if dest.exists():
            shutil.rmtree(dest)
        os.replace(staged, dest)
    frames = list_frames(dest)
    log.info("%d frames from %s in %s", len(frames), source, dest)
    return frames


def read_sha256_list(path: str | os.PathLike) -> dict[str, str]:
    """Read a ``sha256sum``-style list (``<64 hex>  <file name>`` per line) into {name: hash}.

    Raises
    ------
    MeshSourceError
        Naming file and line: a malformed line, or a frame listed twice (the
        same name, or names that are the same frame such as ``a.obj`` and
        ``a.obj.gz``; both lines named): a later entry must not silently
        replace an earlier one, or a wrong first hash would verify.
    """
    out: dict[str, str] = {}
    first: dict[str, tuple[int, str]] = {}  # frame -> (line, name as listed)
    with open(path, encoding="utf-8") as f:
        for ln, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split(None, 1)
            if len(parts) != 2 or not re.fullmatch(r"[0-9a-fA-F]{64}", parts[0]):
                raise MeshSourceError(f"{path}:{ln}: expected '<sha256>  <file>', got {line[:60]!r}")
            name = parts[1].lstrip("*").strip()
            frame = frame_stem(name) if is_frame_name(name) else name
            if frame in first:
                ln0, name0 = first[frame]
                raise MeshSourceError(f"{path}:{ln}: frame {frame!r} is listed twice, as {name0!r} on line {ln0} and "
                                      f"as {name!r} on line {ln}; keep one entry")
            first[frame] = (ln, name)
            out[name] = parts[0].lower()
    return out


def _frame_hash(path: Path) -> str:
    h = hashlib.sha256()
    opener = gzip.open if path.name.lower().endswith(".gz") else open
    try:
        with opener(path, "rb") as f:
            for chunk in iter(lambda: f.read(1 << 20), b""):
                h.update(chunk)
    except (OSError, EOFError) as e:
        raise MeshSourceError(f"{path}: cannot read ({e})") from e
    return h.hexdigest()


def verify_mesh_frames(folder: str | os.PathLike, sums: dict[str, str]) -> pd.DataFrame:
    """Check every frame of ``folder`` against ``sums`` (hashes of the uncompressed OBJ files).

    Returns
    -------
    table : DataFrame
        One row per listed frame: ``frame`` (name of the uncompressed OBJ,
        as listed), ``file`` (as found), ``sha256``. A listed name and a file
        are the same frame when their :func:`~animsynth.io.obj.frame_stem`
        agree (the reader's rule: ``a.obj``, ``a.OBJ`` and ``a.obj.gz`` are
        frame ``a``).

    Raises
    ------
    MeshSourceError
        Naming the first frame that is missing, unlisted or whose hash differs.
    """
    found: dict[str, Path] = {}
    for f in list_frames(folder):
        stem = frame_stem(f.name)
        if stem in found:
            raise MeshSourceError(f"{folder}: {found[stem].name} and {f.name} are the same frame {stem!r} "
                                  "(.obj / .obj.gz in any letter case)")
        found[stem] = f
    listed: dict[str, str] = {}
    for name in sums:
        stem = frame_stem(name) if is_frame_name(name) else name
        if stem in listed:
            raise MeshSourceError(f"checksum list: {listed[stem]} and {name} are the same frame {stem!r}")
        listed[stem] = name
    extra = sorted(set(found) - set(listed))
    if extra:
        raise MeshSourceError(f"{folder}: frame {found[extra[0]].name} is not in the checksum list "
                              f"({len(extra)} unlisted frames)")
    rows = []
    for stem in sorted(listed, key=lambda k: listed[k]):
        name = listed[stem]
        if stem not in found:
            raise MeshSourceError(f"{folder}: frame {name} is missing (listed in the checksum list)")
        got = _frame_hash(found[stem])
        if got != sums[name]:
            raise MeshSourceError(f"{found[stem]}: frame {name} has SHA-256 {got}, expected {sums[name]}")
        rows.append({"frame": name, "file": found[stem].name, "sha256": got})
    return pd.DataFrame(rows, columns=["frame", "file", "sha256"])
