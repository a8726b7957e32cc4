"""Aggregate the per-configuration runs into Table 1 (or the sweep), its timing table and the thresholds."""
import json

import pandas as pd

from animsynth.facegraph.experiments import assemble_table1, assemble_timing, data_note
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.facegraph.settings import read_paper_table1
from animsynth.io.atomic import atomic_write_text
from animsynth.tables import to_markdown, write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
runs = [json.load(open(p)) for p in snakemake.input.runs]  # noqa: F821
db = FaceDatabase.load_npz(snakemake.input.db)  # noqa: F821
paper = read_paper_table1(snakemake.params.paper) if snakemake.params.paper else {}  # noqa: F821
order = snakemake.params.order  # noqa: F821
table = assemble_table1([r["row"] for r in runs], order, paper)
timing = assemble_timing([r["timing"] for r in runs], order, paper)
thr = pd.DataFrame([t for r in runs for t in r["thresholds"]])
src = (f"published values from {snakemake.params.paper}" if paper else  # noqa: F821
       "no published values available (paper_* columns empty)")
note = (f"{data_note(db.source)} {db.n_samples} sequences, {int(db.lengths.sum())} poses. paper_*: {src}. "
        "Node compression = 1 - region-graph nodes / poses (negative when the five region graphs hold more nodes "
        "than poses); velocity angle 100 % = 90 degrees.")
write_table(table, snakemake.output.csv, md=False)  # noqa: F821
write_table(timing, snakemake.output.timing, md=False)  # noqa: F821
# the rendered .md joins the (machine-dependent) timings to the deterministic table
atomic_write_text(snakemake.output.md, to_markdown(table.merge(timing, on="config"), snakemake.params.title,  # noqa: F821
                                                   note + " Times: CPU and wall on this machine (creation includes "
                                                   "the threshold searches); the paper's in Matlab on an i7-4720HQ."))
write_table(thr, snakemake.output.thresholds, title="Thresholds found per region and configuration",  # noqa: F821
            note=f"{data_note(db.source)} Thresholds are medians over samples in per-sample mode; "
                 "in_band_pct = share of samples whose own compression lies in the target band.")
log.info("table: %d rows", len(table))
