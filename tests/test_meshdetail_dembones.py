"""The Dem Bones LBS floor, the across-sequence verdicts and the mesh-sequence config."""
import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from animsynth.config import ConfigError
from animsynth.meshdetail import dembones as D
from animsynth.meshdetail.settings import check, mesh_sequences
from animsynth.meshdetail.verdicts import combine_verdicts, holds_on, side_by_side
from test_meshdetail_skinning import closed_cylinder

CENTRES = np.array([0.5, 1.5, 2.5])


def skinned_tube(frames=24, seed=0):
    """A closed 3 m tube skinned to 3 bones with known weights, posed by random rigid bone transforms
    (exact LBS data; frame 0 is the rest pose)."""
    rng = np.random.default_rng(seed)
    rest, faces = closed_cylinder(length=3.0, radius=0.3, rings=31, around=16)
    W = np.exp(-((rest[:, :1] - CENTRES) ** 2) / 0.15)
    W[W < 0.05 * W.max(axis=1, keepdims=True)] = 0
    W /= W.sum(axis=1, keepdims=True)
    T = np.zeros((frames, 3, 3, 4))
    T[..., :3] = np.eye(3)
    for f in range(1, frames):
        for b in range(3):
            R = Rotation.from_rotvec(rng.normal(0, 0.25, 3)).as_matrix()
            c = np.array([CENTRES[b], 0, 0])
            T[f, b, :, :3], T[f, b, :, 3] = R, c - R @ c + rng.normal(0, 0.05, 3)
    return rest, faces, W, T, D.blend(W, rest, T)


def test_fixed_weight_solve_is_exact_on_lbs_data_and_never_worse_than_given_transforms():
    rest, _, W, T, V = skinned_tube()
    T_hat = D.solve_transforms(W, rest, V[1:])
    assert D.vertex_error_mm(D.blend(W, rest, T_hat), V[1:]).max() < 1e-6  # exact: the data are LBS
    # a skin driven by other (perturbed) transforms, on data with non-LBS detail: the floor is below it
    rng = np.random.default_rng(1)
    Vd = V[1:] + rng.normal(0, 0.01, V[1:].shape)
    Tp = T[1:].copy()
    Tp[..., 3] += rng.normal(0, 0.02, Tp[..., 3].shape)
    given = D.vertex_error_mm(D.blend(W, rest, Tp), Vd).mean()
    floor = D.vertex_error_mm(D.blend(W, rest, D.solve_transforms(W, rest, Vd)), Vd).mean()
    affine = D.vertex_error_mm(D.blend(W, rest, D.affine_transforms(W, rest, Vd)), Vd).mean()
    assert affine <= floor + 1e-9 and floor < given


def test_dembones_floor_reaches_near_zero_on_exact_lbs_data_and_beats_a_wrong_skin():
    rest, faces, W, T, V = skinned_tube()
    folds = np.array_split(np.arange(len(V)), 3)
    # one spare bone: Dem Bones may drop a bone (it kept 2 of 3 on one fold here, bones_used reports it)
    table, preds = D.floor_cv(V, faces, folds, [4], iterations=10, keep_frames=[20])
    assert list(table["fold"]) == [0, 1, 2] and (table["bones_used"] <= 4).all()
    # ~0: below 0.5 % of the 3 m tube on every held-out block (the true weights give exactly 0)
    assert table["heldout_mm"].max() < 0.005 * 3000
    # a skin with wrong weights (bones swapped at the middle), even with the true transforms, is worse
    Wrong = W[:, [0, 2, 1]]
    held = np.concatenate(folds[1:])
    wrong = D.vertex_error_mm(D.blend(Wrong, rest, T[held]), V[held]).mean()
    assert table["heldout_mm"].mean() < wrong
    assert preds[4].shape == (1, len(rest), 3)
    assert D.vertex_error_mm(preds[4], V[[20]]).mean() < 0.005 * 3000
    s = D.floor_summary(table)
    assert list(s["bones"]) == [4] and s.loc[0, "n_folds"] == 3


@pytest.mark.parametrize("verdicts, words, verdict", [
    ({"samba": "reproduced", "crane": "reproduced"}, "holds on both", "reproduced"),
    ({"samba": "reproduced", "crane": "within noise"}, "holds on one (samba)", "partly"),
    ({"samba": "within noise", "crane": "contradicted"}, "holds on neither", "not reproduced"),
    ({"samba": "within noise", "crane": "within noise"}, "holds on neither", "within noise"),
    ({"samba": "undecided", "crane": "undecided"}, "holds on neither", "undecided"),
    ({"samba": "did not run", "crane": "did not run"}, "holds on neither", "did not run"),
    ({"samba": "partly", "crane": "reproduced"}, "holds on one (crane)", "partly"),
])
def test_holds_on_both_one_or_neither(verdicts, words, verdict):
    assert holds_on(verdicts) == (words, verdict)


def _vt(verdict):
    return pd.DataFrame([{"claim": "C", "paper_value": "p", "ours": "1 vs 2 mm", "data": "d", "verdict": verdict,
                          "evidence": "e", "source": "meshdetail/fig5c.csv"}])


def test_combine_verdicts_keeps_every_sequence_and_adds_one_row_per_claim():
    t = combine_verdicts({"samba": _vt("reproduced"), "crane": _vt("within noise")})
    assert list(t["claim"]) == ["[samba] C", "[crane] C", "[all sequences] C"]
    last = t.iloc[-1]
    assert last.verdict == "partly" and last.ours == "holds on one (samba)"
    assert "crane: within noise" in last.evidence and t.iloc[1].source == "meshdetail/crane/fig5c.csv"


def test_side_by_side_has_every_method_per_sequence():
    cols = {f"{k}_mm": 1.0 for k in ("lbs", "hybrid", "hybrid_no_dynamics", "gp_regression", "ridge_cv")}
    cols.update({f"{k}_fold_sd_mm": 0.1 for k in ("lbs", "hybrid", "hybrid_no_dynamics", "gp_regression", "ridge_cv")})
    gen = pd.DataFrame([{"case": "held-out frames (blocked CV)", **cols}])
    db = pd.DataFrame({"fold": [0, 1, 0, 1], "bones": [18, 18, 40, 40], "heldout_mm": [2.0, 4.0, 1.0, 1.0]})
    t = side_by_side({"a": gen, "b": gen}, {"a": db, "b": db}).set_index("method")
    assert len(t) == 7 and {"a_mm", "a_fold_sd_mm", "b_mm", "b_fold_sd_mm"} <= set(t.columns)
    row = t.loc["Dem Bones LBS floor, 18 bones (transforms solved on held-out meshes)"]
    assert row["a_mm"] == 3.0 and row["a_fold_sd_mm"] == pytest.approx(np.std([2.0, 4.0], ddof=1), abs=1e-4)


def _config(**md):
    from animsynth.config import validate_config
    import yaml
    from conftest import REPO

    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    cfg["mesh_dir"] = "../data/samba"
    cfg["meshdetail"]["rig"]["joints"] = {n: [0, 0, 0] for n in __import__("animsynth.skinning").skinning.JOINTS}
    cfg["meshdetail"].update(md)
    validate_config(cfg, str(REPO / "config" / "schema.yaml"))
    return cfg


def test_mesh_sequences_names_and_own_rig():
    joints = {n: [1, 1, 1] for n in __import__("animsynth.skinning").skinning.JOINTS}
    seqs = mesh_sequences(_config(sequences={"crane": {"mesh_dir": "../data/crane", "rig": {"joints": joints}}}))
    assert list(seqs) == ["samba", "crane"]
    assert seqs["crane"]["rig"]["joints"] == joints and seqs["samba"]["rig"]["joints"] != joints
    assert seqs["crane"]["rig"]["skinning"] == seqs["samba"]["rig"]["skinning"]  # other rig keys inherited
    assert seqs["crane"]["render_frames"] == seqs["samba"]["render_frames"]
    with pytest.raises(ConfigError, match="already taken"):
        mesh_sequences(_config(sequences={"samba": {"mesh_dir": "x", "rig": {"joints": joints}}}))
    with pytest.raises(ConfigError, match="crane.rig.joints"):
        check(_config(sequences={"crane": {"mesh_dir": "x", "rig": {"joints": {"hips": [0, 0, 0]}}}}))


def _solve_reference(W, rest, frames, sweeps, T):
    """The block-coordinate Procrustes sweeps written frame-major, bone by bone, as in their definition."""
    T = T.copy()
    P = D.blend(W, rest, T)
    for _ in range(sweeps):
        for b in range(W.shape[1]):
            idx = np.flatnonzero(W[:, b] > 0)
            w, u = W[idx, b], rest[idx]
            own = np.einsum("fij,vj->fvi", T[:, b, :, :3], u) + T[:, b, None, :, 3]
            tgt = (frames[:, idx] - (P[:, idx] - w[None, :, None] * own)) / w[None, :, None]
            c = w ** 2
            mu_u = (c[:, None] * u).sum(0) / c.sum()
            mu_t = np.einsum("v,fvi->fi", c, tgt) / c.sum()
            H = np.einsum("v,vi,fvj->fij", c, u - mu_u, tgt - mu_t[:, None, :])
            U, _, Vt = np.linalg.svd(H)
            d = np.sign(np.linalg.det(np.swapaxes(Vt, 1, 2) @ np.swapaxes(U, 1, 2)))
            Dm = np.tile(np.eye(3), (len(H), 1, 1))
            Dm[:, 2, 2] = d
            R = np.swapaxes(Vt, 1, 2) @ Dm @ np.swapaxes(U, 1, 2)
            t = mu_t - np.einsum("fij,j->fi", R, mu_u)
            P[:, idx] += w[None, :, None] * (np.einsum("fij,vj->fvi", R, u) + t[:, None, :] - own)
            T[:, b, :, :3], T[:, b, :, 3] = R, t
    return T


def test_held_out_solve_matches_the_sweeps_written_frame_major():
    rest, _, W, T, V = skinned_tube(frames=10)
    rng = np.random.default_rng(2)
    Vd = V[1:] + rng.normal(0, 0.01, V[1:].shape)  # not exact LBS: the sweeps have work to do
    start = D.affine_transforms(W, rest, Vd)
    start[..., :3] = D._nearest_rotation(start[..., :3])
    np.testing.assert_allclose(D.solve_transforms(W, rest, Vd, sweeps=4, init=start),
                               _solve_reference(W, rest, Vd, 4, start), rtol=0, atol=1e-12)
    # the default start is that projected affine solve
    np.testing.assert_array_equal(D.solve_transforms(W, rest, Vd, sweeps=4),
                                  D.solve_transforms(W, rest, Vd, sweeps=4, init=start))
