"""Aggregate Snakemake's per-rule benchmark files (runtime, peak memory)."""
import glob

from animsynth.report import aggregate_rule_benchmarks, rule_benchmark_summary
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
jobs = aggregate_rule_benchmarks(glob.glob("benchmarks/rules/**/*.tsv", recursive=True))
write_table(jobs, snakemake.output.jobs, md=False)  # noqa: F821
write_table(rule_benchmark_summary(jobs), snakemake.output.per_rule, md=True,  # noqa: F821
            title="Runtime and peak memory per rule (this machine)")
log.info("%d job benchmark files", len(jobs))
