"""One generator fitted on every clip's database, every seed generated from the clip's start and scored."""
from animsynth.compare.jobs import run_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
p = snakemake.params  # noqa: F821
run_job(snakemake.input[0], snakemake.wildcards.cmpgen, dict(p.cfg), int(p.seed), dict(p.roles),  # noqa: F821
        tuple(p.showcase), dict(snakemake.output))  # noqa: F821
