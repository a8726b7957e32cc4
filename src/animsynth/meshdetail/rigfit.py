"""Skeleton fitting of a mesh sequence: the 18-joint embedding, skinning weights and per-frame poses.

Errors are per-frame mean Euclidean vertex distances in millimetres (the meshes are in metres).
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from ..skinning import (JOINTS, PARENTS, Rig, bone_heat_weights, dominant_joint, joint_transforms, pose_vertices,
                        refit_weights, skinning_weights)
from .fit import PoseFitter, _fk_from_world, place_joints

log = logging.getLogger("animsynth.meshdetail.rigfit")

MM = 1000.0


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
                 weight_power: float = 4.0, compare: bool = False, cache: dict | None = None):
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
    cache : dict, optional
        Kept by the caller between calls on the same mesh and initial ``rig``
        (the folds of a cross-validation): what depends only on those (the
        initial embedding's weights for ``refine``, its winding numbers and
        interior points) is computed once and reused.

    Returns
    -------
    rig, weights (csr), fitter (:class:`PoseFitter`), joints table, comparison table (or None)
    """
    rest = frames[0]
    train = np.asarray(train)
    if refine:
        cache = {} if cache is None else cache
        if "initial_weights" not in cache:
            cache["initial_weights"] = skin_weights("heat" if skinning != "distance" else "distance", rest, faces,
                                                    rig, max_influences, heat_c, weight_power)
        rig, joints = place_joints(rig, cache["initial_weights"], rest, faces, frames[train], cache=cache)
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
    from ..kinematics import xyz_euler_rotation

    F, J = fitter.angles_.shape[:2]
    a = xyz_euler_rotation(fitter.angles_)
    b = xyz_euler_rotation(np.asarray(true_angles)[:F])
    err = np.rad2deg((a.inv() * b).magnitude()).reshape(F, J).mean(axis=0)
    err[0] = np.nan
    return err
