"""Re-sequence one dataset x method x metric x global flag: Dijkstra paths, BVH + GIF of the main path, smoothness."""
import pandas as pd

from animsynth.motion import Motion
from animsynth.io.atomic import atomic_path
from animsynth.resequencing.study import gdof_flag, prepare_motion, resequence
from animsynth.viz import motion_previews
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
cfg = snakemake.params.cfg  # noqa: F821
wc = snakemake.wildcards  # noqa: F821
motion = prepare_motion(Motion.load_npz(snakemake.input.npz), cfg["max_frames"], cfg["frame_step"])  # noqa: F821
mk = pd.read_csv(snakemake.input.min_k)  # noqa: F821
k = int(mk.loc[(mk["method"] == wc.rsmethod) & (mk["metric"] == wc.rsmetric), "k_used"].iloc[0])
paths, (main_path, main), per_path, per_tr = resequence(motion, gdof_flag(wc.rsgdof), wc.rsmethod, wc.rsmetric, k,
                                                        cfg, seed=snakemake.params.seed)  # noqa: F821
rows = [{"pair": "main", "start": int(main_path[0]), "end": int(main_path[-1]), "step": i, "frame": int(f)}
        for i, f in enumerate(main_path)]
rows += [{"pair": p, "start": int(path[0]), "end": int(path[-1]), "step": i, "frame": int(f)}
         for p, path in enumerate(paths) for i, f in enumerate(path)]
with atomic_path(snakemake.output.csv) as tmp:  # noqa: F821
    pd.DataFrame(rows).to_csv(tmp, index=False, lineterminator="\n")
for df in (per_path, per_tr):
    for col, val in (("metric", wc.rsmetric), ("method", wc.rsmethod), ("global_dof", gdof_flag(wc.rsgdof)),
                     ("dataset", wc.rsdata)):
        df.insert(0, col, val)
with atomic_path(snakemake.output.smooth) as tmp:  # noqa: F821
    per_path.to_csv(tmp, index=False, lineterminator="\n", float_format="%.6g")
with atomic_path(snakemake.output.transitions) as tmp:  # noqa: F821
    per_tr.to_csv(tmp, index=False, lineterminator="\n", float_format="%.6g")
label = f"{wc.rsmethod} {wc.rsmetric} {wc.rsgdof} (k={k})"
motion_previews(main, gif_path=snakemake.output.gif, bvh_path=snakemake.output.bvh, original=motion,  # noqa: F821
                titles=["original", label], fps=cfg["gif_fps"])
log.info("%s: k=%d, main path %d frames (%d -> %d); %d pairs, %d re-sequence, %.2f transitions per path", label, k,
         len(main_path), main_path[0], main_path[-1], len(paths), int((per_path["path_class"] == "resequences").sum()),
         per_path["transitions"].mean() if len(per_path) else 0.0)
