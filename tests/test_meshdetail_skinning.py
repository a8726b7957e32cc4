"""Skinning core: bone heat, weight refit, inside test, joint placement; control meshes and RBF reconstruction."""
import numpy as np
from scipy import sparse

from animsynth.meshdetail.detail import ControlMesh, LaplacianCoder, RBFUpsampler
from animsynth.meshdetail.fit import PoseFitter, place_joints
from animsynth.skinning import (Rig, bone_heat_weights, inside_mesh, joint_transforms, lbs, refit_weights,
                                winding_number, forward)


def closed_cylinder(length=2.0, radius=0.2, rings=41, around=24):
    """A closed, outward-oriented tube along +x from 0 to ``length`` with fan caps."""
    t = np.linspace(0, length, rings)
    a = np.linspace(0, 2 * np.pi, around, endpoint=False)
    V = np.stack([np.repeat(t, around), radius * np.tile(np.cos(a), rings), radius * np.tile(np.sin(a), rings)], 1)
    F = []
    for r in range(rings - 1):
        for k in range(around):
            i0, i1 = r * around + k, r * around + (k + 1) % around
            j0, j1 = i0 + around, i1 + around
            F += [[i0, i1, j1], [i0, j1, j0]]
    c0, c1 = len(V), len(V) + 1
    V = np.vstack([V, [[0, 0, 0], [length, 0, 0]]])
    last = (rings - 1) * around
    for k in range(around):
        F.append([c0, (k + 1) % around, k])
        F.append([c1, last + k, last + (k + 1) % around])
    F = np.array(F)
    # orient outward (winding number of an interior point must be +1)
    if winding_number(np.array([[length / 2, 0, 0]]), V, F)[0] < 0:
        F = F[:, ::-1]
    return V, F


def two_bone_rig(length=2.0):
    return Rig(np.array([[0.0, 0, 0], [length / 2, 0, 0]]), np.array([[length / 2, 0, 0], [length, 0, 0]]),
               names=("a", "b"), parents=(-1, 0))


def test_winding_number_inside_outside():
    V, F = closed_cylinder()
    w = winding_number(np.array([[1.0, 0, 0], [1.0, 0.1, 0.05], [1.0, 0.5, 0], [-0.3, 0, 0], [2.5, 0, 0]]), V, F)
    np.testing.assert_allclose(w, [1, 1, 0, 0, 0], atol=1e-6)
    assert inside_mesh(np.array([[0.3, 0, 0.1]]), V, F)[0] and not inside_mesh(np.array([[0.3, 0.3, 0]]), V, F)[0]


def test_bone_heat_weights_nonnegative_sum_to_one_and_smooth():
    V, F = closed_cylinder()
    rig = two_bone_rig()
    W = bone_heat_weights(V, F, rig).toarray()
    assert W.min() >= 0.0
    np.testing.assert_allclose(W.sum(axis=1), 1.0, atol=1e-12)
    # far from the joint each bone owns its half; across the joint the weight changes gradually
    x = V[:, 0]
    assert W[x < 0.6, 0].min() > 0.9 and W[x > 1.4, 1].min() > 0.9
    ring = np.round(x[:-2], 6)
    per_ring = np.array([W[:-2][ring == r, 1].mean() for r in np.unique(ring)])
    assert np.all(np.diff(per_ring) >= -1e-9), "weight of the second bone must grow along the tube"
    assert np.max(np.diff(per_ring)) < 0.25, "no jump: the weight blends over several rings around the joint"
    # smooth: across every mesh edge the weight changes little
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    assert np.abs(W[e[:, 0], 1] - W[e[:, 1], 1]).max() < 0.25


def test_refit_weights_recovers_true_weights_from_posed_frames():
    V, F = closed_cylinder(rings=21, around=12)
    rig = two_bone_rig()
    rng = np.random.default_rng(0)
    truth = np.clip((V[:, 0] - 0.7) / 0.6, 0, 1)  # linear blend over 0.7..1.3
    Wt = sparse.csr_matrix(np.stack([1 - truth, truth], 1))
    ang = rng.normal(0, 0.5, (12, 2, 3))
    Wr, S = forward(rig, np.zeros((12, 3)), ang)
    T = joint_transforms(rig, Wr, S)
    frames = lbs(Wt, V, T)
    start = sparse.csr_matrix(np.full((len(V), 2), 0.5))
    W = refit_weights(start, V, T, frames, parents=rig.parents).toarray()
    assert W.min() >= 0 and np.allclose(W.sum(axis=1), 1.0)
    np.testing.assert_allclose(W[:, 1], truth, atol=1e-4)


def test_place_joints_moves_an_outside_joint_inside():
    V, F = closed_cylinder()
    rig = Rig(np.array([[0.0, 0, 0], [1.0, 0.25, 0]]), np.array([[1.0, 0.25, 0], [2.0, 0, 0]]),
              names=("a", "b"), parents=(-1, 0))  # the joint sits 5 cm outside the tube
    assert not inside_mesh(rig.starts[1:], V, F)[0]
    w = sparse.csr_matrix(np.stack([V[:, 0] < 1, V[:, 0] >= 1], 1).astype(float))
    placed, table = place_joints(rig, w, V, F, V[None])  # one frame: the motion says nothing
    assert bool(table["inside"].all()) and inside_mesh(placed.starts, V, F).all()
    assert np.linalg.norm(placed.starts[1] - rig.starts[1]) < 0.1
    np.testing.assert_allclose(placed.ends[0], placed.starts[1])  # the parent segment follows
    assert "interior" in table["placement"].iloc[1]


def test_collapse_replay_on_rigidly_moved_mesh_equals_moved_decimated_mesh():
    V, F = closed_cylinder()
    # a generic (bumpy) surface: on flat or cylindrical patches the optimal collapse point is not unique
    V = V * (1 + 0.05 * np.random.default_rng(3).uniform(-1, 1, (len(V), 1)))
    cm = ControlMesh(V, F, 10, "collapse")
    assert cm.n_control < 0.2 * len(V) and cm.faces_ is not None
    R = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])
    moved = V @ R.T + [0.3, -1.0, 2.0]
    import fast_simplification

    dec, dec_faces = fast_simplification.simplify(V, F, target_count=int(round(0.2 * len(V))))
    got = cm.replay(np.stack([V, moved]), F)  # the recorded collapses replayed on both frames
    np.testing.assert_allclose(got[0], dec, atol=1e-5)
    np.testing.assert_allclose(got[1], dec @ R.T + [0.3, -1.0, 2.0], atol=1e-5)
    np.testing.assert_array_equal(cm.faces_, dec_faces)
    # the control positions used for the detail (centroids of the collapsed vertices) move rigidly too
    pos = cm.positions(np.stack([V, moved]), F)
    np.testing.assert_allclose(pos[1], pos[0] @ R.T + [0.3, -1.0, 2.0], atol=1e-12)
    assert len(np.unique(cm.mapping_)) == cm.n_control


def test_laplacian_coordinates_round_trip_on_closed_mesh():
    V, F = closed_cylinder(rings=15, around=10)
    c = LaplacianCoder(V, F)
    assert c.n_extra == 1
    d = np.random.default_rng(1).normal(size=(3, len(V), 3))
    np.testing.assert_allclose(c.decode(c.encode(d)), d, atol=1e-8)
    # the code of a smooth field is small away from the component mean: it is a differential code
    smooth = np.repeat(V[None] * 0.01, 1, axis=0)
    assert np.abs(c.encode(smooth)[0, :len(V)]).mean() < np.abs(smooth).mean()


def test_rbf_upsampler_matches_scipy_rbfinterpolator():
    from scipy.interpolate import RBFInterpolator

    rng = np.random.default_rng(2)
    ctrl = rng.uniform(-1, 1, (80, 3))
    fine = rng.uniform(-1, 1, (200, 3))
    vals = rng.normal(size=(80, 3))
    up = RBFUpsampler(ctrl, fine, neighbors=16)
    ref = RBFInterpolator(ctrl, vals, neighbors=16, kernel="thin_plate_spline", degree=1)(fine)
    np.testing.assert_allclose(up(vals), ref, atol=1e-8)
    np.testing.assert_allclose(RBFUpsampler(ctrl, ctrl, 16)(vals), vals, atol=1e-8)  # interpolates
    lin = ctrl @ [1.0, -2.0, 0.5] + 3
    np.testing.assert_allclose(up(lin[:, None])[:, 0], fine @ [1.0, -2.0, 0.5] + 3, atol=1e-8)  # exact on linear


def test_pose_fit_with_heat_weights_on_bent_cylinder():
    V, F = closed_cylinder()
    rig = two_bone_rig()
    W = bone_heat_weights(V, F, rig)
    ang = np.zeros((3, 2, 3))
    ang[:, 1, 2] = [0.2, 0.5, 0.9]
    P = lbs(W, V, joint_transforms(rig, *forward(rig, np.zeros((3, 3)), ang)))
    fit = PoseFitter(iterations=10).fit(rig, W, V, P)
    assert fit.residual_.max() < 1e-6


def test_rbf_upsampler_on_coplanar_control_points_interpolates():
    """A flat patch (all control points in z = 0) makes the local systems singular; it must still interpolate."""
    rng = np.random.default_rng(4)
    ctrl = np.c_[rng.uniform(-1, 1, (60, 2)), np.zeros(60)]
    vals = rng.normal(size=(60, 2))
    up = RBFUpsampler(ctrl, ctrl, neighbors=12)
    np.testing.assert_allclose(up(vals), vals, atol=1e-6)
    lin = ctrl[:, :2] @ [1.0, -2.0] + 0.5
    fine = np.c_[rng.uniform(-0.5, 0.5, (30, 2)), np.zeros(30)]
    np.testing.assert_allclose(RBFUpsampler(ctrl, fine, 12)(lin[:, None])[:, 0], fine[:, :2] @ [1.0, -2.0] + 0.5,
                               atol=1e-6)


def _hits_brute_force(origins, targets, origin_ids, V, F, eps=1e-6):
    """Möller-Trumbore of every segment against every triangle not incident to its origin vertex."""
    out = np.zeros(len(origins), bool)
    v0, e1, e2 = V[F[:, 0]], V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]
    for i, (o, t) in enumerate(zip(origins, targets)):
        d = t - o
        pv = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, pv)
        ok = (np.abs(det) > 1e-15) & ~np.any(F == origin_ids[i], axis=1)
        det = np.where(ok, det, 1.0)
        tv = o - v0
        u = np.einsum("ij,ij->i", tv, pv) / det
        qv = np.cross(tv, e1)
        v = (qv @ d) / det
        s = np.einsum("ij,ij->i", e2, qv) / det
        out[i] = np.any(ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (s > eps) & (s < 1 - eps))
    return out


def test_visibility_search_near_each_segment_finds_every_crossing_that_testing_all_triangles_finds():
    from animsynth.skinning import _segments_hit_mesh

    V, F = closed_cylinder(length=2.0, radius=0.5, rings=81, around=24)  # cap triangles ~4x the side's
    rng = np.random.default_rng(5)
    ids = rng.choice(len(V), 60)
    targets = rng.uniform([-0.5, -0.6, -0.6], [2.5, 0.6, 0.6], (60, 3))  # inside, outside, through the caps
    got = _segments_hit_mesh(V[ids], targets, ids, V, F)
    want = _hits_brute_force(V[ids], targets, ids, V, F)
    assert want.any() and not want.all()
    np.testing.assert_array_equal(got, want)


def test_folds_sharing_a_cache_get_the_skeleton_they_get_alone():
    from animsynth.meshdetail.rigfit import fit_skeleton

    V, F = closed_cylinder()
    rig = Rig(np.array([[0.0, 0, 0], [1.0, 0.25, 0]]), np.array([[1.0, 0.25, 0], [2.0, 0, 0]]),
              names=("a", "b"), parents=(-1, 0))  # the joint sits outside: the interior search runs
    frames = np.stack([V + [0.01 * f, 0, 0] for f in range(12)])
    cache = {}
    for train in (np.arange(3, 12), np.arange(0, 9)):
        alone = fit_skeleton(frames, F, rig, train, refine=True, iterations=2)
        shared = fit_skeleton(frames, F, rig, train, refine=True, iterations=2, cache=cache)
        np.testing.assert_array_equal(alone[0].starts, shared[0].starts)
        assert (alone[1] != shared[1]).nnz == 0
        np.testing.assert_array_equal(alone[2].angles_, shared[2].angles_)
    assert "initial_weights" in cache and ("nearest_interior", 1) in cache
