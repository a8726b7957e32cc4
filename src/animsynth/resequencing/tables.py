"""The paper's published tables in our names, and beside ours: Table 2 (minimum k per motion, method and metric)
and the Lee et al. joint weights.

The files are read with :func:`animsynth.published.read_table` (a missing file: ``None`` and a WARNING); a file
whose layout the paper does not have raises :class:`animsynth.published.PublishedError` naming the file and line.
"""

from __future__ import annotations

import os

import numpy as np
import pandas as pd

from ..config import trial_records
from ..published import PublishedError, read_table
from ..tables import add_paper_differences
from .features import SIGN_MODES
from .settings import METRICS

__all__ = ["PAPER_GLOBAL_DOF", "PAPER_METHODS", "TABLE2_COLUMNS", "PAPER_CMU_TRIALS", "published_table2",
           "lee_weights_table", "min_k_table", "paper_comparable", "comparable_published"]

#: The paper's Table 2 names -> ours.
PAPER_GLOBAL_DOF = {"included": True, "excluded": False}
PAPER_METHODS = {"isomap": "isomap", "st-isomap": "stisomap", "stisomap": "stisomap"}
TABLE2_COLUMNS = ("motion", "frames", "global_dof", "method", "metric", "min_k")
#: The CMU trials that stand for the paper's walk, run and dance (config/cmu.yaml's resequencing_trials).
PAPER_CMU_TRIALS = {"walk": "35_01", "run": "35_17", "dance": "05_02"}


def paper_comparable(config: dict, trials: dict) -> dict[str, bool]:
    """Which re-sequencing datasets run on the paper's trial, so that its Table 2 values may stand beside ours.

    Parameters
    ----------
    config : dict
        The run's config (``mocap_source``, ``trials``).
    trials : dict
        ``{dataset: trial id}`` (``resequencing_trials``).

    Returns
    -------
    dict
        ``{dataset: bool}``. ``True`` for the synthetic stand-ins of the paper's clips (the default run) and
        for a CMU or user trial whose file (``amc``, or ``bvh``) is the CMU trial of :data:`PAPER_CMU_TRIALS`
        for that dataset (``35_01.amc``); ``False`` for anything else: a user's own capture is not the motion
        the paper measured, so its min k is not comparable with the paper's.
    """
    records = {str(t.get("id")): t for t in trial_records(config.get("trials"))}
    out = {}
    for dataset, tid in trials.items():
        if config.get("mocap_source") == "synthetic":
            out[dataset] = True
            continue
        rec = records.get(str(tid), {})
        stems = {os.path.splitext(os.path.basename(str(rec[k])))[0] for k in ("amc", "bvh") if rec.get(k)}
        out[dataset] = PAPER_CMU_TRIALS.get(dataset) in stems
    return out


def comparable_published(published: pd.DataFrame | None, comparable: dict) -> pd.DataFrame | None:
    """``published`` (:func:`published_table2`) without the rows of datasets that are not comparable
    (:func:`paper_comparable`); ``None`` when none is left."""
    if published is None:
        return None
    keep = published[published["dataset"].map(lambda d: bool(comparable.get(d, False)))]
    return keep.reset_index(drop=True) if len(keep) else None


def published_table2(path) -> pd.DataFrame | None:
    """The paper's Table 2 (CSV: motion, frames, global_dof, method, metric, min_k) in our names.

    Read with :func:`animsynth.published.read_table`: ``None`` (and a WARNING) when ``path`` is None or
    absent. Returns columns ``dataset, paper_frames, global_dof (bool), method, metric, min_k_paper``.

    Raises
    ------
    animsynth.published.PublishedError
        A missing column, a non-number, an empty count, or a global_dof / method / metric the table's
        layout does not have (the message names the file and line).
    """
    df = read_table(path, TABLE2_COLUMNS, numeric=("frames", "min_k"), what="re-sequencing paper Table 2",
                    config_key="published.resequencing.table2")
    if df is None:
        return None
    bad = ~df["global_dof"].isin(PAPER_GLOBAL_DOF) | ~df["method"].isin(PAPER_METHODS) | ~df["metric"].isin(METRICS)
    bad |= df["frames"].isna() | df["min_k"].isna()
    if bad.any():
        i = int(bad.to_numpy().nonzero()[0][0])
        raise PublishedError(f"{path}, line {i + 2}: unknown global_dof/method/metric or an empty count "
                             f"{df.iloc[i][list(TABLE2_COLUMNS[1:])].tolist()}")
    return pd.DataFrame({"dataset": df["motion"], "paper_frames": df["frames"].astype(int),
                         "global_dof": df["global_dof"].map(PAPER_GLOBAL_DOF), "method": df["method"].map(PAPER_METHODS),
                         "metric": df["metric"], "min_k_paper": df["min_k"].astype(int)})


def lee_weights_table(path, weights: dict) -> pd.DataFrame | None:
    """Our Lee weights beside the paper's (CSV: joint_pair, weight); ``None`` without the file.

    Columns: ``group, weight_paper, weight_ours, weight_minus_paper, match`` (equal to the paper's four
    printed decimals)."""
    df = read_table(path, ("joint_pair", "weight"), numeric=("weight",), what="re-sequencing paper Lee weights",
                    config_key="published.resequencing.lee_weights")
    if df is None:
        return None
    df = df.rename(columns={"joint_pair": "group", "weight": "weight_paper"})
    df["weight_ours"] = df["group"].map(lambda g: float(weights.get(g, 0.0)))
    df["weight_minus_paper"] = df["weight_ours"] - df["weight_paper"]
    df["match"] = np.isclose(df["weight_ours"], df["weight_paper"], rtol=0, atol=5e-5)
    return df


def min_k_table(grid: pd.DataFrame, published: pd.DataFrame | None, frame_step: int) -> pd.DataFrame:
    """The paper's Table 2 layout (long form): our min k in both sign modes at the
    workflow's ``frame_step``, with the paper's value beside the matching rows
    (the paper's global-DOF setting per motion; other rows empty)."""
    df = grid[grid["frame_step"] == int(frame_step)].copy()
    df["min_k_paper"] = np.nan
    df["paper_frames"] = np.nan
    if published is not None:
        for rec in published.itertuples():
            m = ((df["dataset"] == rec.dataset) & (df["global_dof"] == bool(rec.global_dof))
                 & (df["method"] == rec.method) & (df["metric"] == rec.metric))
            df.loc[m, "min_k_paper"] = rec.min_k_paper
            df.loc[m, "paper_frames"] = rec.paper_frames
    order = {"walk": 0, "run": 1, "dance": 2}
    df["_o"] = df["dataset"].map(lambda d: order.get(d, 9))
    df["_s"] = df["sign_mode"].map(lambda x: SIGN_MODES.index(x) if x in SIGN_MODES else 9)
    df = df.sort_values(["_o", "dataset", "global_dof", "_s", "method", "metric"], kind="stable")
    cols = ["dataset", "trial", "frames", "fps", "global_dof", "sign_mode", "method", "metric", "min_k",
            "min_k_paper", "paper_frames", "components_at_min_k_minus_1", "components_at_min_k"]
    out = add_paper_differences(df[cols].reset_index(drop=True), {"min_k": "min_k_paper", "frames": "paper_frames"})
    for c in ("min_k_paper", "paper_frames", "min_k_minus_paper", "frames_minus_paper"):
        out[c] = out[c].astype("Int64")
    return out
