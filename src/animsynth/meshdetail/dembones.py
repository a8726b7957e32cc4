"""The linear-blend-skinning floor of a mesh sequence with Dem Bones (SSDR, Le & Deng 2012).

Dem Bones (``py_dem_bones.solve_skinning``) fits, from the meshes alone, skinning
weights (at most ``max_influences`` bones per vertex, non-negative, summing to one)
and one rigid transform per bone and frame. Here it is used as a *floor*, not as a
competitor driven by the skeleton:

1. on the training blocks of a cross-validation fold, SSDR fits the weights (and the
   training frames' transforms) with a given bone count;
2. on the held-out blocks the weights stay fixed and only the per-frame bone
   transforms are solved, from the held-out meshes themselves.

The package's public API fits weights and transforms together and cannot hold the
weights fixed, so step 2 is our own least-squares solve (:func:`solve_transforms`):
per frame, the best affine bone transforms (one linear least-squares problem, exact),
projected to rotations, then block-coordinate weighted Procrustes sweeps (one bone at
a time, the others fixed; the SSDR transform update) to the best *rigid* transforms.
The held-out error is thus the best a linear blend skin with those weights does when
the bone transforms are known; what it leaves is detail no such skin expresses.
The affine solve's error (bones may also scale and shear) is reported beside it.

Dem Bones takes no seed: its initialisation (bone clustering of the first frames) is
deterministic for given meshes and options.
"""

from __future__ import annotations

import logging
import time

import numpy as np
import pandas as pd

log = logging.getLogger("animsynth.meshdetail.dembones")

MM = 1000.0


def fit_ssdr(rest: np.ndarray, frames: np.ndarray, faces: np.ndarray, bones: int, max_influences: int = 4,
             iterations: int = 10):
    """SSDR weights and transforms of ``frames`` (F, V, 3) about ``rest`` (V, 3).

    Returns (weights (V, B) dense, transforms (F, B, 3, 4) column-vector [R | t], CPU seconds, wall seconds).
    Dem Bones may return fewer than ``bones`` bones (B <= bones).
    """
    import py_dem_bones

    c0, w0 = time.process_time(), time.perf_counter()
    res = py_dem_bones.solve_skinning(np.asarray(rest, float), np.asarray(frames, float), int(bones),
                                      faces=np.asarray(faces, np.int64), max_influences=int(max_influences),
                                      iterations=int(iterations))
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    W = np.asarray(res.weights, float).T  # (V, B)
    T = np.asarray(res.transforms, float)[:, :, :3, :]  # (F, B, 3, 4)
    return W, T, cpu, wall


def blend(W: np.ndarray, rest: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Linear blend skinning: vertices (F, V, 3) of weights ``W`` (V, B) and transforms ``T`` (F, B, 3, 4).

    One matrix product for all frames: ``[W[v, b] * (rest_v, 1)]`` (V, 4 B) times the transforms stacked as
    (4 B, 3 F); a three-operand einsum over (vertex, bone, frame) cost about 10 times as much at 40 bones.
    """
    T = np.asarray(T, float)
    F, B = T.shape[:2]
    rest = np.asarray(rest, float)
    V = len(rest)
    M = (np.asarray(W, float)[:, :, None] * np.c_[rest, np.ones(V)][:, None, :]).reshape(V, 4 * B)
    A = T.transpose(1, 3, 0, 2).reshape(4 * B, 3 * F)  # A[(b, j), (f, i)] = T[f, b, i, j]
    return (M @ A).reshape(V, F, 3).transpose(1, 0, 2)


def _nearest_rotation(M: np.ndarray) -> np.ndarray:
    U, _, Vt = np.linalg.svd(M)
    d = np.sign(np.linalg.det(U @ Vt))
    U = U.copy()
    U[..., :, -1] *= d[..., None]
    return U @ Vt


def affine_transforms(W: np.ndarray, rest: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """Per-frame affine bone transforms (F, B, 3, 4) minimising the squared vertex error, weights fixed.

    One linear least-squares problem shared by all frames and coordinates: vertex i of
    frame f is ``sum_b W[i, b] A_fb [rest_i; 1]``. Bones with no weight get the identity.
    """
    V, B = W.shape
    F = len(frames)
    used = np.flatnonzero(W.max(axis=0) > 0)
    h = np.c_[rest, np.ones(V)]  # (V, 4)
    M = (W[:, used, None] * h[:, None, :]).reshape(V, 4 * len(used))
    rhs = np.asarray(frames).transpose(1, 0, 2).reshape(V, 3 * F)
    sol, *_ = np.linalg.lstsq(M, rhs, rcond=None)  # (4 B_used, 3 F)
    A = sol.reshape(len(used), 4, F, 3).transpose(2, 0, 3, 1)  # (F, B_used, 3, 4)
    T = np.zeros((F, B, 3, 4))
    T[..., :3] = np.eye(3)
    T[:, used] = A
    return T


def solve_transforms(W: np.ndarray, rest: np.ndarray, frames: np.ndarray, sweeps: int = 10,
                     init: np.ndarray | None = None) -> np.ndarray:
    """Per-frame rigid bone transforms (F, B, 3, 4) for fixed weights ``W`` (V, B), by least squares.

    Start: ``init`` or the affine solve projected to the nearest rotations. Each sweep
    updates one bone at a time by weighted Procrustes (the other bones fixed): bone b
    fits ``W[i, b] (R rest_i + t)`` to ``frame_i - sum_{c != b} W[i, c] T_c(rest_i)`` over the
    vertices it influences, i.e. ``R rest_i + t`` to that residual / ``W[i, b]`` with
    weights ``W[i, b]^2``. The squared error never increases from sweep to sweep.
    """
    frames = np.asarray(frames, float)
    F, V, _ = frames.shape
    B = W.shape[1]
    if init is None:
        T = affine_transforms(W, rest, frames)
        T[..., :3] = _nearest_rotation(T[..., :3])
    else:
        T = np.array(init, float)
    # vertex-major layout (V, F, 3): a bone's vertices are whole rows, and its targets are gathered once
    P = np.ascontiguousarray(blend(W, rest, T).transpose(1, 0, 2))  # current prediction
    frames_vm = frames.transpose(1, 0, 2)
    per_bone = []
    for b in range(B):
        idx = np.flatnonzero(W[:, b] > 0)
        if len(idx):
            w = W[idx, b]
            c = w ** 2
            u = rest[idx]
            mu_u = (c[:, None] * u).sum(0) / c.sum()
            per_bone.append((b, idx, w[:, None, None], c, c.sum(), u, mu_u, (c[:, None] * (u - mu_u)).T,
                             np.ascontiguousarray(frames_vm[idx])))

    def place(R, t, u):  # R (F, 3, 3), t (F, 3), u (n, 3) -> R_f u_v + t_f as (n, F, 3)
        return (u @ R.transpose(2, 0, 1).reshape(3, 3 * F)).reshape(len(u), F, 3) + t[None]

    for _ in range(int(sweeps)):
        for b, idx, w, c, csum, u, mu_u, A, target in per_bone:
            own = place(T[:, b, :, :3], T[:, b, :, 3], u)
            Pb = P[idx]
            tgt = (target - (Pb - w * own)) / w  # what bone b should explain, over its weight
            # weighted Procrustes: weights w^2, source u, target tgt
            mu_t = (c @ tgt.reshape(len(idx), 3 * F)).reshape(F, 3) / csum
            H = (A @ (tgt - mu_t[None]).reshape(len(idx), 3 * F)).reshape(3, F, 3).transpose(1, 0, 2)  # (F, 3, 3)
            U, _, Vt = np.linalg.svd(H)
            d = np.sign(np.linalg.det(np.transpose(Vt, (0, 2, 1)) @ np.transpose(U, (0, 2, 1))))
            D = np.tile(np.eye(3), (F, 1, 1))
            D[:, 2, 2] = d
            R = np.transpose(Vt, (0, 2, 1)) @ D @ np.transpose(U, (0, 2, 1))
            t = mu_t - np.einsum("fij,j->fi", R, mu_u)
            P[idx] = Pb + w * (place(R, t, u) - own)
            T[:, b, :, :3], T[:, b, :, 3] = R, t
    return T


def vertex_error_mm(pred: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per-frame, per-vertex Euclidean error (F, V) in mm."""
    return np.linalg.norm(np.asarray(pred) - np.asarray(truth), axis=-1) * MM


def floor_cv(frames: np.ndarray, faces: np.ndarray, folds: list, bone_counts, max_influences: int = 4,
             iterations: int = 10, sweeps: int = 10, keep_frames=()):
    """The Dem Bones LBS floor under blocked cross-validation.

    For every fold (held-out frame indices) and bone count: SSDR on the other frames
    (rest mesh = frame 0, as for our skin), then weights fixed and rigid transforms
    solved on the held-out frames (:func:`solve_transforms`).

    Returns (table, predictions): one row per fold and bone count (train_mm: SSDR's fit
    of its training frames; heldout_mm: rigid floor; heldout_affine_mm: affine floor; fit and
    solve seconds), and ``{bones: (len(keep_frames), V, 3)}`` held-out predictions of the
    frames ``keep_frames`` (each from the fold that held it out).
    """
    frames = np.asarray(frames, float)
    n = len(frames)
    rest = frames[0]
    keep = [int(f) for f in keep_frames]
    preds = {int(b): np.zeros((len(keep), frames.shape[1], 3)) for b in bone_counts}
    rows = []
    for k, te in enumerate(folds):
        te = np.asarray(te)
        tr = np.setdiff1d(np.arange(n), te)
        for bones in bone_counts:
            W, T_tr, cpu, wall = fit_ssdr(rest, frames[tr], faces, int(bones), max_influences, iterations)
            # training error with SSDR's own transforms (re-solving them as on the held-out frames doubled the
            # job's cost for a number nobody reads)
            train_mm = float(vertex_error_mm(blend(W, rest, T_tr), frames[tr]).mean())
            c0, w0 = time.process_time(), time.perf_counter()
            T_aff = affine_transforms(W, rest, frames[te])
            aff_mm = float(vertex_error_mm(blend(W, rest, T_aff), frames[te]).mean())
            T_start = T_aff.copy()  # solve_transforms' own start, computed once
            T_start[..., :3] = _nearest_rotation(T_start[..., :3])
            T_te = solve_transforms(W, rest, frames[te], sweeps=sweeps, init=T_start)
            P = blend(W, rest, T_te)
            solve_cpu, solve_wall = time.process_time() - c0, time.perf_counter() - w0
            err = vertex_error_mm(P, frames[te])
            for j, f in enumerate(keep):
                hit = np.flatnonzero(te == f)
                if len(hit):
                    preds[int(bones)][j] = P[hit[0]]
            rows.append({"fold": k, "bones": int(bones), "bones_used": int(np.sum(W.max(axis=0) > 0)),
                         "n_train": len(tr), "n_heldout": len(te), "train_mm": round(train_mm, 4),
                         "heldout_mm": round(float(err.mean()), 4), "heldout_affine_mm": round(aff_mm, 4),
                         "fit_cpu_s": round(cpu, 2), "fit_wall_s": round(wall, 2),
                         "solve_cpu_s": round(solve_cpu, 2), "solve_wall_s": round(solve_wall, 2)})
            log.info("fold %d, %d bones (%d used): SSDR train %.2f mm; held-out floor %.2f mm (affine %.2f); "
                     "fit %.1f s CPU, solve %.1f s CPU", k, bones, rows[-1]["bones_used"], train_mm, err.mean(),
                     aff_mm, cpu, solve_cpu)
    return pd.DataFrame(rows), preds


def floor_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Mean over folds and fold SD per bone count (held-out floor, training fit, time)."""
    g = table.groupby("bones")
    out = pd.DataFrame({
        "n_folds": g.size(),
        "heldout_mm": g.heldout_mm.mean(), "heldout_fold_sd_mm": g.heldout_mm.std(ddof=1),
        "heldout_affine_mm": g.heldout_affine_mm.mean(),
        "train_mm": g.train_mm.mean(),
        "fit_cpu_s_per_fold": g.fit_cpu_s.mean(), "solve_cpu_s_per_fold": g.solve_cpu_s.mean(),
    }).reset_index()
    return out.round(4)
