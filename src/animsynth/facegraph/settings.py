"""Settings of the facegraph family: its config checks beyond the JSON Schema (:func:`check`), the
configurations named by the config, and the published Table 1 mapped to them.

Defaults live only in ``config/schema.yaml`` (the validator fills them); nothing here supplies one.
"""

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


def _entry(creation: float, creation_tolerance: float, merge: float, merge_tolerance: float) -> dict:
    return {"name": config_name(creation, merge, creation_tolerance, merge_tolerance), "creation": float(creation),
            "creation_tolerance": float(creation_tolerance), "merge": float(merge),
            "merge_tolerance": float(merge_tolerance)}


def _config_entry(c: dict) -> dict:
    return _entry(c["creation"], c["creation_tolerance"], c["merge"], c["merge_tolerance"])


def configurations(fg: dict) -> list[dict]:
    """Table 1 configurations in config order: dicts with ``name``, ``creation``,
    ``creation_tolerance``, ``merge``, ``merge_tolerance`` (fractions)."""
    return [_config_entry(c) for c in fg["configurations"]]


def sweep_configurations(fg: dict) -> list[dict]:
    """The optional creation x merge grid (``facegraph.sweep``); empty unless enabled."""
    sw = fg["sweep"]
    if not sw["enabled"]:
        return []
    tol = float(sw["tolerance"])
    return [_entry(c, tol, m, tol) for c in sw["creation"] for m in sw["merge"]]


def showcase(fg: dict) -> dict:
    """The configuration whose graphs feed the baseline, uniqueness study and figures."""
    return _config_entry(fg["showcase"])


#: Config key naming the published Table 1 (Serra et al. 2018).
PUBLISHED_KEY = "published.facegraph.table1"
#: Columns of the published Table 1 that name a configuration (fractions).
PAPER_KEYS = ("creation_target", "creation_tolerance", "merge_target", "merge_tolerance")
PAPER_COLUMNS = {  # our column -> column of the published table (s4_table1.csv)
    "node_compression_pct": "nodes_compression_pct", "data_compression_pct": "data_compression_pct",
    "duration_diff": "duration_diff", "duration_diff_sd": "duration_diff_sd",
    "landmark_diff_px": "landmark_diff_px", "landmark_diff_sd": "landmark_diff_sd",
    "velocity_angle_diff_pct": "velocity_angle_diff_pct", "velocity_angle_diff_sd": "velocity_angle_diff_sd",
    "creation_time_s": "creation_time_s", "synthesis_time_s": "synthesis_time_s",
    "synthesis_time_sd": "synthesis_time_sd",
}


def published_table1(path) -> dict[str, dict]:
    """Published Table 1 values keyed by configuration name ({} when there is no file).

    Read with :func:`animsynth.published.read_table` (a missing file or ``None`` logs a WARNING naming
    the path and gives {}). The file (config key ``published.facegraph.table1``) has one row per
    configuration: ``row``, the targets and tolerances :data:`PAPER_KEYS` as fractions, and the published
    columns named in :data:`PAPER_COLUMNS`.

    Returns
    -------
    dict
        ``{config name: {our column: value, ..., "row": published row number}}``.

    Raises
    ------
    animsynth.published.PublishedError
        A column missing, a non-number, an empty target cell or two rows naming one configuration
        (the message names the file and the line).
    """
    import numpy as np

    from ..published import PublishedError, read_table

    cols = ("row", *PAPER_KEYS, *PAPER_COLUMNS.values())
    df = read_table(path, cols, cols, what="Serra et al. 2018 Table 1", config_key=PUBLISHED_KEY)
    if df is None:
        return {}
    out, line_of = {}, {}
    for i, r in enumerate(df.to_dict("records")):
        line = i + 2  # header = line 1
        if not all(np.isfinite(r[k]) for k in ("row", *PAPER_KEYS)):
            raise PublishedError(f"{path}, line {line}: empty row number or target ({PUBLISHED_KEY})")
        name = config_name(r["creation_target"], r["merge_target"], r["creation_tolerance"], r["merge_tolerance"])
        if name in out:
            raise PublishedError(f"{path}, line {line}: configuration {name} already on line {line_of[name]} "
                                 f"({PUBLISHED_KEY})")
        out[name] = {ours: float(r[theirs]) for ours, theirs in PAPER_COLUMNS.items()}
        out[name]["row"] = int(r["row"])
        line_of[name] = line
    return out


def check(config: dict) -> None:
    """Every check of the ``facegraph`` config block the schema cannot express.

    ``config``: the whole workflow config (validated against ``config/schema.yaml``, defaults filled).
    Raises :class:`ConfigError` naming the key.
    """
    fg = config["facegraph"]
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
    d = fg["ckplus_dir"]
    if d is not None and not os.path.isdir(d):
        raise ConfigError(f"config key '{key}.ckplus_dir': {d!r} is not a folder (point it at your CK+ copy "
                          "holding Landmarks/ and Emotion/, or use null for the synthetic database)")
