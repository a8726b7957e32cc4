"""Cross-key checks of the ``facegraph`` config block (beyond the JSON Schema)."""

from __future__ import annotations

import os

from ..config import ConfigError
from ..io.ckplus import EMOTIONS, emotion_code
from .regions import check_regions


def configurations(fg: dict) -> list[tuple[str, float, float]]:
    """(name, creation %, merge %) of every Table 1 configuration, in config order."""
    from .experiments import config_name

    return [(config_name(c["creation"], c["merge"]), float(c["creation"]), float(c["merge"]))
            for c in fg["configurations"]]


def check_facegraph_config(fg: dict) -> None:
    """Raise :class:`ConfigError` naming the key for values the schema cannot check."""
    key = "facegraph"
    pre = fg["preprocess"]
    check_regions(pre["regions"], pre["reduced_landmarks"], pre["rigid_landmarks"], key=f"{key}.preprocess")
    names = [n for n, _, _ in configurations(fg)]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ConfigError(f"config key '{key}.configurations': duplicate configuration(s) {dup}")
    for where, labels in ((f"{key}.uniqueness.labels", fg["uniqueness"]["labels"]),
                          (f"{key}.figures.sequence", fg["figures"]["sequence"])):
        for lab in labels:
            try:
                if emotion_code(lab) == 0:
                    raise ValueError
            except ValueError:
                raise ConfigError(f"config key '{where}': {lab!r} is not an expression label "
                                  f"({list(EMOTIONS[1:])})") from None
    for lm in fg["figures"]["trajectory_landmarks"]:
        if not 0 <= int(lm) <= 67:
            raise ConfigError(f"config key '{key}.figures.trajectory_landmarks': landmark {lm} not in 0-67")
    syn = fg["synthesis"]
    if syn["savgol_window"] % 2 == 0 or syn["savgol_order"] >= syn["savgol_window"]:
        raise ConfigError(f"config key '{key}.synthesis.savgol_window': must be odd and > savgol_order")
    s = fg["synthetic"]
    if not s["min_frames"] * s["n_sequences"] <= s["total_frames"] <= s["max_frames"] * s["n_sequences"]:
        raise ConfigError(f"config key '{key}.synthetic.total_frames': {s['total_frames']} frames cannot be split "
                          f"into {s['n_sequences']} sequences of {s['min_frames']}-{s['max_frames']} frames")
    if s["min_frames"] > s["max_frames"]:
        raise ConfigError(f"config key '{key}.synthetic.min_frames': larger than max_frames")
    d = fg.get("ckplus_dir")
    if d is not None and not os.path.isdir(d):
        raise ConfigError(f"config key '{key}.ckplus_dir': {d!r} is not a folder (point it at your CK+ copy "
                          "holding Landmarks/ and Emotion/, or use null for the synthetic database)")
