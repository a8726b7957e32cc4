"""The long track's tables (:mod:`animsynth.compare.long_track`), gathered from every subject's jobs beside the
2-s track's: ``compare/metrics_long.csv`` (one row per long context x seed and generator), its medians
(``metrics_long.md``), its cost (``metrics_long_timing.csv``: the long track's generation and scoring CPU per
job and database), the long claims' verdicts (appended to ``verdicts.csv`` and ``claims_stats.csv``; their
``source`` is ``compare/metrics_long.csv``) and their section of ``compare/summary.md``.

The long claims (``compare.claims`` with ``track: long``) are decided by the same rule and words as the 2-s claims
(:func:`animsynth.compare.verdicts.decide_claims`), with Holm's correction over the long claims alone: adding
them changes no 2-s verdict.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from .claims import track_claims
from .generators.names import GENERATORS
from .long_track import LONG_NAMES
from .measures.metric_table import on_track

log = logging.getLogger("animsynth.compare.long_tables")

__all__ = ["LONG_ONLY", "LONG_SOURCE", "long_tables", "long_markdown", "with_long_track"]

#: the ``source`` of a long claim's verdict row: the report draws these claims as a scoreboard row of their own
LONG_SOURCE = "compare/metrics_long.csv"
#: the records computed on the long track alone (the columns of the summary's long section)
LONG_ONLY = tuple(m.name for m in on_track("long") if m.tracks == ("long",))


def long_tables(inp: dict, left_out: dict, cfg: dict, clips_full: pd.DataFrame, data: str) -> dict:
    """The long track's tables from the jobs' files (``inp``: ``long_metrics``, ``long_timing`` lists).

    Parameters
    ----------
    inp : the jobs' files
    left_out : {generator: why it did not run}
    cfg : the ``compare`` block (``generators``, ``verdicts``, ``claims``, ``seed``, ``long_track``)
    clips_full : DataFrame, ``compare/clips.csv`` as text (the groups)
    data : what the run is on (the 2-s track's label; the long track's contexts are counted here)

    Returns
    -------
    dict: ``metrics`` (rows in the clips' and the config's generator order), ``medians`` (per generator and long
    record: median and IQR over contexts x seeds), ``timing``, ``verdicts``, ``claims_stats``, ``markdown`` (the
    summary's section)
    """
    from .tables import read_metrics, summary_table
    from .verdicts import decide_claims

    order = list(cfg["generators"])
    metrics = read_metrics(inp["long_metrics"])
    metrics["_g"] = metrics["generator"].map({g: i for i, g in enumerate(order)})
    metrics["_c"] = metrics["clip"].map({c: i for i, c in enumerate(clips_full["clip"])})
    metrics = metrics.sort_values(["_c", "_g", "seed"], kind="stable").drop(columns=["_g", "_c"])
    metrics = metrics[[c for c in metrics if c not in LONG_NAMES + ["note"]] + LONG_NAMES + ["note"]]
    timing = pd.concat([pd.read_csv(p) for p in inp["long_timing"]], ignore_index=True)
    seconds = float(cfg["long_track"]["seconds"])
    label = (f"{data}; the {seconds:g}-s track: {metrics['clip'].nunique()} held-out contexts x up to "
             f"{int(metrics['seed'].max()) + 1 if len(metrics) else 0} seeds")
    own = metrics[metrics["generator"].isin(GENERATORS)]
    verdicts, stats = decide_claims(own, cfg["verdicts"], label, left_out, clips_full,
                                    claims=track_claims(cfg.get("claims"), "long"), seed=int(cfg.get("seed", 0)),
                                    source=LONG_SOURCE)
    medians = summary_table(metrics, order, LONG_NAMES)
    log.info("long track: %d rows (%d contexts x %d generators), %d verdicts: %s", len(metrics),
             metrics["clip"].nunique(), metrics["generator"].nunique(), len(verdicts), ", ".join(verdicts["verdict"]))
    return {"metrics": metrics, "medians": medians, "timing": timing, "verdicts": verdicts, "claims_stats": stats,
            "markdown": long_markdown(metrics, medians, verdicts, seconds, order, label)}


def _pivot(medians: pd.DataFrame, order) -> pd.DataFrame:
    """Generator x long-only record medians (the summary's table)."""
    sub = medians[medians["metric"].isin(LONG_ONLY)]
    tab = sub.pivot(index="generator", columns="metric", values="median")
    tab = tab.reindex(index=[g for g in order if g in tab.index], columns=[m for m in LONG_ONLY if m in tab.columns])
    return tab.reset_index()


def long_markdown(metrics: pd.DataFrame, medians: pd.DataFrame, verdicts: pd.DataFrame, seconds: float, order,
                  data: str) -> str:
    """The summary page's section of the long track: what ran, who did not, the medians of its own records, the
    long claims' verdicts."""
    from ..tables import to_markdown

    out = [f"## The {seconds:g}-second track", "",
           f"Data: {data}. Each subject's long contexts continued for {seconds:g} s from the same build per database "
           "as the 2-s track (docs/compare/long_track.md); rows: `metrics_long.csv`, cost: "
           "`metrics_long_timing.csv`.", ""]
    notes = metrics.loc[metrics["note"] != "", ["generator", "note"]].drop_duplicates("generator")
    if len(notes):
        out += ["Did not run (rows with no values): " + "; ".join(
            f"**{r.generator}**: {r.note.removeprefix('did not run: ')}" for r in notes.itertuples()) + ".", ""]
    tab = _pivot(medians, order)
    if len(tab):
        out += ["Medians over contexts x seeds of the long track's own measures (docs/compare/metrics.md):", "",
                to_markdown(tab.replace({np.nan: None})), ""]
    out += ["### Verdicts of the long track", "", "Declared in advance (compare.claims with `track: long`), decided "
            "by the same rule and words as the 2-s claims, Holm over the long track's claims alone.", ""]
    out += [to_markdown(verdicts[["claim", "ours", "verdict", "evidence"]]) if len(verdicts) else "(no long claim)", ""]
    return "\n".join(out)


def with_long_track(t: dict, inp: dict, left_out: dict, cfg: dict, clips_path) -> dict:
    """The family's tables ``t`` (:func:`animsynth.compare.tables.family_tables`) with the long track's
    (:func:`long_tables` of ``inp``; ``clips_path``: the gathered clips table): ``long`` added, the long claims'
    rows after the 2-s ones in ``verdicts`` and ``claims_stats``, its section at the end of ``summary_md``."""
    long = long_tables(inp, left_out, cfg, pd.read_csv(clips_path, dtype=str), t["data"])
    return dict(t, long=long, verdicts=pd.concat([t["verdicts"], long["verdicts"]], ignore_index=True),
                claims_stats=pd.concat([t["claims_stats"], long["claims_stats"]], ignore_index=True),
                summary_md=t["summary_md"].rstrip("\n") + "\n\n" + long["markdown"])
