"""Unpack mesh_dir (an archive, or a URL of one) into <results_dir>/resources/mesh/<name>/."""
from animsynth.sources import fetch_mesh_frames, read_sha256_list
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
# the sequence's SHA-256 list, or none
sums = list(snakemake.input.get("sums") or [])
sums = sums[0] if sums else None
frames = fetch_mesh_frames(snakemake.params.source, snakemake.output[0],
                           sums=read_sha256_list(sums) if sums else None,
                           max_unpacked_mb=snakemake.params.max_unpacked_mb)
log.info("%d frames from %s", len(frames), snakemake.params.source)
