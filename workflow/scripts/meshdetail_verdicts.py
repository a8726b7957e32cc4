"""Claims of the hybrid-mesh paper checked against the meshdetail tables -> verdicts.csv."""
import pandas as pd

from animsynth.meshdetail.verdicts import build_verdicts
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, o, p = snakemake.input, snakemake.output, snakemake.params
read = lambda path: pd.read_csv(path, keep_default_na=False, na_values=[""])  # noqa: E731
table = build_verdicts(read(i.fig5a), read(i.fig5b), read(i.fig5c), read(i.gen), p.source, p.cv_rig)
write_table(table, o.csv, title="Meshdetail verdicts", note=f"Data: {p.source}. Model comparisons on held-out frames "
            "of the blocked cross-validation; 'undecided' where the margin does not exceed the per-block spread, "
            "'partly' where it does but not every block agrees.")
log.info("verdicts:\n%s", table.to_string())
