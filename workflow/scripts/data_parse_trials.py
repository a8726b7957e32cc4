"""Parse every used trial with the real readers and store each as .npz (values, columns, skeleton)."""
from animsynth.data import load_trial
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
p = snakemake.params  # noqa: F821
for trial, out in zip(p.trials, snakemake.output):  # noqa: F821
    raw = p.raw[trial]
    m = load_trial(amc=raw.get("amc"), asf=raw.get("asf"), bvh=raw.get("bvh"), fps=p.fps, name=trial,
                   joint_roles=p.joint_roles, bvh_length_to_m=p.bvh_length_to_m)
    m.save_npz(out)
    log.info("%s: %d frames x %d DOF", m.name, m.n_frames, m.values.shape[1])
