"""Cost curves of every family -> cost_curves.csv, fitted exponents, log-log plot."""
import pandas as pd

from animsynth import scale
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
curves = pd.concat([pd.read_csv(p) for p in snakemake.input], ignore_index=True)
cols = scale.COLUMNS + [c for c in curves.columns if c not in scale.COLUMNS]
curves = curves[cols]
write_table(curves, snakemake.output.curves, title="Cost curves (machine- and load-dependent)",
            note="CPU and wall seconds per step; peak_mb = peak resident memory of the measuring process during "
                 "the step (peak_kind). See docs/scale.md.")
ex = scale.exponents(curves)
write_table(ex, snakemake.output.exponents, title="Fitted exponents of the cost curves",
            note="Least-squares slope of log(cost) on log(n) per step.")
scale.plot_curves(curves, snakemake.output.plot)
log.info("%d cost rows, %d curves", len(curves), len(ex))
