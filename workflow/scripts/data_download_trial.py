"""Fetch one trial's files from the CMU site, a mirror or a user folder, verifying checksums."""
from animsynth.data import fetch_file
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
if "bvh" in snakemake.output.keys():
    fetch_file(p.source, p.bvh, snakemake.output.bvh, p.sha256)
else:
    fetch_file(p.source, p.asf, snakemake.output.asf, p.asf_sha256)
    fetch_file(p.source, p.amc, snakemake.output.amc, p.sha256)
