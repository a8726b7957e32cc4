"""Every leave-one-out fold of one dataset of the Gauch & Peters main table (all methods, ensemble of starts)
-> one JSON."""
from animsynth.simplicial.jobs import run_main_fold, write_fold_json
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
wc, p = snakemake.wildcards, snakemake.params
rows, members = [], []
for fold in p.ids:
    r, m = run_main_fold(list(snakemake.input), list(p.ids), wc.dataset, fold, dict(p.cfg), int(p.seed))
    rows += r
    members.append(m)
write_fold_json(snakemake.output[0], rows, members)
