"""budget_sweep.csv / .md / .png: the graph generators at every transition budget."""
from animsynth.compare.jobs import sweep_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
sweep_job({"default": list(snakemake.input.default), "sweep": list(snakemake.input.sweep)}, dict(snakemake.output),
          float(p.default), list(p.budgets), list(p.generators), list(p.order))
