"""Joint parameterisation x detail encoding study."""
from animsynth.meshdetail.evaluation import run_representations
from animsynth.meshdetail.jobs import load_prepared
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, o, p = snakemake.input, snakemake.output, snakemake.params
d = load_prepared(i.seq, i.pose, i.edits, p.train_fraction)
table = run_representations(d, dict(p.cfg))
write_table(table, o.table, title="Representations: joint parameterisation and detail encoding",
            note="Hybrid model (SGPLVM+GPDM) at the configured control level; mean vertex error (mm).")
log.info("\n%s", table.to_string())
