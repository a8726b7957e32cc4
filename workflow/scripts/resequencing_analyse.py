"""Exact min k, Isomap / ST-Isomap fits, residual variance and 2-D embeddings of one dataset x global flag."""
import numpy as np

from animsynth.motion import Motion
from animsynth.atomic import atomic_path
from animsynth.resequencing.jobs import analyse, prepare_motion
from animsynth.resequencing.settings import gdof_flag
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
cfg = snakemake.params.cfg
wc = snakemake.wildcards
motion = prepare_motion(Motion.load_npz(snakemake.input[0]), cfg["max_frames"], cfg["frame_step"])
log.info("%s (%s): %d frames at %.4g fps", wc.rsdata, snakemake.params.trial, motion.n_frames, motion.fps)
min_k, rv, emb, timing = analyse(motion, wc.rsdata, snakemake.params.trial, gdof_flag(wc.rsgdof), cfg,
                                  budget_gib=snakemake.params.budget_gib)
out = snakemake.output
with atomic_path(out.min_k) as tmp:
    min_k.to_csv(tmp, index=False, lineterminator="\n")
with atomic_path(out.rv) as tmp:
    rv.to_csv(tmp, index=False, lineterminator="\n")
with atomic_path(out.emb, suffix=".npz") as tmp:
    np.savez_compressed(tmp, **emb)
with atomic_path(out.timing) as tmp:
    timing.to_csv(tmp, index=False, lineterminator="\n", float_format="%.4f")
