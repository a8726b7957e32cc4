"""Facial regions of the 68-point (iBUG / CK+) landmark scheme.

Each region gets its own motion graph. ``DEFAULT_REGIONS`` partitions the 68
landmarks; ``DEFAULT_REDUCED`` is the reduced landmark set of each region used
by the similarity metric (eq. 3) while the graph nodes keep every landmark of
the region, so synthesis still assembles a full 68-landmark face.
"""

from __future__ import annotations

import numpy as np

from ..config import ConfigError

REGION_NAMES = ("eyes", "eyebrows", "nose", "mouth", "cheeks_jaw")

DEFAULT_REGIONS = {
    "eyes": list(range(36, 48)),
    "eyebrows": list(range(17, 27)),
    "nose": list(range(27, 36)),
    "mouth": list(range(48, 68)),
    "cheeks_jaw": list(range(0, 17)),
}
DEFAULT_REDUCED = {
    "eyes": [36, 37, 39, 41, 42, 44, 45, 46],      # corners + one upper and one lower lid point per eye
    "eyebrows": [17, 19, 21, 22, 24, 26],          # ends and middle of each brow
    "nose": [27, 30, 31, 33, 35],                  # bridge top, tip, wings, base centre
    "mouth": [48, 50, 51, 52, 54, 56, 57, 58, 62, 66],  # corners, outer lips, inner lip centres
    "cheeks_jaw": [2, 4, 6, 8, 10, 12, 14],        # every other jaw-line point
}
#: Stage-1 rigid alignment landmarks: nose bridge and eye corners.
DEFAULT_RIGID = [27, 28, 29, 30, 36, 39, 42, 45]


def check_regions(regions: dict | None, reduced: dict | None, rigid=None,
                  key: str = "facegraph.preprocess") -> tuple[dict, dict, np.ndarray]:
    """Validate region definitions; return (regions, reduced, rigid) as int arrays.

    Regions must partition the 68 landmarks; each reduced set must be a
    non-empty subset of its region with at least 2 landmarks.
    """
    regions = DEFAULT_REGIONS if regions is None else regions
    reduced = DEFAULT_REDUCED if reduced is None else reduced
    rigid = DEFAULT_RIGID if rigid is None else rigid
    if set(regions) != set(REGION_NAMES):
        raise ConfigError(f"config key '{key}.regions': expected regions {list(REGION_NAMES)}, got {sorted(regions)}")
    if set(reduced) != set(REGION_NAMES):
        raise ConfigError(f"config key '{key}.reduced_landmarks': expected regions {list(REGION_NAMES)}, got {sorted(reduced)}")
    seen: dict[int, str] = {}
    out_r, out_red = {}, {}
    for name in REGION_NAMES:
        ids = [int(i) for i in regions[name]]
        if not ids or len(set(ids)) != len(ids) or min(ids) < 0 or max(ids) > 67:
            raise ConfigError(f"config key '{key}.regions.{name}': need distinct landmark ids 0-67, got {ids}")
        for i in ids:
            if i in seen:
                raise ConfigError(f"config key '{key}.regions': landmark {i} is in both {seen[i]!r} and {name!r}")
            seen[i] = name
        red = [int(i) for i in reduced[name]]
        bad = [i for i in red if i not in ids]
        if len(red) < 2 or len(set(red)) != len(red) or bad:
            raise ConfigError(f"config key '{key}.reduced_landmarks.{name}': need >= 2 distinct landmarks of the "
                              f"region; not in region: {bad}")
        out_r[name] = np.array(ids, dtype=int)
        out_red[name] = np.array(red, dtype=int)
    missing = sorted(set(range(68)) - set(seen))
    if missing:
        raise ConfigError(f"config key '{key}.regions': landmarks {missing} belong to no region (must cover 0-67)")
    rig = np.array([int(i) for i in rigid], dtype=int)
    if len(rig) < 3 or len(set(rig.tolist())) != len(rig) or rig.min() < 0 or rig.max() > 67:
        raise ConfigError(f"config key '{key}.rigid_landmarks': need >= 3 distinct landmark ids 0-67")
    return out_r, out_red, rig
