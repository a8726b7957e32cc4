"""Gauch & Peters Table I for the configured data, with the published lengths beside ours (results/data/datasets.csv + .md)."""
from animsynth.simplicial.jobs import table1_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, p = snakemake.input, snakemake.params
# the published table is an input only when its file exists (published_input in common.smk)
table1_job(list(i.trials), dict(p.subsets), p.source, dict(snakemake.output.items()),
           paper_table1=next(iter(i.paper_table1), None), paper_label=p.paper_label)
