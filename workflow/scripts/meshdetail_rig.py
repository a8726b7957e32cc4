"""Place the 18-joint skeleton, compute skinning weights, fit every frame; fit, joint and skinning tables."""
import pandas as pd

from animsynth.meshdetail.jobs import fit_pose
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
i, o, p = snakemake.input, snakemake.output, snakemake.params
table, joints, comparison, method = fit_pose(i.seq, i.truth[0] if len(i.truth) else None, dict(p.rig),
                                             float(p.train_fraction), o.pose)
write_table(table, o.table, title="Skeleton fit (18 joints, LBS): residual per bone, training and held-out frames",
            note=f"Embedding: {method}; skinning: {p.rig['skinning']}. Poses are fitted per frame (a held-out "
                 "frame's pose uses that frame only); weights use the training frames only. A bone's row covers "
                 "the vertices it dominates.")
write_table(joints, o.joints, title="Joint centres in the first-frame mesh",
            note="winding_number: generalised winding number of the joint centre w.r.t. the first-frame mesh "
                 "(1 inside, 0 outside a closed mesh).")
if comparison is None:
    comparison = pd.DataFrame({"skinning": [p.rig["skinning"]], "used": [True]})
write_table(comparison, o.skinning, title="Skinning methods: LBS residual on training and held-out frames",
            note="Mean vertex distance (mm) of the pose fit with each method's weights (same joints).")
log.info("\n%s\n%s\n%s", table.to_string(), joints.to_string(), comparison.to_string())
