"""Config checks of the simplicial family and the published values it shows beside ours.

The paper's Table II is read from a CSV (config key ``simplicial.paper_table2``,
default ``../shared/papers/s1_table2.csv`` relative to the working directory)
with columns ``metric, method, <subsets...>, all``. The paper calls its k-NN
method ``knn16`` (k = 16); any ``knn<k>`` is shown as our ``knn`` row. A
missing file means "no published values": the ``paper_*`` columns stay empty
and the verdicts fall back to ``simplicial.paper_claim`` for the ordering.
A file that exists but is malformed is an error naming the file and line.
"""

from __future__ import annotations

import logging
import os
import re

import numpy as np
import pandas as pd

log = logging.getLogger("animsynth.simplicial.settings")

PAPER_SUBSETS = ("w1", "w2", "r1", "r2", "all")


def read_paper_table2(path) -> pd.DataFrame | None:
    """The paper's Table II as ``metric, method, w1, w2, r1, r2, all`` (float), or None when absent.

    Parameters
    ----------
    path : str or None
        CSV path; None, "" or a missing file -> None (logged).
    """
    if not path:
        return None
    path = os.fspath(path)
    if not os.path.exists(path):
        log.info("published Table II not found at %s: paper columns left empty", path)
        return None
    try:
        df = pd.read_csv(path, dtype=str, keep_default_na=False)
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: cannot parse the published Table II ({exc})") from None
    missing = [c for c in ("metric", "method") if c not in df.columns]
    if missing:
        raise ValueError(f"{path}: line 1: missing column(s) {missing} (config key 'simplicial.paper_table2')")
    subsets = [c for c in df.columns if c not in ("metric", "method")]
    rows = []
    for i, r in df.iterrows():
        line = i + 2
        metric = r["metric"].strip()
        if metric not in ("error_a", "error_f"):
            raise ValueError(f"{path}: line {line}: metric must be error_a or error_f, got {metric!r}")
        method = r["method"].strip()
        m = re.fullmatch(r"knn(\d*)", method)
        out = {"metric": metric, "method": "knn" if m else method, "paper_method": method}
        for c in subsets:
            txt = r[c].strip()
            if txt == "":
                out[c] = np.nan
                continue
            try:
                out[c] = float(txt)
            except ValueError:
                raise ValueError(f"{path}: line {line}: column {c!r} is not a number: {txt!r}") from None
        rows.append(out)
    return pd.DataFrame(rows, columns=["metric", "method", "paper_method"] + subsets)


def paper_claim_from(paper: pd.DataFrame | None, fallback: str, methods=("delaunay", "knn")) -> str:
    """The ordering the paper concludes: from its overall medians when available, else ``fallback``.

    ``delaunay_better`` when the first method has the lower ``all`` median on
    both metrics in the paper, ``knn_better`` when the second has, else ``fallback``.
    """
    if paper is None or "all" not in paper.columns:
        return fallback
    a, b = methods
    p = paper.set_index(["metric", "method"])["all"]
    try:
        lower = [p[(m, a)] < p[(m, b)] for m in ("error_a", "error_f")]
        higher = [p[(m, a)] > p[(m, b)] for m in ("error_a", "error_f")]
    except KeyError:
        return fallback
    if all(lower):
        return f"{a}_better"
    if all(higher):
        return f"{b}_better"
    return fallback
