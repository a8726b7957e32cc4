"""Distinct animations from one label sequence over N seeded runs."""
from animsynth.facegraph.jobs import data_note, uniqueness_tables
from animsynth.facegraph.regiongraph import load_graphs
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.atomic import atomic_path
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
db = FaceDatabase.load_npz(snakemake.input.db)  # noqa: F821
graphs, _ = load_graphs(snakemake.input.graphs)  # noqa: F821
summary, pairs = uniqueness_tables(graphs, snakemake.params.cfg, snakemake.params.seed)  # noqa: F821
write_table(summary, snakemake.output.csv, title="Uniqueness of synthesised animations",  # noqa: F821
            note=f"{data_note(db.source)} Pairwise distances: {snakemake.output.pairs}.")  # noqa: F821
with atomic_path(snakemake.output.pairs) as tmp:  # noqa: F821
    pairs.to_csv(tmp, index=False, float_format="%.6g", lineterminator="\n")
log.info("uniqueness:\n%s", summary.to_string())
