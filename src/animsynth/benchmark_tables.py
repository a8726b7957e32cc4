"""Benchmark tables: one benchmark row and its ratio convention (:func:`benchmark_row`, what every
``benchmarks/bench_*.py`` returns), running those scripts into ``benchmarks.csv`` (:func:`run_benchmarks`), and
the per-rule and per-family cost of a run from Snakemake's ``benchmark:`` files."""

from __future__ import annotations

import importlib.util
import logging
import os
import platform
from pathlib import Path

import numpy as np
import pandas as pd

log = logging.getLogger("animsynth.benchmarks")


def benchmark_row(family: str, benchmark: str, value, unit: str, *, better: str, baseline: str = "none",
                  baseline_value=None, target: str = "report only", meets_target=None,
                  digits: int | None = None, **extra) -> dict:
    """One benchmark row, with the one ratio convention of every benchmark table.

    ``ratio`` is how many times better the row's value is than its baseline, so a ratio above 1 always means
    the value beats the baseline: ``baseline_value / value`` when lower is better (times, memory, errors),
    ``value / baseline_value`` when higher is better (rates). ``better`` says which, and is written in the row.

    Parameters
    ----------
    family, benchmark, unit : str
    value : float, the measured value (ours, unless the benchmark's name says otherwise)
    better : {"lower", "higher"}
    baseline : str, what the baseline is (measured in the same run, or published)
    baseline_value : float or None; None: no baseline, no ratio
    target : str; meets_target : bool or None (None: report only)
    digits : int, optional, round the ratio to this many decimals (the value and baseline as the caller gives them)
    **extra : further columns (after the common ones)

    Raises
    ------
    ValueError
        ``better`` is neither "lower" nor "higher".
    """
    if better not in ("lower", "higher"):
        raise ValueError(f"benchmark {benchmark!r}: better must be 'lower' or 'higher', got {better!r}")
    v = float(value)
    if baseline_value is None or not np.isfinite(float(baseline_value)):
        bv, ratio = np.nan, np.nan
    else:
        bv = float(baseline_value)
        num, den = (bv, v) if better == "lower" else (v, bv)
        ratio = num / den if den != 0 else np.nan
        if digits is not None and np.isfinite(ratio):
            ratio = round(ratio, digits)
    return {"family": family, "benchmark": benchmark, "value": v, "unit": unit, "better": better,
            "baseline": baseline, "baseline_value": bv, "ratio": ratio, "target": target,
            "meets_target": np.nan if meets_target is None else bool(meets_target), **extra}


#: The columns of a benchmark row, in order: those :func:`benchmark_row` writes (it names them once).
BENCHMARK_COLUMNS = tuple(benchmark_row("", "", 0.0, "", better="lower"))


def aggregate_rule_benchmarks(paths, root: str = "benchmarks/rules") -> pd.DataFrame:
    """Collect Snakemake ``benchmark:`` TSVs into one table (one row per job).

    ``paths`` are the benchmark files of exactly the jobs of one run (the
    workflow declares them as inputs); a missing or empty file is an error,
    never a silently shorter table.

    Columns: rule, job (the file's path below the rule folder), seconds,
    max_rss_mb (peak resident memory), and the other columns Snakemake writes.
    """
    rows = []
    for p in sorted(map(str, paths)):
        try:
            df = pd.read_csv(p, sep="\t")
        except pd.errors.EmptyDataError:
            raise ValueError(f"{p}: empty benchmark file (the job that writes it was interrupted?)") from None
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


def _per_group(df: pd.DataFrame, key: str, columns: dict) -> pd.DataFrame:
    """Per value of ``key``: its job count and each ``{output column: (input column, "sum"|"max", decimals)}``."""
    cols = [key, "jobs", *columns]
    if df.empty:
        return pd.DataFrame(columns=cols)
    g = df.groupby(key, sort=True)
    out = {key: list(g.groups), "jobs": g.size().values}
    out.update({name: getattr(g[col], how)().round(nd).values for name, (col, how, nd) in columns.items()})
    return pd.DataFrame(out)[cols]


def rule_benchmark_summary(df: pd.DataFrame) -> pd.DataFrame:
    """Per rule: jobs, total and max runtime, peak memory."""
    return _per_group(df, "rule", {"total_seconds": ("seconds", "sum", 2), "max_seconds": ("seconds", "max", 2),
                                   "peak_rss_mb": ("max_rss_mb", "max", 1)})


def family_benchmark_summary(df: pd.DataFrame) -> pd.DataFrame:
    """Per family (data, simplicial, ...): jobs, summed wall and CPU seconds, peak memory of one job."""
    return _per_group(df, "family", {"wall_s": ("seconds", "sum", 1), "cpu_s": ("cpu_time_s", "sum", 1),
                                     "peak_rss_mb": ("max_rss_mb", "max", 1)})


def machine_label() -> str:
    """Where a benchmark ran: architecture, core count and Python, e.g. ``x86_64 2 cores, CPython 3.12.3``."""
    return f"{platform.machine()} {os.cpu_count()} cores, {platform.python_implementation()} {platform.python_version()}"


BENCHMARK_SIZES = ("full", "demo")


def run_benchmarks(files, size: str = "full") -> pd.DataFrame:
    """Import each ``benchmarks/bench_*.py`` and call its ``run(size)``; one row per measurement.

    ``size`` is "full" (the sizes the performance targets are stated for: the
    paper run and ``python3 run.py bench``) or "demo" (seconds, for the default
    and tiny runs). Demo rows keep their measured values and ratios but judge no
    target (``meets_target`` empty): a target holds or fails at full size only.
    Every row carries the machine it ran on and its size, so quoted figures say
    where they came from. The rows come from :func:`benchmark_row`:
    ``better`` says which direction is better, and ``ratio`` above 1 always means
    the value beats its baseline.
    """
    if size not in BENCHMARK_SIZES:
        raise ValueError(f"benchmark size must be one of {BENCHMARK_SIZES}, got {size!r}")
    rows = []
    machine = machine_label()
    for f in sorted(map(str, files)):
        name = Path(f).stem
        spec = importlib.util.spec_from_file_location(f"animsynth_bench_{name}", f)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)  # type: ignore[union-attr]
        log.info("running %s (%s size)", f, size)
        for r in mod.run(size=size):
            r = dict(r)
            r.setdefault("family", name.replace("bench_", ""))
            if size != "full":
                r["meets_target"] = np.nan
                r["target"] = f"{r.get('target', '')} (judged at full size only: python3 run.py bench)"
            r["size"] = size
            r["machine"] = machine
            rows.append(r)
    cols = [*BENCHMARK_COLUMNS[:2], "size", *BENCHMARK_COLUMNS[2:], "machine"]
    df = pd.DataFrame(rows)
    for c in cols:
        if c not in df:
            df[c] = np.nan
    return df[cols + [c for c in df.columns if c not in cols]]
