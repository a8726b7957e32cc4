"""Derivative and beyond-the-paper summaries, their figures, and verdicts.csv."""
from animsynth.simplicial.jobs import summary_job
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, p = snakemake.input, snakemake.params
summary_job({"folds": list(i.derivative), "members": list(i.derivative_members)},
            {"folds": list(i.beyond), "members": list(i.beyond_members)},
            {k: i[k] for k in ("folds", "members", "paired", "table2", "table2_ensemble")},
            list(p.datasets), dict(p.cfg, seed_value=p.seed), dict(snakemake.output.items()),
            paper_table2=next(iter(i.paper_table2), None))  # an input only when the file exists
log.info("wrote %s", ", ".join(map(str, snakemake.output)))
