"""Cross-key checks of the ``meshdetail`` config block (beyond the JSON Schema)."""

from __future__ import annotations

import re

import numpy as np

from ..config import ConfigError
from ..skinning import JOINTS


def check_meshdetail_config(md: dict, mesh_dir: str | None, key: str = "meshdetail") -> None:
    """Raise :class:`ConfigError` naming the key for values the schema cannot check."""
    joints = md["rig"].get("joints")
    if mesh_dir and joints:
        missing = [n for n in JOINTS if n not in joints]
        if missing:
            raise ConfigError(f"config key '{key}.rig.joints' misses {missing}")
        extra = sorted(set(joints) - set(JOINTS))
        if extra:
            raise ConfigError(f"config key '{key}.rig.joints': unknown joint(s) {extra} (names: {list(JOINTS)})")
    for name in md["rig"].get("ends") or {}:
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
    entry's own; unset ``mesh_fps`` / ``render_frames`` come from ``meshdetail``.
    """
    from ..sources import mesh_source_name

    md = config["meshdetail"]
    top = config.get("mesh_dir")
    first = mesh_source_name(top) if top else SYNTHETIC_NAME
    seqs = {first: {"mesh_dir": top, "mesh_sha256": config.get("mesh_sha256") if top else None,
                    "mesh_fps": md["mesh_fps"] if top else md["character"]["fps"],
                    "render_frames": list(md["render_frames"]), "rig": dict(md["rig"])}}
    for name, entry in (md.get("sequences") or {}).items():
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
    for name, s in seqs.items():
        if s["mesh_dir"]:
            check_meshdetail_config({**md, "rig": s["rig"]}, s["mesh_dir"], key=f"meshdetail.sequences.{name}"
                                    if name != first else "meshdetail")
    return seqs
