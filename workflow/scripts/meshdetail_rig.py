"""Embed the 18-joint skeleton, compute skinning weights, fit every frame; write the fit-quality table."""
from animsynth.meshdetail.pipeline import fit_pose
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)  # noqa: F821
i, o, p = snakemake.input, snakemake.output, snakemake.params  # noqa: F821
table, method = fit_pose(i.seq, i.truth[0] if len(i.truth) else None, dict(p.rig), o.pose)
write_table(table, o.table, title="Skeleton fit (18 joints, LBS)",
            note=f"Embedding: {method}; weights: smooth distance falloff to the bone segments; "
                 "per-frame root translation and joint rotations by least squares (Kabsch init + Levenberg-Marquardt).")
log.info("\n%s", table.to_string())
