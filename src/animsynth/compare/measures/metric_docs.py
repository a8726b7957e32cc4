"""The metric table of ``docs/compare/metrics.md``, rendered from the records (:mod:`.metric_table`).

:func:`metric_table_markdown` renders one row per record; :func:`update_page` writes it between the page's two
markers (:data:`BEGIN`, :data:`END`) and leaves the rest of the page as it is. Run after changing a record::

    .venv/bin/python -m animsynth.compare.measures.metric_docs docs/compare/metrics.md

``tests/test_metric_docs.py`` fails while the page differs from the records.
"""

from __future__ import annotations

import sys
from pathlib import Path

from .metric_table import METRICS, NEEDS, Metric

__all__ = ["BEGIN", "END", "metric_table_markdown", "render_page", "update_page", "main"]

#: the line before the generated table
BEGIN = "<!-- metric table: generated from compare/measures/metric_table.py by compare.measures.metric_docs -->"
#: the line after it
END = "<!-- end of the generated metric table -->"
_HEAD = ("column", "unit", "better", "needs", "tracks", "margin", "why this margin", "heading", "computed by")


def _cell(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _row(m: Metric) -> tuple:
    margin = "" if m.margin is None else f"{m.margin:g}"
    needs = m.needs or "motion"
    return (f"`{m.name}`", m.unit, m.better or "-", needs, ", ".join(m.tracks), margin, m.margin_why,
            m.label or m.title, f"`{m.compute}`")


def metric_table_markdown() -> str:
    """The records as a markdown table (column, unit, better, needs, tracks, margin and why, heading, computation),
    in the order of :data:`~.metric_table.METRICS`, then what each ``needs`` means."""
    lines = ["| " + " | ".join(_HEAD) + " |", "|" + "---|" * len(_HEAD)]
    lines += ["| " + " | ".join(_cell(c) for c in _row(m)) + " |" for m in METRICS]
    lines += ["", "needs: " + "; ".join(f"`{k or 'motion'}`: {v}" for k, v in NEEDS.items()) + "."]
    return "\n".join(lines)


def render_page(text: str, where: str = "the page") -> str:
    """``text`` with the lines between :data:`BEGIN` and :data:`END` replaced by :func:`metric_table_markdown`
    (``ValueError`` naming ``where`` unless each marker is a line of its own, once, in that order)."""
    lines = text.split("\n")
    if lines.count(BEGIN) != 1 or lines.count(END) != 1 or lines.index(BEGIN) > lines.index(END):
        raise ValueError(f"{where}: the markers {BEGIN!r} and {END!r} must each be a line of their own, once, in "
                         "that order")
    a, b = lines.index(BEGIN), lines.index(END)
    return "\n".join([*lines[:a + 1], metric_table_markdown(), *lines[b:]])


def update_page(path) -> bool:
    """Write the generated table into the page ``path``; True when it changed."""
    p = Path(path)
    old = p.read_text(encoding="utf-8")
    new = render_page(old, str(p))
    if new != old:
        p.write_text(new, encoding="utf-8")
    return new != old


def main(pages) -> int:
    """Update each page (default ``docs/compare/metrics.md``); 2 with a one-line error when one cannot be."""
    for page in pages or ["docs/compare/metrics.md"]:
        try:
            print(f"{page}: {'updated' if update_page(page) else 'up to date'}")
        except (OSError, ValueError) as exc:
            print(f"metric_docs: {exc}", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":  # pragma: no cover - the command the module docstring gives
    sys.exit(main(sys.argv[1:]))
