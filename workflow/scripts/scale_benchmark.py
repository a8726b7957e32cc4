"""The 100,000-frame re-sequencing benchmark rows (benchmarks/scale_reseq.py) -> results/scale/benchmarks.csv."""
import importlib.util

import pandas as pd

from animsynth.benchmark_tables import machine_label
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
spec = importlib.util.spec_from_file_location("animsynth_scale_reseq", snakemake.input[0])
mod = importlib.util.module_from_spec(spec)
spec.loader.exec_module(mod)
cfg = snakemake.params.cfg
rows = mod.run(frames=cfg["benchmark"]["frames"], cfg=cfg, seed=int(snakemake.params.seed),
               cmu_mirror=snakemake.params.mirror)
df = pd.DataFrame(rows).assign(machine=machine_label())
write_table(df, snakemake.output[0], title="Re-sequencing at scale (machine-dependent)")
for r in rows:
    log.info("%s = %.4g %s (target %s, meets %s)", r["benchmark"], r["value"], r["unit"], r["target"], r["meets_target"])
