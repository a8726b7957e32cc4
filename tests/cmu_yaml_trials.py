"""The real trials of config/cmu.yaml, read from ../shared/data as the parse job reads them, once per test process.

Two test modules check the same trials: tests/test_cmu_many_subjects.py (every trial's parse, capture check and
figure) and tests/test_compare_protocol.py (GenMM's levels on every clip of the paper protocol). Parsing them all
costs about 9 CPU s, so they are parsed once (:func:`_parsed`) and every caller gets its own deep copy: no test
sees what another did to its trials, and a test run alone reads them itself.

The callers skip (``conftest.need``) when the data are absent; nothing here is read at import.
"""

from __future__ import annotations

import copy
import functools
import logging


from animsynth.config import TRIAL_READ_KEYS, trial_setting
from animsynth.data import load_trial
from conftest import CMU, CMU_MANY, merged_config


@functools.cache
def _config() -> dict:
    return merged_config("config.yaml", "cmu.yaml")


def paper_config() -> dict:
    """config/config.yaml with config/cmu.yaml over it, validated (defaults filled in): the paper run's trials,
    groups and settings."""
    return copy.deepcopy(_config())


def read_trial(config: dict, rec: dict, first_frame: int | None = None):
    """One trial record read as the parse job reads it (rule ``parse_trial``: the config's ``fps``, the record's
    reading settings over the top-level ones); ``first_frame`` overrides the record's."""
    root = CMU_MANY if rec.get("mirror") == "many" else CMU
    files = {k: root / rec[k] for k in ("amc", "asf", "bvh") if k in rec}
    kw = {k: trial_setting(config, rec, k) for k in TRIAL_READ_KEYS}
    ff = rec.get("first_frame", 0) if first_frame is None else first_frame
    if rec.get("bvh_root"):
        kw["bvh_root"] = rec["bvh_root"]
    return load_trial(**files, fps=config["fps"], name=rec["id"], first_frame=ff, **kw)


class _Warnings(logging.Handler):
    def __init__(self):
        super().__init__(logging.WARNING)
        self.lines: list[str] = []

    def emit(self, record):
        self.lines.append(record.getMessage())


@functools.cache
def _parsed() -> dict:
    config, out, root = _config(), {}, logging.getLogger()
    for rec in config["trials"]:
        handler = _Warnings()
        root.addHandler(handler)
        try:
            out[rec["id"]] = (rec, read_trial(config, rec), handler.lines)
        finally:
            root.removeHandler(handler)
    return out


def cmu_yaml_trials() -> dict:
    """``{trial id: (record, Motion, [warnings logged while reading it])}`` of every trial of config/cmu.yaml, in
    config order: a deep copy of the process's one parse."""
    return copy.deepcopy(_parsed())
