"""Fig. 5b (error and stored size per control-mesh level, two decimations) and its timing table."""
from animsynth.meshdetail.evaluation import run_resolution
from animsynth.meshdetail.jobs import load_prepared
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, o, p = snakemake.input, snakemake.output, snakemake.params
d = load_prepared(i.seq, i.pose, i.edits, p.train_fraction)
fig5b, timing = run_resolution(d, dict(p.cfg))
write_table(fig5b, o.fig5b, title="Fig. 5b: error vs control-mesh resolution",
            note="Edge collapse (the paper's): the first frame is decimated by quadric edge collapses, the collapse "
                 "sequence is replayed on every frame; farthest-point subset: a vertex subset of the first frame. "
                 "The full mesh is rebuilt from the control detail by thin-plate RBF interpolation. Size: numbers "
                 "stored by the model as % of F x V x 3.")
write_table(timing, o.timing, title="Fig. 5b timing (machine- and load-dependent)",
            note="Wall and CPU seconds. Training = SGPLVM+GPDM + inverse GP (+ RBF map), per 100 training frames; "
                 "reconstruction = one frame at a time (FK, LBS, GP, sparse RBF map).")
log.info("\n%s\n%s", fig5b.to_string(), timing.to_string())
