"""Face graph (Zhang et al. 2004) vs region graphs on the same re-synthesis queries."""
from animsynth.facegraph.jobs import baseline_table, data_note
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.facegraph.regiongraph import load_graphs
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
db = FaceDatabase.load_npz(snakemake.input.db)  # noqa: F821
graphs, _ = load_graphs(snakemake.input.graphs)  # noqa: F821
table, timing = baseline_table(db, graphs, snakemake.params.cfg, snakemake.params.seed, snakemake.params.showcase)  # noqa: F821
write_table(table, snakemake.output.csv, title="Face graph (Zhang et al. 2004) vs region graphs",  # noqa: F821
            note=f"{data_note(db.source)} built = false: the complete graph(s) exceed baseline.max_nodes; memory "
                 "computed from their size, accuracy not measured. Path-finding times: baseline_timing.csv.")
write_table(timing, snakemake.output.timing, md=False)  # noqa: F821
log.info("baseline:\n%s\n%s", table.to_string(), timing.to_string())
