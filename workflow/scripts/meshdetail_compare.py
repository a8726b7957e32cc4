"""Sequences side by side (held-out mean and fold SD per method) and the verdicts of every sequence with one
row per claim saying on which sequences it holds."""
import pandas as pd

from animsynth import verdicts as common
from animsynth.meshdetail.verdicts import combine_verdicts, side_by_side
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, o, p = snakemake.input, snakemake.output, snakemake.params
read = lambda path: pd.read_csv(path, keep_default_na=False, na_values=[""])  # noqa: E731
names = list(p.names)
table = side_by_side({n: read(f) for n, f in zip(names, i.gen)}, {n: read(f) for n, f in zip(names, i.dembones)})
write_table(table, o.table, title="Hybrid mesh animation: sequences side by side (held-out frames, blocked CV)",
            note="Mean vertex error (mm) over the folds and the SD of the fold means, per sequence ("
                 + ", ".join(names) + "). Dem Bones rows are a floor (best LBS with SSDR weights from the training "
                 "blocks when the bone transforms are solved from the held-out meshes), not a skeleton-driven model.")
verdicts = combine_verdicts({n: common.read(f) for n, f in zip(names, i.verdicts)})
write_table(verdicts, o.verdicts, title="Meshdetail verdicts (every sequence, and across sequences)",
            note="Per sequence: model comparisons on held-out frames of the blocked cross-validation; 'undecided' "
                 "where the margin does not exceed the per-block spread, 'partly' where it does but not every block "
                 "agrees. [all sequences]: a "
                 "claim holds on a sequence when its verdict there is 'reproduced'.")
log.info("\n%s\n%s", table.to_string(), verdicts.to_string())
