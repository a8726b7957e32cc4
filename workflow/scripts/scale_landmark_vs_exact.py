"""Landmark vs exact Isomap on one database size (dense pipeline cross-checked too)."""
from animsynth.resequencing.jobs import landmark_vs_exact
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
cfg = snakemake.params.cfg  # noqa: F821
c, r = cfg["landmark_vs_exact"], cfg["resequencing"]
seed = int(snakemake.params.seed)  # noqa: F821
summary, rv = landmark_vs_exact(int(snakemake.wildcards.scn), metric="l2", method="isomap",  # noqa: F821
                                      n_candidates=r["n_candidates"], k=r["k"], n_landmarks=c["n_landmarks"],
                                      seeds=[seed + s for s in range(int(c["landmark_seeds"]))],
                                      max_dim=c["max_dim"], pairs=c["pairs"], seed=seed,
                                      trial_frames=cfg["trial_frames"], cmu_mirror=snakemake.params.mirror)  # noqa: F821
write_table(summary, snakemake.output.summary, md=False)  # noqa: F821
write_table(rv, snakemake.output.rv, md=False)  # noqa: F821
log.info("n=%s: Procrustes 2-D %s", snakemake.wildcards.scn, summary["procrustes_2d"].round(4).tolist())  # noqa: F821
