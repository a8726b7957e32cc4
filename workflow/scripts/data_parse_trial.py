"""Parse one trial with the real readers and store it as .npz (values, columns, skeleton).

Errors name the user's own file (params.settings.source_files), not its copy under resources/.
"""
import sys

from animsynth.config import ConfigError
from animsynth.data import load_trial
from animsynth.errors import MotionFormatError
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
inp, p = snakemake.input, snakemake.params
try:
    m = load_trial(amc=inp.get("amc"), asf=inp.get("asf"), bvh=inp.get("bvh"), fps=p.fps,
                   name=snakemake.wildcards.trial, **p.settings)
except (MotionFormatError, ConfigError) as exc:  # the file's or the config's fault: one line, no traceback
    log.error("trial %s: %s", snakemake.wildcards.trial, exc)
    print(f"error: trial {snakemake.wildcards.trial}: {exc}", file=sys.stderr)
    sys.exit(1)
m.save_npz(snakemake.output[0])
log.info("%s: %d frames x %d DOF", m.name, m.n_frames, m.values.shape[1])
