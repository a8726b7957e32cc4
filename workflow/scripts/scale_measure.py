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
if fam == "resequencing":
    c = cfg["resequencing"]
    rows = scale.measure("resequencing_steps", n=n, metric=c["metric"], method=c["method"],
                         n_candidates=c["n_candidates"], k=c["k"], embedding=c["embedding"],
                         exact_max_frames=c["exact_max_frames"], n_landmarks=c["n_landmarks"],
                         landmarks=c["landmarks"], seed=seed, trial_frames=cfg["trial_frames"],
                         cmu_mirror=snakemake.params.mirror)
elif fam == "simplicial":
    c = cfg["simplicial"]
    rows = scale.measure("simplicial_steps", n=n, seed=seed, steps=c["path_steps"], trial_frames=c["trial_frames"])
elif fam == "facegraph":
    c = cfg["facegraph"]
    rows = scale.measure("facegraph_steps", n=n, seed=seed, creation=c["creation"], merge=c["merge"])
else:
    c = cfg["meshdetail"]
    rows = scale.measure("meshdetail_steps", n=n, resolution=float(res), seed=seed, iterations=c["iterations"])
df = pd.DataFrame(rows)
write_table(df, snakemake.output[0], md=False)
for r in rows:
    log.info("%s %s n=%d: %.2f s CPU, %.2f s wall, peak %.0f MB", r["family"], r["step"], r["n"], r["cpu_s"],
             r["wall_s"], r["peak_mb"])
