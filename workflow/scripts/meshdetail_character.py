"""Generate the synthetic skirt character: OBJ sequences of the clip and of its edits + truth.npz."""
import os

from animsynth.meshdetail.jobs import make_character
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
out = snakemake.output
info = make_character(dict(snakemake.params.cfg), int(snakemake.params.seed), os.path.dirname(out.truth))
log.info("wrote %s", info)
