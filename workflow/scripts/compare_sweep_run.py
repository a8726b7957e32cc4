"""One graph generator at one further transition budget over every clip and seed (the budget sweep)."""
from animsynth.compare.jobs import run_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
run_job(snakemake.input[0], snakemake.wildcards.cmpgraph, dict(p.cfg), int(p.seed), dict(p.roles), None,
        dict(snakemake.output))
