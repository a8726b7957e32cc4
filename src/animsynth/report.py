"""Summary, benchmark aggregation: everything generated from the CSVs, never typed by hand."""

from __future__ import annotations

import importlib.util
import logging
import os
import platform
from pathlib import Path

import numpy as np
import pandas as pd

from .tables import to_markdown

log = logging.getLogger("animsynth.report")

VERDICT_COLUMNS = ["claim", "verdict", "evidence"]


def aggregate_rule_benchmarks(paths, root: str = "benchmarks/rules") -> pd.DataFrame:
    """Collect Snakemake ``benchmark:`` TSVs into one table (one row per job).

    Columns: rule, job (the file's path below the rule folder), seconds,
    max_rss_mb (peak resident memory), and the other columns Snakemake writes.
    """
    rows = []
    for p in sorted(map(str, paths)):
        try:
            df = pd.read_csv(p, sep="\t")
        except (pd.errors.EmptyDataError, FileNotFoundError):
            continue
        rel = os.path.relpath(p, root)
        parts = rel.split(os.sep)
        # layout: <family>/<step>.tsv (one job) or <family>/<step>/<job>.tsv
        step = parts[1][:-4] if len(parts) == 2 else parts[1]
        job = "/".join(parts[2:])[:-4] if len(parts) > 2 else ""
        for _, r in df.iterrows():
            rows.append({"family": parts[0], "rule": f"{parts[0]}/{step}", "job": job,
                         "seconds": float(r.get("s", np.nan)), "max_rss_mb": float(r.get("max_rss", np.nan)),
                         "max_vms_mb": float(r.get("max_vms", np.nan)), "cpu_time_s": float(r.get("cpu_time", np.nan))})
    cols = ["family", "rule", "job", "seconds", "max_rss_mb", "max_vms_mb", "cpu_time_s"]
    return pd.DataFrame(rows, columns=cols)


def rule_benchmark_summary(df: pd.DataFrame) -> pd.DataFrame:
    """Per rule: jobs, total and max runtime, peak memory."""
    if df.empty:
        return pd.DataFrame(columns=["rule", "jobs", "total_seconds", "max_seconds", "peak_rss_mb"])
    g = df.groupby("rule", sort=True)
    return pd.DataFrame({
        "rule": list(g.groups),
        "jobs": g.size().values,
        "total_seconds": g["seconds"].sum().round(2).values,
        "max_seconds": g["seconds"].max().round(2).values,
        "peak_rss_mb": g["max_rss_mb"].max().round(1).values,
    })


def run_benchmarks(files) -> pd.DataFrame:
    """Import each ``benchmarks/bench_*.py`` and call its ``run()``; one row per measurement.

    Every row carries the machine it ran on, so quoted figures say where they
    came from.
    """
    rows = []
    machine = f"{platform.machine()} {os.cpu_count()} cores, {platform.python_implementation()} {platform.python_version()}"
    for f in sorted(map(str, files)):
        name = Path(f).stem
        spec = importlib.util.spec_from_file_location(f"animsynth_bench_{name}", f)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)  # type: ignore[union-attr]
        log.info("running %s", f)
        for r in mod.run():
            r = dict(r)
            r.setdefault("family", name.replace("bench_", ""))
            r["machine"] = machine
            rows.append(r)
    cols = ["family", "benchmark", "value", "unit", "baseline", "baseline_value", "ratio", "target", "meets_target", "machine"]
    df = pd.DataFrame(rows)
    for c in cols:
        if c not in df:
            df[c] = np.nan
    return df[cols + [c for c in df.columns if c not in cols]]


def read_verdicts(paths) -> pd.DataFrame:
    frames = []
    for p in sorted(map(str, paths)):
        df = pd.read_csv(p, keep_default_na=False)
        missing = [c for c in VERDICT_COLUMNS if c not in df]
        if missing:
            raise ValueError(f"{p}: verdict table lacks columns {missing}")
        df = df[VERDICT_COLUMNS].copy()
        df.insert(0, "family", Path(p).parent.name)
        frames.append(df)
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=["family"] + VERDICT_COLUMNS)


def build_summary(sections: list[dict], verdict_paths, source_note: str) -> str:
    """Markdown summary: verdicts first, then every table, each rendered from its CSV.

    ``sections``: dicts with ``title``, ``csv`` and optional ``note`` (what it
    reproduces and on which data), in order.
    """
    out = ["# animsynth: reproduction summary", "", source_note, ""]
    verdicts = read_verdicts(verdict_paths)
    out += ["## Verdicts (generated from the tables below)", ""]
    if verdicts.empty:
        out += ["(no verdicts were produced)", ""]
    else:
        out.append(to_markdown(verdicts))
    for s in sections:
        df = pd.read_csv(s["csv"], keep_default_na=False, na_values=[""])
        out += [f"## {s['title']}", "", f"`{s['csv']}`", ""]
        if s.get("note"):
            out += [s["note"], ""]
        if len(df) > s.get("max_rows", 60):
            out.append(f"(first {s.get('max_rows', 60)} of {len(df)} rows; full table in the CSV)")
            df = df.head(s.get("max_rows", 60))
        out.append(to_markdown(df))
    return "\n".join(out) + "\n"
