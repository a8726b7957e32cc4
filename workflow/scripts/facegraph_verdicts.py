"""Claims of the paper checked against the facegraph tables -> verdicts.csv."""
import pandas as pd

from animsynth.facegraph.jobs import data_note
from animsynth.facegraph.verdicts import build_verdicts
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
read = lambda p: pd.read_csv(p, keep_default_na=False, na_values=[""])  # noqa: E731
samples = {n: read(p) for n, p in zip(snakemake.params.order, snakemake.input.samples)}
table = build_verdicts(read(snakemake.input.table1), read(snakemake.input.baseline), read(snakemake.input.uniqueness),
                 snakemake.params.source, samples)
write_table(table, snakemake.output.csv, title="Facegraph verdicts", note=data_note(snakemake.params.source))
log.info("verdicts:\n%s", table.to_string())
