"""One call from labels to a face animation (CLI, notebooks)."""

from __future__ import annotations

import logging
import os
import tempfile

import numpy as np
from threadpoolctl import threadpool_limits

from ..io.ckplus import EMOTIONS, emotion_code, read_ckplus
from .model import FaceGraphModel
from .preprocess import FacePreprocessor
from .synthesis import FaceSynthesizer

log = logging.getLogger("animsynth.facegraph.quick")


def synthesise_from_labels(labels, out: str, ckplus_dir: str | None = None, seed: int = 0,
                           creation: float = 20.0, merge: float = 70.0, creation_tolerance: float = 10.0,
                           merge_tolerance: float = 20.0) -> str:
    """Build region graphs from a CK+ folder (default: a fresh synthetic CK+-layout
    database) and synthesise ``labels`` (e.g. ``["fear", "surprise", "happy"]``).

    ``creation`` / ``merge`` and their tolerances are in %; the defaults are the
    paper's configuration 0.2 +/- 0.1, 0.7 +/- 0.2.
    Writes ``out``: an animated GIF of the 68 landmarks, or a CSV (frame,
    landmark, x, y) if ``out`` ends in ``.csv``. Returns a one-line summary.
    """
    from ..synth.faces import generate_database

    for label in labels:
        emotion_code(label)  # fail fast on an unknown label, before any work
    with tempfile.TemporaryDirectory() as tmp:
        root = ckplus_dir
        if root is None:
            root = os.path.join(tmp, "ckplus")
            generate_database(root, seed=seed)
        seqs = read_ckplus(root)
        have = {sq.label for sq in seqs if sq.label is not None}
        missing = [lb for lb in labels if EMOTIONS[emotion_code(lb)] not in have]
        if missing:
            raise ValueError(f"{root}: no labelled sequence for {', '.join(repr(m) for m in missing)} "
                             f"(this copy has {', '.join(sorted(have)) or 'no labels'})")
        db = FacePreprocessor().fit_transform(seqs, source=str(ckplus_dir or "synthetic CK+-layout data"))
    with threadpool_limits(1):
        model = FaceGraphModel(creation, merge, seed=seed, creation_tolerance=creation_tolerance,
                               merge_tolerance=merge_tolerance).fit(db)
        synth = FaceSynthesizer(model.graphs_, noise_share=0.2, duration_noise=True)
        anim = synth.synthesize(list(labels), rng=np.random.default_rng(seed))
    pos = anim.positions(db.mean_neutral)
    if out.endswith(".csv"):
        import pandas as pd

        from ..atomic import atomic_path

        f, k = np.meshgrid(np.arange(pos.shape[0]), np.arange(pos.shape[1]), indexing="ij")
        df = pd.DataFrame({"frame": f.ravel(), "landmark": k.ravel(), "x": pos[..., 0].ravel(), "y": pos[..., 1].ravel()})
        with atomic_path(out) as t:
            df.to_csv(t, index=False, float_format="%.3f")
    elif out.endswith(".gif"):
        from .plots import face_gif

        face_gif(out, pos, anim.segments)
    else:
        raise ValueError(f"output {out!r}: use a .gif or .csv file name")
    return f"{anim.n_frames} frames, labels {' -> '.join(labels)}, segments {anim.segments}"
