"""Getting mocap trials: download/copy with checksums, and parse (Gauch & Peters Table I of the subsets:
:mod:`animsynth.simplicial.table1`).

Real CMU files are fetched per file from ``<mirror>/subjects/<SS>/<file>``
where the mirror is ``http://mocap.cs.cmu.edu`` (the official site) or any URL
or local folder with the same layout (``cmu_mirror`` in the config).
Checksums are SHA-256 of the file with line endings normalised to LF, since
mirrors of the same CMU file differ only in CRLF vs LF. Files are written
atomically: a failed download or a checksum mismatch leaves no file behind.
"""

from __future__ import annotations

import hashlib
import logging
import time
import urllib.error
import urllib.request

from .config import ConfigError, resolve_inside
from .io.amc import read_amc
from .io.asf import read_asf
from .atomic import atomic_path
from .motion import Motion

log = logging.getLogger("animsynth.data")


class DownloadError(RuntimeError):
    """A file could not be fetched, or its checksum did not match."""


def sha256_normalised(data: bytes) -> str:
    """SHA-256 of ``data`` with CRLF (and lone CR) line endings turned into LF."""
    return hashlib.sha256(data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")).hexdigest()


def _is_url(s: str) -> bool:
    return s.startswith(("http://", "https://", "ftp://", "file://"))


def fetch_bytes(source: str, rel: str, timeout: float = 60.0, attempts: int = 3, wait: float = 5.0) -> bytes:
    """Read ``rel`` below ``source`` (a URL or a local folder).

    ``rel`` must stay inside ``source`` (see
    :func:`animsynth.config.resolve_inside`); anything else is refused.
    A network failure (no answer, timeout) is tried ``attempts`` times,
    ``wait * n`` seconds apart; an HTTP error status, a missing local file and
    (in :func:`fetch_file`) a checksum mismatch are deterministic and fail at
    once, so the workflow rule itself does not retry.
    """
    try:
        inside = resolve_inside(source, rel, rel)
    except ConfigError as exc:
        raise DownloadError(f"refusing to fetch {rel!r}: {str(exc).split(': ', 1)[1]}") from None
    if _is_url(source):
        url = inside
        for attempt in range(1, attempts + 1):
            try:
                with urllib.request.urlopen(url, timeout=timeout) as r:  # noqa: S310 (configured mirror)
                    return r.read()
            except urllib.error.HTTPError as exc:  # the server answered: retrying gives the same answer
                raise DownloadError(f"cannot download {url}: {exc}") from None
            except (urllib.error.URLError, TimeoutError, OSError) as exc:
                if attempt == attempts:
                    raise DownloadError(f"cannot download {url}: {exc} ({attempts} attempts)") from None
                log.warning("download of %s failed (%s); attempt %d of %d in %.0f s", url, exc, attempt + 1,
                            attempts, wait * attempt)
                time.sleep(wait * attempt)
    path = inside
    try:
        with open(path, "rb") as f:
            return f.read()
    except OSError as exc:
        raise DownloadError(f"cannot read {path} (mirror {source!r}): {exc.strerror}") from None


def fetch_file(source: str, rel: str, dest, sha256: str | None, attempts: int = 3, wait: float = 5.0) -> str:
    """Fetch ``rel`` from ``source`` into ``dest`` after checking its checksum.

    Returns the normalised SHA-256. Raises :class:`DownloadError` on a network
    failure (after ``attempts`` tries, see :func:`fetch_bytes`), a path that
    leaves ``source`` or a checksum mismatch (at once); ``dest`` is then not
    created.
    """
    data = fetch_bytes(source, rel, attempts=attempts, wait=wait)
    got = sha256_normalised(data)
    if sha256 is not None and got != sha256.lower():
        raise DownloadError(
            f"checksum mismatch for {rel} from {source!r}: expected {sha256}, got {got} "
            "(SHA-256 after normalising line endings to LF; not retried: the file itself differs)"
        )
    with atomic_path(dest) as tmp:
        with open(tmp, "wb") as f:
            f.write(data)
    log.info("fetched %s from %s (sha256 %s)", rel, source, got)
    return got


def load_trial(amc=None, asf=None, bvh=None, fps: float = 120.0, name: str = "", joint_roles: dict | None = None,
               bvh_length_to_m: float = 1.0) -> Motion:
    """Parse one trial (ASF+AMC, or BVH) into a :class:`Motion`.

    ``joint_roles`` (config ``joint_roles``) are checked against the skeleton
    and stored on it (:attr:`Skeleton.roles`, see :mod:`animsynth.joints`).
    A BVH file's lengths are ``bvh_length_to_m`` metres per unit; a skeleton
    whose rest height is then below 0.3 m or above 3 m is logged as a warning
    (the unit is probably wrong).
    """
    from .joints import check_role_overrides

    if bvh is not None:
        from .io.bvh import read_bvh
        from .kinematics import forward_kinematics

        m = read_bvh(bvh)
        m.skeleton.length_to_m = float(bvh_length_to_m)
        rest = forward_kinematics(m.skeleton, m.values[:1] * 0.0)[0] * m.skeleton.length_to_m
        height = float(rest[:, 1].max() - rest[:, 1].min())
        if not 0.3 <= height <= 3.0:
            log.warning("%s: the skeleton is %.3g m tall at rest with bvh_length_to_m=%g; set bvh_length_to_m to "
                        "the file's unit (0.01 for centimetres, 0.0254 for inches)", bvh, height, bvh_length_to_m)
    else:
        m = read_amc(amc, read_asf(asf), fps=fps)
    try:
        check_role_overrides(m.skeleton.names, joint_roles)
    except ValueError as exc:
        raise ConfigError(f"config key {exc} (in {bvh or asf})") from None
    m.skeleton.roles = dict(joint_roles or {})
    m.name = name or m.name
    return m
