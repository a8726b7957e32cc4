"""Write the synthetic CK+-layout database (Landmarks/..., Emotion/...)."""
from animsynth.synth.faces import generate_database
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
cfg = snakemake.params.cfg  # noqa: F821
table = generate_database(snakemake.output[0], seed=snakemake.params.seed, **cfg)  # noqa: F821
lab = table[table.emotion != ""]
log.info("synthetic CK+ layout: %d subjects, %d labelled sequences (%d frames), %d unlabelled",
         table.subject.nunique(), len(lab), lab.frames.sum(), (table.emotion == "").sum())
