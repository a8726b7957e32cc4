"""The scoreboard: every claim of a run as one coloured cell, one row per paper (and one for the generators
side by side), drawn from ``claims.csv`` with matplotlib.

A reader answers "how many of each paper's claims hold, and on what data?" at a glance:

* one cell per claim, coloured by its verdict (the words of :data:`animsynth.verdicts.VOCABULARY`; a word
  outside it is drawn grey and named in the legend, never dropped), labelled with the claim's id (the id of
  the claims table);
* claims on synthetic data are hatched and their row carries a "synthetic data" badge, claims on real data
  are plain with a "real data" badge;
* sanity checks (claims true by construction, marked in ``claims.csv``; see :func:`sanity_checks`) stand
  apart at the right end of their row and are not counted among the findings;
* under each row its counts, the same numbers :func:`scoreboard_counts` returns (``scoreboard.csv``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from . import families
from .atomic import atomic_path
from .verdicts import VOCABULARY

__all__ = ["VERDICT_COLOURS", "ROW_ORDER", "sanity_checks", "scoreboard_rows", "scoreboard_counts",
           "draw_scoreboard", "scoreboard_figure", "read_claims"]

#: verdict -> cell colour (a diverging green-to-red scale; the cell's id and the legend carry the word too)
VERDICT_COLOURS = {
    "reproduced": "#1a9641",
    "partly": "#a6d96a",
    "within noise": "#fee08b",
    "not reproduced": "#fdae61",
    "contradicted": "#d7191c",
    # not on the scale: too few independent units to decide (a neutral grey-blue, apart from "within noise")
    "undecided": "#9fb4c7",
    # decided, but neither way: equivalence within the margin (a blue, apart from the green-to-red scale)
    "no material difference": "#2b83ba",
    # no evidence at all: the thing did not run (near white)
    "did not run": "#f7f7f7",
}
#: a verdict word outside the vocabulary (a family's newer word): drawn grey, named in the legend
OTHER_COLOUR = "#bdbdbd"
_DARK = {"reproduced", "contradicted", "no material difference"}  # white id text on these
HATCH = "///"  # the cells of claims on synthetic data
#: the order of the rows: the four papers as the project lists them, then the generators side by side (the family
#: registry's report order, :func:`animsynth.families.report_order`); a family not named here follows in the order
#: of ``claims.csv``
ROW_ORDER = tuple(f.name for f in families.report_order())
#: the words that mark a claim true by construction (a column value or a verdict)
SANITY_WORDS = ("sanity check", "sanity-check", "sanity_check", "sanity checks", "sanity")
_TRUE = ("true", "yes", "1", "y")


def _truthy(v) -> bool:
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, float, np.integer, np.floating)):
        return bool(np.isfinite(v) and v != 0)
    s = str(v).strip().lower()
    return s in _TRUE or s in SANITY_WORDS


def sanity_checks(claims: pd.DataFrame) -> pd.Series:
    """Which rows of ``claims`` are sanity checks (true by construction, not findings).

    A row is one when ``claims.csv`` says so in any of the ways a family may mark it: a boolean column
    ``sanity_check`` (or ``sanity``) that is true, a column ``kind`` (or ``type``) whose value is "sanity check",
    or the verdict "sanity check". Without such a marker no row is one; no word of a claim's text decides it.

    Returns
    -------
    Series of bool, aligned with ``claims``.
    """
    mask = pd.Series(False, index=claims.index)
    for col in ("sanity_check", "sanity"):
        if col in claims:
            mask |= claims[col].map(_truthy).astype(bool)
    for col in ("kind", "type"):
        if col in claims:
            mask |= claims[col].astype(str).str.strip().str.lower().isin(SANITY_WORDS)
    if "verdict" in claims:
        mask |= claims["verdict"].astype(str).str.strip().str.lower().isin(SANITY_WORDS)
    return mask


def _real(v) -> bool:
    return _truthy(v)


def scoreboard_rows(claims: pd.DataFrame) -> list[str]:
    """The families of ``claims`` in scoreboard order (:data:`ROW_ORDER`, then any other in table order)."""
    fams = list(dict.fromkeys(claims["family"].astype(str)))
    return [f for f in ROW_ORDER if f in fams] + [f for f in fams if f not in ROW_ORDER]


def _row_parts(claims: pd.DataFrame) -> list[tuple[str, str, pd.DataFrame]]:
    """``(family, paper, rows)`` of every scoreboard row: the families in :func:`scoreboard_rows` order, a family's
    rows split by their ``paper`` label in table order (a family's claims of another kind, such as the comparison's
    long track, carry a label of their own and form a row of their own)."""
    out = []
    for fam in scoreboard_rows(claims):
        part = claims[claims["family"].astype(str) == fam]
        for paper in dict.fromkeys(part["paper"].astype(str)):
            out.append((fam, paper, part[part["paper"].astype(str) == paper]))
    return out


def _verdict_words(claims: pd.DataFrame) -> list[str]:
    """The verdict columns of the counts: the vocabulary from best to worst (:data:`VERDICT_COLOURS`' order),
    then any other word of the findings (sorted)."""
    finding = ~sanity_checks(claims)
    known = [*VERDICT_COLOURS, *(w for w in VOCABULARY if w not in VERDICT_COLOURS)]
    extra = sorted(set(claims.loc[finding, "verdict"].astype(str)) - set(known))
    return [*known, *extra]


def scoreboard_counts(claims: pd.DataFrame) -> pd.DataFrame:
    """The counts the scoreboard draws: one row per scoreboard row.

    Parameters
    ----------
    claims : DataFrame
        ``claims.csv`` (columns ``paper, family, verdict, real`` at least; one row per claim).

    Returns
    -------
    DataFrame with columns ``family, paper, data`` ("real data", "synthetic data" or "real and synthetic
    data"), ``claims`` (findings: every claim but the sanity checks), one column per verdict word
    (the vocabulary first), ``sanity_checks``. The verdict columns of a row sum to its ``claims``.
    """
    words = _verdict_words(claims)
    sanity = sanity_checks(claims)
    rows = []
    for fam, paper, part in _row_parts(claims):
        real = part["real"].map(_real)
        data = "real data" if real.all() else "synthetic data" if not real.any() else "real and synthetic data"
        findings = part[~sanity.loc[part.index]]
        counts = findings["verdict"].astype(str).value_counts()
        rows.append({"family": fam, "paper": paper, "data": data, "claims": len(findings),
                     **{w: int(counts.get(w, 0)) for w in words},
                     "sanity_checks": int(sanity.loc[part.index].sum())})
    return pd.DataFrame(rows, columns=["family", "paper", "data", "claims", *words, "sanity_checks"])


def counts_text(row: pd.Series, words) -> str:
    """One row's counts in words, e.g. '12 claims: 5 reproduced, 3 partly, 4 not reproduced; 2 sanity checks'."""
    n = int(row["claims"])
    parts = [f"{int(row[w])} {w}" for w in words if int(row[w])]
    text = f"{n} claim{'s' if n != 1 else ''}" + (": " + ", ".join(parts) if parts else "")
    s = int(row["sanity_checks"])
    if s:
        text += f"; {s} sanity check{'s' if s != 1 else ''} apart"
    return text


def _colour(verdict: str) -> str:
    return VERDICT_COLOURS.get(verdict, OTHER_COLOUR)


def draw_scoreboard(claims: pd.DataFrame, title: str = "", per_line: int = 24):
    """The scoreboard of ``claims`` as a matplotlib figure, and the counts it draws.

    Parameters
    ----------
    claims : DataFrame
        ``claims.csv``: columns ``id`` (the cell's label; row numbers when absent), ``paper``, ``family``,
        ``verdict``, ``real`` and any sanity-check marker (:func:`sanity_checks`).
    title : the line above the rows ('' for one naming the claim counts, '-' for none)
    per_line : cells per line of a row (a row with more findings wraps)

    Returns
    -------
    fig : matplotlib Figure (one axes in inches, y down; every cell a patch with its id as text, gid
        ``cell:<id>``)
    counts : DataFrame
        The counts under each row (:func:`scoreboard_counts`), one row per scoreboard row.
    """
    import matplotlib.pyplot as plt

    claims = claims.reset_index(drop=True)
    if "id" not in claims:
        claims = claims.assign(id=[str(i + 1) for i in range(len(claims))])
    counts = scoreboard_counts(claims)
    words = [c for c in counts.columns if c not in ("family", "paper", "data", "claims", "sanity_checks")]
    sanity = sanity_checks(claims)
    lay = _Layout(claims, counts, sanity, title, per_line)
    fig = plt.figure(figsize=(lay.width, lay.height), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(0, lay.width)
    ax.set_ylim(lay.height, 0)
    ax.axis("off")
    n_find = int((~sanity).sum())
    n_real = int((claims["real"].map(_real) & ~sanity).sum())
    if title != "-":
        head = title or (f"{n_find} claims tested: {n_real} on real data, {n_find - n_real} on synthetic data"
                         + (f"; {int(sanity.sum())} sanity checks apart" if lay.any_sanity else ""))
        ax.text(lay.left, 0.42, head, fontsize=13, fontweight="bold", va="center", ha="left")
    for (fam, find, san, y0, lines), (_, crow) in zip(lay.blocks, counts.iterrows()):
        _draw_row(fig, ax, lay, crow, find, san, y0, lines, words)
    if lay.any_sanity:
        ax.plot([lay.sanity_x0 - 0.2] * 2, [0.7, lay.height - lay.legend_h + 0.05], color="0.6", lw=0.8, ls="--")
    _draw_legend(ax, lay, counts, words, int(sanity.sum()))
    return fig, counts


class _Layout:
    """Where the scoreboard's parts go (inches, y down): the page's size, the cells' size and spacing, the
    column of sanity checks, and one block ``(family, findings, sanity checks, top, lines)`` per row."""

    cell, gap, left = 0.40, 0.06, 0.25

    def __init__(self, claims: pd.DataFrame, counts: pd.DataFrame, sanity: pd.Series, title: str, per_line: int):
        cell, gap, left = self.cell, self.gap, self.left
        self.per_line = per_line
        self.any_sanity = bool(sanity.any())
        parts = _row_parts(claims)
        n_sanity_cols = max([int(sanity.loc[part.index].sum()) for _f, _p, part in parts] or [0])
        self.n_sanity_cols = min(n_sanity_cols, 6)
        sanity_w = (0.35 + self.n_sanity_cols * (cell + gap) + 0.1) if self.any_sanity else 0.0
        self.width = max(left + per_line * (cell + gap) + sanity_w + 0.25, 8.0)
        self.blocks = []
        y = 0.85 if title != "-" else 0.25
        for fam, _paper, part in parts:
            find = part[~sanity.loc[part.index]]
            san = part[sanity.loc[part.index]]
            lines = max(1, int(np.ceil(len(find) / per_line)), int(np.ceil(len(san) / max(self.n_sanity_cols, 1))))
            self.blocks.append((fam, find, san, y, lines))
            y += self.block_height(lines) + 0.12
        n_handles = len(_verdict_words(claims)) + 2 + int(self.any_sanity)
        self.legend_h = 0.5 if n_handles <= 7 else 0.75
        self.height = y + self.legend_h
        self.sanity_x0 = left + per_line * (cell + gap) + 0.35

    def block_height(self, lines: int) -> float:
        """A row block's height: the name line, ``lines`` lines of cells, the counts line."""
        return 0.32 + lines * (self.cell + self.gap) + 0.30


def _draw_row(fig, ax, lay: _Layout, crow: pd.Series, find: pd.DataFrame, san: pd.DataFrame, y0: float, lines: int,
              words) -> None:
    """One scoreboard row from its top ``y0``: the paper's name and data badge, a cell per finding and per
    sanity check, and the counts line under them."""
    from matplotlib.patches import Rectangle

    cell, gap, left = lay.cell, lay.gap, lay.left
    synthetic_row = crow["data"] == "synthetic data"
    if synthetic_row:  # a light band behind every row on synthetic data
        ax.add_patch(Rectangle((0.08, y0 - 0.06), lay.width - 0.16, lay.block_height(lines) + 0.06,
                               facecolor="#f2f2f2", edgecolor="none", zorder=0))
    name = ax.text(left, y0 + 0.13, str(crow["paper"]), fontsize=11, fontweight="bold", va="center",
                   ha="left")
    badge = crow["data"].upper()
    # the badge right after the paper's name: its position from the name's rendered width (inches)
    name_w = name.get_window_extent(fig.canvas.get_renderer()).width / fig.dpi + 0.15
    ax.text(left + name_w, y0 + 0.13, f" {badge} ", fontsize=8, fontweight="bold", va="center", ha="left",
            color="white" if not synthetic_row else "0.25",
            bbox=dict(boxstyle="round,pad=0.25", facecolor="#2b5d8a" if not synthetic_row else "white",
                      edgecolor="#2b5d8a" if not synthetic_row else "0.3", linewidth=0.8))
    for group, x0, ncol in ((find, left, lay.per_line), (san, lay.sanity_x0, max(lay.n_sanity_cols, 1))):
        for k, (_, r) in enumerate(group.iterrows()):
            _draw_cell(ax, r, x0 + (k % ncol) * (cell + gap), y0 + 0.32 + (k // ncol) * (cell + gap), cell)
    ax.text(left, y0 + 0.32 + lines * (cell + gap) + 0.1, counts_text(crow, words), fontsize=9, va="center",
            ha="left", color="0.15")
    if lay.any_sanity and len(san):
        ax.text(lay.sanity_x0, y0 + 0.13, "sanity checks", fontsize=8, va="center", ha="left", color="0.3",
                style="italic")


def _draw_cell(ax, r: pd.Series, cx: float, cy: float, cell: float) -> None:
    """One claim's cell at ``(cx, cy)``: coloured by its verdict, hatched on synthetic data, its id inside."""
    from matplotlib.patches import FancyBboxPatch

    verdict = str(r["verdict"])
    real = _real(r["real"])
    ax.add_patch(FancyBboxPatch((cx, cy), cell, cell, boxstyle="round,pad=0,rounding_size=0.05",
                                facecolor=_colour(verdict), edgecolor="0.25",
                                linewidth=0.8, hatch=None if real else HATCH, zorder=2,
                                gid=f"cell:{r['id']}"))
    # on a hatched cell the id sits on a light patch, so it stays readable
    ax.text(cx + cell / 2, cy + cell / 2, str(r["id"]), fontsize=7, ha="center", va="center",
            color="white" if verdict in _DARK and real else "black", zorder=3,
            bbox=None if real else dict(boxstyle="round,pad=0.15", facecolor="white", alpha=0.85,
                                        edgecolor="none"))


def _draw_legend(ax, lay: _Layout, counts: pd.DataFrame, words, n_sanity: int) -> None:
    """The legend: every verdict word with its total over the findings, then real / synthetic, then sanity
    checks."""
    from matplotlib.patches import Patch

    handles = [Patch(facecolor=_colour(w), edgecolor="0.25", label=f"{w} ({int(counts[w].sum())})") for w in words]
    handles += [Patch(facecolor="white", edgecolor="0.25", label="real data"),
                Patch(facecolor="white", edgecolor="0.25", hatch=HATCH, label="synthetic data")]
    if lay.any_sanity:
        handles.append(Patch(facecolor="white", edgecolor="0.6", linestyle="--",
                             label=f"sanity check, right of the line ({n_sanity}, not counted)"))
    ax.legend(handles=handles, loc="lower left", bbox_to_anchor=(lay.left / lay.width, 0.02 / lay.height),
              ncol=len(handles) if len(handles) <= 7 else int(np.ceil(len(handles) / 2)), fontsize=8.5, frameon=False,
              handlelength=1.6, columnspacing=1.2)


def scoreboard_figure(claims: pd.DataFrame, path, title: str = "", per_line: int = 24) -> pd.DataFrame:
    """Draw the scoreboard (:func:`draw_scoreboard`) to the PNG ``path`` (atomically; no time stamp in the file);
    return the counts drawn."""
    import matplotlib.pyplot as plt

    fig, counts = draw_scoreboard(claims, title, per_line)
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=100, metadata={"Software": None})
    plt.close(fig)
    return counts


def read_claims(path) -> pd.DataFrame:
    """``claims.csv`` as written by the summary rule (every text a string, ``real`` as bool)."""
    df = pd.read_csv(Path(path), keep_default_na=False, dtype=str)
    if "real" in df:
        df["real"] = df["real"].map(_real)
    return df
