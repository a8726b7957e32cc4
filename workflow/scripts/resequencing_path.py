"""Re-sequence one dataset for every method x metric x global flag: Dijkstra paths, BVH + GIF of the main path, smoothness."""
import pandas as pd

from animsynth.motion import Motion
from animsynth.atomic import atomic_path
from animsynth.resequencing.jobs import prepare_motion, resequence
from animsynth.resequencing.settings import gdof_flag
from animsynth.viz import motion_previews
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
cfg = snakemake.params.cfg
out = snakemake.output
dataset = snakemake.wildcards.rsdata
motion = prepare_motion(Motion.load_npz(snakemake.input.npz), cfg["max_frames"], cfg["frame_step"])
min_k = {}  # (method, metric, global flag) -> k of the configuration's first min-k row
for gdof, path in zip(snakemake.params.gdof, snakemake.input.min_k):
    for _, r in pd.read_csv(path).iterrows():
        min_k.setdefault((r["method"], r["metric"], gdof), int(r["k_used"]))

for i, (method, metric, gdof) in enumerate(snakemake.params.configs):
    k = min_k[(method, metric, gdof)]
    paths, (main_path, main), per_path, per_tr = resequence(motion, gdof_flag(gdof), method, metric, k, cfg,
                                                            seed=snakemake.params.seed,
                                                            budget_gib=snakemake.params.budget_gib)
    rows = [{"pair": "main", "start": int(main_path[0]), "end": int(main_path[-1]), "step": j, "frame": int(f)}
            for j, f in enumerate(main_path)]
    rows += [{"pair": p, "start": int(path[0]), "end": int(path[-1]), "step": j, "frame": int(f)}
             for p, path in enumerate(paths) for j, f in enumerate(path)]
    with atomic_path(out.csv[i]) as tmp:
        pd.DataFrame(rows).to_csv(tmp, index=False, lineterminator="\n")
    for df in (per_path, per_tr):
        for col, val in (("metric", metric), ("method", method), ("global_dof", gdof_flag(gdof)), ("dataset", dataset)):
            df.insert(0, col, val)
    with atomic_path(out.smooth[i]) as tmp:
        per_path.to_csv(tmp, index=False, lineterminator="\n", float_format="%.6g")
    with atomic_path(out.transitions[i]) as tmp:
        per_tr.to_csv(tmp, index=False, lineterminator="\n", float_format="%.6g")
    label = f"{method} {metric} {gdof} (k={k})"
    motion_previews(main, gif_path=out.gif[i], bvh_path=out.bvh[i], original=motion, titles=["original", label],
                    fps=cfg["gif_fps"])
    log.info("%s %s: k=%d, main path %d frames (%d -> %d); %d pairs, %d re-sequence, %.2f transitions per path",
             dataset, label, k, len(main_path), main_path[0], main_path[-1], len(paths),
             int((per_path["path_class"] == "resequences").sum()),
             per_path["transitions"].mean() if len(per_path) else 0.0)
