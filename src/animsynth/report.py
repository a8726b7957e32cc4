"""Summary and report pages: everything generated from the CSVs, never typed by hand."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pandas as pd

from . import families
from . import verdicts as verdict_format
from .tables import to_markdown

log = logging.getLogger("animsynth.report")

#: which paper each family's verdicts speak for (from the family registry, :mod:`animsynth.families`)
FAMILY_PAPERS = {f.name: f.paper for f in families.report_order()}
#: the section of summary.md and of the report's home page that puts the generators side by side
SIDE_BY_SIDE = families.get("compare").section
#: ``{verdict source: label}``: a family's claims decided on that table form a scoreboard row of their own, its
#: ``paper`` the family's with the label added (the comparison's long-track claims beside its 2-s claims)
ROW_PARTS = {"compare/metrics_long.csv": "the long track"}


PAPER_RUN_COMMAND = ("python3 run.py paper --config cmu_mirror=../shared/data/cmu_mocap "
                     "mesh_dir=../shared/data/vlasic_mesh_animation/samba")


def demo_banner(family_real: dict[str, bool] | None, demo: bool = True) -> str:
    """The line that opens the summary of a demo run: one whose config says ``demo: true`` (the embedded
    default's demo sizes) and in which some family ran on synthetic data; '' otherwise.

    A full-size run with a family on synthetic data (the paper run's facial study on the synthetic
    CK+-layout database) gets no banner: its provenance table says what each family ran on.
    """
    synthetic = sorted(f for f, real in (family_real or {}).items() if not real)
    if not demo or not synthetic:
        return ""
    return ("**This is a demo on synthetic data** (" + ", ".join(synthetic) + "): every study runs, on data the "
            "workflow generates, at demo size (see config/config.yaml). Verdicts on synthetic data say whether "
            "the code reproduces a claim's mechanism, not whether the claim holds on real data. The real-data "
            f"reproduction of the four papers at full size: `{PAPER_RUN_COMMAND}`.")




def run_banner(family_real: dict[str, bool] | None, demo: bool = True) -> str:
    """The line that opens the summary: the demo banner (:func:`demo_banner`) in a demo with synthetic data,
    otherwise which families ran on real data (and which, if any, on synthetic data, labelled as such)."""
    banner = demo_banner(family_real, demo)
    if banner or not family_real:
        return banner
    real = [f for f, r in family_real.items() if r and f != "data"]
    synthetic = [f for f, r in family_real.items() if not r and f != "data"]
    size = " at the demo sizes of config/config.yaml" if demo else " at full size"
    if not real:
        return f"**On synthetic data**{size}: " + ", ".join(synthetic) + "."
    text = f"**On real data**{size}: " + ", ".join(real)
    if synthetic:
        text += "; on synthetic data, labelled as such wherever it appears: " + ", ".join(synthetic)
    return text + "."


#: the short name of each paper in the claims table (its full name heads the family's section)
FAMILY_SHORT = {f.name: f.short for f in families.report_order()}
#: the letter of each family's claim ids (S1, S2, ...: the id of a claim's cell in the scoreboard)
FAMILY_LETTER = {f.name: f.letter for f in families.report_order()}
#: the heading of each family's section in summary.md and on the report's home page
FAMILY_SECTION = {f.name: f.section for f in families.report_order()}
#: no line of the summary's claims table is longer than this (characters)
LINE_LIMIT = 400
#: the longest text of each cell of the claims table (characters; a longer one is cut at a word, ending in '…',
#: and the claim's full text is one click away in its family's section)
CELL_LIMITS = {"claim": 140, "paper_value": 60, "ours": 70, "verdict": 30}
#: what "ours" means, said once above the claims table
OURS_MEANS = ("*ours*: this run's number, computed by the workflow on the data listed at the top; "
              "each id links to the claim in full (data, evidence, the table behind it) in its family's section.")


#: A family's table of claims true by construction (same format as verdicts.csv); its rows are sanity checks.
SANITY_FILE = "sanity_checks.csv"


def claim_ids(families) -> list[str]:
    """The id of each claim: its family's letter (:data:`FAMILY_LETTER`) and its line in the family's verdicts.csv.

    A family without a letter takes the first two letters of its name (upper case).
    """
    seen: dict[str, int] = {}
    out = []
    for fam in map(str, families):
        seen[fam] = seen.get(fam, 0) + 1
        out.append(f"{FAMILY_LETTER.get(fam, fam[:2].upper())}{seen[fam]}")
    return out


def claim_anchor(claim_id: str) -> str:
    """The anchor of a claim's full entry (``claim-s3``), in summary.md and on the report's home page."""
    return "claim-" + "".join(ch for ch in str(claim_id).lower() if ch.isalnum())


def shorten(text, limit: int) -> str:
    """``text`` on one line, at most ``limit`` characters: cut at a word and ended with '…' when longer."""
    s = " ".join(str(text).split())
    if len(s) <= limit:
        return s
    cut = s[: max(limit - 1, 1)]
    space = cut.rfind(" ")
    if space >= limit // 2:
        cut = cut[:space]
    return cut.rstrip(" ,;:(") + "…"


def claims_table(paths, family_data: dict[str, str] | None = None,
                 family_real: dict[str, bool] | None = None) -> pd.DataFrame:
    """Every claim of the four papers, one row each, from the families' ``verdicts.csv``.

    Parameters
    ----------
    paths : iterable of path
        ``<family>/verdicts.csv`` (and ``<family>/sanity_checks.csv``) files (the family is the parent folder's
        name), each in the common format of :mod:`animsynth.verdicts` (checked: columns and vocabulary).
    family_data : dict, optional
        {family: what it ran on}; fills ``data`` where a verdict row leaves it empty.
    family_real : dict
        {family: True if it ran on real data}, as the data layer recorded it. Every row's ``real``
        comes from its family's entry; a family missing here is an error (no word in a text decides it).

    Returns
    -------
    claims : DataFrame
        Columns ``id, paper, family, claim, paper_value, ours, data, verdict, evidence, source, real,
        sanity_check`` (``id``: :func:`claim_ids`; ``real`` is False for synthetic data; ``sanity_check`` True for
        the rows of a family's ``sanity_checks.csv``: claims true by construction, shown apart and not counted
        among the findings), real data first, then by family in the order given.
    """
    family_data = family_data or {}
    family_real = family_real or {}
    frames = []
    for p in map(str, paths):
        df = verdict_format.read(p).copy()
        fam = Path(p).parent.name
        if fam not in family_real:
            raise ValueError(f"{p}: the data layer recorded no provenance (real or synthetic) for family {fam!r}; "
                             f"recorded: {sorted(family_real)}")
        df.loc[df["data"].str.strip() == "", "data"] = family_data.get(fam, "")
        df.insert(0, "family", fam)
        df.insert(0, "paper", FAMILY_PAPERS.get(fam, fam))
        for source, part in ROW_PARTS.items():  # claims drawn as a scoreboard row of their own
            df.loc[df["source"].astype(str) == source, "paper"] = f"{FAMILY_PAPERS.get(fam, fam)}: {part}"
        df["real"] = bool(family_real[fam])
        # a family's sanity_checks.csv (claims true by construction, same format) is shown apart, not counted
        df["sanity_check"] = Path(p).name == SANITY_FILE
        df["order"] = len(frames)
        frames.append(df)
    cols = ["id", "paper", "family", *verdict_format.COLUMNS, "real", "sanity_check"]
    if not frames:
        return pd.DataFrame(columns=cols)
    out = pd.concat(frames, ignore_index=True)
    out.insert(0, "id", claim_ids(out["family"]))
    out = out.sort_values(["real", "order"], ascending=[False, True], kind="stable")
    return out[cols].reset_index(drop=True)


def _ids(claims: pd.DataFrame) -> pd.Series:
    """The claims' ids (from an older claims.csv without them: numbered per family)."""
    return claims["id"].astype(str) if "id" in claims else pd.Series(claim_ids(claims["family"]), index=claims.index)


def _md_escape(s: str) -> str:
    return str(s).replace("|", "\\|")


def claim_line_md(r: pd.Series, claim_id: str) -> str:
    """One line of the claims table: id (a link to the claim in full), paper, claim, the paper's number, ours,
    verdict; every cell cut to :data:`CELL_LIMITS`, tightened further until the line fits :data:`LINE_LIMIT`."""
    limits = dict(CELL_LIMITS)
    while True:
        cells = [f"[{claim_id}](#{claim_anchor(claim_id)})",
                 FAMILY_SHORT.get(str(r["family"]), shorten(r["paper"], 24)),
                 shorten(r["claim"], limits["claim"]),
                 shorten(r["paper_value"], limits["paper_value"]),
                 shorten(r["ours"], limits["ours"]),
                 f"**{shorten(r['verdict'], limits['verdict'])}**" if str(r["verdict"]) else ""]
        line = "| " + " | ".join(_md_escape(c) for c in cells) + " |"
        if len(line) <= LINE_LIMIT or limits["claim"] <= 20:
            return line
        limits = {k: max(10, int(v * 0.85)) for k, v in limits.items()}


def _claims_rows_md(df: pd.DataFrame) -> str:
    head = ["| id | paper | claim | paper's number | ours | verdict |", "|---|---|---|---|---|---|"]
    return "\n".join(head + [claim_line_md(r, i) for i, (_, r) in zip(_ids(df), df.iterrows())]) + "\n"


def verdict_counts_md(part: pd.DataFrame) -> str:
    """The counts of some claims in words, counted as the scoreboard counts them
    (:func:`animsynth.scoreboard.scoreboard_counts`): the findings by verdict, from best to worst (then any other
    word), and the sanity checks apart and named as such, e.g. '2 partly, 6 within noise; 2 sanity checks.'

    Parameters
    ----------
    part : DataFrame, rows of ``claims.csv`` (one family, or every claim on real or on synthetic data)
    """
    from .scoreboard import scoreboard_counts

    counts = scoreboard_counts(part)
    words = [c for c in counts.columns if c not in ("family", "paper", "data", "claims", "sanity_checks")]
    text = ", ".join(f"{int(counts[w].sum())} {w}" for w in words if int(counts[w].sum()))
    n_sanity = int(counts["sanity_checks"].sum())
    if n_sanity:
        text += ("; " if text else "") + f"{n_sanity} sanity check{'s' if n_sanity != 1 else ''}"
    return text + "."


def claims_markdown(claims: pd.DataFrame) -> str:
    """The claims section of ``summary.md``: one line per claim, real-data claims first, synthetic ones apart,
    sanity checks (:func:`animsynth.scoreboard.sanity_checks`) in a table of their own after the findings."""
    from .scoreboard import sanity_checks

    out = ["## Claims of the four papers", "", OURS_MEANS, ""]
    sanity = sanity_checks(claims) if len(claims) else pd.Series(dtype=bool)
    for title, mask in (("On real data", claims["real"]), ("On synthetic data", ~claims["real"])):
        mask = mask.astype(bool)
        part = claims[mask & ~sanity] if len(claims) else claims
        checks = claims[mask & sanity] if len(claims) else claims
        out += [f"### {title}", ""]
        if part.empty and checks.empty:
            out += ["(none in this run)", ""]
            continue
        out += [verdict_counts_md(claims[mask]), ""]
        if not part.empty:
            out += [_claims_rows_md(part).rstrip("\n"), ""]
        if not checks.empty:
            out += ["Sanity checks (true by construction, not counted among the findings):", "",
                    _claims_rows_md(checks).rstrip("\n"), ""]
    return "\n".join(out)


def _source_md(src: str) -> str:
    """A claim's table or figure as a link (a single path) or as code (anything else)."""
    src = str(src).strip()
    if not src:
        return ""
    parts = [p.strip() for p in src.replace(";", ",").split(",") if p.strip()]
    if all(" " not in p and "." in p for p in parts):
        return ", ".join(f"[{p}]({p})" for p in parts)
    return f"`{src}`"


_FULL_FIELDS = (("paper_value", "paper's number"), ("ours", "ours"), ("data", "data"), ("evidence", "evidence"))


def claims_in_full_md(part: pd.DataFrame) -> list[str]:
    """The claims of one family in full, each under the anchor the claims table links to: the claim, the
    paper's number, ours, the data, the evidence and the table or figure behind it (nothing cut)."""
    from .scoreboard import sanity_checks

    sanity = sanity_checks(part)
    out = []
    for cid, (idx, r) in zip(_ids(part), part.iterrows()):
        kind = "real data" if bool(r["real"]) else "synthetic data"
        if sanity.loc[idx]:
            kind += "; sanity check, not counted among the findings"
        out += [f'<a id="{claim_anchor(cid)}"></a>', "",
                f"**{cid} · {r['verdict']}** ({kind}): {' '.join(str(r['claim']).split())}", ""]
        for col, label in _FULL_FIELDS:
            text = " ".join(str(r[col]).split())
            if text:
                out.append(f"- {label}: {text}")
        if str(r["source"]).strip():
            out.append(f"- table / figure: {_source_md(r['source'])}")
        out.append("")
    return out


def _rst_cell(s: str) -> str:
    return " ".join(str(s).split()).replace("|", "/").replace("*", "\\*").replace("`", "'")


def _side_by_side_rst(winners: pd.DataFrame, data: str) -> list[str]:
    """The home page's table of the generators side by side: which generator wins which metric."""
    out = [f"Every generator on the same held-out clips ({_rst_cell(data)}); the best and second-best by median "
           "(replay and concat, the realism bounds, aside), and whether their interquartile ranges are apart. "
           "Every table and figure: category *The generators side by side*.", ""]
    if winners is None or winners.empty:
        return out + ["(no metric with two generators in this run)", ""]
    out += [".. list-table::", "   :header-rows: 1", "", "   * - metric", "     - better", "     - best (median)",
            "     - second (median)", "     - beyond the spread", "     - best wins (share of pairs)"]
    for _, r in winners.iterrows():
        cells = [r["metric"], r["better"], f"{r['best']} ({fmt_num(r['best_median'])})",
                 f"{r['second']} ({fmt_num(r['second_median'])})", "yes" if r["beyond_spread"] else "no",
                 fmt_num(r["best_wins_share"])]
        out.append(f"   * - {_rst_cell(cells[0])}")
        out += [f"     - {_rst_cell(c)}" for c in cells[1:]]
    return out + [""]


def fmt_num(x) -> str:
    """A number for the summary texts: 4 significant digits, '' for a missing value."""
    try:
        x = float(x)
    except (TypeError, ValueError):
        return str(x)
    return "" if not np.isfinite(x) else f"{x:.4g}"


def png_data_uri(path, max_width: int = 1100) -> str:
    """A PNG as a ``data:`` URI for the report's home page (self-contained), scaled down to ``max_width``
    pixels when wider (Pillow, Lanczos; deterministic)."""
    import base64
    import io

    from PIL import Image

    with Image.open(path) as im:
        im.load()
        if im.width > max_width:
            im = im.resize((max_width, max(1, round(im.height * max_width / im.width))), Image.LANCZOS)
        buf = io.BytesIO()
        im.save(buf, format="PNG", optimize=True)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


#: The report's page is a flex box that centres its content vertically, so a home page taller than the
#: screen opens in its middle (and its top cannot be scrolled to), in a column 32 rem wide: this style,
#: part of the home page's own HTML, aligns it to the top and widens it (beside the rule graph).
HOME_STYLE = (
    "<style>"
    "div.h-screen.overflow-auto.items-center{align-items:flex-start!important;justify-content:flex-start!important}"
    "div.prose.max-w-lg{max-width:none!important;width:min(58rem,calc(100vw - 20rem))}"
    "div.prose img{max-width:100%;height:auto}"
    "</style>"
)


def _rst_image(uri: str, alt: str, target: str = "") -> list[str]:
    """An image directive; a long (data) URI is wrapped over lines of 76 characters (docutils refuses lines
    longer than its line-length limit and drops the whitespace of a URI)."""
    out = [f".. image:: {uri[:76]}"] + [f"   {uri[i:i + 76]}" for i in range(76, len(uri), 76)]
    out += [f"   :alt: {_rst_cell(alt)}", "   :width: 100%"]
    if target:
        out.append(f"   :target: {target}")
    return out + [""]


def claims_rst(claims: pd.DataFrame, provenance: pd.DataFrame | None, report_outputs=(),
               side_by_side: pd.DataFrame | None = None, side_by_side_data: str = "",
               side_by_side_real: bool = False, *, banner: str = "", scoreboard_png=None,
               family_figures: dict | None = None, family_data: dict[str, str] | None = None,
               family_tables: dict | None = None) -> str:
    """The report's home page (reStructuredText): the scoreboard first, what ran on what, one line per claim,
    then one section per family with its key figures and every claim in full.

    Parameters
    ----------
    claims : DataFrame, ``claims.csv``
    provenance : DataFrame (family, data, status), what each family ran on
    report_outputs : every output path wrapped in ``report(...)``: a claim's table or figure becomes a link into
        the report when a report output ends with it and its file name is unique among the report's files (the
        report names its entries by file name only)
    side_by_side : ``compare/winners.csv`` (when the comparison ran): its table opens the section of the
        generators side by side
    banner : the run's banner (:func:`run_banner`), Markdown bold allowed
    scoreboard_png : path of the scoreboard PNG: embedded (data URI) at the top, linked to its report entry
    family_figures : {family: [{"png": path on disk, "src": path below the results folder, "caption": text}]}:
        each family's key figures, embedded in its section with their captions
    family_data : {family: what it ran on}
    family_tables : {family: [path below the results folder]}: each family's key tables, linked from its section
    """
    from .scoreboard import sanity_checks, scoreboard_rows

    links = _ReportLinks(report_outputs)
    out = [".. raw:: html", "", "   " + HOME_STYLE, ""]
    out += _home_top_rst(banner, scoreboard_png, provenance, links)
    sanity = sanity_checks(claims) if len(claims) else pd.Series(dtype=bool)
    ids = _ids(claims) if len(claims) else pd.Series(dtype=str)
    for title, mask in (("Claims on real data", claims["real"]), ("Claims on synthetic data", ~claims["real"])):
        out += _claims_list_rst(title, claims[mask.astype(bool)] if len(claims) else claims, sanity, ids)
    fams = scoreboard_rows(claims) if len(claims) else []
    if side_by_side is not None and "compare" not in fams:
        fams.append("compare")
    for fam in fams:
        part = claims[claims["family"].astype(str) == fam] if len(claims) else claims
        data = (family_data or {}).get(fam) or (side_by_side_data if fam == "compare" else "")
        real = bool(part["real"].iloc[0]) if len(part) else (side_by_side_real if fam == "compare" else False)
        out += _family_head_rst(fam, data, real, (family_figures or {}).get(fam, []), (family_tables or {}).get(fam),
                                links)
        if fam == "compare" and side_by_side is not None:
            out += _side_by_side_rst(side_by_side, side_by_side_data)
        out += _claims_in_full_rst(FAMILY_SECTION.get(fam, fam), part, sanity, ids, links)
    return "\n".join(out) + "\n"


class _ReportLinks:
    """Links from the home page into the report: a path becomes a link when a report output (``report(...)`` in
    the workflow) ends with it and its file name is unique among the report's files (the report names its
    entries by file name only)."""

    def __init__(self, report_outputs):
        self.names: dict[str, list[str]] = {}
        for path in map(str, report_outputs):
            self.names.setdefault(Path(path).name, []).append(path)

    def target(self, src: str) -> str:
        """The report entry's link target for ``src`` (``"name_"``), or "" when there is none."""
        paths = self.names.get(Path(src).name, [])
        return f"{Path(src).name}_" if src and len(paths) == 1 and paths[0].endswith(src) else ""

    def link(self, src: str) -> str:
        """``src`` as a link into the report, else as literal text ("" for no path)."""
        if not src:
            return ""
        t = self.target(src)
        return f"`{t[:-1]}`_" if t else f"``{_rst_cell(src)}``"


def _home_top_rst(banner: str, scoreboard_png, provenance: pd.DataFrame | None, links: _ReportLinks) -> list[str]:
    """The home page's top: the run's banner, the scoreboard and what each part ran on."""
    out = []
    if banner:
        out += [_rst_cell(banner).replace("\\*\\*", "**"), ""]
    if scoreboard_png is not None:
        out += ["Scoreboard", "~~~~~~~~~~", ""]
        out += _rst_image(png_data_uri(scoreboard_png, 1400), "Scoreboard: one cell per claim, coloured by verdict",
                          links.target("scoreboard.png"))
        out += ["One cell per claim, coloured by its verdict, one row per paper and one for the generators side by "
                "side; hatched cells and grey rows ran on synthetic data. The ids are those of the tables below; "
                "the counts per row are in ``scoreboard.csv``.", ""]
    if provenance is not None and not provenance.empty:
        out += ["What each part ran on", "~~~~~~~~~~~~~~~~~~~~~", ""]
        for _, r in provenance.iterrows():
            out.append(f"- **{_rst_cell(r['family'])}**: {_rst_cell(r['data'])} ({_rst_cell(r['status'])})")
        out.append("")
    return out


def _claims_list_rst(title: str, part: pd.DataFrame, sanity: pd.Series, ids: pd.Series) -> list[str]:
    """One line per claim of ``part`` (a list table under ``title``), each id linked to the claim in full."""
    out = [title, "~" * len(title), ""]
    if part.empty:
        return out + ["(none in this run)", ""]
    out += [OURS_MEANS, "",
            ".. list-table::", "   :header-rows: 1", "   :widths: 6 12 40 14 18 10", "",
            "   * - id", "     - paper", "     - claim", "     - paper's number", "     - ours", "     - verdict"]
    for idx, r in part.iterrows():
        cid = ids.loc[idx]
        verdict = _rst_cell(shorten(r["verdict"], CELL_LIMITS["verdict"]))
        if sanity.loc[idx]:
            verdict += " (sanity check)"
        cells = [f"`{cid} <#{claim_anchor(cid)}>`__", _rst_cell(FAMILY_SHORT.get(str(r["family"]), r["paper"])),
                 _rst_cell(shorten(r["claim"], CELL_LIMITS["claim"])),
                 _rst_cell(shorten(r["paper_value"], CELL_LIMITS["paper_value"])),
                 _rst_cell(shorten(r["ours"], CELL_LIMITS["ours"])), f"**{verdict}**" if verdict else ""]
        out.append(f"   * - {cells[0]}")
        out += [f"     - {c}".rstrip() for c in cells[1:]]
    return out + [""]


def _family_head_rst(fam: str, data: str, real: bool, figures: list, tables, links: _ReportLinks) -> list[str]:
    """A family's section heading, what it ran on, its key figures (embedded) and key tables (linked)."""
    heading = FAMILY_SECTION.get(fam, fam)
    out = [heading, "~" * len(heading), ""]
    if data:
        out += [f"**Data:** {_rst_cell(data)} ({'real' if real else 'synthetic'} data).", ""]
    for fig in figures:
        out += _rst_image(png_data_uri(fig["png"]), fig.get("caption", ""), links.target(fig["src"]))
        out += [f"*{Path(fig['src']).name}:* {_rst_cell(fig.get('caption', ''))}", ""]
    if tables:
        out += ["**Key table:** " + ", ".join(links.link(t) for t in tables)
                + " (the menu's categories hold every table and figure).", ""]
    return out


def _claims_in_full_rst(heading: str, part: pd.DataFrame, sanity: pd.Series, ids: pd.Series,
                        links: _ReportLinks) -> list[str]:
    """Every claim of ``part`` in full (the targets of the claim list's links), under ``heading``."""
    if not len(part):
        return []
    sub = f"{heading}: claims in full"
    out = [sub, "^" * len(sub), ""]
    for idx, r in part.iterrows():
        cid = ids.loc[idx]
        kind = "real data" if bool(r["real"]) else "synthetic data"
        if sanity.loc[idx]:
            kind += "; sanity check, not counted among the findings"
        out += [f".. _{claim_anchor(cid)}:", "",
                f"**{cid} / {_rst_cell(r['verdict'])}** ({kind}): {_rst_cell(r['claim'])}", ""]
        fields = [(label, _rst_cell(r[col])) for col, label in _FULL_FIELDS if str(r[col]).strip()]
        if str(r["source"]).strip():
            fields.append(("table / figure", links.link(str(r["source"]).strip())))
        out += [f":{label}: {text}" for label, text in fields] + [""]
    return out


def scoreboard_markdown(counts: pd.DataFrame, png: str | None) -> list[str]:
    """The scoreboard section of summary.md: the picture, then its counts as a table (the same numbers)."""
    out = ["## Scoreboard", ""]
    if png:
        out += [f"![Scoreboard: one cell per claim, coloured by verdict, one row per paper]({png})", ""]
    out += ["One cell per claim, coloured by its verdict; hatched cells and grey rows ran on synthetic data; "
            "sanity checks stand apart and are not counted. The counts per row:", ""]
    view = counts.drop(columns=["family"]).rename(columns={"sanity_checks": "sanity checks"})
    if not int(counts["sanity_checks"].sum()):
        view = view.drop(columns=["sanity checks"])
    return out + [to_markdown(view).rstrip("\n")]


def _provenance_md(provenance: pd.DataFrame, family_real: dict[str, bool] | None) -> list[str]:
    view = provenance[["family", "data", "status"]].copy()
    if family_real:
        view.insert(2, "kind", [("real" if family_real.get(f) else "synthetic") if f in family_real else ""
                                for f in view["family"]])
    return ["## What each part ran on", "", to_markdown(view).rstrip("\n")]


def build_summary(sections: list[dict], verdict_paths, source_note: str,
                  provenance: pd.DataFrame | None = None, family_data: dict[str, str] | None = None,
                  family_real: dict[str, bool] | None = None, demo: bool = True, *,
                  scoreboard_png: str | None = None, family_figures: dict | None = None,
                  timing_tables=()) -> str:
    """Markdown summary, read top-down: the banner and what each part ran on (once), the scoreboard, one line
    per claim, one section per family (its key figures, its key table, its claims in full), the detailed tables,
    then the machine-dependent timing tables it names but does not show.

    Parameters
    ----------
    sections : list of dict
        The tables in order: ``title``, ``csv``, optional ``note`` (what it reproduces and on which data),
        ``group`` (a heading shared by several, e.g. "The generators side by side"), ``family`` and ``key``
        (true: the family's key table, shown in its section; every other table goes to the detailed tables).
    verdict_paths : the families' verdicts.csv
    source_note : the short sentence after the provenance table (what the numbers are computed on)
    provenance : DataFrame (family, data, status)
    family_data, family_real : what each family ran on, and whether that is real data
    demo : the run is a demo (config ``demo``)
    scoreboard_png : path of the scoreboard picture relative to the summary ('' or None: counts only)
    family_figures : {family: [{"src": path relative to the summary, "caption": what to see in it}]}
    timing_tables : paths of the machine-dependent timing tables (wall and CPU time, different between runs):
        named in a list of their own at the end (:data:`TIMING_HEADING`), not rendered, so that the summary is
        byte-identical between two runs of one config; a short line after ``source_note`` points there
    """
    from .scoreboard import scoreboard_counts, scoreboard_rows

    family_figures = family_figures or {}
    out = ["# animsynth: reproduction summary", ""]
    banner = run_banner(family_real, demo)
    if banner:
        out += [banner, ""]
    if provenance is not None and not provenance.empty:
        out += _provenance_md(provenance, family_real) + [""]
    out += [source_note] + ([TIMING_POINTER] if timing_tables else []) + [""]
    claims = claims_table(verdict_paths, family_data, family_real)
    if claims.empty:
        out += ["## Claims of the four papers", "", "(no verdicts were produced)", ""]
    else:
        out += scoreboard_markdown(scoreboard_counts(claims), scoreboard_png) + [""]
        out.append(claims_markdown(claims))
    keys: dict[str, list[dict]] = {}
    for s in sections:
        if s.get("key") and s.get("family"):
            keys.setdefault(s["family"], []).append(s)
    fams = scoreboard_rows(claims) if len(claims) else []
    fams += [f for f in keys if f not in fams and f in FAMILY_SECTION]
    shown = set()
    for fam in fams:
        part = claims[claims["family"].astype(str) == fam] if len(claims) else claims
        out += [f"## {FAMILY_SECTION.get(fam, fam)}", ""]
        if len(part):
            kind = "real data" if bool(part["real"].iloc[0]) else "synthetic data"
            out += [f"**Data:** {(family_data or {}).get(fam) or part['data'].iloc[0]} ({kind}). "
                    f"Claims {_ids(part).iloc[0]} to {_ids(part).iloc[-1]}: {verdict_counts_md(part)}", ""]
        for fig in family_figures.get(fam, []):
            out += [f"![{fig.get('caption', '')}]({fig['src']})", "",
                    f"*{Path(fig['src']).name}:* {fig.get('caption', '')}", ""]
        for s in keys.get(fam, []):
            out += _summary_section(s, "###")
            out.append("")
            shown.add(id(s))
        if len(part):
            out += [f"### Every claim in full ({FAMILY_SHORT.get(fam, fam)})", ""] + claims_in_full_md(part)
    rest = [s for s in sections if id(s) not in shown]
    if rest:
        out += ["## Detailed tables", ""]
        for s in rest:
            title = f"{s['group']}: {s['title']}" if s.get("group") else s["title"]
            out += _summary_section({**s, "title": title}, "###") + [""]
    if timing_tables:
        out += timing_tables_md(timing_tables) + [""]
    return "\n".join(out).rstrip("\n") + "\n"


#: The heading of the summary's last section: the timing tables it names but does not show.
TIMING_HEADING = "Timing tables"
#: The line after the sentence under the provenance table that points to that section.
TIMING_POINTER = f"Machine-dependent timing tables are listed at the end ([{TIMING_HEADING}](#timing-tables))."


def timing_tables_md(paths) -> list[str]:
    """The summary's last section: the machine-dependent timing tables, one per line (not rendered: their wall
    and CPU times differ between runs)."""
    return [f"## {TIMING_HEADING}", "",
            "Machine-dependent timing tables are not shown here (they differ between runs):", "",
            *(f"- `{t}`" for t in paths)]


def _summary_section(s: dict, level: str) -> list[str]:
    """One table of summary.md: heading, path, note, the table (at most ``max_rows`` rows)."""
    df = pd.read_csv(s["csv"], keep_default_na=False, na_values=[""])
    out = [f"{level} {s['title']}", "", f"`{s['csv']}`", ""]
    if s.get("note"):
        out += [s["note"], ""]
    if len(df) > s.get("max_rows", 60):
        out.append(f"(first {s.get('max_rows', 60)} of {len(df)} rows; full table in the CSV)")
        df = df.head(s.get("max_rows", 60))
    out.append(to_markdown(df).rstrip("\n"))
    return out
