"""Fig 7: a generated walk reprojected to a stick figure (filmstrip PNG, BVH, animated GIF)."""
from animsynth.simplicial.jobs import walk_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
walk_job(list(snakemake.input), list(p.ids), p.dataset, dict(p.cfg), dict(snakemake.output.items()))
log.info("wrote %s", ", ".join(map(str, snakemake.output)))
