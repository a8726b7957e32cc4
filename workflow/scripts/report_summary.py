"""results/summary.md: every table (rendered from its CSV) and the verdicts."""
from animsynth.io.atomic import atomic_write_text
from animsynth.report import build_summary
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
p = snakemake.params  # noqa: F821
note = (f"Mocap data: **{p.source}**. Meshes: **{p.mesh_dir or 'synthetic skirt character'}**. "
        f"Faces: **{p.faces or 'synthetic CK+-layout database (not real CK+)'}**. "
        "Every number below is computed by the workflow on that data; paper values are quoted beside ours where the paper gives them.")
if p.timing:
    note += (" Machine-dependent timing tables are not shown here (they differ between runs): "
             + ", ".join(f"`{t}`" for t in p.timing) + ".")
atomic_write_text(snakemake.output[0], build_summary(p.sections, snakemake.input.verdicts, note))  # noqa: F821
log.info("summary with %d tables and %d verdict files", len(p.sections), len(snakemake.input.verdicts))  # noqa: F821
