"""Tables: written once as CSV, rendered to Markdown from that CSV."""

from __future__ import annotations

import os

import numpy as np
import pandas as pd

from .atomic import atomic_path, atomic_write_text


def _fmt(v) -> str:
    if v is None or (isinstance(v, float) and np.isnan(v)):
        return ""
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (float, np.floating)):
        a = abs(float(v))
        if a != 0 and (a < 1e-3 or a >= 1e6):
            return f"{float(v):.3e}"
        return f"{float(v):.4g}"
    return str(v).replace("|", "\\|")


def to_markdown(df: pd.DataFrame, title: str | None = None, note: str | None = None) -> str:
    """Render a DataFrame as a GitHub-flavoured Markdown table (no extra dependency)."""
    lines = []
    if title:
        lines += [f"### {title}", ""]
    cols = [str(c) for c in df.columns]
    lines.append("| " + " | ".join(cols) + " |")
    lines.append("|" + "|".join("---" for _ in cols) + "|")
    for row in df.itertuples(index=False):
        lines.append("| " + " | ".join(_fmt(v) for v in row) + " |")
    if note:
        lines += ["", note]
    return "\n".join(lines) + "\n"


def write_table(df: pd.DataFrame, csv_path, md=True, title: str | None = None,
                note: str | None = None, float_format: str = "%.6g") -> None:
    """Write ``df`` to ``csv_path`` atomically and a Markdown copy rendered from the CSV just written.

    ``md``: the Markdown file's path (a workflow passes its declared output), True for the ``.md``
    beside the CSV, False for none. Every file a rule writes is one of its declared outputs (the
    workflow tests check that a run leaves no untracked file).
    """
    with atomic_path(csv_path) as tmp:
        df.to_csv(tmp, index=False, float_format=float_format, lineterminator="\n")
    if md:
        back = pd.read_csv(csv_path, keep_default_na=False, na_values=[""])
        md_path = os.path.splitext(os.fspath(csv_path))[0] + ".md" if md is True else os.fspath(md)
        atomic_write_text(md_path, to_markdown(back, title, note))


def add_paper_differences(df: pd.DataFrame, pairs: dict[str, str], suffix: str = "_minus_paper") -> pd.DataFrame:
    """Put ``ours - paper`` beside each published column.

    Parameters
    ----------
    df : DataFrame with our columns and the paper's
    pairs : {our column: the paper's column}; pairs whose columns are absent are skipped
    suffix : the difference column is ``<our column><suffix>``

    Returns
    -------
    A copy with each difference inserted right after the paper's column
    (empty where either value is missing or not numeric).
    """
    out = df.copy()
    for ours, paper in pairs.items():
        if ours not in out or paper not in out:
            continue
        a = pd.to_numeric(out[ours], errors="coerce").astype(float)
        b = pd.to_numeric(out[paper], errors="coerce").astype(float)
        name = ours + suffix
        if name in out:
            out = out.drop(columns=name)
        out.insert(out.columns.get_loc(paper) + 1, name, a - b)
    return out


#: The columns of a benchmark row (``benchmarks.csv``), in order.
BENCHMARK_COLUMNS = ("family", "benchmark", "value", "unit", "better", "baseline", "baseline_value", "ratio",
                     "target", "meets_target")


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
