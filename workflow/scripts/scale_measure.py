"""Cost of one family at one size, measured in a fresh child process (animsynth.scale.measure)."""
import re

import pandas as pd

from animsynth import scale
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
cfg = snakemake.params.cfg
fam = snakemake.wildcards.scfamily
m = re.fullmatch(r"n(\d+)(?:_r([0-9.]+))?", snakemake.wildcards.scpoint)
n, res = int(m.group(1)), m.group(2)
seed = int(snakemake.params.seed)
target, kwargs = scale.point_kwargs(fam, cfg, n, seed, resolution=res, mirror=snakemake.params.mirror)
rows = scale.measure(target, **kwargs)
df = pd.DataFrame(rows)
write_table(df, snakemake.output[0], md=False)
for r in rows:
    log.info("%s %s n=%d: %.2f s CPU, %.2f s wall, peak %.0f MB", r["family"], r["step"], r["n"], r["cpu_s"],
             r["wall_s"], r["peak_mb"])
