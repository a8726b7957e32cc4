"""Aggregate the per-configuration runs into Table 1 and the threshold table."""
import json

import pandas as pd

from animsynth.facegraph.experiments import assemble_table1, data_note
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
runs = [json.load(open(p)) for p in snakemake.input.runs]
db = FaceDatabase.load_npz(snakemake.input.db)
table = assemble_table1([r["row"] for r in runs], snakemake.params.order)
thr = pd.DataFrame([t for r in runs for t in r["thresholds"]])
write_table(table, snakemake.output.csv, title="Table 1: region motion graphs per compression configuration",
            note=f"{data_note(db.source)} {db.n_samples} sequences, {int(db.lengths.sum())} frames. paper_* columns "
                 "are empty: the published values are not available to us. timing_* columns are wall-clock on this "
                 "machine (machine-dependent); all other numbers are deterministic.")
write_table(thr, snakemake.output.thresholds, title="Thresholds found per region and configuration",
            note=data_note(db.source))
log.info("table 1: %d rows", len(table))
