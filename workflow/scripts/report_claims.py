"""claims.csv: every claim of the run, one row each, from the families' verdicts.csv (real data first)."""
from animsynth.report import claims_table
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
claims = claims_table(list(snakemake.input.verdicts), p.family_data, p.family_real)
write_table(claims, snakemake.output.claims, md=False)
log.info("%d claims (%d on real data)", len(claims), int(claims["real"].sum()))
