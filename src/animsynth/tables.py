"""Tables: written once as CSV, rendered to Markdown from that CSV."""

from __future__ import annotations

import os

import numpy as np
import pandas as pd

from .io.atomic import atomic_path, atomic_write_text


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


def write_table(df: pd.DataFrame, csv_path, md: bool = True, title: str | None = None,
                note: str | None = None, float_format: str = "%.6g") -> None:
    """Write ``df`` to ``csv_path`` atomically and, if ``md``, a Markdown copy
    rendered from the CSV just written (``.md`` beside it)."""
    with atomic_path(csv_path) as tmp:
        df.to_csv(tmp, index=False, float_format=float_format, lineterminator="\n")
    if md:
        back = pd.read_csv(csv_path, keep_default_na=False, na_values=[""])
        atomic_write_text(os.path.splitext(os.fspath(csv_path))[0] + ".md", to_markdown(back, title, note))
