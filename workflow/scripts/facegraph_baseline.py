"""Face graph (Zhang et al. 2004) vs region graphs on the same re-synthesis queries."""
from animsynth.facegraph.jobs import baseline_table, data_note
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.facegraph.regiongraph import load_graphs
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
db = FaceDatabase.load_npz(snakemake.input.db)
graphs, _ = load_graphs(snakemake.input.graphs)
table, timing = baseline_table(db, graphs, snakemake.params.cfg, snakemake.params.seed, snakemake.params.showcase)
write_table(table, snakemake.output.csv, title="Face graph (Zhang et al. 2004) vs region graphs",
            note=f"{data_note(db.source)} built = false: the complete graph(s) exceed baseline.max_nodes; memory "
                 "computed from their size, accuracy not measured. Path-finding times: baseline_timing.csv.")
write_table(timing, snakemake.output.timing, md=False)
log.info("baseline:\n%s\n%s", table.to_string(), timing.to_string())
