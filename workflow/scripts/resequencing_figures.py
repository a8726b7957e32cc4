"""Figures of one dataset: Fig 2 (2-D embeddings with neighbourhood edges, one figure per method; panels:
metric x global flag) and Fig 3 (residual variance against embedding dimension)."""
import numpy as np
import pandas as pd

from animsynth.resequencing.plots import embedding_figure, residual_variance_figure
from animsynth.resequencing.settings import METHOD_LABEL, METRIC_LABEL
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
dataset = snakemake.wildcards.rsdata
inp = snakemake.input
min_k = [pd.read_csv(p) for p in inp.min_k]
for method, out in zip(snakemake.params.methods, snakemake.output.fig2):
    panels = []
    for emb_path, mk in zip(inp.emb, min_k):
        with np.load(emb_path) as z:
            for metric in snakemake.params.metrics:
                key = f"{method}_{metric}"
                row = mk[(mk["method"] == method) & (mk["metric"] == metric)].iloc[0]
                panels.append({"xy": z[f"{key}_xy"], "edges": z[f"{key}_edges"],
                               "label": f"{METRIC_LABEL[metric]}, global DOF {'in' if row['global_dof'] else 'out'}, "
                                        f"k={int(row['k_used'])} (min {int(row['min_k'])})"})
    title = f"{METHOD_LABEL[method]} embedding of the {dataset} ({row['trial']}, {int(row['frames'])} frames)"
    embedding_figure(out, panels, title)
    log.info("Fig 2 %s: %d panels", method, len(panels))
rv = pd.concat([pd.read_csv(p) for p in inp.rv], ignore_index=True)
residual_variance_figure(snakemake.output.fig3, rv, f"Residual variance, {dataset}")
log.info("Fig 3: %d residual-variance values plotted", len(rv))
