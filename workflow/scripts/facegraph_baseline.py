"""Face graph (Zhang et al. 2004) vs region graphs on the same re-synthesis queries."""
from animsynth.facegraph.experiments import baseline_table, data_note
from animsynth.facegraph.regiongraph import load_graphs
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
db = FaceDatabase.load_npz(snakemake.input.db)
graphs, _ = load_graphs(snakemake.input.graphs)
table = baseline_table(db, graphs, snakemake.params.cfg, snakemake.params.seed, snakemake.params.showcase)
write_table(table, snakemake.output.csv, title="Face graph (Zhang et al. 2004) vs region graphs",
            note=f"{data_note(db.source)} paper_pathfinding_s: the ~1.9 s the paper reports for the face graph's "
                 "path finding (Matlab). timing_* columns are machine-dependent.")
log.info("baseline:\n%s", table.to_string())
