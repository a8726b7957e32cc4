"""Aggregate the benchmark files of this run's jobs (declared inputs: runtime, peak memory), per rule and per family."""
from animsynth.benchmark_tables import aggregate_rule_benchmarks, family_benchmark_summary, rule_benchmark_summary
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
out = snakemake.output
root = snakemake.params.root
jobs = aggregate_rule_benchmarks(list(snakemake.input), root=root)
write_table(jobs, out.jobs, md=False)
write_table(rule_benchmark_summary(jobs), out.per_rule, md=out.per_rule_md,
            title="Runtime and peak memory per rule (this machine)")
write_table(family_benchmark_summary(jobs), out.per_family, md=out.per_family_md,
            title="Wall time, CPU time and peak memory per family (this machine)")
log.info("%d job benchmark files below %s", len(jobs), root)
