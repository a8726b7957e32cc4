"""Check every OBJ frame of the mesh sequence against its SHA-256 list (mismatch names the frame)."""
from animsynth.sources import read_sha256_list, verify_mesh_frames
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
table = verify_mesh_frames(snakemake.input.frames, read_sha256_list(snakemake.input.sums))
write_table(table, snakemake.output[0], md=False)
log.info("%d frames match %s", len(table), snakemake.input.sums)
