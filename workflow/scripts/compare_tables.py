"""clips.csv, metrics.csv, summary.csv, winners.csv, cost_timing.csv, verdicts.csv and summary.md of the comparison
(and the long track's metrics_long.csv), gathered from every subject's jobs."""
from animsynth.compare.jobs import tables_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
inp = snakemake.input
tables_job({"clips": list(inp.clips), "clip_files": list(inp.clip_files), "captures": list(inp.captures),
            "metrics": list(inp.metrics), "timing": list(inp.timing), "sweep": list(inp.sweep),
            "long_metrics": list(inp.long_metrics), "long_timing": list(inp.long_timing)},
           dict(snakemake.output), list(p.generators), dict(p.left_out), dict(p.cfg), p.source, dict(p.sweep))
