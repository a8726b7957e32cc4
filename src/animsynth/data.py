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
import os
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


#: A skeleton's standing height (metres) outside this range is logged as a probably wrong unit.
HEIGHT_RANGE_M = (0.3, 3.0)


def _rename_path(exc: Exception, files: dict, shown: dict):
    """``exc`` (a MotionFormatError) naming the user's own file instead of the copy that was read."""
    from .errors import MotionFormatError

    if isinstance(exc, MotionFormatError):
        for key, p in files.items():
            if p is not None and key in shown and os.path.abspath(exc.path) == os.path.abspath(os.fspath(p)):
                return MotionFormatError(shown[key], exc.line, exc.message)
    return exc


def load_trial(amc=None, asf=None, bvh=None, fps: float = 120.0, name: str = "", joint_roles: dict | None = None,
               bvh_length_to_m: float = 1.0, up_axis: str | None = "auto", forward_axis: str | None = "auto",
               source_files: dict | None = None) -> Motion:
    """Parse one trial (ASF+AMC, or BVH) into a :class:`Motion` in the canonical frame (+y up, +z forward).

    Parameters
    ----------
    amc, asf, bvh : path, optional
        ASF + AMC, or BVH.
    fps : float
        Frame rate of an AMC file (a BVH file carries its own).
    joint_roles : dict, optional
        ``{role: joint name}`` (config ``joint_roles``, the trial's over the
        top-level ones); checked against the skeleton and stored on it
        (:attr:`Skeleton.roles`, see :mod:`animsynth.joints`).
    bvh_length_to_m : float
        A BVH file's metres per length unit (0.01 centimetres, 0.05644
        cgspeed's CMU conversions, which keep the ASF unit).
    up_axis, forward_axis : str or None
        The file's world axes (``"+z"``, ...), or ``"auto"``/None. For BVH,
        ``auto`` detects the up axis from the motion
        (:func:`animsynth.kinematics.detect_up_axis`) and takes the forward
        axis that the smallest turn to +y brings to +z; the motion is then
        turned into the canonical frame
        (:func:`animsynth.kinematics.to_canonical_frame`). ASF/AMC is +y up by
        the format's convention (CMU): ``auto`` keeps it, logging a warning
        if the motion looks otherwise.
    source_files : dict, optional
        ``{"amc"|"asf"|"bvh": the user's own path}``: named in errors instead
        of the copy that is read (the workflow reads copies under resources/).

    The standing height (median over frames of the extent along the up axis,
    :func:`animsynth.kinematics.standing_height`) in metres outside
    :data:`HEIGHT_RANGE_M` is logged as a warning (the unit is probably
    wrong). One log line gives the axes used and how they were found.

    Every rotational DOF is made continuous along time
    (:func:`animsynth.kinematics.unwrap_angles`: an angle that wraps past 180
    degrees gets the multiple of 360 that removes the jump; logged when it
    happens), so no method sees a wrap. Translations are untouched.
    """
    from .errors import MotionFormatError
    from .joints import check_role_overrides
    from .kinematics import (CANONICAL_FORWARD, CANONICAL_UP, default_forward, detect_forward_axis, detect_up_axis,
                             parse_axis, standing_height, to_canonical_frame, translated_joints, unwrap_angles)

    files = {"amc": amc, "asf": asf, "bvh": bvh}
    shown = dict(source_files or {})
    where = shown.get("bvh") or shown.get("asf") or bvh or asf
    try:
        if bvh is not None:
            from .io.bvh import read_bvh

            m = read_bvh(bvh)
            m.skeleton.length_to_m = float(bvh_length_to_m)
        else:
            m = read_amc(amc, read_asf(asf), fps=fps)
    except MotionFormatError as exc:
        raise _rename_path(exc, files, shown) from None
    try:
        check_role_overrides(m.skeleton.names, joint_roles)
    except ValueError as exc:
        raise ConfigError(f"config key {exc} (in {where})") from None
    m.skeleton.roles = dict(joint_roles or {})
    roles = m.skeleton.roles
    sk, v = m.skeleton, m.values
    auto_up = up_axis in (None, "auto")
    detected, info = detect_up_axis(sk, v, roles)
    if bvh is None and auto_up:
        up = CANONICAL_UP
        if detected != up:
            log.warning("%s: the motion looks %s up (median extents x y z: %s), ASF/AMC is read +y up; set up_axis "
                        "on the trial if the file is not", where, detected, _fmt(info["extent"]))
    else:
        up = detected if auto_up else parse_axis(up_axis)
    fwd = default_forward(up) if forward_axis in (None, "auto") else parse_axis(forward_axis)
    how = (f"detected (tallest along it in most frames, sign from {info['sign_from']}; median extents x y z "
           f"{_fmt(info['extent'])})" if auto_up and bvh is not None else "given" if not auto_up else "ASF/AMC")
    if auto_up and bvh is not None and info["ratio"] > 0.8:
        log.warning("%s: the up axis %s is ambiguous (median extents x y z %s); set up_axis on the trial",
                    where, up, _fmt(info["extent"]))
    if (up, fwd) != (CANONICAL_UP, CANONICAL_FORWARD):
        sk, v = to_canonical_frame(sk, v, up, fwd)
        m = Motion(v, sk, m.fps, m.name, m.meta)
    faces, src = detect_forward_axis(sk, v, CANONICAL_UP, roles)
    log.info("%s: up axis %s (%s), forward axis %s%s; turned to +y up, +z forward; the body faces mostly %s in the "
             "result (from the %s)", where, up, how, fwd, " (given)" if forward_axis not in (None, "auto") else "",
             faces, src)
    moved = translated_joints(sk)
    if moved:
        log.info("%s: joints other than the root with translation over the frames: %s (their translation is part "
                 "of the pose: see docs/data.md for how each family uses it)", where, ", ".join(moved))
    height = standing_height(sk, v, CANONICAL_UP) * sk.length_to_m if bvh is not None else None
    if height is not None:
        log.info("%s: stands %.3g m tall (median over frames along the up axis) with bvh_length_to_m=%g", where,
                 height, bvh_length_to_m)
    if height is not None and not HEIGHT_RANGE_M[0] <= height <= HEIGHT_RANGE_M[1]:
        log.warning("%s: the skeleton stands %.3g m tall (median over frames along the up axis %s) with "
                    "bvh_length_to_m=%g; set bvh_length_to_m to the file's unit (0.01 for centimetres, 0.0254 for "
                    "inches, 0.05644 for cgspeed's CMU conversions)", where, height, up, bvh_length_to_m)
    m.name = name or m.name
    return unwrap_angles(m, where)


def _fmt(a) -> str:
    return " ".join(f"{float(x):.4g}" for x in a)
