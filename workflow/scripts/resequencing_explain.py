"""Min k over the candidate explanations of the paper's Table 2 (sign mode x frame rate x global DOF) and sign flips."""
from animsynth.motion import Motion
from animsynth.atomic import atomic_path
from animsynth.resequencing.jobs import explain
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
wc = snakemake.wildcards
motion = Motion.load_npz(snakemake.input[0])
grid, flips = explain(motion, wc.rsdata, snakemake.params.trial, snakemake.params.cfg,
                      budget_gib=snakemake.params.budget_gib)
with atomic_path(snakemake.output.grid) as tmp:
    grid.to_csv(tmp, index=False, lineterminator="\n")
with atomic_path(snakemake.output.flips) as tmp:
    flips.to_csv(tmp, index=False, lineterminator="\n")
log.info("%s: %d min-k rows, %d sign flips in matrix_naive quaternions", wc.rsdata, len(grid),
         int(flips["flips_matrix_naive"].sum()))
