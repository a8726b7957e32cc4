"""Generate one synthetic CMU-skeleton trial as ASF + AMC."""
from animsynth.synth.mocap import write_trial
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p, out = snakemake.params, snakemake.output
spec = p.spec
m = write_trial(out.amc, out.asf, kind=spec["kind"], frames=spec["frames"], seed=p.seed, subject=spec["subject"],
                subject_master_seed=p.subject_seed, fps=p.fps, name=spec["id"])
log.info("wrote %s: %s, %d frames, subject %s", spec["id"], spec["kind"], m.n_frames, spec["subject"])
