# One summary for all four systems, the report's home page, benchmark aggregation.
# Each family of the registry (animsynth.families) has a .smk that defines <FAMILY>_SUMMARY
# (tables for summary.md), <FAMILY>_VERDICTS (its verdicts.csv files) and <FAMILY>_FIGURES
# (its key figures); they are collected here for the families that run (see FAMILY_RAN in common.smk).
import os
import re

DATA_SUMMARY = [
    {
        "title": "Gauch & Peters Table I: datasets",
        "csv": R("data/datasets.csv"),
        "note": "Subsets, pose dimension (56 = 62 DOF minus the root), lengths and total nodes.",
    }
]
FAMILY_SUMMARIES = {"data": DATA_SUMMARY, **{f.name: family_part(f.name, "SUMMARY") for f in FAMILIES}}
FAMILY_VERDICTS = {f.name: family_part(f.name, "VERDICTS") for f in FAMILIES}
# Every table of the summary, in order, with its family; the first table of each family (the data layer's
# aside) is its key table, shown in the family's section beside its key figures; the others go to the
# summary's detailed tables.
SUMMARY_SECTIONS = [
    dict(s, family=fam, key=(i == 0 and fam != "data"))
    for fam, ss in FAMILY_SUMMARIES.items()
    if FAMILY_RAN[fam]
    for i, s in enumerate(ss)
]
# Machine-dependent tables (wall/CPU time: *_timing.csv, timing.csv) are named
# in the summary but not rendered, so that summary.md, like every other table,
# is byte-identical between two runs of one config.
SUMMARY_TIMING = [s["csv"] for s in SUMMARY_SECTIONS if re.search(r"(^|_)timing\.csv$", os.path.basename(s["csv"]))]
VERDICT_FILES = [v for fam, vs in FAMILY_VERDICTS.items() if FAMILY_RAN[fam] for v in vs]
# Each family's key figures (<FAMILY>_FIGURES of its .smk), shown in its section of summary.md and of the report's
# home page, with what to see in them; in the report's order.
FAMILY_FIGURES = {f.name: family_part(f.name, "FIGURES") for f in report_order()}
KEY_FIGURES = {fam: figs for fam, figs in FAMILY_FIGURES.items() if FAMILY_RAN[fam]}
BENCH_SCRIPTS = sorted(glob_wildcards("benchmarks/bench_{name}.py").name)
# With the scale study on, its 100,000-frame re-sequencing rows join benchmarks.csv.
BENCH_EXTRA = [R("scale/benchmarks.csv")] if config["scale"]["enabled"] else []


rule claims:
    input:
        verdicts=VERDICT_FILES,
    output:
        claims=report(
            R("claims.csv"),
            caption="../report/claims.rst",
            category="0. Summary",
        ),
    params:
        family_data={fam: label for fam, (label, _ok, _why) in FAMILY_STATUS.items()},
        family_real=FAMILY_REAL,
    threads: 1
    resources:
        mem_mb=300,
        runtime=5,
    log:
        L("report/claims.log"),
    benchmark:
        B("report/claims.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/report_claims.py"


rule scoreboard:
    input:
        claims=R("claims.csv"),
    output:
        png=report(
            R("scoreboard.png"),
            caption="../report/scoreboard.rst",
            category="0. Summary",
        ),
        counts=report(
            R("scoreboard.csv"),
            caption="../report/scoreboard_counts.rst",
            category="0. Summary",
        ),
    threads: 1
    resources:
        mem_mb=400,
        runtime=5,
    log:
        L("report/scoreboard.log"),
    benchmark:
        B("report/scoreboard.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/report_scoreboard.py"


rule summary:
    input:
        tables=[s["csv"] for s in SUMMARY_SECTIONS],
        verdicts=VERDICT_FILES,
        claims=R("claims.csv"),
        scoreboard=R("scoreboard.png"),
        figures=[f["png"] for figs in KEY_FIGURES.values() for f in figs],
        side_by_side=[R("compare/winners.csv")] if FAMILY_RAN["compare"] else [],
    output:
        summary=report(
            R("summary.md"),
            caption="../report/summary.rst",
            category="0. Summary",
        ),
        home=R("claims.rst"),
    params:
        sections=[s for s in SUMMARY_SECTIONS if s["csv"] not in SUMMARY_TIMING],
        timing=SUMMARY_TIMING,
        provenance=provenance_rows(),
        family_data={fam: label for fam, (label, _ok, _why) in FAMILY_STATUS.items()},
        family_real=FAMILY_REAL,
        figures=KEY_FIGURES,
        demo=config["demo"],
        report_outputs=report_outputs,
        side_by_side_data=FAMILY_STATUS["compare"][0],
        side_by_side_real=FAMILY_REAL["compare"],
    threads: 1
    resources:
        mem_mb=500,
        runtime=10,
    log:
        L("report/summary.log"),
    benchmark:
        B("report/summary.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/report_summary.py"


rule benchmarks:
    input:
        scripts=expand("benchmarks/bench_{name}.py", name=BENCH_SCRIPTS),
        extra=BENCH_EXTRA,
    output:
        csv=report(
            R("benchmarks.csv"),
            caption="../report/benchmarks.rst",
            category="0. Summary",
        ),
        md=R("benchmarks.md"),
    params:
        size=config["benchmark_size"],
    # full size: ~160 s CPU, 254 MB peak; demo size: seconds
    # 2 threads: the simplicial many-path rows spread paths over numba's threads (fewer with --cores 1)
    threads: 2
    resources:
        mem_mb=1000,
        runtime=30,
    log:
        L("report/benchmarks.log"),
    benchmark:
        B("report/benchmarks.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/report_benchmarks.py"


rule rule_benchmarks:
    input:
        run_benchmark_files,
    output:
        jobs=R("rule_benchmarks.csv"),
        per_rule=report(
            R("rule_benchmarks_per_rule.csv"),
            caption="../report/rule_benchmarks.rst",
            category="0. Summary",
        ),
        per_family=report(
            R("rule_benchmarks_per_family.csv"),
            caption="../report/rule_benchmarks_per_family.rst",
            category="0. Summary",
        ),
        per_rule_md=R("rule_benchmarks_per_rule.md"),
        per_family_md=R("rule_benchmarks_per_family.md"),
    params:
        root=BENCH_ROOT,
    threads: 1
    resources:
        mem_mb=500,
        runtime=10,
    log:
        L("report/rule_benchmarks.log"),
    benchmark:
        B("report/rule_benchmarks.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/report_rule_benchmarks.py"


REPORT_TARGETS = [R("summary.md"), R("scoreboard.png"), R("benchmarks.csv"), R("rule_benchmarks.csv")]
