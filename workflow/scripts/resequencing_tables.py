"""Aggregate: Table 2 beside the paper, explanations, sign flips, residual variance, smoothness, verdicts, timings."""
import pandas as pd

from animsynth.atomic import atomic_path
from animsynth.resequencing.jobs import summarise_paths
from animsynth.resequencing.tables import (PAPER_CMU_TRIALS, comparable_published, lee_weights_table,
                                          min_k_table, published_table2)
from animsynth.resequencing.verdicts import build_verdicts
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
inp, out = snakemake.input, snakemake.output
cfg = snakemake.params.cfg
trials = snakemake.params.trials


def cat(paths):
    return pd.concat([pd.read_csv(p) for p in paths], ignore_index=True)


def published(files):
    """A published table's declared input: its path, or None when the file is absent (no input)."""
    files = [files] if isinstance(files, str) else list(files)
    return files[0] if files else None


def csv(df, path):
    with atomic_path(path) as tmp:
        df.to_csv(tmp, index=False, lineterminator="\n", float_format="%.6g")


# the paper's values stand only beside the trials it measured (its CMU clips, or the synthetic stand-ins)
comparable = dict(snakemake.params.comparable)
not_comparable = [d for d, ok in comparable.items() if not ok]
for d in not_comparable:
    log.info("resequencing Table 2: %s trial %s is not the paper's CMU %s: the paper's min k is not shown beside it",
             d, trials[d], PAPER_CMU_TRIALS.get(d, "trial"))
table2_paper = comparable_published(published_table2(published(inp.published_table2)), comparable)
grid = cat(inp.explain)
step = int(cfg["frame_step"])
table2 = min_k_table(grid, table2_paper, step)
CLIPS = ("Our clips differ from the paper's: CMU 35_01 has 358 frames at 120 fps (paper: a 516-frame walk), 35_17 "
         "has 167 (paper: a 405-frame run), and 05_02 is an expressive dance, not hip-hop (paper: 800 frames); the "
         "paper states neither the frame rate nor the source of its clips. ")
write_table(table2, out.table2, title="Table 2: smallest k giving one connected neighbourhood graph",
            note=CLIPS + "min_k is exact (bottleneck of a minimum spanning tree over neighbour ranks) and cross-checked "
                 "with scipy connected_components at min_k - 1 and min_k. sign_mode continuous = our method (shortest "
                 "quaternion increments); matrix_naive = quaternions from rotation matrices with their largest "
                 "component positive and log via acos(w), a reproduction of a probable artefact of the paper, not a "
                 "method (it affects L2 only; the Lee metric is sign-invariant). ST-Isomap keeps the adjacent "
                 "temporal neighbours in every neighbourhood, so its min k is 1 on one sequence; the paper's "
                 "ST-Isomap L2 rows repeat its Isomap L2 values (79, 107), which a graph holding the temporal chain "
                 "cannot give, while its ST-Isomap Lee rows (1) match ours. min_k_paper: the "
                 "paper's value on the rows of its setting (global DOF excluded for walk and run, included for dance)"
                 + (f"; empty for {', '.join(not_comparable)}: not the paper's CMU trial (your own data), so the "
                    "paper's values are not comparable with it" if not_comparable else "")
                 + ("." if table2_paper is not None or not_comparable else "; empty: the published file was not "
                    "found."))
write_table(grid, out.explanations, title="Minimum k under the candidate explanations of the paper's Table 2",
            note=CLIPS + "Every combination of sign mode, frame step (120 fps / frame_step) and global DOF.")
flips = cat(inp.flips)
csv(flips, out.flips)
lw = lee_weights_table(published(inp.published_lee_weights), cfg["lee"]["weights"])
csv(lw if lw is not None else pd.DataFrame(columns=["group", "weight_paper", "weight_ours", "match"]), out.lee_weights)
if lw is not None and not lw["match"].all():
    log.warning("Lee weights differ from the paper's: %s", lw[~lw["match"]].to_dict("records"))
csv(cat(inp.rv), out.rv)
per_path = cat(inp.smooth)
csv(per_path, out.smooth_paths)
csv(cat(inp.transitions), out.smooth_transitions)
smooth = summarise_paths(per_path)
write_table(smooth, out.smooth, title="Re-sequenced motions: transitions and per-transition smoothness",
            note="Pairs: seeded start/end frames with the end before the start (the path must leave the original "
                 "order). Counts over all pairs; *_resequencing_mean over the paths with at least one non-temporal "
                 "transition only. Ratios against the capture (1 = an ordinary step of the original). See "
                 "docs/config_resequencing.md for definitions.")
trial_txt = " ".join(f"{d} {t}" for d, t in trials.items())
npairs = int(per_path.groupby(["dataset", "method", "metric", "global_dof"]).size().max()) if len(per_path) else 0
v = build_verdicts(table2, grid, table2_paper, per_path, step, cfg, data_min_k=trial_txt,
                 data_paths=f"{trial_txt} ({npairs} pairs per configuration)")
write_table(v, out.verdicts, title="Re-sequencing: verdicts on the paper's claims")
for r in v.itertuples():
    log.info("%s: %s", r.claim, r.verdict)
csv(cat(inp.timing), out.timing)
