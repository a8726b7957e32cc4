"""Cross-key checks of the ``facegraph`` config block (beyond the JSON Schema)."""

from __future__ import annotations

import os

from ..config import ConfigError
from ..io.ckplus import EMOTIONS, emotion_code
from .regions import check_regions


def config_name(creation: float, merge: float, creation_tolerance: float | None = None,
                merge_tolerance: float | None = None) -> str:
    """Wildcard-safe name of a compression configuration (fractions), e.g.
    ``c0.2t0.1_m0.7t0.3`` (creation 0.2 +/- 0.1, merge 0.7 +/- 0.3) or, without
    tolerances, ``c0.5_m0.3``. The one place the name format is defined."""
    c = f"c{float(creation):g}" + ("" if creation_tolerance is None else f"t{float(creation_tolerance):g}")
    m = f"m{float(merge):g}" + ("" if merge_tolerance is None else f"t{float(merge_tolerance):g}")
    return f"{c}_{m}"


def _entry(c: dict, tolerance: float | None = None) -> dict:
    ct = c.get("creation_tolerance", tolerance)
    mt = c.get("merge_tolerance", tolerance)
    return {"name": config_name(c["creation"], c["merge"], ct, mt), "creation": float(c["creation"]),
            "creation_tolerance": float(ct), "merge": float(c["merge"]), "merge_tolerance": float(mt)}


def configurations(fg: dict) -> list[dict]:
    """Table 1 configurations in config order: dicts with ``name``, ``creation``,
    ``creation_tolerance``, ``merge``, ``merge_tolerance`` (fractions)."""
    return [_entry(c) for c in fg["configurations"]]


def sweep_configurations(fg: dict) -> list[dict]:
    """The optional creation x merge grid (``facegraph.sweep``); empty unless enabled."""
    sw = fg.get("sweep", {})
    if not sw.get("enabled", False):
        return []
    tol = float(sw["tolerance"])
    return [_entry({"creation": c, "merge": m}, tol) for c in sw["creation"] for m in sw["merge"]]


def showcase(fg: dict) -> dict:
    """The configuration whose graphs feed the baseline, uniqueness study and figures."""
    return _entry(fg["showcase"])


PAPER_COLUMNS = {  # our column -> column of the published table (s4_table1.csv)
    "node_compression_pct": "nodes_compression_pct", "data_compression_pct": "data_compression_pct",
    "duration_diff": "duration_diff", "duration_diff_sd": "duration_diff_sd",
    "landmark_diff_px": "landmark_diff_px", "landmark_diff_sd": "landmark_diff_sd",
    "velocity_angle_diff_pct": "velocity_angle_diff_pct", "velocity_angle_diff_sd": "velocity_angle_diff_sd",
    "creation_time_s": "creation_time_s", "synthesis_time_s": "synthesis_time_s",
    "synthesis_time_sd": "synthesis_time_sd",
}


def read_paper_table1(path) -> dict[str, dict]:
    """Published Table 1 values keyed by configuration name ({} if the file is missing).

    The file (``facegraph.paper_table1``) has one row per configuration with
    ``creation_target, creation_tolerance, merge_target, merge_tolerance`` as
    fractions and the published columns named in :data:`PAPER_COLUMNS`.
    """
    import logging

    import pandas as pd

    if not path or not os.path.isfile(path):
        logging.getLogger("animsynth.facegraph.settings").info(
            "no published Table 1 at %r: paper_* columns left empty", path)
        return {}
    df = pd.read_csv(path)
    need = {"creation_target", "creation_tolerance", "merge_target", "merge_tolerance"}
    missing = need - set(df.columns)
    if missing:
        raise ConfigError(f"config key 'facegraph.paper_table1': {path} lacks column(s) {sorted(missing)}")
    out = {}
    for _, r in df.iterrows():
        name = config_name(r.creation_target, r.merge_target, r.creation_tolerance, r.merge_tolerance)
        out[name] = {ours: float(r[theirs]) for ours, theirs in PAPER_COLUMNS.items() if theirs in df.columns}
        if "row" in df.columns:
            out[name]["row"] = int(r["row"])
    return out


def check_facegraph_config(fg: dict) -> None:
    """Raise :class:`ConfigError` naming the key for values the schema cannot check."""
    key = "facegraph"
    pre = fg["preprocess"]
    check_regions(pre["regions"], pre["reduced_landmarks"], pre["rigid_landmarks"], key=f"{key}.preprocess")
    names = [c["name"] for c in configurations(fg)]
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
