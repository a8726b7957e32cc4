"""Generate one synthetic CMU-skeleton trial as ASF + AMC."""
from animsynth.synth.mocap import write_trial
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
spec = snakemake.params.spec
m = write_trial(snakemake.output.amc, snakemake.output.asf, kind=spec["kind"], frames=spec["frames"],
                seed=snakemake.params.seed, subject=spec["subject"],
                subject_master_seed=snakemake.params.subject_seed, fps=snakemake.params.fps, name=spec["id"])
log.info("wrote %s: %s, %d frames, subject %s", spec["id"], spec["kind"], m.n_frames, spec["subject"])
