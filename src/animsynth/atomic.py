"""Atomic file writing: write to a temporary file beside the target, then rename.

A crash or an exception never leaves a half-written output under the final
name. The temporary is named after its target (``.tmp-<name>-XXXXXXXX<ext>``)
so that :func:`clean_stale_temporaries` can remove the ones a killed job
(SIGKILL, node failure) left behind without touching other jobs' live
temporaries in the same folder. Errors name the target, not the temporary.
"""

from __future__ import annotations

import contextlib
import errno
import glob
import logging
import os
import tempfile

log = logging.getLogger("animsynth.io")

TMP_PREFIX = ".tmp-"

#: errno values of a full disk or quota: raised by a write, they name no file.
_FULL = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG}


def _tmp_prefix(path: str) -> str:
    # the name is cut so that prefix + random part + suffix fit a file name
    return f"{TMP_PREFIX}{os.path.basename(path)[:100]}-"


def _reraise_for_target(exc: OSError, path: str):
    """The same OSError type and errno, naming ``path`` instead of the temporary."""
    return type(exc)(exc.errno, f"cannot write {path}: {exc.strerror or exc}")


@contextlib.contextmanager
def atomic_path(path, suffix: str | None = None):
    """Yield a temporary path in the target's folder; rename it to ``path`` on success.

    ``suffix`` defaults to the target's own extension so that writers which
    infer the format from the name (matplotlib, numpy) behave.

    Raises
    ------
    OSError
        (e.g. ``PermissionError``) naming ``path`` when its folder cannot be
        created or written, and when the disk or quota is full while the
        caller writes the temporary (``ENOSPC``, ``EDQUOT``, ``EFBIG``: the
        system's message names no file).
    """
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    base = os.path.basename(path)
    if suffix is None:
        suffix = base[base.index("."):] if "." in base else ""
    try:
        os.makedirs(folder, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=_tmp_prefix(path), suffix=suffix, dir=folder)
    except OSError as exc:
        raise _reraise_for_target(exc, path) from None
    os.close(fd)
    # mkstemp makes 0600 files; give the output the usual umask-based mode
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    try:
        try:
            yield tmp
        except OSError as exc:
            if exc.errno in _FULL:  # the write itself names no file: name the output
                raise _reraise_for_target(exc, path) from None
            raise
        try:
            os.replace(tmp, path)
        except OSError as exc:
            raise _reraise_for_target(exc, path) from None
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def clean_stale_temporaries(outputs) -> list[str]:
    """Remove temporaries that :func:`atomic_path` left for ``outputs``.

    A job killed with SIGKILL (or a node that died) cannot remove its
    ``.tmp-<name>-*`` files. Call this at the start of the job that (re)makes
    ``outputs``: only temporaries named after these targets are removed, so
    other jobs writing into the same folder are not disturbed. Directory
    outputs are skipped (Snakemake empties them itself).

    Parameters
    ----------
    outputs : iterable of path
        The job's output files.

    Returns
    -------
    list of str
        The removed files (each is also logged).
    """
    removed = []
    for out in outputs:
        out = os.fspath(out)
        folder = os.path.dirname(os.path.abspath(out))
        pattern = os.path.join(glob.escape(folder), glob.escape(_tmp_prefix(out)) + "*")
        for tmp in glob.glob(pattern):
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
                removed.append(tmp)
                log.info("removed stale temporary %s of %s (left by an interrupted run)", tmp, out)
    return removed


def atomic_write_text(path, text: str) -> None:
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)


def atomic_write_bytes(path, data: bytes) -> None:
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as f:
            f.write(data)
