"""The derivative-variant grid or the beyond-the-paper grid for one subset -> fold rows and ensemble member rows."""
from animsynth.simplicial.jobs import grid_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
wc, p = snakemake.wildcards, snakemake.params
grid_job(list(snakemake.input), list(p.ids), wc.dataset, wc.grid, dict(p.cfg), int(p.seed),
         dict(snakemake.output.items()))
