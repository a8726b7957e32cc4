"""Aggregate fold JSONs -> folds/members CSVs, Table II (paper layout, units, ensemble), paired test."""
from animsynth.simplicial.jobs import table_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, p = snakemake.input, snakemake.params
cfg = dict(p.cfg, seed_value=p.seed)
# the published Table II is an input only when its file exists (published_input in common.smk)
table_job(list(i.folds), list(p.datasets), list(p.methods), cfg, dict(snakemake.output.items()),
          paper_table2=next(iter(i.paper_table2), None), paper_label=p.paper_label)
log.info("wrote %s", ", ".join(map(str, snakemake.output)))
