"""The paper's experiments (Fig. 5 a-c, representations, resolution, generalisation, timing)
as functions from prepared data to tables.

Errors are per-frame mean Euclidean vertex distances in millimetres (the
meshes are in metres). Frames are split into a contiguous training block (the
first ``train_fraction``) and the held-out remainder.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy import sparse

from ..skinning import (JOINTS, PARENTS, Rig, bone_heat_weights, dominant_joint, joint_transforms, pose_vertices,
                        refit_weights, skinning_weights)
from .fit import PoseFitter, _fk_from_world, place_joints
from .models import HybridModel, MeshContext, mean_vertex_error, pose_features, reconstruction_seconds_per_frame

log = logging.getLogger("animsynth.meshdetail.experiments")

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


def rig_from_joints(joints: dict, ends: dict | None = None) -> Rig:
    """A rig from user-supplied joint start positions ``{name: [x, y, z]}`` (all 18 names).

    Segment ends are the start of the (first) child; leaves (head, hands, feet)
    take ``ends[name]`` if given, else continue the parent direction for half
    the parent's length.
    """
    missing = [n for n in JOINTS if n not in joints]
    if missing:
        raise ValueError(f"config key 'meshdetail.rig.joints' misses {missing}")
    st = np.array([joints[n] for n in JOINTS], float)
    en = np.zeros_like(st)
    ends = ends or {}
    for j, n in enumerate(JOINTS):
        kids = [k for k, p in enumerate(PARENTS) if p == j]
        if n in ends:
            en[j] = ends[n]
        elif n == "hips":
            en[j] = st[JOINTS.index("spine")]
        elif kids:
            en[j] = st[kids[0]]
        else:
            p = PARENTS[j]
            en[j] = st[j] + 0.5 * (st[j] - st[p])
    return Rig(st, en)


SKINNINGS = ("heat", "heat+refit", "distance")


def skin_weights(method: str, rest, faces, rig: Rig, max_influences: int = 4, heat_c: float = 1.0,
                 weight_power: float = 4.0):
    """First-frame skinning weights: ``heat`` (bone heat, also the start of ``heat+refit``) or ``distance``."""
    if method == "distance":
        return skinning_weights(rest, rig, power=weight_power, max_influences=max_influences)
    if method in ("heat", "heat+refit"):
        return bone_heat_weights(rest, faces, rig, c=heat_c, max_influences=max_influences)
    raise ValueError(f"config key 'meshdetail.rig.skinning': must be one of {SKINNINGS}, got {method!r}")


def _transforms(rig: Rig, fitter: PoseFitter):
    return joint_transforms(rig, fitter.W_, _fk_from_world(rig, fitter.W_, fitter.root_t_))


def fit_skeleton(frames: np.ndarray, faces: np.ndarray, rig: Rig, train: np.ndarray, skinning: str = "heat+refit",
                 refine: bool = False, max_influences: int = 4, iterations: int = 8, heat_c: float = 1.0,
                 weight_power: float = 4.0, compare: bool = False):
    """Place the joints, compute weights, fit every frame's pose.

    1. (``refine``) joints from the mesh motion of the **training** frames, each
       checked to lie inside the first-frame mesh (:func:`~.fit.place_joints`);
    2. first-frame weights (``heat`` / ``distance``);
    3. per-frame pose fit of all frames (each frame alone: a held-out frame's
       pose uses only that frame);
    4. ``heat+refit``: weights refitted (non-negative, sum to one) on the
       training frames' poses and meshes only, then every pose refitted.

    Parameters
    ----------
    frames : (F, V, 3); faces : (T, 3); rig : initial embedding; train : training frame indices
    compare : bool
        Also fit the other skinning methods and return their residuals (the
        measurement behind the default).

    Returns
    -------
    rig, weights (csr), fitter (:class:`PoseFitter`), joints table, comparison table (or None)
    """
    rest = frames[0]
    train = np.asarray(train)
    if refine:
        w0 = skin_weights("heat" if skinning != "distance" else "distance", rest, faces, rig, max_influences,
                          heat_c, weight_power)
        rig, joints = place_joints(rig, w0, rest, faces, frames[train])
    else:
        rig, joints = place_joints(rig, None, rest, faces, None)
    results = {}
    methods = SKINNINGS if compare else (skinning,)
    for m in ("distance", "heat", "heat+refit"):
        if m not in methods and not (m == "heat" and skinning == "heat+refit"):
            continue
        if m == "heat+refit":
            w_h, fit_h = results["heat"]
            w = refit_weights(w_h, rest, _transforms(rig, fit_h)[train], frames[train], parents=rig.parents,
                              max_influences=max_influences)
        else:
            w = skin_weights(m, rest, faces, rig, max_influences, heat_c, weight_power)
        results[m] = (w, PoseFitter(iterations=iterations).fit(rig, w, rest, frames))
        log.info("skinning %s: LBS residual train %.2f mm, held-out %.2f mm", m,
                 MM * results[m][1].residual_[train].mean(),
                 MM * np.delete(results[m][1].residual_, train).mean() if len(train) < len(frames) else np.nan)
    weights, fitter = results[skinning]
    comparison = None
    if compare:
        test = np.setdiff1d(np.arange(len(frames)), train)
        comparison = pd.DataFrame([{
            "skinning": m, "used": m == skinning,
            "train_mean_mm": round(float(MM * f.residual_[train].mean()), 3),
            "heldout_mean_mm": round(float(MM * f.residual_[test].mean()), 3) if len(test) else np.nan}
            for m, (_, f) in results.items()])
    return rig, weights, fitter, joints, comparison


def rig_fit_table(frames, rig, weights, fitter, train, labels=None) -> pd.DataFrame:
    """LBS residual of the fitted skeleton, overall and per bone, on training and held-out frames.

    A bone's vertices are those it dominates (largest weight); ``labels``
    (name -> vertex mask) adds rows for named vertex sets (e.g. body / skirt).
    Columns: part, split, n_frames, n_vertices, mean_mm, median_mm, p95_mm.
    """
    P = pose_vertices(rig, weights, frames[0], fitter.root_t_, fitter.angles_)
    r = np.linalg.norm(P - frames, axis=-1) * MM
    dom = dominant_joint(weights)
    test = np.setdiff1d(np.arange(len(frames)), train)
    parts = [("all", np.ones(r.shape[1], bool))] + [(n, dom == j) for j, n in enumerate(rig.names)]
    parts += [(f"[{k}]", v) for k, v in (labels or {}).items()]
    rows = []
    for split, idx in (("train", np.asarray(train)), ("held-out", test)):
        if not len(idx):
            continue
        for name, mask in parts:
            x = r[np.ix_(idx, np.flatnonzero(mask))]
            rows.append({"part": name, "split": split, "n_frames": len(idx), "n_vertices": int(mask.sum()),
                         "mean_mm": round(float(x.mean()), 3) if x.size else np.nan,
                         "median_mm": round(float(np.median(x)), 3) if x.size else np.nan,
                         "p95_mm": round(float(np.percentile(x, 95)), 3) if x.size else np.nan})
    return pd.DataFrame(rows)


def joint_rotation_errors(fitter, true_angles) -> np.ndarray:
    """Per-joint mean angle (degrees) between fitted and true local rotations (root excluded: NaN)."""
    from scipy.spatial.transform import Rotation

    F, J = fitter.angles_.shape[:2]
    a = Rotation.from_euler("xyz", fitter.angles_.reshape(-1, 3))
    b = Rotation.from_euler("xyz", np.asarray(true_angles)[:F].reshape(-1, 3))
    err = np.rad2deg((a.inv() * b).magnitude()).reshape(F, J).mean(axis=0)
    err[0] = np.nan
    return err


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


def context(d: Prepared, levels=(5.0,), cfg: dict | None = None) -> MeshContext:
    below = [lv for lv in levels if lv < 100]
    cfg = cfg or {}
    return MeshContext(d.rest, d.faces, d.rig, d.weights, max_level=max(below) if below else 5.0,
                       decimation=cfg.get("decimation", "collapse"), rbf_neighbors=cfg.get("rbf_neighbors", 24))


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


def pack_weights(w: sparse.csr_matrix) -> dict:
    w = sparse.csr_matrix(w)
    return {"w_data": w.data, "w_indices": w.indices, "w_indptr": w.indptr, "w_shape": np.array(w.shape)}


def unpack_weights(z) -> sparse.csr_matrix:
    return sparse.csr_matrix((z["w_data"], z["w_indices"], z["w_indptr"]), shape=tuple(z["w_shape"]))


def timed(fn, *a, **k):
    t0 = time.perf_counter()
    out = fn(*a, **k)
    return out, time.perf_counter() - t0
