"""metrics.png (every metric per generator with its spread), strips.png (one skeleton strip per generator) and the
showcase's BVH files."""
from animsynth.compare.jobs import figures_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
figures_job(snakemake.input.metrics, list(snakemake.input.shown), list(p.generators), p.source,
            dict(snakemake.output))
