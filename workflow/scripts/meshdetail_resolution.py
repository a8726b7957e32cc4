"""Fig. 5b (error and compressed size per resolution level) and timing (machine-dependent)."""
from animsynth.meshdetail.experiments import run_resolution
from animsynth.meshdetail.pipeline import load_prepared
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
i, o, p = snakemake.input, snakemake.output, snakemake.params  # noqa: F821
d = load_prepared(i.seq, i.pose, i.edits, p.train_fraction)
fig5b, timing = run_resolution(d, dict(p.cfg))
write_table(fig5b, o.fig5b, title="Fig. 5b: error vs control-mesh resolution",
            note="Decimation: farthest-point vertex subset of the first frame (same for all frames); fine mesh by "
                 "biharmonic interpolation of the detail. Size: numbers stored by the model as % of F x V x 3.")
write_table(timing, o.timing, title="Timing (machine-dependent)",
            note="Training = SGPLVM+GPDM + inverse GP (+ up-sampler), per 100 training frames; reconstruction = one "
                 "frame at a time (FK, LBS, GP, up-sampling). Targets: < 30 s per 100 frames, > 30 frames/s.")
log.info("\n%s\n%s", fig5b.to_string(), timing.to_string())
