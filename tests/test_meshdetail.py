"""meshdetail: LBS, FK, pose fitting, GP gradients, detail coding, the hybrid model."""
import numpy as np
import pytest
from scipy import sparse
from scipy.spatial.transform import Rotation

from animsynth.kinematics import forward_kinematics
from animsynth.meshdetail.detail import LaplacianCoder, farthest_point_order, level_indices
from animsynth.meshdetail.fit import PoseFitter, refine_joints_from_motion
from animsynth.meshdetail.gp import GPRegression, SharedGPDM
from animsynth.meshdetail.models import HybridModel, MeshContext, mean_vertex_error, pose_features
from animsynth.skinning import (Rig, default_rig, forward, pose_vertices, rebase,
                                      rebase_pose, skinning_weights)


def blob_mesh(rig, per=12, n=6, sd=0.03, seed=0):
    rng = np.random.default_rng(seed)
    pts = []
    for j in range(rig.n_joints):
        for u in np.linspace(0, 1, per):
            pts.append(rig.starts[j] + u * (rig.ends[j] - rig.starts[j]) + rng.normal(0, sd, (n, 3)))
    return np.concatenate(pts)


# ----------------------------------------------------------------------------- LBS / FK
def test_lbs_two_bone_toy():
    """Two bones along +x; bend the second 90 degrees about z at x=1."""
    starts = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    ends = np.array([[1.0, 0, 0], [2.0, 0, 0]])
    rig = Rig(starts, ends, names=("a", "b"), parents=(-1, 0))
    rest = np.array([[0.5, 0, 0], [2.0, 0, 0], [1.0, 0.1, 0], [1.5, 0, 0]])
    w = np.array([[1, 0], [0, 1], [0.5, 0.5], [0, 1]], float)
    angles = np.zeros((1, 2, 3))
    angles[0, 1, 2] = np.pi / 2
    out = pose_vertices(rig, sparse.csr_matrix(w), rest, np.zeros((1, 3)), angles)[0]
    np.testing.assert_allclose(out[0], [0.5, 0, 0], atol=1e-12)  # first bone: unchanged
    np.testing.assert_allclose(out[1], [1.0, 1.0, 0], atol=1e-12)  # tip rotated about the joint
    np.testing.assert_allclose(out[3], [1.0, 0.5, 0], atol=1e-12)
    # blended vertex at the joint: average of (1, .1, 0) and its rotation (0.9, 0, 0)
    np.testing.assert_allclose(out[2], [0.95, 0.05, 0], atol=1e-12)
    # root translation moves everything
    out2 = pose_vertices(rig, sparse.csr_matrix(w), rest, np.array([[1.0, 2.0, 3.0]]), angles)[0]
    np.testing.assert_allclose(out2 - out, np.tile([1.0, 2.0, 3.0], (4, 1)), atol=1e-12)


def test_forward_matches_generic_skeleton_fk():
    rig = default_rig()
    rng = np.random.default_rng(1)
    ang = rng.normal(0, 0.4, (5, 18, 3))
    rt = rng.normal(0, 0.3, (5, 3))
    W, S = forward(rig, rt, ang)
    sk = rig.to_skeleton()
    pos = forward_kinematics(sk, rig.motion_values(rt, ang), ends=False)
    np.testing.assert_allclose(S, pos, atol=1e-12)
    ends = forward_kinematics(sk, rig.motion_values(rt, ang), ends=True)
    np.testing.assert_allclose(S + np.einsum("fjab,jb->fja", W, rig.ends - rig.starts), ends, atol=1e-12)


def test_skinning_weights_rows_and_rigid_near_bone():
    rig = default_rig()
    rest = blob_mesh(rig, sd=0.01)
    w = skinning_weights(rest, rig, max_influences=4)
    dense = w.toarray()
    np.testing.assert_allclose(dense.sum(axis=1), 1.0)
    assert (dense > 0).sum(axis=1).max() <= 4
    mid = rig.starts[13] + 0.5 * (rig.ends[13] - rig.starts[13])  # middle of the left shin
    k = np.argmin(np.linalg.norm(rest - mid, axis=1))
    assert dense[k, 13] > 0.95


def test_rebase_keeps_world_motion():
    rig = default_rig()
    rng = np.random.default_rng(2)
    ang = rng.normal(0, 0.3, (6, 18, 3))
    rt = rng.normal(0, 0.2, (6, 3)) + rig.starts[0]
    rig0 = rebase(rig, rt[0], ang[0])
    ang0 = rebase_pose(rig, rt, ang, ang[0])
    np.testing.assert_allclose(ang0[0], 0.0, atol=1e-9)
    _, S = forward(rig, rt, ang)
    _, S0 = forward(rig0, rt, ang0)
    np.testing.assert_allclose(S0, S, atol=1e-9)


# ----------------------------------------------------------------------------- pose fitting
def test_pose_fit_recovers_known_angles():
    rig = default_rig()
    rest = blob_mesh(rig)
    w = skinning_weights(rest, rig)
    rng = np.random.default_rng(3)
    ang = rng.normal(0, 0.35, (8, 18, 3))
    rt = rng.normal(0, 0.2, (8, 3)) + rig.starts[0]
    P = pose_vertices(rig, w, rest, rt, ang)
    fit = PoseFitter(iterations=15).fit(rig, w, rest, P)
    a = Rotation.from_euler("xyz", fit.angles_.reshape(-1, 3))
    b = Rotation.from_euler("xyz", ang.reshape(-1, 3))
    assert np.rad2deg((a.inv() * b).magnitude()).max() < 1e-4
    np.testing.assert_allclose(fit.root_t_, rt, atol=1e-7)
    assert fit.residual_.max() < 1e-7


def test_pose_fit_is_robust_to_loose_cloth():
    """Vertices displaced by 'cloth' (a tenth of them, 5-10 cm) barely move the fitted angles."""
    rig = default_rig()
    rest = blob_mesh(rig)
    w = skinning_weights(rest, rig)
    rng = np.random.default_rng(4)
    ang = rng.normal(0, 0.25, (4, 18, 3))
    rt = np.tile(rig.starts[0], (4, 1))
    P = pose_vertices(rig, w, rest, rt, ang)
    cloth = rng.random(len(rest)) < 0.1
    P[:, cloth] += rng.uniform(0.05, 0.1, (4, cloth.sum(), 1)) * rng.normal(size=(4, cloth.sum(), 3))
    fit = PoseFitter().fit(rig, w, rest, P)
    err = np.rad2deg((Rotation.from_euler("xyz", fit.angles_.reshape(-1, 3)).inv()
                      * Rotation.from_euler("xyz", ang.reshape(-1, 3))).magnitude())
    assert np.median(err) < 1.0


def test_refine_joints_moves_a_misplaced_elbow_back():
    rig = default_rig()
    rest = blob_mesh(rig, per=16, n=8, sd=0.02)
    w = skinning_weights(rest, rig)
    rng = np.random.default_rng(5)
    ang = rng.normal(0, 0.5, (25, 18, 3))
    P = pose_vertices(rig, w, rest, np.tile(rig.starts[0], (25, 1)), ang)
    bad = Rig(rig.starts.copy(), rig.ends.copy())
    bad.starts[7] += [0.04, 0.03, 0.0]  # left elbow misplaced by 5 cm
    fixed = refine_joints_from_motion(bad, w, rest, P)
    assert np.linalg.norm(fixed.starts[7] - rig.starts[7]) < 0.01


# ----------------------------------------------------------------------------- GP gradients
def _numgrad(f, th, eps=1e-6):
    g = np.zeros_like(th)
    for i in range(len(th)):
        e = np.zeros_like(th)
        e[i] = eps
        g[i] = (f(th + e) - f(th - e)) / (2 * eps)
    return g


def test_shared_gpdm_gradient_matches_finite_differences():
    rng = np.random.default_rng(6)
    t = np.linspace(0, 4, 15)
    Y1 = np.c_[np.sin(t), np.cos(2 * t), 0.3 * t] + 0.01 * rng.normal(size=(15, 3))
    Y2 = np.c_[np.sin(t) ** 2, np.cos(t)] @ rng.normal(size=(2, 7))
    m = SharedGPDM(latent_dim=3, iterations=3).fit([Y1, Y2])
    m._YYt = [n.transform(Y) @ n.transform(Y).T for n, Y in zip(m.norm_, [Y1, Y2])]
    m._D = [3, 7]
    th = np.concatenate([m.X_.ravel() + 0.2 * rng.normal(size=m.X_.size), np.log([0.8, 1.3, 0.05]),
                         np.log([1.1, 0.6, 0.02]), np.log([0.9, 1.2, 0.2, 0.03])])
    f, g = m.objective(th)
    gn = _numgrad(lambda x: m.objective(x)[0], th)
    np.testing.assert_allclose(g, gn, rtol=1e-4, atol=1e-4 * np.abs(gn).max())


def test_gp_regression_gradient_and_fit():
    rng = np.random.default_rng(7)
    X = rng.normal(size=(30, 2))
    Y = np.c_[np.sin(X[:, 0]), X[:, 1] ** 2]
    r = GPRegression(iterations=50)
    YYt = Y @ Y.T
    h = np.log([1.3, 0.7, 0.05])
    f, g = r.objective(h, X, YYt, 2)
    gn = _numgrad(lambda x: r.objective(x, X, YYt, 2)[0], h)
    np.testing.assert_allclose(g, gn, rtol=1e-5)
    r.fit(X, Y)
    assert np.abs(r.predict(X) - Y).max() < 0.05


# ----------------------------------------------------------------------------- detail coding
def test_farthest_point_levels_are_nested_subsets():
    from animsynth.synth.character import build_character

    ch = build_character(default_rig(), resolution=0.5, skirt_rings=6, skirt_around=16)
    order = farthest_point_order(ch.rest, 200)
    ctrl = level_indices(order, len(ch.rest), 10)
    assert len(np.unique(ctrl)) == len(ctrl) == round(0.1 * len(ch.rest))
    assert set(level_indices(order, len(ch.rest), 5)) <= set(ctrl)


def test_laplacian_coder_knn_roundtrip():
    rng = np.random.default_rng(9)
    pts = np.concatenate([rng.normal(size=(40, 3)), rng.normal(size=(30, 3)) + 20])  # two components
    c = LaplacianCoder(pts, k=5)
    assert c.n_extra == 2
    d = rng.normal(size=(3, 70, 3))
    np.testing.assert_allclose(c.decode(c.encode(d)), d, atol=1e-8)


def test_pose_features_shapes_and_previous_frame():
    ang = np.random.default_rng(10).normal(0, 0.3, (5, 18, 3))
    for p, k in (("euler", 51), ("expmap", 51), ("quaternion", 68)):
        f = pose_features(ang, p)
        assert f.shape == (5, 2 * k)
        np.testing.assert_allclose(f[1:, k:], f[:-1, :k])
    with pytest.raises(ValueError, match="joint parameterisation"):
        pose_features(ang, "matrix")


# ----------------------------------------------------------------------------- hybrid model
@pytest.fixture(scope="module")
def skirt_data():
    from animsynth.synth.character import SkirtParams, build_character, procedural_motion, simulate

    rig = default_rig()
    ch = build_character(rig, resolution=0.6, skirt_rings=10, skirt_around=28)
    rt, A = procedural_motion("dance", 70, 30.0, 3, rig)
    V = simulate(ch, rt, A, 30.0, SkirtParams(substeps=4))
    return rig, ch, rt, A, V


def test_skirt_depends_on_motion_history(skirt_data):
    """Same pose, different history -> different skirt (second-order dynamics)."""
    from animsynth.synth.character import SkirtParams, simulate

    rig, ch, rt, A, V = skirt_data
    held = simulate(ch, np.repeat(rt[40:41], 5, 0), np.repeat(A[40:41], 5, 0), 30.0, SkirtParams(substeps=4))
    sk = ch.skirt.ravel()
    body = np.setdiff1d(np.arange(len(ch.rest)), sk)
    np.testing.assert_allclose(held[0, body], V[40, body], atol=1e-9)
    assert np.linalg.norm(held[0, sk] - V[40, sk], axis=1).mean() > 0.005


def test_hybrid_beats_lbs_on_training_frames(skirt_data):
    rig, ch, rt, A, V = skirt_data
    ctx = MeshContext(ch.rest, ch.faces, rig, ch.weights)
    tr = np.arange(60)
    lbs_m = HybridModel(level=10, regressor="none").fit(ctx, V[tr], rt[tr], A[tr])
    hyb = HybridModel(level=10, regressor="gp", iterations=60).fit(ctx, V[tr], rt[tr], A[tr])
    e_lbs = mean_vertex_error(lbs_m.predict(ctx, rt[tr], A[tr]), V[tr])
    e_hyb = mean_vertex_error(hyb.predict(ctx, rt[tr], A[tr]), V[tr])
    assert e_hyb.mean() < 0.5 * e_lbs.mean()
    assert np.mean(e_hyb < e_lbs) > 0.9
    assert hyb.gp_.X_.shape == (60, 4)
    for reg in ("gp_regression", "ridge_cv"):  # the baselines learn the detail too
        m = HybridModel(level=10, regressor=reg).fit(ctx, V[tr], rt[tr], A[tr])
        assert mean_vertex_error(m.predict(ctx, rt[tr], A[tr]), V[tr]).mean() < 0.5 * e_lbs.mean()
    assert m.ridge_.alpha_ in m.ridge_alphas


def test_single_frame_prediction_matches_batch(skirt_data):
    rig, ch, rt, A, V = skirt_data
    ctx = MeshContext(ch.rest, ch.faces, rig, ch.weights)
    m = HybridModel(level=10, regressor="gp", iterations=20).fit(ctx, V[:50], rt[:50], A[:50])
    batch = m.predict(ctx, rt[:12], A[:12])
    one = m.predict(ctx, rt[11:12], A[11:12], prev_angles=A[10:11])
    np.testing.assert_allclose(one[0], batch[11], atol=1e-10)


def test_verdict_is_undecided_when_blocks_disagree():
    import pandas as pd

    from animsynth.meshdetail.verdicts import block_margin, block_verdict

    block = np.repeat(np.arange(5), 4)
    clear = pd.DataFrame({"block": block, "a": 1.0, "b": 2.0 + 0.01 * block})
    m, sd, share, k = block_margin(clear, "a", "b")
    assert k == 5 and share == 1.0 and block_verdict(m, sd, share, k) == "reproduced"
    mixed = pd.DataFrame({"block": block, "a": 1.0, "b": np.where(block == 2, 0.5, 1.1)})
    m, sd, share, k = block_margin(mixed, "a", "b")
    assert m < 0.1 and share == 0.8 and block_verdict(m, sd, share, k) == "undecided"   # margin within its spread
    worse = pd.DataFrame({"block": block, "a": 3.0, "b": 1.0})
    assert block_verdict(*block_margin(worse, "a", "b")) == "contradicted"
