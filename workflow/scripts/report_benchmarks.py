"""Run benchmarks/bench_*.py (ratios against in-run baselines) -> results/benchmarks.csv.

Rows measured by other rules (the scale study's 100,000-frame re-sequencing
benchmark, when it is on) are appended as they are.
"""
import os

# numba's OpenMP threads would otherwise spin after each parallel run and take CPU from the next
# timing; set before any benchmark module starts them
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import pandas as pd  # noqa: E402

from animsynth.benchmark_tables import run_benchmarks  # noqa: E402
from animsynth.tables import write_table  # noqa: E402
from animsynth.workflow_utils import setup_logging  # noqa: E402

log = setup_logging(snakemake)
df = run_benchmarks(snakemake.input.scripts, size=snakemake.params.size)
extra = [pd.read_csv(p) for p in snakemake.input.extra]
if extra:
    df = pd.concat([df, *extra], ignore_index=True)[list(df.columns)]
write_table(df, snakemake.output.csv, md=snakemake.output.md, title="Benchmarks (machine-dependent)")
log.info("%d benchmark rows", len(df))
