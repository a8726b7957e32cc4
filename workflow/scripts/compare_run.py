"""One generator fitted on every clip's database, every seed generated from the clip's start and scored."""
from animsynth.compare.jobs import run_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
run_job(snakemake.input[0], snakemake.wildcards.cmpgen, dict(p.cfg), int(p.seed), dict(p.roles),
        tuple(p.showcase), dict(snakemake.output))
