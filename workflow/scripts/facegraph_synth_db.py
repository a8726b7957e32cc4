"""Write the synthetic CK+-layout database (Landmarks/..., Emotion/...)."""
from animsynth.synth.faces import generate_database
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
cfg = snakemake.params.cfg
table = generate_database(snakemake.output[0], seed=snakemake.params.seed, **cfg)
lab = table[table.emotion != ""]
log.info("synthetic CK+ layout: %d subjects, %d labelled sequences (%d frames), %d unlabelled",
         table.subject.nunique(), len(lab), lab.frames.sum(), (table.emotion == "").sum())
