"""Aggregate fold JSONs -> folds/members CSVs, Table II (paper layout, units, ensemble), paired test."""
from animsynth.simplicial.jobs import table_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
p = snakemake.params  # noqa: F821
cfg = dict(p.cfg, seed_value=p.seed)
table_job(list(snakemake.input), list(p.datasets), list(p.methods), cfg, dict(snakemake.output.items()))  # noqa: F821
log.info("wrote %s", ", ".join(map(str, snakemake.output)))  # noqa: F821
