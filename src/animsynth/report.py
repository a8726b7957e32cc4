"""Summary, benchmark aggregation: everything generated from the CSVs, never typed by hand."""

from __future__ import annotations

import importlib.util
import logging
import os
import platform
from pathlib import Path

import numpy as np
import pandas as pd

from . import verdicts as verdict_format
from .tables import to_markdown

log = logging.getLogger("animsynth.report")

# Which paper each family's verdicts speak for.
FAMILY_PAPERS = {
    "simplicial": "Gauch & Peters (simplicial complex)",
    "resequencing": "Isomap / ST-Isomap re-sequencing",
    "meshdetail": "Hybrid mesh animation",
    "facegraph": "Serra et al. 2018 (facial motion graphs)",
    "compare": "Beyond the papers: generators side by side",
}
#: the section of summary.md and of the report's home page that puts the generators side by side
SIDE_BY_SIDE = "The generators side by side"


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


def family_benchmark_summary(df: pd.DataFrame) -> pd.DataFrame:
    """Per family (data, simplicial, ...): jobs, summed wall and CPU seconds, peak memory of one job."""
    cols = ["family", "jobs", "wall_s", "cpu_s", "peak_rss_mb"]
    if df.empty:
        return pd.DataFrame(columns=cols)
    g = df.groupby("family", sort=True)
    return pd.DataFrame({
        "family": list(g.groups),
        "jobs": g.size().values,
        "wall_s": g["seconds"].sum().round(1).values,
        "cpu_s": g["cpu_time_s"].sum().round(1).values,
        "peak_rss_mb": g["max_rss_mb"].max().round(1).values,
    })[cols]


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
    where they came from.
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
    cols = ["family", "benchmark", "size", "value", "unit", "baseline", "baseline_value", "ratio", "target",
            "meets_target", "machine"]
    df = pd.DataFrame(rows)
    for c in cols:
        if c not in df:
            df[c] = np.nan
    return df[cols + [c for c in df.columns if c not in cols]]


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


def claims_table(paths, family_data: dict[str, str] | None = None,
                 family_real: dict[str, bool] | None = None) -> pd.DataFrame:
    """Every claim of the four papers, one row each, from the families' ``verdicts.csv``.

    Parameters
    ----------
    paths : iterable of path
        ``<family>/verdicts.csv`` files (the family is the parent folder's name), each in the common
        format of :mod:`animsynth.verdicts` (checked: columns and vocabulary).
    family_data : dict, optional
        {family: what it ran on}; fills ``data`` where a verdict row leaves it empty.
    family_real : dict
        {family: True if it ran on real data}, as the data layer recorded it. Every row's ``real``
        comes from its family's entry; a family missing here is an error (no word in a text decides it).

    Returns
    -------
    claims : DataFrame
        Columns ``paper, family, claim, paper_value, ours, data, verdict,
        evidence, source, real`` (``real`` is False for synthetic data), real
        data first, then by family in the order given.
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
        df["real"] = bool(family_real[fam])
        df["order"] = len(frames)
        frames.append(df)
    cols = ["paper", "family", *verdict_format.COLUMNS, "real"]
    if not frames:
        return pd.DataFrame(columns=cols)
    out = pd.concat(frames, ignore_index=True)
    out = out.sort_values(["real", "order"], ascending=[False, True], kind="stable")
    return out[cols].reset_index(drop=True)


def _claims_rows_md(df: pd.DataFrame) -> str:
    view = pd.DataFrame({
        "paper": df["paper"],
        "claim": df["claim"],
        "paper's number": df["paper_value"],
        "ours": df["ours"],
        "data": df["data"],
        "verdict": df["verdict"].map(lambda v: f"**{v}**" if v else v),
        "table / figure": df["source"].map(lambda s: f"[{s}]({s})" if s else ""),
    })
    return to_markdown(view)


def claims_markdown(claims: pd.DataFrame, provenance: pd.DataFrame | None = None) -> str:
    """The claims section of ``summary.md``: real-data claims first, synthetic ones apart."""
    out = ["## Claims of the four papers", ""]
    if provenance is not None and not provenance.empty:
        out += ["What each part ran on:", "", to_markdown(provenance), ""]
    for title, mask in (("On real data", claims["real"]), ("On synthetic data", ~claims["real"])):
        part = claims[mask.astype(bool)] if len(claims) else claims
        out += [f"### {title}", ""]
        if part.empty:
            out += ["(none in this run)", ""]
        else:
            counts = part["verdict"].value_counts()
            out += [", ".join(f"{counts[v]} {v}" for v in counts.index) + ".", "", _claims_rows_md(part), ""]
    return "\n".join(out)


def _rst_cell(s: str) -> str:
    return " ".join(str(s).split()).replace("|", "/").replace("*", "\\*").replace("`", "'")


def _side_by_side_rst(winners: pd.DataFrame, data: str) -> list[str]:
    """The home page's section "The generators side by side": which generator wins which metric."""
    out = [SIDE_BY_SIDE, "~" * len(SIDE_BY_SIDE), "",
           f"Every generator on the same held-out clips ({_rst_cell(data)}); the best and second-best by median "
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


def claims_rst(claims: pd.DataFrame, provenance: pd.DataFrame | None, report_outputs=(),
               side_by_side: pd.DataFrame | None = None, side_by_side_data: str = "",
               side_by_side_real: bool = False) -> str:
    """The report's home page (reStructuredText): what ran on what, then every claim.

    ``side_by_side`` (``compare/winners.csv``, when the comparison ran) adds the section "The generators
    side by side" after the claims on the same kind of data (real data first).

    A claim's table or figure becomes a link into the report when a rule's
    ``report(...)`` output ends with it and its file name is unique among the
    report's files (the report names its entries by file name only).
    """
    names: dict[str, list[str]] = {}
    for path in map(str, report_outputs):
        names.setdefault(Path(path).name, []).append(path)

    def link(src: str) -> str:
        if not src:
            return ""
        paths = names.get(Path(src).name, [])
        if len(paths) == 1 and paths[0].endswith(src):
            return f"`{Path(src).name}`_"
        return f"``{_rst_cell(src)}``"

    out = []
    if provenance is not None and not provenance.empty:
        out += ["What each part ran on", "~~~~~~~~~~~~~~~~~~~~~", ""]
        for _, r in provenance.iterrows():
            out.append(f"- **{_rst_cell(r['family'])}**: {_rst_cell(r['data'])} ({_rst_cell(r['status'])})")
        out.append("")
    for title, mask, real in (("Claims on real data", claims["real"], True),
                              ("Claims on synthetic data", ~claims["real"], False)):
        part = claims[mask.astype(bool)] if len(claims) else claims
        out += [title, "~" * len(title), ""]
        if part.empty:
            out += ["(none in this run)", ""]
            if side_by_side is not None and side_by_side_real == real:
                out += _side_by_side_rst(side_by_side, side_by_side_data)
            continue
        out += [".. list-table::", "   :header-rows: 1", "   :widths: 14 26 12 16 12 8 12", "",
                "   * - paper", "     - claim", "     - paper's number", "     - ours", "     - data",
                "     - verdict", "     - table / figure"]
        for _, r in part.iterrows():
            cells = [_rst_cell(r["paper"]), _rst_cell(r["claim"]), _rst_cell(r["paper_value"]), _rst_cell(r["ours"]),
                     _rst_cell(r["data"]), f"**{_rst_cell(r['verdict'])}**" if r["verdict"] else "", link(r["source"])]
            out.append(f"   * - {cells[0]}".rstrip())
            out += [f"     - {c}".rstrip() for c in cells[1:]]
        out.append("")
        if side_by_side is not None and side_by_side_real == real:
            out += _side_by_side_rst(side_by_side, side_by_side_data)
    return "\n".join(out) + "\n"


def build_summary(sections: list[dict], verdict_paths, source_note: str,
                  provenance: pd.DataFrame | None = None, family_data: dict[str, str] | None = None,
                  family_real: dict[str, bool] | None = None, demo: bool = True) -> str:
    """Markdown summary: the papers' claims first (real data, then synthetic), then every table.

    ``sections``: dicts with ``title``, ``csv`` and optional ``note`` (what it
    reproduces and on which data), in order. Sections with a ``group`` (e.g. "The generators side by
    side") come right after the claims, under one heading of that name.
    """
    out = ["# animsynth: reproduction summary", ""]
    banner = demo_banner(family_real, demo)
    if banner:
        out += [banner, ""]
    out += [source_note, ""]
    claims = claims_table(verdict_paths, family_data, family_real)
    if claims.empty:
        out += ["## Claims of the four papers", "", "(no verdicts were produced)", ""]
    else:
        out.append(claims_markdown(claims, provenance))
    groups: dict[str, list[dict]] = {}
    for s in sections:
        if s.get("group"):
            groups.setdefault(s["group"], []).append(s)
    for group, members in groups.items():
        out += [f"## {group}", ""]
        for s in members:
            out += _summary_section(s, "###")
    for s in sections:
        if not s.get("group"):
            out += _summary_section(s, "##")
    return "\n".join(out) + "\n"


def _summary_section(s: dict, level: str) -> list[str]:
    """One table of summary.md: heading, path, note, the table (at most ``max_rows`` rows)."""
    df = pd.read_csv(s["csv"], keep_default_na=False, na_values=[""])
    out = [f"{level} {s['title']}", "", f"`{s['csv']}`", ""]
    if s.get("note"):
        out += [s["note"], ""]
    if len(df) > s.get("max_rows", 60):
        out.append(f"(first {s.get('max_rows', 60)} of {len(df)} rows; full table in the CSV)")
        df = df.head(s.get("max_rows", 60))
    out.append(to_markdown(df))
    return out
