"""Getting mocap trials: download/copy with checksums, and parse (Gauch & Peters Table I of the subsets:
:mod:`animsynth.simplicial.table1`).

Real CMU files are fetched per file from ``<mirror>/subjects/<SS>/<file>``
where the mirror is ``http://mocap.cs.cmu.edu`` (the official site) or any URL
or local folder with the same layout (``cmu_mirror`` in the config; a trial
whose record sets ``mirror: many`` is read from ``cmu_many_mirror``).
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
from typing import TYPE_CHECKING

from .atomic import atomic_path
from .config import ConfigError, resolve_inside

# The readers and Motion are imported where a trial is parsed: a download job (fetch_file) copies a file and
# needs none of numpy and scipy.
if TYPE_CHECKING:
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


#: How errors and warnings of :func:`load_trial` name its settings (the workflow's config keys).
CONFIG_SETTING_NAMES = {"joint_roles": "config key joint_roles", "up_axis": "up_axis on the trial (config key)",
                        "bvh_length_to_m": "bvh_length_to_m"}

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
               source_files: dict | None = None, first_frame: int = 0,
               setting_names: dict | None = None, bvh_root: str | None = None) -> Motion:
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
        A BVH file's metres per length unit (0.01 centimetres, 0.05644 cgspeed's CMU conversions, the ASF unit).
    bvh_root : str, optional
        The root joint of the skeleton to read from a BVH file of several (:func:`animsynth.io.bvh.read_bvh`
        ``root``; config ``bvh_root`` on the trial, command line ``--root``).
    up_axis, forward_axis : str or None
        The file's world axes (``"+z"``, ...), or ``"auto"``/None. For BVH,
        ``auto`` detects the up axis from the motion
        (:func:`animsynth.axes.detect_up_axis`) and takes the forward
        axis that the smallest turn to +y brings to +z; the motion is then
        turned into the canonical frame
        (:func:`animsynth.axes.to_canonical_frame`). ASF/AMC is +y up by
        the format's convention (CMU): ``auto`` keeps it, logging a warning
        if the motion looks otherwise.
    source_files : dict, optional
        ``{"amc"|"asf"|"bvh": the user's own path}``: named in errors instead
        of the copy that is read (the workflow reads copies under resources/).
    first_frame : int
        Frames before this one are dropped after reading (the trial record's
        ``first_frame``: e.g. the T-pose frame 0 that cgspeed's BVH
        conversions put before the capture's first frame).
    setting_names : dict, optional
        How errors and warnings name the settings ``joint_roles``, ``up_axis``
        and ``bvh_length_to_m`` (default :data:`CONFIG_SETTING_NAMES`, the
        config keys; the command line passes its options).

    Up axis: detected by :func:`animsynth.axes.detect_up_axis` (a biped by its joint roles, another body by its
    legs). A warning names the file and the ``up_axis`` setting when the body is not a biped, when the answer is
    ambiguous (a body that is not a biped then keeps the file's own axes, +y up), and when a given ``up_axis``
    leaves the body lying down or on its head (:func:`animsynth.axes.lying_down`). A joint that plays two roles
    is warned about.

    The standing height (median over frames of the extent along the up axis,
    :func:`animsynth.axes.standing_height`) in metres outside
    :data:`HEIGHT_RANGE_M` is logged as a warning (the unit is probably
    wrong). One log line gives the axes used and how they were found.

    Every rotational DOF is made continuous along time
    (:func:`animsynth.retarget.unwrap_angles`: an angle that wraps past 180
    degrees gets the multiple of 360 that removes the jump; logged when it
    happens), so no method sees a wrap. Translations are untouched.
    """
    from .axes import to_canonical_frame
    from .kinematics import CANONICAL_FORWARD, CANONICAL_UP
    from .motion import Motion
    from .retarget import unwrap_angles

    shown = dict(source_files or {})
    where = shown.get("bvh") or shown.get("asf") or bvh or asf
    m = _read_trial_files(amc, asf, bvh, fps, bvh_length_to_m, shown, bvh_root)
    m = _drop_first_frames(m, int(first_frame), where)
    names = dict(CONFIG_SETTING_NAMES, **(setting_names or {}))
    roles = _set_roles(m.skeleton, joint_roles, where, names)
    sk, v = m.skeleton, m.values
    up, fwd, how = _file_axes(sk, v, roles, bvh is not None, up_axis, forward_axis, where, names)
    if (up, fwd) != (CANONICAL_UP, CANONICAL_FORWARD):
        sk, v = to_canonical_frame(sk, v, up, fwd)
        m = Motion(v, sk, m.fps, m.name, m.meta)
    _log_frame(sk, v, roles, where, f"up axis {up} ({how}), forward axis {fwd}"
               + (" (given)" if forward_axis not in (None, "auto") else ""))
    if bvh is not None:
        _check_height(sk, v, up, bvh_length_to_m, where, names)
    m.name = name or m.name
    return unwrap_angles(m, where)


def _set_roles(skeleton, joint_roles: dict | None, where, names: dict) -> dict:
    """Check the given joint roles against ``skeleton`` and store them on it (:attr:`Skeleton.roles`), warning about
    a joint that plays two roles; returns the roles."""
    from .joints import check_role_overrides

    try:
        check_role_overrides(skeleton.names, joint_roles, where=names["joint_roles"])
    except ValueError as exc:
        raise ConfigError(f"{exc} (in {where})") from None
    skeleton.roles = dict(joint_roles or {})
    _warn_shared_roles(skeleton, skeleton.roles, where, names["joint_roles"])
    return skeleton.roles


def _log_frame(sk, v, roles: dict, where, axes: str) -> None:
    """Log the file's ``axes`` (as found) with the way the body faces once turned to the canonical frame, and the
    joints other than the root that translate."""
    from .axes import detect_forward_axis
    from .kinematics import CANONICAL_UP, translated_joints

    faces, src = detect_forward_axis(sk, v, CANONICAL_UP, roles)
    log.info("%s: %s; turned to +y up, +z forward; the body faces mostly %s in the result (from the %s)", where,
             axes, faces, src)
    moved = translated_joints(sk)
    if moved:
        log.info("%s: joints other than the root with translation over the frames: %s (their translation is part "
                 "of the pose: see config/README.md, BVH files, for how each family uses it)", where, ", ".join(moved))


def _read_trial_files(amc, asf, bvh, fps: float, bvh_length_to_m: float, shown: dict,
                      bvh_root: str | None = None) -> Motion:
    """The motion of a BVH file (its lengths in metres by ``bvh_length_to_m``; the skeleton under ``bvh_root``
    when the file holds several) or of an ASF + AMC pair (at ``fps``), as read; a format error names the user's
    own file (``shown``) instead of the copy read."""
    from .errors import MotionFormatError

    try:
        if bvh is not None:
            from .io.bvh import read_bvh

            m = read_bvh(bvh, root=bvh_root)
            m.skeleton.length_to_m = float(bvh_length_to_m)
        else:
            from .io.amc import read_amc
            from .io.asf import read_asf

            m = read_amc(amc, read_asf(asf), fps=fps)
    except MotionFormatError as exc:
        raise _rename_path(exc, {"amc": amc, "asf": asf, "bvh": bvh}, shown) from None
    return m


def _drop_first_frames(m: Motion, first_frame: int, where) -> Motion:
    """``m`` without its frames before ``first_frame`` (config key ``first_frame``; 0 keeps every frame)."""
    from .motion import Motion

    if not first_frame:
        return m
    if not 0 < first_frame < m.n_frames:
        raise ConfigError(f"config key 'first_frame': {first_frame} leaves no frame of the {m.n_frames} "
                          f"in {where}")
    m = Motion(m.values[first_frame:], m.skeleton, m.fps, m.name, m.meta)
    log.info("%s: the first %d frame(s) dropped (first_frame), %d left", where, first_frame,
             m.n_frames)
    return m


def _file_axes(sk, v, roles: dict, is_bvh: bool, up_axis, forward_axis, where, names: dict):
    """``(up, forward, how)``: the file's up and forward axes and how the up axis was found, given
    (``up_axis``, ``forward_axis``) or detected (:func:`load_trial`'s rules), with its warnings."""
    from .axes import default_forward, detect_up_axis, lying_down
    from .kinematics import CANONICAL_UP, parse_axis

    auto_up = up_axis in (None, "auto")
    detected, info = detect_up_axis(sk, v, roles)
    override = names["up_axis"]
    if not is_bvh and auto_up:
        up = CANONICAL_UP
        if detected != up and not info["ambiguous"]:
            log.warning("%s: the motion looks %s up (%s; median extents x y z: %s), ASF/AMC is read +y up; set %s "
                        "if the file is not", where, detected, info["why"], _fmt(info["extent"]), override)
    else:
        up = detected if auto_up else parse_axis(up_axis)
    fwd = default_forward(up) if forward_axis in (None, "auto") else parse_axis(forward_axis)
    how = (f"detected ({info['why']}; median extents x y z {_fmt(info['extent'])})"
           if auto_up and is_bvh else "given" if not auto_up else "ASF/AMC")
    if auto_up and is_bvh:
        if not info["biped"]:
            log.warning("%s: the body is not a biped (%s); %s; set %s if that is wrong%s", where, info["why"],
                        f"up axis {up} from its legs" if info["sign_from"] == "legs" else
                        "its up axis is ambiguous: the file's own axes are kept (+y up, BVH's convention)",
                        override, f" (a biped whose joint names the role map does not know: name its head and "
                                  f"feet with {names['joint_roles']})" if info["why"].startswith("no head") else "")
        elif info["ambiguous"]:
            log.warning("%s: the up axis %s is ambiguous (%s; median extents x y z %s); set %s", where, up,
                        info["why"], _fmt(info["extent"]), override)
    if not auto_up:
        lying = lying_down(sk, v, up, roles)
        if lying:
            log.warning("%s: with the given up axis %s the body lies down or stands on its head (%s); check %s",
                        where, up, lying, override)
    return up, fwd, how


def _check_height(sk, v, up, bvh_length_to_m: float, where, names: dict) -> None:
    """Log a BVH skeleton's standing height in metres, and warn when it lies outside :data:`HEIGHT_RANGE_M`
    (the file's unit is probably not ``bvh_length_to_m``)."""
    from .axes import standing_height
    from .kinematics import CANONICAL_UP

    height = standing_height(sk, v, CANONICAL_UP) * sk.length_to_m
    log.info("%s: stands %.3g m tall (median over frames along the up axis) with bvh_length_to_m=%g", where,
             height, bvh_length_to_m)
    if not HEIGHT_RANGE_M[0] <= height <= HEIGHT_RANGE_M[1]:
        log.warning("%s: the skeleton stands %.3g m tall (median over frames along the up axis %s) with "
                    "bvh_length_to_m=%g; set %s to the file's unit (0.01 for centimetres, 0.0254 for "
                    "inches, 0.05644 for cgspeed's CMU conversions)", where, height, up, bvh_length_to_m,
                    names["bvh_length_to_m"])


def _warn_shared_roles(skeleton, overrides: dict, where: str, setting: str) -> None:
    """Log a warning for every joint that plays two roles or more (given or found by name).

    One case is the documented setting, not a mistake, and is an info line: a toe role given to the joint that is
    the same side's ankle when that joint ends its chain (a skeleton without toe joints, e.g. cgspeed's CMU BVH
    files: the foot's End Site is the toe tip), so the foot's contacts are measured at the ankle joint."""
    from .joints import ROLES, JointRoleError, resolve_role

    played: dict[str, list[str]] = {}
    for role in ROLES:
        try:
            played.setdefault(resolve_role(skeleton, role, overrides), []).append(role)
        except JointRoleError:
            continue
    for joint, rs in played.items():
        if len(rs) <= 1:
            continue
        given = [r for r in rs if r in (overrides or {})]
        side = rs[0].split("_")[0]
        if sorted(rs) == [f"{side}_ankle", f"{side}_toe"] and given == [f"{side}_toe"] and \
                not skeleton.children(skeleton.names.index(joint)):
            log.info("%s: joint %r is %s and, as given, %s (the skeleton has no toe joint below it)", where, joint,
                     rs[0], rs[1])
            continue
        log.warning("%s: joint %r plays %d roles (%s%s); each role should be its own joint: check %s", where,
                    joint, len(rs), ", ".join(rs), f"; given: {', '.join(given)}" if given else "", setting)


def _fmt(a) -> str:
    return " ".join(f"{float(x):.4g}" for x in a)
