# One summary for all four systems, and benchmark aggregation.
import os
import re

# Each family's .smk defines <FAMILY>_SUMMARY (tables for results/summary.md)
# and <FAMILY>_VERDICTS (its verdicts.csv files); they are collected here.

DATA_SUMMARY = [
    {
        "title": "Gauch & Peters Table I: datasets",
        "csv": "results/data/datasets.csv",
        "note": "Subsets, pose dimension (56 = 62 DOF minus the root), lengths and total nodes.",
    }
]
SUMMARY_SECTIONS = DATA_SUMMARY + SIMPLICIAL_SUMMARY + RESEQUENCING_SUMMARY + FACEGRAPH_SUMMARY + MESHDETAIL_SUMMARY
# Machine-dependent tables (wall/CPU time: *_timing.csv, timing.csv) are named
# in the summary but not rendered, so that summary.md, like every other table,
# is byte-identical between two runs of one config.
SUMMARY_TIMING = [s["csv"] for s in SUMMARY_SECTIONS if re.search(r"(^|_)timing\.csv$", os.path.basename(s["csv"]))]
VERDICT_FILES = SIMPLICIAL_VERDICTS + RESEQUENCING_VERDICTS + FACEGRAPH_VERDICTS + MESHDETAIL_VERDICTS
BENCH_SCRIPTS = sorted(glob_wildcards("benchmarks/bench_{name}.py").name)


rule summary:
    input:
        tables=[s["csv"] for s in SUMMARY_SECTIONS],
        verdicts=VERDICT_FILES,
    output:
        report(
            "results/summary.md",
            caption="../report/summary.rst",
            category="0. Summary",
        ),
    params:
        sections=[s for s in SUMMARY_SECTIONS if s["csv"] not in SUMMARY_TIMING],
        timing=SUMMARY_TIMING,
        source=SOURCE,
        mesh_dir=config["mesh_dir"],
        faces=config["facegraph"].get("ckplus_dir"),
    threads: 1
    resources:
        mem_mb=500,
        runtime=10,
    log:
        "logs/report/summary.log",
    benchmark:
        "benchmarks/rules/report/summary.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/report_summary.py"


rule benchmarks:
    input:
        expand("benchmarks/bench_{name}.py", name=BENCH_SCRIPTS),
    output:
        report(
            "results/benchmarks.csv",
            caption="../report/benchmarks.rst",
            category="0. Summary",
        ),
    # measured on the tiny config: 254 MB peak, 10 min wall on a loaded 2-core machine
    threads: 1
    resources:
        mem_mb=1000,
        runtime=30,
    log:
        "logs/report/benchmarks.log",
    benchmark:
        "benchmarks/rules/report/benchmarks.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/report_benchmarks.py"


rule rule_benchmarks:
    input:
        DATA_TARGETS + SIMPLICIAL_TARGETS + RESEQUENCING_TARGETS + FACEGRAPH_TARGETS + MESHDETAIL_TARGETS,
        "results/summary.md",
    output:
        jobs="results/rule_benchmarks.csv",
        per_rule=report(
            "results/rule_benchmarks_per_rule.csv",
            caption="../report/rule_benchmarks.rst",
            category="0. Summary",
        ),
    threads: 1
    resources:
        mem_mb=500,
        runtime=10,
    log:
        "logs/report/rule_benchmarks.log",
    benchmark:
        "benchmarks/rules/report/rule_benchmarks.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/report_rule_benchmarks.py"


REPORT_TARGETS = ["results/summary.md", "results/benchmarks.csv", "results/rule_benchmarks.csv"]
