"""Region graph drawing, original vs synthesised trajectories, animated GIF."""
import numpy as np

from animsynth.facegraph.jobs import synth_kwargs
from animsynth.facegraph.regiongraph import load_graphs
from animsynth.facegraph.preprocess import FaceDatabase
from animsynth.facegraph.synthesis import FaceSynthesizer
from animsynth.facegraph.plots import draw_region_graphs, draw_trajectories, face_gif
from animsynth.io.ckplus import EMOTIONS
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
cfg = snakemake.params.cfg
db = FaceDatabase.load_npz(snakemake.input.db)
graphs, _ = load_graphs(snakemake.input.graphs)
src = "synthetic CK+-layout data" if db.source.startswith("synthetic") else db.source
draw_region_graphs(snakemake.output.graph, graphs, f"Region graphs ({snakemake.params.showcase}, {src})")
plain = FaceSynthesizer(graphs, **synth_kwargs(cfg["synthesis"], noise=bool(cfg["evaluation"]["noise"])))
items = []
for e in sorted(set(db.emotions.tolist()))[:3]:  # first sample of three labels, as in Table 1's re-synthesis
    s = int(np.flatnonzero(db.emotions == e)[0])
    rng = np.random.default_rng([int(snakemake.params.graph_seed), s])
    anim = plain.synthesize([e], start=plain.start_nodes(sample=s), rng=rng)
    items.append((f"{db.names[s]} ({EMOTIONS[e]})", db.forward(s), anim.disp))
draw_trajectories(snakemake.output.trajectories, items, cfg["figures"]["trajectory_landmarks"],
                  f"Original (blue) vs re-synthesised (red) landmark displacements ({src})")
noisy = FaceSynthesizer(graphs, **synth_kwargs(cfg["synthesis"], noise=True))
labels = cfg["figures"]["sequence"]
anim = noisy.synthesize(labels, rng=np.random.default_rng(snakemake.params.seed))
face_gif(snakemake.output.gif, anim.positions(db.mean_neutral), anim.segments, fps=cfg["figures"]["fps"])
log.info("GIF %s: %d frames, segments %s", " -> ".join(labels), anim.n_frames, anim.segments)
