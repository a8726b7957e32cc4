"""The derivative-variant grid or the beyond-the-paper grid for one subset -> CSV of fold rows."""
from animsynth.simplicial.jobs import grid_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
wc = snakemake.wildcards  # noqa: F821
grid_job(list(snakemake.input), list(snakemake.params.ids), wc.dataset, wc.grid, dict(snakemake.params.cfg),  # noqa: F821
         snakemake.output[0])  # noqa: F821
