"""Landmark vs exact Isomap on one database size (dense pipeline cross-checked too)."""
from animsynth.resequencing.cost import landmark_vs_exact
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
cfg = snakemake.params.cfg
c, r = cfg["landmark_vs_exact"], cfg["resequencing"]
seed = int(snakemake.params.seed)
summary, rv = landmark_vs_exact(int(snakemake.wildcards.scn), metric="l2", method="isomap",
                                      n_candidates=r["n_candidates"], k=r["k"], n_landmarks=c["n_landmarks"],
                                      seeds=[seed + s for s in range(int(c["landmark_seeds"]))],
                                      max_dim=c["max_dim"], pairs=c["pairs"], seed=seed,
                                      trial_frames=cfg["trial_frames"], cmu_mirror=snakemake.params.mirror)
write_table(summary, snakemake.output.summary, md=False)
write_table(rv, snakemake.output.rv, md=False)
log.info("n=%s: Procrustes 2-D %s", snakemake.wildcards.scn, summary["procrustes_2d"].round(4).tolist())
