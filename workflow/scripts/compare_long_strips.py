"""long_strips.png of the comparison: the showcase subject's long context, seed 0, every generator side by side."""
from animsynth.compare.jobs import long_strips_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
long_strips_job(list(snakemake.input.shown), list(p.generators), p.source, float(p.seconds), snakemake.output.strips)
