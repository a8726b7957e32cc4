"""Fig. 5a (full deformation vs detail), Fig. 5c and generalisation under blocked CV, held-out predictions."""
import numpy as np

from animsynth.atomic import atomic_path
from animsynth.meshdetail.evaluation import run_main
from animsynth.meshdetail.jobs import fold_rig_fitter, load_prepared
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, o, p = snakemake.input, snakemake.output, snakemake.params
d = load_prepared(i.seq, i.pose, i.edits, p.train_fraction)
refit = None
if p.cfg["cv_rig"] == "per_fold":
    refit = fold_rig_fitter(i.seq, i.truth[0] if len(i.truth) else None, dict(p.rig))
fig5a, fig5c, gen, preds = run_main(d, dict(p.cfg), refit_rig=refit)
k = p.cfg["cv_folds"]
write_table(fig5a, o.fig5a, title="Fig. 5a: GP on full deformation vs on fine detail only",
            note=f"Mean vertex error (mm) per frame; frames {len(d.train)}.. are held out. "
                 f"Control level {p.cfg['level']}% ({p.cfg['decimation']}).")
write_table(fig5c, o.fig5c, title="Fig. 5c: held-out error per frame, LBS vs hybrid vs plain GP vs CV ridge",
            note=f"Blocked cross-validation: {k} contiguous blocks; each frame's error comes from the models "
                 "trained on the other blocks"
                 + (", each fold with its own skeleton and skin fitted on those blocks" if refit else
                    ", all folds sharing one skeleton fitted on the first training fraction") + ". Mean vertex error (mm).")
write_table(gen, o.gen, title="Generalisation: held-out frames (blocked CV) and edited motions",
            note=f"Mean over {k} folds and the SD of the fold means (*_fold_sd_mm). Edited motions: the model gets "
                 "the edited skeleton motion; ground truth is the re-simulated character.")
frames = sorted({min(max(int(f), 0), len(d.frames) - 1) for f in p.render_frames})
with atomic_path(o.preds, suffix=".npz") as tmp:
    np.savez_compressed(tmp, frames=np.array(frames), **{m: v[frames] for m, v in preds.items()})
log.info("\n%s", gen.to_string())
