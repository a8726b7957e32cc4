"""Figs 1-6 of Gauch & Peters: G' edges, vector fields, held-out vs generated paths."""
from animsynth.simplicial.jobs import figures_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
figures_job(list(snakemake.input), list(p.ids), p.dataset, dict(p.cfg), dict(snakemake.output.items()))
log.info("wrote %s", ", ".join(map(str, snakemake.output)))
