"""Fig 3: residual variance against embedding dimension for one dataset."""
import pandas as pd

from animsynth.resequencing.plots import residual_variance_figure
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
rv = pd.concat([pd.read_csv(p) for p in snakemake.input], ignore_index=True)  # noqa: F821
residual_variance_figure(snakemake.output[0], rv, f"Residual variance, {snakemake.wildcards.rsdata}")  # noqa: F821
log.info("%d residual-variance values plotted", len(rv))
