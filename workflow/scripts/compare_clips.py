"""One subject's held-out clips (windows) of the comparison with their databases and starts at the working rate, and
their databases and starts at the native rate of the generators that run at one (fairmotion's 60 fps) ->
compare/clips/<subject>.npz and .csv."""
from animsynth.compare.jobs import clips_job
from animsynth.motion import Motion
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
trials = {t: Motion.load_npz(f) for t, f in zip(p.trials, snakemake.input)}
for t, m in trials.items():
    m.name = t
clips = clips_job(trials, dict(p.subsets), dict(p.resequencing), dict(p.cfg), dict(snakemake.output),
                  subjects=dict(p.subjects), first_frames=dict(p.first_frames))
log.info("subject %s: %d held-out clips", snakemake.wildcards.cmpsubj, len(clips))
