"""Aggregate the per-configuration runs into Table 1 (or the sweep), its timing table and the thresholds."""
import json
import os

import pandas as pd

from animsynth.facegraph.jobs import assemble_table1, assemble_timing, data_note
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.facegraph.settings import published_table1
from animsynth.atomic import atomic_write_text
from animsynth.tables import to_markdown, write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
runs = [json.load(open(p)) for p in snakemake.input.runs]
db = FaceDatabase.load_npz(snakemake.input.db)
# Table 1 declares the published table as input "paper" (empty when the file is absent: read_table(None)
# then logs the WARNING); the sweep has no published counterpart and declares none.
published = None
paper = {}
if "paper" in snakemake.input.keys():
    published = snakemake.input.paper[0] if snakemake.input.paper else None
    paper = published_table1(published)
order = snakemake.params.order
table = assemble_table1([r["row"] for r in runs], order, paper)
timing = assemble_timing([r["timing"] for r in runs], order, paper)
thr = pd.DataFrame([t for r in runs for t in r["thresholds"]])
src = (f"published values from {os.path.relpath(published)}" if paper else
       "no published values available (paper_* columns empty)")
note = (f"{data_note(db.source)} {db.n_samples} sequences, {int(db.lengths.sum())} poses. paper_*: {src}. "
        "Node compression = 1 - region-graph nodes / poses (negative when the five region graphs hold more nodes "
        "than poses); velocity angle 100 % = 90 degrees.")
write_table(table, snakemake.output.csv, md=False)
write_table(timing, snakemake.output.timing, md=False)
# the rendered .md joins the (machine-dependent) timings to the deterministic table
atomic_write_text(snakemake.output.md, to_markdown(table.merge(timing, on="config"), snakemake.params.title,
                                                   note + " Times: CPU and wall on this machine (creation includes "
                                                   "the threshold searches); the paper's in Matlab on an i7-4720HQ."))
write_table(thr, snakemake.output.thresholds, title="Thresholds found per region and configuration",
            note=f"{data_note(db.source)} Thresholds are medians over samples in per-sample mode; "
                 "in_band_pct = share of samples whose own compression lies in the target band.")
log.info("table: %d rows", len(table))
