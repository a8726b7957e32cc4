"""metrics.png (every metric per generator with its spread) and strips.png (one skeleton strip per generator)."""
import pandas as pd

from animsynth.compare.jobs import load_shown
from animsynth.compare.plots import metrics_figure, strips_figure
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
out = snakemake.output
data = "synthetic mocap" if p.source == "synthetic" else f"{p.source} mocap"
metrics = pd.read_csv(snakemake.input.metrics)
metrics_figure(out.metrics, metrics, list(p.generators), f"Generators side by side ({data}): values over held-out "
               "clips x seeds (box: IQR, whiskers: 5-95 %; grey: the realism bounds)")
shown = {g: load_shown(f) for g, f in zip(p.generators, snakemake.input.shown)}
strips_figure(out.strips, shown, title=f"From the same start: clip {p.showcase[0]}, seed {p.showcase[1]} ({data}); "
              "grey: last start frame, red: frames at a seam")
log.info("metrics.png: %d rows; strips.png: %s", len(metrics), ", ".join(shown))
