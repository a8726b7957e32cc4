"""Parse one trial with the real readers and store it as .npz (values, columns, skeleton)."""
from animsynth.data import load_trial
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
inp = snakemake.input
m = load_trial(amc=inp.get("amc"), asf=inp.get("asf"), bvh=inp.get("bvh"), fps=snakemake.params.fps,
               name=snakemake.wildcards.trial)
m.save_npz(snakemake.output[0])
log.info("%s: %d frames x %d DOF", m.name, m.n_frames, m.values.shape[1])
