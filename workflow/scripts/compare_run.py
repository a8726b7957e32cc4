"""One generator job of one subject: every row it runs (a generator; fairmotion's two rows; a graph generator's
further budgets of the sweep) fitted once per database of the subject's clips, every seed of every window generated
from its start and scored, in one process (so fairmotion's loading of every trial and its graph construction run
once per database for all its rows and budgets); with compare.long_track on, each default-budget row's long track
from the same builds."""
from animsynth.compare.jobs import run_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p, o = snakemake.params, snakemake.output
for name, cfg, roles, prefix, show in p.rows:
    keys = ("metrics", "timing", "shown") if show is not None else ("metrics", "timing")
    if cfg.get("long_track"):  # the long track's files, from the same builds
        keys += ("long_metrics", "long_timing", "long_shown")
    run_job(snakemake.input[0], name, dict(cfg), int(p.seed), dict(roles), None if show is None else tuple(show),
            {k: getattr(o, f"{prefix}{k}") for k in keys})
