"""Fig 2: 2-D embeddings with neighbourhood edges of one dataset and method (panels: metric x global flag)."""
import numpy as np
import pandas as pd

from animsynth.resequencing.plots import embedding_figure
from animsynth.resequencing.study import METHOD_LABEL, METRIC_LABEL
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
wc = snakemake.wildcards  # noqa: F821
panels = []
for emb_path, mk_path in zip(snakemake.input.emb, snakemake.input.min_k):  # noqa: F821
    mk = pd.read_csv(mk_path)
    with np.load(emb_path) as z:
        for metric in snakemake.params.metrics:  # noqa: F821
            key = f"{wc.rsmethod}_{metric}"
            row = mk[(mk["method"] == wc.rsmethod) & (mk["metric"] == metric)].iloc[0]
            panels.append({"xy": z[f"{key}_xy"], "edges": z[f"{key}_edges"],
                           "label": f"{METRIC_LABEL[metric]}, global DOF {'in' if row['global_dof'] else 'out'}, "
                                    f"k={int(row['k_used'])} (min {int(row['min_k'])})"})
title = f"{METHOD_LABEL[wc.rsmethod]} embedding of the {wc.rsdata} ({row['trial']}, {int(row['frames'])} frames)"
embedding_figure(snakemake.output[0], panels, title)  # noqa: F821
log.info("wrote %d panels", len(panels))
