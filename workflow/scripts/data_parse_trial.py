"""Parse one trial with the real readers and store it as .npz (values, columns, skeleton)."""
from animsynth.data import load_trial
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
inp, p = snakemake.input, snakemake.params
m = load_trial(amc=inp.get("amc"), asf=inp.get("asf"), bvh=inp.get("bvh"), fps=p.fps,
               name=snakemake.wildcards.trial, joint_roles=p.joint_roles,
               bvh_length_to_m=p.bvh_length_to_m)
m.save_npz(snakemake.output[0])
log.info("%s: %d frames x %d DOF", m.name, m.n_frames, m.values.shape[1])
