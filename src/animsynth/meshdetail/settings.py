"""Cross-key checks of the ``meshdetail`` config block (beyond the JSON Schema)."""

from __future__ import annotations

import numpy as np

from ..config import ConfigError
from ..skinning import JOINTS


def check_meshdetail_config(md: dict, mesh_dir: str | None) -> None:
    """Raise :class:`ConfigError` naming the key for values the schema cannot check."""
    key = "meshdetail"
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
