"""One generator job of one subject: every row it runs (a generator; the rows of one method; fairmotion's two rows; a
graph generator's further budgets of the sweep) fitted once per database of the subject's clips, every seed of every
window generated from its start and scored, in one process (the clips read and their references made once for all
rows; fairmotion's loading of every trial and its graph construction once per database for all its rows and
budgets); with compare.long_track on, each default-budget row's long track from the same builds."""
from animsynth.compare.jobs import run_rows
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
run_rows(snakemake.input[0], snakemake.params.rows, snakemake.params.seed,
         lambda name: getattr(snakemake.output, name))
