"""One Table 1 configuration: threshold search, region graphs, re-synthesis of every sequence."""
import json

from animsynth.facegraph.experiments import run_configuration
from animsynth.facegraph.regiongraph import save_graphs
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.io.atomic import atomic_path, atomic_write_text
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
creation, merge = snakemake.params.target
db = FaceDatabase.load_npz(snakemake.input[0])
row, thr, model, per = run_configuration(db, creation, merge, snakemake.params.cfg, snakemake.params.seed)
save_graphs(snakemake.output.graphs, model.graphs_,
            meta={"config": row["config"], "source": db.source, "seed_sample": model.seed_sample_})
atomic_write_text(snakemake.output.run, json.dumps({"row": row, "thresholds": thr.to_dict("records")}, indent=1))
with atomic_path(snakemake.output.samples) as tmp:
    per.round({"landmark_diff_px": 4, "velocity_angle_diff_pct": 4}).to_csv(tmp, index=False, float_format="%.6g")
log.info("%s: %s", row["config"], row)
