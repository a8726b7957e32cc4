"""Run benchmarks/bench_*.py (ratios against in-run baselines) -> results/benchmarks.csv."""
from animsynth.report import run_benchmarks
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
df = run_benchmarks(snakemake.input)  # noqa: F821
write_table(df, snakemake.output[0], md=True, title="Benchmarks (machine-dependent)")  # noqa: F821
log.info("%d benchmark rows", len(df))
