"""Workflow steps of the meshdetail family (the scripts in workflow/scripts only call these).

Files between steps:

* ``character/`` (synthetic only): ``main/mesh_NNNN.obj.gz`` and
  ``edit_<name>/mesh_NNNN.obj.gz`` OBJ sequences, ``truth.npz`` (true rig, poses
  of the clip and of every edit);
* ``data/sequence.npz``: the parsed main sequence (:class:`MeshSequence`);
  ``data/edits.npz``: parsed edited sequences with their true poses;
* ``data/pose.npz``: fitted rig, skinning weights, per-frame root translation and angles.
"""

from __future__ import annotations

import json
import logging
import os

import numpy as np
from scipy import sparse

from ..io import read_amc, read_asf
from ..atomic import atomic_path
from ..io.obj import MeshSequence, read_obj_sequence, write_obj_sequence
from ..skinning import Rig, cmu_motion_to_rig, default_rig, rebase, rebase_pose
from ..synth.character import SkirtParams, build_character, edit_motion, procedural_motion, simulate
from ..synth.mocap import cmu_like_skeleton, generate_motion
from .evaluation import Prepared, blocks, split_frames
from .rigfit import fit_skeleton, joint_rotation_errors, rig_fit_table, rig_from_joints
from .settings import check_character

log = logging.getLogger("animsynth.meshdetail.jobs")


def pack_weights(w: sparse.csr_matrix) -> dict:
    """Sparse skinning weights as the arrays of ``data/pose.npz``."""
    w = sparse.csr_matrix(w)
    return {"w_data": w.data, "w_indices": w.indices, "w_indptr": w.indptr, "w_shape": np.array(w.shape)}


def unpack_weights(z) -> sparse.csr_matrix:
    """The skinning weights stored by :func:`pack_weights` (``z``: the loaded npz)."""
    return sparse.csr_matrix((z["w_data"], z["w_indices"], z["w_indptr"]), shape=tuple(z["w_shape"]))


def driving_motion(cfg: dict, seed: int, speed: float = 1.0):
    """Rig and pose (root_t, angles) that drive the synthetic character."""

    check_character(cfg)
    drv, fps, n = cfg["driver"], float(cfg["fps"]), int(cfg["frames"])
    if drv == "procedural":
        rig = default_rig()
        rt, A = procedural_motion(cfg["motion"], n, fps, seed, rig, speed=speed)
        return rig, rt, A
    step = 120.0 / fps
    if drv == "cmu_synthetic":
        sk = cmu_like_skeleton("syn_skirt", seed)
        m = generate_motion(cfg["motion"], int(np.ceil(n * step * speed)) + 2, seed, sk, fps=120.0)
    else:  # amc
        m = read_amc(cfg["amc"], read_asf(cfg["asf"]), 120.0)
    rig, rt, A = cmu_motion_to_rig(m)
    src = np.arange(n) * step * speed
    if src[-1] > len(rt) - 1:
        raise ValueError(f"driving motion has {len(rt)} frames at 120 fps, need {src[-1]:.0f}")
    i0 = np.floor(src).astype(int)
    i1 = np.minimum(i0 + 1, len(rt) - 1)
    a = (src - i0)[:, None]
    return rig, (1 - a) * rt[i0] + a * rt[i1], (1 - a[..., None]) * A[i0] + a[..., None] * A[i1]


def make_character(cfg: dict, seed: int, out_dir: str) -> dict:
    """Generate, simulate and write the synthetic skirt character (main clip + edits)."""
    rig, rt, A = driving_motion(cfg, seed)
    ch = build_character(rig, cfg["resolution"], cfg["skirt_rings"], cfg["skirt_around"])
    sp = SkirtParams(hem_frequency=cfg["hem_frequency"], damping=cfg["damping"], substeps=cfg["substeps"])
    fps = float(cfg["fps"])
    V = simulate(ch, rt, A, fps, sp)
    log.info("character: %d vertices, %d faces, %d frames; skirt %d vertices", len(ch.rest), len(ch.faces), len(V),
             ch.skirt.size)
    write_obj_sequence(os.path.join(out_dir, "main"), MeshSequence(V, ch.faces, fps=fps), gz=True)
    # The known skeleton placed in the first-frame mesh: poses are stored relative to frame 0.
    rig0 = rebase(rig, rt[0], A[0])
    truth = {"rig": np.array(rig0.to_json()), "root_t": rt, "angles": rebase_pose(rig, rt, A, A[0]),
             "skirt": ch.skirt.ravel(), "edits": np.array(json.dumps(list(cfg["edits"]))),
             "tpose_rig": np.array(rig.to_json())}
    for name in cfg["edits"]:
        regen = (lambda s: driving_motion(cfg, seed, speed=s)[1:]) if name.startswith("speed") else None
        ert, eA = edit_motion(rt, A, name, regenerate=regen)
        Ve = simulate(ch, ert, eA, fps, sp)
        write_obj_sequence(os.path.join(out_dir, f"edit_{name}"), MeshSequence(Ve, ch.faces, fps=fps), gz=True)
        truth[f"root_t:{name}"] = ert
        truth[f"angles:{name}"] = rebase_pose(rig, ert, eA, A[0])
    with atomic_path(os.path.join(out_dir, "truth.npz"), suffix=".npz") as tmp:
        np.savez_compressed(tmp, **truth)
    return {"vertices": int(len(ch.rest)), "frames": int(len(V))}


def load_sequences(main_dir: str, truth_npz: str | None, seq_out: str, edits_out: str, fps: float,
                   max_frames: int | None = None) -> MeshSequence:
    """Parse the main OBJ sequence (cached as npz) and, for synthetic data, the edited ones."""
    seq = read_obj_sequence(main_dir, fps=fps, max_frames=max_frames)
    seq.save_npz(seq_out)
    edits = {}
    if truth_npz:
        root = os.path.dirname(truth_npz)
        with np.load(truth_npz) as z:
            names = json.loads(str(z["edits"]))
            for name in names:
                e = read_obj_sequence(os.path.join(root, f"edit_{name}"), fps=fps, max_frames=max_frames)
                if e.n_vertices != seq.n_vertices or not np.array_equal(e.faces, seq.faces):
                    raise ValueError(f"edited sequence {name!r} does not share the main sequence's topology")
                edits[f"vertices:{name}"] = e.vertices
                edits[f"root_t:{name}"] = z[f"root_t:{name}"][: e.n_frames]
                edits[f"angles:{name}"] = z[f"angles:{name}"][: e.n_frames]
    with atomic_path(edits_out, suffix=".npz") as tmp:
        np.savez_compressed(tmp, names=np.array(json.dumps(sorted({k.split(":", 1)[1] for k in edits}))), **edits)
    return seq


def initial_rig(seq: MeshSequence, truth_npz: str | None, rig_cfg: dict):
    """The skeleton of ``seq`` before fitting: the generator's rig (synthetic data) or the configured embedding.

    Returns (rig, refine, method description, true angles or None, vertex labels or None).
    """
    true_angles = labels = None
    if truth_npz:
        with np.load(truth_npz) as z:
            rig = Rig.from_json(str(z["rig"]))
            true_angles = z["angles"][: seq.n_frames]
            skirt = np.zeros(seq.n_vertices, bool)
            skirt[z["skirt"]] = True
        labels = {"body": ~skirt, "skirt": skirt}
        refine = False
        method = "ground-truth rig of the generator"
    else:
        if not rig_cfg.get("joints"):
            raise ValueError("config key 'meshdetail.rig.joints': real mesh data needs an 18-joint embedding "
                             "(joint start positions in the first frame; see docs/config_meshdetail.md)")
        rig = rig_from_joints(rig_cfg["joints"], rig_cfg.get("ends") or {})
        refine = bool(rig_cfg["refine"])
        method = "user-supplied embedding" + (", joints refined from the training frames' motion" if refine else "")
    return rig, refine, method, true_angles, labels


def fold_rig_fitter(seq_npz: str, truth_npz: str | None, rig_cfg: dict):
    """A function ``train -> (rig, weights, root_t, angles)`` that redoes the whole skeleton
    step (joint placement, weights, pose fit of every frame) from the given training frames
    only, so a cross-validation fold's held-out frames never shape its skin."""
    seq = MeshSequence.load_npz(seq_npz)
    rig0, refine, _, _, _ = initial_rig(seq, truth_npz, rig_cfg)
    cache: dict = {}  # what every fold shares (the initial embedding's weights and interior checks)

    def refit(train):
        rig, weights, fitter, _, _ = fit_skeleton(
            seq.vertices, seq.faces, rig0, np.asarray(train), skinning=rig_cfg["skinning"], refine=refine,
            max_influences=rig_cfg["max_influences"], iterations=rig_cfg["fit_iterations"],
            heat_c=rig_cfg["heat_c"], weight_power=rig_cfg["weight_power"], compare=False, cache=cache)
        return rig, weights, fitter.root_t_, fitter.angles_

    return refit


def fit_pose(seq_npz: str, truth_npz: str | None, rig_cfg: dict, train_fraction: float, out_npz: str):
    """Embed the 18-joint skeleton, compute weights, fit every frame.

    Returns (rig_fit table, joints table, skinning comparison table or None, description of the embedding).
    """
    seq = MeshSequence.load_npz(seq_npz)
    train, _ = split_frames(seq.n_frames, train_fraction)
    rig, refine, method, true_angles, labels = initial_rig(seq, truth_npz, rig_cfg)
    rig, weights, fitter, joints, comparison = fit_skeleton(
        seq.vertices, seq.faces, rig, train, skinning=rig_cfg["skinning"], refine=refine,
        max_influences=rig_cfg["max_influences"], iterations=rig_cfg["fit_iterations"], heat_c=rig_cfg["heat_c"],
        weight_power=rig_cfg["weight_power"], compare=bool(rig_cfg["compare_skinning"]))
    if true_angles is not None:
        joints["rotation_error_mean_deg"] = np.round(joint_rotation_errors(fitter, true_angles), 4)
    table = rig_fit_table(seq.vertices, rig, weights, fitter, train, labels)
    with atomic_path(out_npz, suffix=".npz") as tmp:
        np.savez_compressed(tmp, rig=np.array(rig.to_json()), root_t=fitter.root_t_, angles=fitter.angles_,
                            residual=fitter.residual_, method=np.array(method), **pack_weights(weights))
    return table, joints, comparison, method


def load_prepared(seq_npz: str, pose_npz: str, edits_npz: str, train_fraction: float) -> Prepared:
    seq = MeshSequence.load_npz(seq_npz)
    with np.load(pose_npz) as z:
        rig = Rig.from_json(str(z["rig"]))
        weights = unpack_weights(z)
        root_t, angles = z["root_t"], z["angles"]
    edits = {}
    with np.load(edits_npz) as z:
        for name in json.loads(str(z["names"])):
            edits[name] = (z[f"vertices:{name}"], z[f"root_t:{name}"], z[f"angles:{name}"])
    tr, te = split_frames(seq.n_frames, train_fraction)
    return Prepared(seq.vertices, seq.faces, rig, weights, root_t, angles, tr, te, edits)


def dembones_floor(seq_npz: str, cfg: dict, cv_folds: int, render_frames, out_npz: str):
    """The Dem Bones LBS floor of one sequence under the meshdetail blocked CV (same folds as Fig. 5c).

    Returns (per-fold table, per-bone-count summary); writes the held-out predictions of the
    error-map frame (the first render frame) per bone count to ``out_npz``.
    """
    from .dembones import floor_cv, floor_summary

    seq = MeshSequence.load_npz(seq_npz)
    frame = min(max(int(list(render_frames)[0]), 0), seq.n_frames - 1)
    table, preds = floor_cv(seq.vertices, seq.faces, blocks(seq.n_frames, int(cv_folds)), list(cfg["bones"]),
                            max_influences=int(cfg["max_influences"]), iterations=int(cfg["iterations"]),
                            sweeps=int(cfg["sweeps"]), keep_frames=[frame])
    with atomic_path(out_npz, suffix=".npz") as tmp:
        np.savez_compressed(tmp, frame=np.array(frame), bones=np.array(list(cfg["bones"])),
                            **{f"bones_{b}": p[0] for b, p in preds.items()})
    return table, floor_summary(table)


# ----------------------------------------------------------------------------- cost curves (animsynth.scale)


def scale_steps(recorder, n: int, resolution: float = 1.0, seed: int = 0, level: float = 5.0, iterations: int = 100,
                     latent_dim: int = 4):
    """The hybrid (GP detail) model trained on ``n`` frames of the synthetic skirt character."""
    from .models import HybridModel, MeshContext

    cfg = {"driver": "cmu_synthetic", "motion": "dance", "frames": int(n), "fps": 30.0}
    rig, rt, A = driving_motion(cfg, seed)
    ch = build_character(rig, resolution)
    V = simulate(ch, rt, A, 30.0, SkirtParams())
    rig0 = rebase(rig, rt[0], A[0])
    ang = rebase_pose(rig, rt, A, A[0])
    ctx = MeshContext(V[0], ch.faces, rig0, ch.weights, max_level=max(level, 5.0))
    S = recorder("meshdetail", n, vertices=int(V.shape[1]), resolution=resolution)
    with S.step("training"):
        HybridModel(level=level, latent_dim=latent_dim, iterations=iterations).fit(ctx, V, rt, ang)
    return S.rows
