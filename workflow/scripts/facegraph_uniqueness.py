"""Distinct animations from one label sequence over N seeded runs."""
from animsynth.facegraph.jobs import data_note, uniqueness_tables
from animsynth.facegraph.regiongraph import load_graphs
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.atomic import atomic_path
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
db = FaceDatabase.load_npz(snakemake.input.db)
graphs, _ = load_graphs(snakemake.input.graphs)
summary, pairs = uniqueness_tables(graphs, snakemake.params.cfg, snakemake.params.seed)
write_table(summary, snakemake.output.csv, title="Uniqueness of synthesised animations",
            note=f"{data_note(db.source)} Pairwise distances: {snakemake.output.pairs}.")
with atomic_path(snakemake.output.pairs) as tmp:
    pairs.to_csv(tmp, index=False, float_format="%.6g", lineterminator="\n")
log.info("uniqueness:\n%s", summary.to_string())
