"""Config checks of the simplicial family and the published values it shows beside ours.

:func:`check` holds every check of the ``simplicial`` config block beyond the schema (the workflow calls
it once, from ``workflow/rules/common.smk``); every default comes from ``config/schema.yaml``.

The published tables are named by config ``published.simplicial.table1`` and ``.table2`` and read only
through :func:`animsynth.published.read_table` (a missing file: ``None`` and a WARNING, the ``paper_*``
columns stay empty and the verdicts fall back to ``simplicial.paper_claim`` for the ordering; a
malformed file: :class:`~animsynth.published.PublishedError` naming the file and line). This module maps
them to the shapes the tables use:

* Table II (:func:`read_paper_table2`): columns ``metric, method, w1, w2, r1, r2, all``. The paper calls
  its k-NN method ``knn16`` (k = 16); any ``knn<k>`` is shown as our ``knn`` row.
* Table I (:func:`read_paper_table1`): columns ``dataset`` and ``lengths`` (space-separated frame counts).
"""

from __future__ import annotations

import re

import pandas as pd

from ..config import ConfigError
from ..published import PublishedError, read_table

#: Subset columns of the published Table II (the paper's w1 w2 r1 r2 and all folds).
TABLE2_SUBSETS = ("w1", "w2", "r1", "r2", "all")
TABLE2_METRICS = ("error_a", "error_f")


def check_figure_folds(figures: dict, n_trials: int, dataset: str) -> None:
    """Fold indices of ``simplicial.figures`` (``folds``, ``field_fold``, ``walk_fold``) inside the subset.

    Raises
    ------
    ConfigError
        naming the key, when an index is not in ``0 .. n_trials - 1``.
    """
    named = [("folds", i) for i in figures["folds"]] + [("field_fold", figures["field_fold"]),
                                                        ("walk_fold", figures["walk_fold"])]
    for key, i in named:
        if not 0 <= int(i) < n_trials:
            raise ConfigError(f"config key 'simplicial.figures.{key}': fold index {i} outside 0..{n_trials - 1} "
                              f"(subset {dataset!r} has {n_trials} trials)")


def check(config: dict) -> None:
    """Checks of the ``simplicial`` block beyond the schema, on a schema-validated config.

    Raises
    ------
    ConfigError
        naming the key: ``simplicial.figures.dataset`` not one of the subsets in use (a subset set to
        null is not in use).

    The figure fold indices are checked by the figure jobs (:func:`check_figure_folds`), not here: a
    config whose subsets are shorter than the default figure folds must still be able to run every
    other job (its data downloads, its tables) and learns about the folds only if it asks for figures.
    """
    fig = config["simplicial"]["figures"]
    subsets = {k: v for k, v in config["subsets"].items() if v}
    if fig["dataset"] not in subsets:
        raise ConfigError(f"config key 'simplicial.figures.dataset': {fig['dataset']!r} is not a subset "
                          f"({list(subsets)})")


def read_paper_table2(path) -> pd.DataFrame | None:
    """The paper's Table II as ``metric, method, paper_method, w1, w2, r1, r2, all`` (floats), or None.

    Parameters
    ----------
    path : str, path or None
        The published table (config ``published.simplicial.table2``, resolved by the workflow); None or a
        missing file -> None (a WARNING names the path).

    Raises
    ------
    PublishedError
        a missing column, a non-number in a subset column, or a metric other than ``error_a``/``error_f``
        (the message names the file and line).
    """
    df = read_table(path, ("metric", "method") + TABLE2_SUBSETS, numeric=TABLE2_SUBSETS,
                    what="Gauch & Peters Table II", config_key="published.simplicial.table2")
    if df is None:
        return None
    rows = []
    for i, r in enumerate(df.itertuples(index=False)):
        metric, method = r.metric.strip(), r.method.strip()
        if metric not in TABLE2_METRICS:
            raise PublishedError(f"{path}, line {i + 2}: metric must be one of {list(TABLE2_METRICS)}, "
                                 f"got {metric!r}")
        rows.append({"metric": metric, "method": "knn" if re.fullmatch(r"knn(\d*)", method) else method,
                     "paper_method": method})
    out = pd.DataFrame(rows, columns=["metric", "method", "paper_method"])
    for c in TABLE2_SUBSETS:
        out[c] = df[c].to_numpy(float)
    return out


def read_paper_table1(path) -> dict[str, list[int]] | None:
    """The paper's Table I lengths as ``{subset: [frames, ...]}``, or None when there is no file.

    Parameters
    ----------
    path : str, path or None
        The published table (config ``published.simplicial.table1``); None or a missing file -> None
        (a WARNING names the path).

    Raises
    ------
    PublishedError
        a missing ``dataset`` or ``lengths`` column, or lengths that are not integers (file and line).
    """
    df = read_table(path, ("dataset", "lengths"), what="Gauch & Peters Table I",
                    config_key="published.simplicial.table1")
    if df is None:
        return None
    out = {}
    for i, (name, lengths) in enumerate(zip(df["dataset"], df["lengths"])):
        try:
            out[name.strip()] = [int(x) for x in lengths.split()]
        except ValueError:
            raise PublishedError(f"{path}, line {i + 2}: lengths must be integers separated by spaces, "
                                 f"got {lengths!r}") from None
    return out


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


__all__ = ["TABLE2_SUBSETS", "check", "check_figure_folds", "paper_claim_from", "read_paper_table1",
           "read_paper_table2"]
