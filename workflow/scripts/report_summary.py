"""summary.md (banner, provenance, scoreboard, one line per claim, a section per family, the detailed tables)
and the report's home page (claims.rst)."""
import os

import pandas as pd

from animsynth.atomic import atomic_write_text
from animsynth.report import build_summary, claims_rst, run_banner
from animsynth.scoreboard import read_claims
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p = snakemake.params
out = snakemake.output
verdicts = list(snakemake.input.verdicts)
provenance = pd.DataFrame(p.provenance, columns=["family", "data", "status"])
note = ("Every number below is computed by the workflow on the data named above; paper values are quoted beside "
        "ours where the paper gives them.")
here = os.path.dirname(out.summary)
# key figures: the path on disk (embedded in the home page) and below the results folder (summary.md's links)
figures = {fam: [{**f, "src": os.path.relpath(f["png"], here)} for f in figs] for fam, figs in p.figures.items()}
tables = {}
for s in p.sections:
    if s.get("key"):
        tables.setdefault(s["family"], []).append(os.path.relpath(s["csv"], here))
claims = read_claims(snakemake.input.claims)
side_by_side = list(snakemake.input.side_by_side)
side = pd.read_csv(side_by_side[0]) if side_by_side else None
atomic_write_text(out.home, claims_rst(
    claims, provenance, p.report_outputs, side, p.side_by_side_data, bool(p.side_by_side_real),
    banner=run_banner(p.family_real, p.demo), scoreboard_png=snakemake.input.scoreboard, family_figures=figures,
    family_data=p.family_data, family_tables=tables))
atomic_write_text(out.summary, build_summary(
    p.sections, verdicts, note, provenance, p.family_data, p.family_real, p.demo,
    scoreboard_png=os.path.relpath(snakemake.input.scoreboard, here), family_figures=figures,
    timing_tables=p.timing))
log.info("summary with %d tables, %d claims (%d on real data)", len(p.sections), len(claims), int(claims["real"].sum()))
