"""scoreboard.png (one cell per claim, one row per paper) and the counts it draws (scoreboard.csv), from claims.csv."""
from animsynth.scoreboard import read_claims, scoreboard_figure
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
claims = read_claims(snakemake.input.claims)
counts = scoreboard_figure(claims, snakemake.output.png)
write_table(counts, snakemake.output.counts, md=False)
log.info("scoreboard: %d rows, %d claims", len(counts), len(claims))
