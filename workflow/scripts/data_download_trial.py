"""Fetch one trial's files from the CMU site, a mirror or a user folder, verifying checksums."""
import sys

from animsynth.data import DownloadError, fetch_file
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
out = snakemake.output
try:
    if "bvh" in out.keys():
        fetch_file(p.source, p.bvh, out.bvh, p.sha256)
    else:
        fetch_file(p.source, p.asf, out.asf, p.asf_sha256)
        fetch_file(p.source, p.amc, out.amc, p.sha256)
except DownloadError as exc:  # deterministic or already retried: one line, no traceback
    log.error("%s", exc)
    print(f"error: {exc}", file=sys.stderr)
    sys.exit(1)
