"""Compression configurations, one after the other: per-sample threshold search, region graphs, re-synthesis of
every sequence. An untimed warm-up fit first, so that every configuration's creation time excludes numba's
compile or cache load."""
import json

from animsynth.facegraph.jobs import run_configuration, warm_up
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.facegraph.regiongraph import save_graphs
from animsynth.atomic import atomic_path, atomic_write_text
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
out = snakemake.output
cfg, seed = snakemake.params.cfg, snakemake.params.seed
db = FaceDatabase.load_npz(snakemake.input[0])
confs = snakemake.params.confs
warm_up(db, confs[0], cfg, seed)
for i, conf in enumerate(confs):
    row, timing, thr, model, per = run_configuration(db, conf, cfg, seed)
    save_graphs(out.graphs[i], model.graphs_,
                meta={"config": row["config"], "source": db.source, "seed_sample": model.seed_sample_})
    atomic_write_text(out.run[i], json.dumps({"row": row, "timing": timing, "thresholds": thr.to_dict("records")},
                                             indent=1))
    with atomic_path(out.samples[i]) as tmp:
        # wall-clock synthesis times live in the run's timing record, not in this table
        per.drop(columns=[c for c in per.columns if c.startswith("timing_")]).round(6).to_csv(
            tmp, index=False, float_format="%.6g")
    with atomic_path(out.sample_thresholds[i]) as tmp:
        model.samples_.round(6).to_csv(tmp, index=False, float_format="%.6g")
    log.info("%s: %s; timing %s", row["config"], row, timing)
