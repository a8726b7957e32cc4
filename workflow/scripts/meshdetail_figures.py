"""The three Fig. 5 panels and rendered frames (original, LBS, hybrid, CV ridge; held-out predictions) with an error colour map."""
import numpy as np
import pandas as pd

from animsynth.io.obj import MeshSequence
from animsynth.meshdetail import plots
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
i, o = snakemake.input, snakemake.output  # noqa: F821
plots.plot_fig5a(pd.read_csv(i.fig5a), o.fig5a)
plots.plot_fig5b(pd.read_csv(i.fig5b), o.fig5b)
plots.plot_fig5c(pd.read_csv(i.fig5c), o.fig5c)
seq = MeshSequence.load_npz(i.seq)
with np.load(i.preds) as z:
    frames = [int(f) for f in z["frames"]]
    preds = {k: z[k] for k in ("lbs", "hybrid", "ridge_cv")}
truth = seq.vertices[frames]
plots.render_frames(o.frames, truth, seq.faces, preds, list(range(len(frames))), titles=frames)
log.info("wrote %s", ", ".join(map(str, snakemake.output)))  # noqa: F821
