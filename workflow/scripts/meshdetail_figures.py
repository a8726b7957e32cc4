"""The three Fig. 5 panels and rendered frames (original, LBS, hybrid, CV ridge; held-out predictions)
with an error colour map."""
import numpy as np
import pandas as pd

from animsynth.io.obj import MeshSequence
from animsynth.meshdetail import plots
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, o = snakemake.input, snakemake.output
plots.plot_fig5a(pd.read_csv(i.fig5a), o.fig5a)
plots.plot_fig5b(pd.read_csv(i.fig5b), o.fig5b)
plots.plot_fig5c(pd.read_csv(i.fig5c), o.fig5c)
seq = MeshSequence.load_npz(i.seq)
with np.load(i.preds) as z:
    frames = [int(f) for f in z["frames"]]
    preds = {k: z[k] for k in ("lbs", "hybrid", "ridge_cv")}
truth = seq.vertices[frames]
plots.render_frames(o.frames, truth, seq.faces, preds, list(range(len(frames))), titles=frames)
# Error map: per-vertex held-out error of one frame (the first render frame): our skin, the Dem Bones floor, the hybrid
with np.load(i.dembones) as z:
    f, bones = int(z["frame"]), int(z["bones"][0])
    floor = z[f"bones_{bones}"]
j = frames.index(f)
plots.error_map(o.error_map, truth[j], seq.faces,
                {"our skin (LBS)": preds["lbs"][j], f"Dem Bones floor ({bones} bones)": floor, "hybrid": preds["hybrid"][j]},
                title=f"{snakemake.params.name}, frame {f}: held-out per-vertex error (blocked CV)")
log.info("wrote %s", ", ".join(map(str, snakemake.output)))
