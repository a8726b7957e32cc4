"""One dataset x method x fold of the Gauch & Peters main table -> fold JSON."""
from animsynth.simplicial.jobs import run_main_fold, write_fold_json
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
wc = snakemake.wildcards  # noqa: F821
res = run_main_fold(list(snakemake.input), list(snakemake.params.ids), wc.dataset, wc.method, wc.fold,  # noqa: F821
                    dict(snakemake.params.cfg))  # noqa: F821
write_fold_json(snakemake.output[0], res.row)  # noqa: F821
