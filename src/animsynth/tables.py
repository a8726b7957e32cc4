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
