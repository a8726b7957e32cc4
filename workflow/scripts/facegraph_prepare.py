"""Parse the CK+ folder with the strict loader and pre-process the labelled sequences."""
import pandas as pd

from animsynth.facegraph.preprocess import FacePreprocessor
from animsynth.io.ckplus import read_ckplus
from animsynth.tables import write_table
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
cfg = snakemake.params.cfg
seqs = read_ckplus(snakemake.input.db)
log.info("read %d sequences (%d labelled) from %s", len(seqs), sum(s.emotion is not None for s in seqs),
         snakemake.input.db)
pre = FacePreprocessor(cfg["regions"], cfg["reduced_landmarks"], cfg["rigid_landmarks"],
                       cfg["sigmoid_min_range_px"], cfg["min_frames"], cfg["max_sequences"], cfg["align_before_fit"])
db = pre.fit_transform(seqs, source=snakemake.params.source)
db.save_npz(snakemake.output.npz)
log.info("pre-processing: %s", pre.report_)
used = set(db.names)
st = pre.sigmoid_status_
df = pd.DataFrame([{"subject": s.subject, "sequence": s.sequence, "emotion": s.label or "", "frames": s.n_frames,
                    "used": s.name in used, "sigmoid_fit": st.get(s.name, {}).get("fit", ""),
                    "sigmoid_grid_fallback": st.get(s.name, {}).get("grid", ""),
                    "sigmoid_static": st.get(s.name, {}).get("static", "")} for s in seqs])
write_table(df, snakemake.output.csv, title="Facial expression database (parsed by the CK+ loader)",
            note=f"Source: {db.source}. Sequences used: {len(db.names)} labelled, {int(db.lengths.sum())} frames; "
                 f"Sigmoid fits per landmark: {pre.report_['fit']} by curve_fit, {pre.report_['grid']} kept the grid fit "
                 f"(fallback share {100 * pre.report_['grid_fallback_share']:.1f} % of moving landmarks), "
                 f"{pre.report_['static']} static.")
