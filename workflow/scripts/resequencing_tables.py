"""Aggregate: Table 2 (min k), residual variance, smoothness, verdicts, machine-dependent timings."""
import pandas as pd

from animsynth.io.atomic import atomic_path
from animsynth.resequencing.study import min_k_table, summarise_paths, verdicts
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
inp, out = snakemake.input, snakemake.output


def cat(paths):
    return pd.concat([pd.read_csv(p) for p in paths], ignore_index=True)


table2 = min_k_table(cat(inp.min_k), snakemake.params.published)
have_paper = table2["min_k_paper"].notna().any()
write_table(table2, out.table2, title="Table 2: smallest k giving one connected neighbourhood graph",
            note="min_k is exact (bottleneck of a minimum spanning tree over neighbour ranks) and cross-checked "
                 "with scipy connected_components at min_k - 1 (> 1 component) and min_k (1 component). "
                 "For ST-Isomap, k counts neighbours chosen under the spatio-temporally adjusted distances. "
                 "k_used = the k of the embeddings and paths. "
                 + ("min_k_paper: published values from config." if have_paper else
                    "min_k_paper is empty: the paper's published Table 2 values were not available to us "
                    "(set resequencing.published_min_k to fill them in)."))
rv = cat(inp.rv)
with atomic_path(out.rv) as tmp:
    rv.to_csv(tmp, index=False, lineterminator="\n", float_format="%.6g")
per_path = cat(inp.smooth)
with atomic_path(out.smooth_paths) as tmp:
    per_path.to_csv(tmp, index=False, lineterminator="\n", float_format="%.6g")
smooth = summarise_paths(per_path)
write_table(smooth, out.smooth, title="Smoothness of re-sequenced motions (means over start/end pairs)",
            note="Ratios are against the original trial (1 = as smooth as the capture). jerk_events: frames "
                 "jerkier than any frame of the capture. See docs/config_resequencing.md for definitions.")
v = verdicts(smooth, snakemake.params.margin)
write_table(v, out.verdicts, title="Re-sequencing: verdicts on the paper's qualitative claims")
for r in v.itertuples():
    log.info("%s: %s", r.claim, r.verdict)
with atomic_path(out.timing) as tmp:
    cat(inp.timing).to_csv(tmp, index=False, lineterminator="\n", float_format="%.4f")
