"""Gauch & Peters Table I for the configured data, with the published lengths beside ours (results/data/datasets.csv + .md)."""
import os

from animsynth.data import datasets_table, read_paper_table1
from animsynth.motion import Motion
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
motions = {os.path.basename(p)[:-4]: Motion.load_npz(p) for p in snakemake.input}  # noqa: F821
paper = read_paper_table1(snakemake.params.paper_table1)  # noqa: F821
df = datasets_table(snakemake.params.subsets, motions, snakemake.params.source, paper)  # noqa: F821
if paper:
    diff = [f"{r.dataset}: {r.length_match}" for r in df.itertuples() if r.length_match and not r.length_match.startswith("all")]
    note = ("`paper_*`: Gauch & Peters Table I, read from " + str(snakemake.params.paper_table1) + ". "  # noqa: F821
            + ("Subsets whose lengths differ from the paper's (same position): " + "; ".join(diff) + "."
               if diff else "Every trial has the paper's length."))
else:
    note = f"No published Table I at {snakemake.params.paper_table1!r}: paper columns left empty."  # noqa: F821
write_table(df, snakemake.output.csv, md=True, title=f"Table I: datasets ({snakemake.params.source} data)", note=note)  # noqa: F821
log.info("wrote Table I with %d subsets", len(df))
