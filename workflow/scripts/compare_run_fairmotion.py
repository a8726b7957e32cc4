"""fairmotion's rows (as released, with the fixes) and its budget sweep in one job: each row and budget is run
as compare_run and compare_sweep_run run a generator, in one process, so fairmotion's loading of every trial and
its graph construction (which no threshold, budget or fix changes) run once."""
from animsynth.compare.jobs import run_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p, o = snakemake.params, snakemake.output
for name, cfg in p.rows:
    run_job(snakemake.input[0], name, dict(cfg), int(p.seed), dict(p.roles), tuple(p.showcase),
            {k: getattr(o, f"{k}_{name}") for k in ("metrics", "timing", "shown", "bvh")})
for i, (name, _budget, cfg) in enumerate(p.sweep):
    run_job(snakemake.input[0], name, dict(cfg), int(p.seed), dict(p.sweep_roles), None,
            {"metrics": getattr(o, f"sweep{i}"), "timing": getattr(o, f"sweep{i}_timing")})
