"""One Table 1 configuration: per-sample threshold search, region graphs, re-synthesis of every sequence."""
import json

from animsynth.facegraph.experiments import run_configuration
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.facegraph.regiongraph import save_graphs
from animsynth.io.atomic import atomic_path, atomic_write_text
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
conf = snakemake.params.conf  # noqa: F821
db = FaceDatabase.load_npz(snakemake.input[0])  # noqa: F821
row, timing, thr, model, per = run_configuration(db, conf, snakemake.params.cfg, snakemake.params.seed)  # noqa: F821
save_graphs(snakemake.output.graphs, model.graphs_,  # noqa: F821
            meta={"config": row["config"], "source": db.source, "seed_sample": model.seed_sample_})
atomic_write_text(snakemake.output.run, json.dumps({"row": row, "timing": timing,  # noqa: F821
                                                     "thresholds": thr.to_dict("records")}, indent=1))
with atomic_path(snakemake.output.samples) as tmp:  # noqa: F821
    # wall-clock synthesis times live in the run's timing record, not in this table
    per.drop(columns=[c for c in per.columns if c.startswith("timing_")]).round(6).to_csv(
        tmp, index=False, float_format="%.6g")
with atomic_path(snakemake.output.sample_thresholds) as tmp:  # noqa: F821
    model.samples_.round(6).to_csv(tmp, index=False, float_format="%.6g")
log.info("%s: %s; timing %s", row["config"], row, timing)
