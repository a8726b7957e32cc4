"""Render the cost tables of docs/cost.md from runs' own ``rule_benchmarks_per_family.csv``.

Usage::

    python benchmarks/cost_table.py "default run" results "paper run" results/paper
    python benchmarks/cost_table.py --benchmarks results/paper/benchmarks.csv

prints one Markdown table per run: per family the number of jobs, the summed
wall time and CPU time of its jobs (Snakemake's ``benchmark:`` files) and the
largest job's peak memory, then the total. Whole-run wall and CPU time (with
the scheduler's own work and job start-up) are measured around the command
itself (``/usr/bin/time -v``) and quoted beside these tables in docs/cost.md.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd


def cost_table(per_family_csv) -> str:
    df = pd.read_csv(per_family_csv)
    total = {"family": "**total**", "jobs": int(df["jobs"].sum()), "wall_s": df["wall_s"].sum(),
             "cpu_s": df["cpu_s"].sum(), "peak_rss_mb": df["peak_rss_mb"].max()}
    df = pd.concat([df, pd.DataFrame([total])], ignore_index=True)
    lines = ["| family | jobs | wall s (sum over jobs) | CPU s | largest job's peak MB |", "|---|---:|---:|---:|---:|"]
    for r in df.itertuples():
        lines.append(f"| {r.family} | {int(r.jobs)} | {r.wall_s:.0f} | {r.cpu_s:.0f} | {r.peak_rss_mb:.0f} |")
    return "\n".join(lines)


def benchmark_table(benchmarks_csv) -> str:
    """The performance targets of a run's ``benchmarks.csv``: ours, which direction is better, the in-run baseline,
    ratio (above 1: ours is better; :func:`animsynth.benchmark_tables.benchmark_row`), target, met."""
    df = pd.read_csv(benchmarks_csv)
    if "better" not in df:
        raise ValueError(f"{benchmarks_csv}: no column 'better' (written before the one ratio convention; "
                         "rerun the benchmarks)")
    lines = ["| family | benchmark | ours | better | baseline (same run) | ratio (> 1: ours better) | target | met |",
             "|---|---|---:|---|---:|---:|---|---|"]
    for r in df.itertuples():
        met = "" if pd.isna(r.meets_target) else ("yes" if str(r.meets_target).lower() == "true" else "**no**")
        base = "" if pd.isna(r.baseline_value) else f"{r.baseline_value:.4g}"
        ratio = "" if pd.isna(r.ratio) else f"{r.ratio:.3g}"
        lines.append(f"| {r.family} | `{r.benchmark}` | {r.value:.4g} {r.unit} | {r.better} | {base} | {ratio} | "
                     f"{r.target} | {met} |")
    return "\n".join(lines)


def provenance_line(path) -> str:
    """When and where a table was made: the file's modification date and this machine (run it where the run ran)."""
    import datetime

    from animsynth.benchmark_tables import machine_label

    when = datetime.datetime.fromtimestamp(Path(path).stat().st_mtime).strftime("%Y-%m-%d")
    return f"Measured {when} on {machine_label()} (`{path}`)."


def main(argv: list[str]) -> int:
    if len(argv) == 2 and argv[0] == "--benchmarks":
        print(f"{provenance_line(argv[1])}\n\n{benchmark_table(argv[1])}")
        return 0
    if len(argv) < 2 or len(argv) % 2:
        print(__doc__)
        return 2
    for label, folder in zip(argv[::2], argv[1::2]):
        path = Path(folder) / "rule_benchmarks_per_family.csv"
        if not path.is_file():
            print(f"cost_table: {path} does not exist (run the workflow first)", file=sys.stderr)
            return 2
        print(f"{label}: {provenance_line(path)}\n\n{cost_table(path)}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
