"""The paper's experiments (Fig. 5 a-c, representations, resolution, generalisation, timing)
as functions from a prepared sequence (:class:`Prepared`: frames, fitted skeleton, split) to tables.

Errors are per-frame mean Euclidean vertex distances in millimetres (the
meshes are in metres). Frames are split into a contiguous training block (the
first ``train_fraction``) and the held-out remainder; model comparisons use
blocked cross-validation (:func:`blocks`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy import sparse

from ..skinning import Rig
from .models import HybridModel, MeshContext, mean_vertex_error, pose_features, reconstruction_seconds_per_frame

log = logging.getLogger("animsynth.meshdetail.evaluation")

MM = 1000.0


# --------------------------------------------------------------------------- data
@dataclass
class Prepared:
    """A mesh sequence with its fitted skeleton (what every experiment needs)."""

    frames: np.ndarray  # (F, V, 3) metres
    faces: np.ndarray
    rig: Rig
    weights: sparse.csr_matrix
    root_t: np.ndarray  # fitted
    angles: np.ndarray  # fitted (F, J, 3) radians
    train: np.ndarray
    test: np.ndarray
    edits: dict = field(default_factory=dict)  # name -> (frames, root_t, angles) ground truth + pose

    @property
    def rest(self) -> np.ndarray:
        return self.frames[0]


def split_frames(n: int, train_fraction: float):
    k = int(round(n * train_fraction))
    if k < 8 or k > n:
        raise ValueError(f"train_fraction {train_fraction} leaves {k} of {n} frames for training (need >= 8)")
    return np.arange(k), np.arange(k, n)


# --------------------------------------------------------------------------- models
MODEL_COLUMNS = {"lbs": "lbs_mm", "hybrid": "hybrid_mm", "gp_regression": "gp_regression_mm",
                 "ridge_cv": "ridge_cv_mm", "hybrid_no_dynamics": "hybrid_no_dynamics_mm"}


def _model(cfg: dict, **over) -> HybridModel:
    kw = dict(level=cfg["level"], latent_dim=cfg["latent_dim"], iterations=cfg["iterations"],
              dynamics_weight=cfg["dynamics_weight"], ridge_alphas=cfg["ridge_alphas"],
              joint_param=cfg["joint_param"], detail=cfg["detail"], decimation=cfg["decimation"])
    kw.update(over)
    return HybridModel(**kw)


def _variants(cfg):
    return {"lbs": dict(regressor="none"), "hybrid": dict(regressor="gp"),
            "gp_regression": dict(regressor="gp_regression"), "ridge_cv": dict(regressor="ridge_cv"),
            "hybrid_no_dynamics": dict(regressor="gp", dynamics_weight=0.0)}


def _fit(model, ctx, d: Prepared, idx=None):
    """Fit on frames ``idx`` (default: the training frames) with cached control positions."""
    idx = d.train if idx is None else np.asarray(idx)
    if model.regressor == "none":
        return model.fit(ctx, d.frames[idx], d.root_t[idx], d.angles[idx])
    feats = pose_features(d.angles, model.joint_param)[idx]
    Pc = ctx.control_positions(model.level, d.frames, model.decimation, cache="frames")
    Ps, _, _ = ctx.skin(d.root_t, d.angles)
    Psc = ctx.control_positions(model.level, Ps, model.decimation, cache="skinned")
    return model.fit(ctx, d.frames[idx], d.root_t[idx], d.angles[idx], features=feats, control=(Pc[idx], Psc[idx]))


def _predict(model, ctx, d: Prepared, idx):
    idx = np.asarray(idx)
    prev = d.angles[idx[0] - 1: idx[0]] if idx[0] > 0 else None
    return model.predict(ctx, d.root_t[idx], d.angles[idx], prev_angles=prev)


def _err(model, ctx, frames, root_t, angles):
    return mean_vertex_error(model.predict(ctx, root_t, angles), frames) * MM


def context(d: Prepared, levels, cfg: dict) -> MeshContext:
    """The mesh context of ``d`` for control levels ``levels`` (``cfg``: the meshdetail model keys, with
    ``decimation`` and ``rbf_neighbors``)."""
    below = [lv for lv in levels if lv < 100]
    return MeshContext(d.rest, d.faces, d.rig, d.weights, max_level=max(below) if below else 5.0,
                       decimation=cfg["decimation"], rbf_neighbors=cfg["rbf_neighbors"])


def blocks(n: int, k: int) -> list:
    """``k`` contiguous blocks of ``range(n)`` (blocked cross-validation)."""
    if n < 2 * k:
        raise ValueError(f"config key 'meshdetail.cv_folds': {k} blocks need at least {2 * k} frames, got {n}")
    return np.array_split(np.arange(n), k)


def run_main(d: Prepared, cfg: dict, refit_rig=None):
    """Fig. 5a, Fig. 5c and the generalisation table under blocked cross-validation.

    ``refit_rig`` (optional, e.g. :func:`.jobs.fold_rig_fitter`): a function
    ``train -> (rig, weights, root_t, angles)``. When given, every fold redoes
    the skeleton step (joint placement, skinning weights, pose fit) from its
    own training blocks, so no held-out frame shapes the skin of the models
    that are tested on it. Without it the fold models share ``d``'s skeleton
    (fitted on ``d.train``, which overlaps the held-out blocks of early folds).

    Every model (LBS only, the paper's SGPLVM+GPDM hybrid, plain GP
    regression, CV-tuned ridge, the hybrid without the GPDM term) is trained
    on all blocks but one and tested on that block, for each of
    ``cv_folds`` contiguous blocks. The GPDM sees the training frames as one
    sequence (one spurious transition across a held-out block).

    Returns (fig5a, fig5c, generalisation, predictions): fig5c has every
    frame's held-out error (from the fold that held it out); generalisation
    the mean over folds and the spread (SD of the fold means); predictions the
    held-out (F, V, 3) reconstructions per model.
    """
    ctx = context(d, (cfg["level"],), cfg)
    n = len(d.frames)
    folds = blocks(n, int(cfg["cv_folds"]))
    names = list(_variants(cfg))
    oof = {k: np.empty(n) for k in names}
    preds = {k: np.empty_like(d.frames) for k in ("lbs", "hybrid", "gp_regression", "ridge_cv")}
    fold_test = {k: [] for k in names}
    fold_train = {k: [] for k in names}
    edit_err = {name: {k: [] for k in names} for name in d.edits}
    block = np.empty(n, int)
    for b, te in enumerate(folds):
        block[te] = b
        tr = np.setdiff1d(np.arange(n), te)
        if refit_rig is None:
            db, cb = d, ctx
        else:
            rig_b, w_b, rt_b, ang_b = refit_rig(tr)
            db = replace(d, rig=rig_b, weights=w_b, root_t=rt_b, angles=ang_b, train=tr, test=te)
            cb = ctx.with_skin(rig_b, w_b)  # the mesh-only pieces (control mesh, upsampler) are shared
        for k, over in _variants(cfg).items():
            m = _fit(_model(cfg, **over), cb, db, tr)
            p = _predict(m, cb, db, te)
            e = mean_vertex_error(p, d.frames[te]) * MM
            oof[k][te] = e
            fold_test[k].append(e.mean())
            fold_train[k].append(float(np.mean(mean_vertex_error(m.predict(cb, db.root_t[tr], db.angles[tr]),
                                                                  d.frames[tr]) * MM)))
            if k in preds:
                preds[k][te] = p
            for name, (fr, rt, ang) in d.edits.items():
                edit_err[name][k].append(float(np.mean(_err(m, cb, fr, rt, ang))))
        log.info("fold %d/%d: held-out %s", b + 1, len(folds), {k: round(v[-1], 2) for k, v in fold_test.items()})
    r4 = lambda x: np.round(x, 4)  # noqa: E731
    fig5c = pd.DataFrame({"frame": np.arange(n), "block": block, **{MODEL_COLUMNS[k]: r4(oof[k]) for k in names}})
    rows = []

    def row(case, nf, per_fold):
        r = {"case": case, "n_frames": nf, "n_folds": len(folds)}
        for k in names:
            v = np.asarray(per_fold[k], float)
            r[MODEL_COLUMNS[k]] = float(r4(v.mean()))
            r[MODEL_COLUMNS[k][:-3] + "_fold_sd_mm"] = float(r4(v.std(ddof=1))) if len(v) > 1 else np.nan
        rows.append(r)

    row("training frames (in-fold fit)", n - len(folds[0]), fold_train)
    row("held-out frames (blocked CV)", n, fold_test)
    for name in d.edits:
        row(f"edited motion: {name}", len(d.edits[name][0]), edit_err[name])
    gen = pd.DataFrame(rows)
    # Fig. 5a on the configured split: GP on the full deformation vs on the detail only
    split = np.where(np.isin(np.arange(n), d.train), "train", "test")
    full = _fit(_model(cfg, regressor="gp", target="full"), ctx, d)
    hyb = _fit(_model(cfg, regressor="gp"), ctx, d)
    fig5a = pd.DataFrame({"frame": np.arange(n), "split": split,
                          "full_deformation_mm": r4(_err(full, ctx, d.frames, d.root_t, d.angles)),
                          "detail_only_mm": r4(_err(hyb, ctx, d.frames, d.root_t, d.angles))})
    return fig5a, fig5c, gen, preds


def run_resolution(d: Prepared, cfg: dict, timing_frames: int = 30):
    """Fig. 5b (error and stored size per control-mesh level, both decimations) and its timing table.

    The paper's decimation (replayed edge collapses) and the farthest-point
    vertex subset, both reconstructed by RBF. Timing (wall and CPU): training
    per 100 frames and one-frame-at-a-time reconstruction.
    """
    levels = [float(v) for v in cfg["levels"]]
    ctx = context(d, levels, cfg)
    n_orig = d.frames.size
    rows, trows = [], []
    tf = slice(0, min(timing_frames + 1, len(d.frames)))
    for method in ("collapse", "farthest"):
        for lv in levels:
            if lv >= 100 and method == "farthest":
                continue
            m = _fit(_model(cfg, regressor="gp", level=lv, decimation=method), ctx, d)
            e = _err(m, ctx, d.frames, d.root_t, d.angles)
            size = 100.0 * m.stored_floats(ctx, len(d.frames)) / n_orig
            label = "full mesh" if lv >= 100 else ("edge collapse (replayed)" if method == "collapse" else
                                                   "farthest-point subset")
            rows.append({"decimation": label, "level_pct": lv, "n_control": len(m.control_),
                         "train_mm": round(float(e[d.train].mean()), 4),
                         "test_mm": round(float(e[d.test].mean()), 4) if len(d.test) else np.nan,
                         "size_pct_of_original": round(size, 3)})
            spf, cpf = reconstruction_seconds_per_frame(m, ctx, d.root_t[tf], d.angles[tf], repeat=2)
            per = 100.0 / len(d.train)
            trows.append({"decimation": label, "level_pct": lv, "n_control": len(m.control_),
                          "train_frames": len(d.train), "train_wall_s_per_100_frames": round(m.train_seconds_ * per, 3),
                          "train_cpu_s_per_100_frames": round(m.train_cpu_seconds_ * per, 3),
                          "recon_wall_ms_per_frame": round(1000 * spf, 3), "recon_cpu_ms_per_frame": round(1000 * cpf, 3),
                          "recon_fps": round(1.0 / spf, 1)})
            log.info("%s %s%%: train %.2f mm test %.2f mm, size %.2f%%, %.2f s/100 frames, %.1f fps", label, lv,
                     rows[-1]["train_mm"], rows[-1]["test_mm"], size, m.train_seconds_ * per, 1 / spf)
    return pd.DataFrame(rows), pd.DataFrame(trows)


def run_representations(d: Prepared, cfg: dict) -> pd.DataFrame:
    """Joint parameterisation (Euler / quaternion / exponential map) x detail encoding (XYZ / Laplacian)."""
    ctx = context(d, (cfg["level"],), cfg)
    rows = []
    for jp in ("euler", "quaternion", "expmap"):
        for det in ("xyz", "laplacian"):
            m = _fit(_model(cfg, regressor="gp", joint_param=jp, detail=det), ctx, d)
            e = _err(m, ctx, d.frames, d.root_t, d.angles)
            rows.append({"joint_param": jp, "detail": det, "default": jp == cfg["joint_param"] and det == cfg["detail"],
                         "n_skeleton_features": m.gp_.alpha_[0].shape[1],
                         "train_mm": round(float(e[d.train].mean()), 4),
                         "test_mm": round(float(e[d.test].mean()), 4) if len(d.test) else np.nan})
    return pd.DataFrame(rows)
