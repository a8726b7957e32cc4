"""Config of the ``meshdetail`` block: its cross-key checks (beyond the JSON Schema, which holds the
defaults) and the mesh sequences of a run."""

from __future__ import annotations

import re

import numpy as np

from ..config import ConfigError
from ..rig_layout import JOINTS

__all__ = ["check", "check_character", "check_sequence", "mesh_sequences"]

DRIVERS = ("cmu_synthetic", "procedural", "amc")


def check(config: dict) -> None:
    """Every meshdetail check the schema cannot make; raise :class:`ConfigError` naming the key.

    ``config``: the whole workflow config, validated by ``config/schema.yaml`` (defaults filled in). Checks
    the ``meshdetail.sequences`` entries (:func:`mesh_sequences`), each sequence's block
    (:func:`check_sequence`) and, when the first sequence is the synthetic character, its driver
    (:func:`check_character`).
    """
    md = config["meshdetail"]
    seqs = mesh_sequences(config)
    for name, entry in (md["sequences"] or {}).items():
        unknown = sorted(set(entry.get("rig") or {}) - set(md["rig"]))
        if unknown:
            raise ConfigError(f"config key 'meshdetail.sequences.{name}.rig': unknown key(s) {unknown} "
                              f"(keys: {sorted(md['rig'])})")
    first = next(iter(seqs))
    if not seqs[first]["mesh_dir"]:
        check_character(md["character"])
    for name, s in seqs.items():
        check_sequence({**md, "rig": s["rig"]}, s["mesh_dir"],
                       key="meshdetail" if name == first else f"meshdetail.sequences.{name}")


def check_character(ch: dict, key: str = "meshdetail.character") -> None:
    """The synthetic character's driver: a known driver, a frame rate the CMU-like generator can resample
    (it records at 120 fps), the ASF/AMC files of driver ``amc``."""
    drv = ch["driver"]
    if drv not in DRIVERS:
        raise ConfigError(f"config key '{key}.driver': unknown driver {drv!r} (one of {list(DRIVERS)})")
    fps = float(ch["fps"])
    if drv == "cmu_synthetic" and abs(120.0 / fps - round(120.0 / fps)) > 1e-9:
        raise ConfigError(f"config key '{key}.fps': must divide 120 for the CMU-like generator, got {fps:g}")
    if drv == "amc" and not (ch.get("asf") and ch.get("amc")):
        raise ConfigError(f"config keys '{key}.asf' and '{key}.amc' are needed for driver 'amc'")


def check_sequence(md: dict, mesh_dir: str | None, key: str = "meshdetail") -> None:
    """One sequence's ``meshdetail`` block (``md``, with the sequence's own ``rig``): the 18-joint embedding
    of real data, the leaves' ends, the frames the synthetic character (``mesh_dir`` None) leaves for
    training and for the blocked cross-validation, the Fig. 5b levels."""
    joints = md["rig"]["joints"]
    if mesh_dir and joints:
        missing = [n for n in JOINTS if n not in joints]
        if missing:
            raise ConfigError(f"config key '{key}.rig.joints' misses {missing}")
        extra = sorted(set(joints) - set(JOINTS))
        if extra:
            raise ConfigError(f"config key '{key}.rig.joints': unknown joint(s) {extra} (names: {list(JOINTS)})")
    for name in md["rig"]["ends"] or {}:
        if name not in JOINTS:
            raise ConfigError(f"config key '{key}.rig.ends': unknown joint {name!r}")
    if not mesh_dir:
        n = int(md["character"]["frames"])
        if md["max_frames"]:
            n = min(n, int(md["max_frames"]))
        k = int(round(n * float(md["train_fraction"])))
        if k < 8 or k > n:
            raise ConfigError(f"config key '{key}.train_fraction': leaves {k} of {n} frames for training (need >= 8)")
        if n < 2 * int(md["cv_folds"]):
            raise ConfigError(f"config key '{key}.cv_folds': {md['cv_folds']} blocks need at least "
                              f"{2 * int(md['cv_folds'])} frames, the character has {n}")
    if not np.all(np.diff(sorted(md["levels"])) > 0):
        raise ConfigError(f"config key '{key}.levels': duplicate levels {md['levels']}")


SYNTHETIC_NAME = "character"
SEQUENCE_KEYS = ("mesh_dir", "mesh_sha256", "mesh_fps", "render_frames", "rig")


def mesh_sequences(config: dict) -> dict:
    """The mesh sequences of one run: ``{name: {mesh_dir, mesh_sha256, mesh_fps, render_frames, rig}}``.

    The first is the top-level ``mesh_dir`` (named after its folder or archive, e.g.
    ``samba``) or, when that is null, the synthetic character (``character``); then every
    entry of ``meshdetail.sequences`` (real sequences only). An entry's ``rig`` keys
    override ``meshdetail.rig`` except the embedding (``joints``, ``ends``), which is the
    entry's own; unset ``mesh_fps`` / ``render_frames`` come from ``meshdetail``. Raises
    :class:`ConfigError` for an entry it cannot place (name taken or malformed, unknown key, no mesh_dir);
    :func:`check` checks the rest.
    """
    from ..sources import mesh_source_name

    md = config["meshdetail"]
    top = config.get("mesh_dir")
    first = mesh_source_name(top) if top else SYNTHETIC_NAME
    seqs = {first: {"mesh_dir": top, "mesh_sha256": config.get("mesh_sha256") if top else None,
                    "mesh_fps": md["mesh_fps"] if top else md["character"]["fps"],
                    "render_frames": list(md["render_frames"]), "rig": dict(md["rig"])}}
    for name, entry in (md["sequences"] or {}).items():
        key = f"meshdetail.sequences.{name}"
        if name in seqs:
            raise ConfigError(f"config key '{key}': the name is already taken by the top-level mesh_dir "
                              f"(or the synthetic character); choose another")
        if not re.fullmatch(r"[A-Za-z0-9_-]+", name):
            raise ConfigError(f"config key '{key}': names may use letters, digits, '_' and '-' only")
        unknown = sorted(set(entry) - set(SEQUENCE_KEYS))
        if unknown:
            raise ConfigError(f"config key '{key}': unknown key(s) {unknown} (keys: {list(SEQUENCE_KEYS)})")
        if not entry.get("mesh_dir"):
            raise ConfigError(f"config key '{key}.mesh_dir' is required")
        rig = {**md["rig"], "joints": None, "ends": {}, **(entry.get("rig") or {})}
        seqs[name] = {"mesh_dir": entry["mesh_dir"], "mesh_sha256": entry.get("mesh_sha256"),
                      "mesh_fps": entry.get("mesh_fps") or md["mesh_fps"],
                      "render_frames": list(entry.get("render_frames") or md["render_frames"]), "rig": rig}
    return seqs
