"""Trials of a local CMU mirror folder (``subjects/<s>/<s>.asf`` and ``<s>_<t>.amc``), read in order."""

from __future__ import annotations

import logging
import os

import numpy as np

from ..motion import Motion
from .amc import read_amc
from .asf import read_asf

log = logging.getLogger("animsynth.io.cmu_mirror")


def read_mirror_motions(mirror: str, n_frames: int, subjects=None):
    """Trials of a CMU mirror (``subjects/<s>/<s>_<t>.amc``), in sorted order, until ``n_frames``
    frames (the last trial cut). ``subjects``: restrict to these subject folders."""
    root = os.path.join(mirror, "subjects")
    if not os.path.isdir(root):
        raise FileNotFoundError(f"config key 'cmu_mirror': {mirror} has no subjects/ folder")
    subs = sorted(os.listdir(root)) if not subjects else [str(s) for s in subjects]
    out, total = [], 0
    for s in subs:
        d = os.path.join(root, s)
        asf = os.path.join(d, f"{s}.asf")
        if not os.path.isfile(asf):
            continue
        sk = read_asf(asf)
        for f in sorted(os.listdir(d)):
            if not f.endswith(".amc"):
                continue
            m = read_amc(os.path.join(d, f), sk, 120.0)
            take = min(m.n_frames, int(n_frames) - total)
            if take < 12:
                return out
            if take < m.n_frames:
                m = Motion(np.asarray(m.values)[:take], m.skeleton, m.fps, m.name, dict(m.meta))
            out.append(m)
            total += take
            if total >= n_frames:
                return out
    if total < n_frames:
        log.warning("CMU mirror %s has only %d frames (asked for %d)", mirror, total, n_frames)
    return out
