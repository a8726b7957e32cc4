"""metrics.png (every metric per generator with its spread) and strips.png (one skeleton strip per generator)."""
from animsynth.compare.jobs import figures_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
figures_job(snakemake.input.metrics, list(snakemake.input.shown), list(p.generators), tuple(p.showcase), p.source,
            dict(snakemake.output))
