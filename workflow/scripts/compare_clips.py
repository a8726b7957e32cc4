"""Every held-out clip of the comparison (database, start, length) at the working rate, and its database and start
at the native rate of the generators that run at one (fairmotion's 60 fps) -> clips.npz, clips.csv."""
from animsynth.compare.jobs import clips_job
from animsynth.motion import Motion
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
trials = {t: Motion.load_npz(f) for t, f in zip(p.trials, snakemake.input)}
for t, m in trials.items():
    m.name = t
clips = clips_job(trials, dict(p.subsets), dict(p.resequencing), dict(p.cfg), dict(snakemake.output))
log.info("%d held-out clips", len(clips))
