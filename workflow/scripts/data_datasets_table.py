"""Gauch & Peters Table I for the configured data (results/data/datasets.csv + .md)."""
import os

from animsynth.data import PAPER_TABLE_I, datasets_table
from animsynth.motion import Motion
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
motions = {os.path.basename(p)[:-4]: Motion.load_npz(p) for p in snakemake.input}  # noqa: F821
df = datasets_table(snakemake.params.subsets, motions, snakemake.params.source)  # noqa: F821
note = "Paper (Gauch & Peters, Table I) lengths: " + "; ".join(
    f"{k}: {' '.join(map(str, v))}" for k, v in PAPER_TABLE_I.items())
title = f"Table I: datasets ({snakemake.params.source} data)"  # noqa: F821
write_table(df, snakemake.output.csv, md=True, title=title, note=note)  # noqa: F821
log.info("wrote Table I with %d subsets", len(df))
