"""Parse the mesh sequence (OBJ / OBJ.gz frames, one topology) and edited sequences into npz caches."""
from animsynth.meshdetail.jobs import load_sequences
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, o, p = snakemake.input, snakemake.output, snakemake.params
truth = i.truth[0] if len(i.truth) else None
seq = load_sequences(str(i.main), truth, o.seq, o.edits, float(p.fps), p.max_frames)
log.info("%d frames x %d vertices, %d faces", seq.n_frames, seq.n_vertices, len(seq.faces))
