"""summary.md (claims first, then every table), claims.csv and the report's home page (claims.rst)."""
import pandas as pd

from animsynth.atomic import atomic_write_text
from animsynth.report import build_summary, claims_rst, claims_table
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
out = snakemake.output
verdicts = list(snakemake.input.verdicts)
provenance = pd.DataFrame(p.provenance, columns=["family", "data", "status"])
note = ("What each part ran on: " + "; ".join(f"**{r.family}**: {r.data} ({r.status})" for r in provenance.itertuples())
        + ". Every number below is computed by the workflow on that data; paper values are quoted beside ours"
        " where the paper gives them.")
if p.timing:
    note += (" Machine-dependent timing tables are not shown here (they differ between runs): "
             + ", ".join(f"`{t}`" for t in p.timing) + ".")
claims = claims_table(verdicts, p.family_data, p.family_real)
write_table(claims, out.claims, md=False)
side_by_side = list(snakemake.input.side_by_side)
side = pd.read_csv(side_by_side[0]) if side_by_side else None
atomic_write_text(out.home, claims_rst(claims, provenance, p.report_outputs, side, p.side_by_side_data,
                                       bool(p.side_by_side_real)))
atomic_write_text(out.summary, build_summary(p.sections, verdicts, note, provenance, p.family_data, p.family_real,
                                                 p.demo))
log.info("summary with %d tables, %d claims (%d on real data)", len(p.sections), len(claims), int(claims["real"].sum()))
