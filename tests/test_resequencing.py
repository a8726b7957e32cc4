"""Unit tests of the re-sequencing library (Isomap / ST-Isomap)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial.distance import cdist
from scipy.spatial.transform import Rotation
from sklearn.manifold import Isomap
from sklearn.neighbors import kneighbors_graph

from animsynth.kinematics import qlog
from animsynth.motion import Motion
from animsynth.resequencing.distances import (PAPER_WEIGHTS, check_distance_matrix, joint_weights, l2_distances,
                                              lee_distances, lee_metric)
from animsynth.resequencing.embedding import (DisconnectedGraphError, PrecomputedIsomap, STIsomap, graph_components,
                                              knn_graph, min_connected_k, neighbor_ranks, nontrivial_neighbors,
                                              residual_variance, spatio_temporal_distances)
from animsynth.resequencing.features import (angular_velocity, linearize_quaternions, matrix_naive_quaternions,
                                             motion_features, relative_log, sign_flips)
from animsynth.resequencing.metrics import (Reference, TransitionReference, classify_path, foot_skate, pass_jumps,
                                            jerk_magnitude, pose_steps, root_reversals, smoothness,
                                            transition_measures, transitions)
from animsynth.generator import play_path
from animsynth.resequencing.paths import pad_path, resolve_frame, shortest_path_frames
from animsynth.resequencing.jobs import analyse, explain, path_pairs, prepare_motion, resequence, splice, summarise_paths
from animsynth.resequencing.tables import min_k_table, published_table2
from animsynth.resequencing.verdicts import (explanation_verdicts, global_dof_verdict, lee_vs_l2_verdict,
                                             st_smoother_verdict)
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion
from conftest import config_block


def full_cfg(overrides=None):
    """The resequencing block at full size (config.yaml with cmu.yaml's sizes; schema defaults filled in)."""
    return config_block("resequencing", overrides, ("config.yaml", "cmu.yaml"))


def rot(axis, deg):
    return Rotation.from_euler(axis, np.reshape(np.asarray(deg, float), (-1, 1)), degrees=True).as_quat()


@pytest.fixture(scope="module")
def walk():
    return generate_motion("walk_straight", 240, 5, cmu_like_skeleton("t35", 1))


# --------------------------------------------------------------- linearisation
def test_relative_log_is_half_angle_the_shorter_way():
    q, one = rot("x", 90.0)[0], np.array([0.0, 0.0, 0.0, 1.0])
    np.testing.assert_allclose(relative_log(one, q), [np.pi / 4, 0, 0], atol=1e-12)
    np.testing.assert_allclose(relative_log(one, -q), [np.pi / 4, 0, 0], atol=1e-12)  # double cover
    np.testing.assert_allclose(relative_log(q, one), [-np.pi / 4, 0, 0], atol=1e-12)


def test_constant_velocity_rotation_linearises_to_a_straight_line():
    axis = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])
    w = 0.13  # rad per frame, total 60 frames -> several full turns of the log range
    rv = np.arange(60)[:, None] * w * axis[None, :]
    q = Rotation.from_rotvec(rv).as_quat()
    q[1::2] *= -1  # sign flips must not matter
    v = linearize_quaternions(q)
    np.testing.assert_allclose(v[0], 0.0)
    # every frame lies on the line through 0 along the axis, equally spaced by w/2
    np.testing.assert_allclose(v, np.arange(60)[:, None] * (w / 2) * axis[None, :], atol=1e-10)
    # plain quaternion logs wrap around (not a line): the linearisation is needed
    assert np.abs(0.5 * qlog(q) - v).max() > 1.0


def test_linearisation_per_joint_shapes():
    q = np.stack([rot("x", np.arange(5) * 10.0), rot("y", np.arange(5) * 5.0)], axis=1)
    v = linearize_quaternions(q)
    assert v.shape == (5, 2, 3)
    np.testing.assert_allclose(v[:, 0, 0], np.deg2rad(np.arange(5) * 10.0) / 2, atol=1e-12)
    np.testing.assert_allclose(v[:, 1, 1], np.deg2rad(np.arange(5) * 5.0) / 2, atol=1e-12)


def test_motion_features_global_columns(walk):
    f = motion_features(walk)
    assert len(f.joint_names) == 28 and "root" not in f.joint_names
    assert f.linearised(False).shape == (240, 84)
    X = f.linearised(True)
    assert X.shape == (240, 90)
    np.testing.assert_allclose(X[:, -3:], f.root_pos)  # root position in metres, last
    D = l2_distances(X)
    np.testing.assert_allclose(D, cdist(X, X), atol=1e-12)
    check_distance_matrix(D)
    X[3, 2] = np.nan
    with pytest.raises(ValueError, match="frame 3"):
        l2_distances(X)


# ------------------------------------------------------------------ Lee metric
def test_lee_metric_on_hand_made_poses():
    # frame 0: identity; frame 1: joint 0 turned 90 deg about x, joint 1 60 deg about y, joint 2 anything
    q = np.zeros((2, 3, 4))
    q[:, :, 3] = 1.0
    q[1, 0] = rot("x", 90.0)[0]
    q[1, 1] = rot("y", 60.0)[0]
    q[1, 2] = rot("z", 170.0)[0]
    w = np.array([1.0, 0.5, 0.0])
    D = lee_metric(q, w, fps=1.0, nu=0.0)
    expected = 1.0 * (np.pi / 4) ** 2 + 0.5 * (np.pi / 6) ** 2
    np.testing.assert_allclose(D, [[0, expected], [expected, 0]], atol=1e-9)
    # the root term (global DOF included): + |dp|^2
    p = np.array([[0.0, 1.0, 0.0], [3.0, 1.0, 4.0]])
    Dg = lee_metric(q, w, fps=1.0, nu=0.0, root_pos=p)
    np.testing.assert_allclose(Dg[0, 1], expected + 25.0, atol=1e-9)
    np.testing.assert_allclose(lee_metric(q, w, 1.0, 0.0, sqrt=True)[0, 1], np.sqrt(expected), atol=1e-9)


def test_lee_metric_velocity_term():
    # one weighted joint turning about x by 0, a, 3a degrees: half-angle velocities (rad/s) at fps 10 are
    # forward a/2*fps, central (3a/2)/2*fps, backward (2a/2)*fps
    a, fps, nu = np.deg2rad(6.0), 10.0, 0.3
    q = Rotation.from_euler("x", [[0.0], [a], [3 * a]]).as_quat()[:, None, :]
    D = lee_metric(q, np.array([1.0]), fps=fps, nu=nu)
    om = np.array([a / 2 * fps, 3 * a / 4 * fps, a * fps])
    ang = np.array([0.0, a, 3 * a]) / 2
    for i in range(3):
        for j in range(3):
            assert D[i, j] == pytest.approx((ang[i] - ang[j]) ** 2 + nu * (om[i] - om[j]) ** 2, abs=1e-9)
    np.testing.assert_allclose(angular_velocity(q, fps)[:, 0, 0], om, atol=1e-9)


def test_lee_weights_and_global_term_on_a_cmu_motion(walk):
    f = motion_features(walk)
    w = joint_weights(f.joint_names, PAPER_WEIGHTS)
    assert w[f.joint_names.index("lfemur")] == 1.0 and w[f.joint_names.index("rradius")] == 0.0247
    assert np.count_nonzero(w) == 8
    with pytest.raises(ValueError, match="neither"):
        joint_weights(f.joint_names, {"ankles": 1.0})
    D0 = lee_distances(f, nu=0.01, include_global=False)
    D1 = lee_distances(f, nu=0.01, include_global=True)
    check_distance_matrix(D0)
    pv = np.gradient(f.root_pos, axis=0) * f.fps
    extra = cdist(f.root_pos, f.root_pos, "sqeuclidean") + 0.01 * cdist(pv, pv, "sqeuclidean")
    np.fill_diagonal(extra, 0.0)
    np.testing.assert_allclose(D1 - D0, extra, atol=1e-9)


# ------------------------------------------------------------------ min k
def brute_force_min_k(D):
    n = D.shape[0]
    for k in range(1, n):
        G = kneighbors_graph(D, k, metric="precomputed", mode="connectivity")
        if connected_components(G, directed=False)[0] == 1:
            return k
    raise AssertionError("never connected")


@pytest.mark.parametrize("seed", range(8))
def test_exact_min_k_matches_brute_force(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(12, 45))
    # clusters of different sizes and spreads make the minimum k non-trivial
    centres = rng.normal(scale=6.0, size=(int(rng.integers(1, 5)), int(rng.integers(2, 6))))
    X = centres[rng.integers(0, len(centres), n)] + rng.normal(scale=rng.uniform(0.2, 2.0), size=(n, centres.shape[1]))
    D = cdist(X, X)
    k = min_connected_k(D)
    assert k == brute_force_min_k(D)
    assert graph_components(D, k) == 1
    if k > 1:
        assert graph_components(D, k - 1) > 1
    # and on ST-adjusted matrices (treating the rows as a sequence)
    Dst, _, _ = spatio_temporal_distances(D, 1, 3.0, 2.0, ctn_neighbors=2, ctn_min_gap=3, ctn_reach=2)
    assert min_connected_k(Dst) == brute_force_min_k(Dst)


def test_knn_graph_matches_scikit_learn():
    rng = np.random.default_rng(3)
    X = rng.normal(size=(40, 3))
    D = cdist(X, X)
    for k in (1, 3, 7):
        ours = knn_graph(D, k).toarray() > 0
        sk = kneighbors_graph(D, k, metric="precomputed", mode="connectivity").toarray() > 0
        np.testing.assert_array_equal(ours, sk | sk.T)
    R = neighbor_ranks(D)
    assert (np.diag(R) == 0).all() and sorted(R[0]) == list(range(40))


@pytest.mark.filterwarnings("ignore::scipy.sparse.SparseEfficiencyWarning")
def test_isomap_refuses_disconnected_graphs_that_scikit_learn_joins():
    rng = np.random.default_rng(0)
    X = np.vstack([rng.normal(size=(15, 2)), rng.normal(size=(15, 2)) + 100.0])
    D = cdist(X, X)
    with pytest.raises(DisconnectedGraphError, match="smallest k giving one component is 15"):
        PrecomputedIsomap(n_neighbors=5, n_components=2).fit(D)
    with pytest.warns(UserWarning, match="connected components"):  # scikit-learn silently completes the graph
        Isomap(n_neighbors=5, n_components=2, metric="precomputed").fit(D)
    iso = PrecomputedIsomap(n_neighbors=None, n_components=2).fit(D)
    assert iso.n_neighbors_ == iso.min_k_ == 15


# ------------------------------------------------------------------ ST-Isomap
def loops_sequence(n_loops=3, per_loop=40, reverse_last=False):
    """A point circling n_loops times (radius drifts slightly); optionally a last loop backwards."""
    t = np.arange(n_loops * per_loop)
    phase = 2 * np.pi * (t % per_loop) / per_loop
    if reverse_last:
        last = t >= (n_loops - 1) * per_loop
        phase[last] = -phase[last]
    r = 1.0 + 0.01 * (t // per_loop)
    return np.stack([r * np.cos(phase), r * np.sin(phase), 0.002 * t], axis=1)


def test_st_isomap_neighbourhoods_on_repeated_loops():
    P = 40
    X = loops_sequence(3, P)
    D = cdist(X, X)
    Dst, temporal, ctn = spatio_temporal_distances(D, temporal_window=1, c_atn=5.0, c_ctn=4.0, ctn_neighbors=2,
                                                   ctn_min_gap=5, ctn_tolerance=1, ctn_reach=3)
    n = len(X)
    i, j = np.nonzero(temporal)
    assert set(np.abs(i - j)) == {1} and temporal.sum() == 2 * (n - 1)
    np.testing.assert_allclose(Dst[temporal], D[temporal] / 5.0)
    # common temporal neighbours are the same phase one or two loops away (within the tolerance)
    ci, cj = np.nonzero(ctn)
    assert ci.size > 0
    lag = np.abs(ci - cj)
    assert np.all(np.minimum(lag % P, P - lag % P) <= 1)
    np.testing.assert_allclose(Dst[ctn], D[ctn] / 4.0)
    # nearly every frame of the middle loop has a CTN in each neighbouring loop
    assert np.mean(ctn[P:2 * P].any(axis=1)) > 0.9
    untouched = ~(temporal | ctn)
    np.testing.assert_allclose(Dst[untouched], D[untouched])


def test_st_isomap_no_ctn_for_a_pass_in_the_opposite_direction():
    P = 40
    X = loops_sequence(3, P, reverse_last=True)
    D = cdist(X, X)
    _, _, ctn = spatio_temporal_distances(D, 1, 5.0, 4.0, ctn_neighbors=2, ctn_min_gap=5, ctn_tolerance=1,
                                          ctn_reach=3)
    last = np.arange(2 * P + 2, 3 * P - 2)  # the reversed loop, away from where the direction flips
    # it passes the same points as loops 1-2, but never in the same direction: no CTN with them
    assert not ctn[np.ix_(last, np.arange(2, 2 * P - 2))].any()
    assert ctn[:P, P:2 * P].any()


def test_nontrivial_neighbours_one_per_pass():
    X = loops_sequence(4, 30)
    D = cdist(X, X)
    M = nontrivial_neighbors(D, 3, min_gap=5)
    assert (M >= 0).all()
    for i, row in enumerate(M):
        assert np.all(np.abs(row - i) > 5)
        assert len({int(r) // 30 for r in row}) == 3  # each from a different loop


def test_st_isomap_registers_loops_that_isomap_keeps_apart():
    P = 40
    X = loops_sequence(3, P)
    X[:, 2] = 0.02 * np.arange(len(X))  # a helix: loops 0.8 apart, frames 0.16 apart
    D = cdist(X, X)
    iso = PrecomputedIsomap(6, 2).fit(D)
    st = STIsomap(6, 2, c_atn=2.0, c_ctn=50.0, ctn_neighbors=2, ctn_min_gap=15, ctn_tolerance=1, ctn_reach=20).fit(D)
    ci, cj = np.nonzero(st.ctn_)
    inner = (np.minimum(ci, cj) > 0) & (np.maximum(ci, cj) < len(X) - 1)  # the ends check one side only
    lag = np.abs(ci - cj)[inner]
    assert lag.size > 100 and np.all(np.abs(lag - P * np.round(lag / P)) <= 1)

    def same_phase_ratio(Y):
        Dy = cdist(Y, Y)
        idx = np.arange(len(X) - P)
        return Dy[idx, idx + P].mean() / Dy.mean()

    assert same_phase_ratio(st.embedding_) < 0.5 * same_phase_ratio(iso.embedding_)


# ------------------------------------------------------------ residual variance
def test_residual_variance_on_known_intrinsic_dimension():
    t = np.linspace(0, 3 * np.pi, 150)
    curve = np.stack([np.cos(t), np.sin(t), 0.3 * t], axis=1)  # helix: intrinsic dimension 1
    iso = PrecomputedIsomap(8, 4).fit(cdist(curve, curve))
    rv = residual_variance(iso.dist_matrix_, iso.embedding_)
    assert rv[0] < 0.01
    u, v = np.meshgrid(np.linspace(0, 3, 15), np.linspace(0, 1.5, 8))
    u, v = u.ravel(), v.ravel()
    sheet = np.stack([np.cos(u) * 3, np.sin(u) * 3, v * 2], axis=1)  # rolled-up sheet: dimension 2
    iso = PrecomputedIsomap(8, 4).fit(cdist(sheet, sheet))
    rv = residual_variance(iso.dist_matrix_, iso.embedding_)
    assert rv[0] > 0.05 and rv[1] < 0.01


def test_residual_variance_rejects_disconnected_geodesics():
    with pytest.raises(DisconnectedGraphError):
        residual_variance(np.array([[0, np.inf], [np.inf, 0]]), np.zeros((2, 1)))


# ------------------------------------------------------------------ paths
def test_dijkstra_path_on_a_hand_made_graph():
    # 0-1-2-3 chain (weight 1 each) and a shortcut 0-3 of weight 2.5 and 0-2 of 5
    rows, cols, w = [0, 1, 2, 0, 0], [1, 2, 3, 3, 2], [1.0, 1.0, 1.0, 2.5, 5.0]
    G = csr_matrix((w, (rows, cols)), shape=(5, 5))
    path, cost = shortest_path_frames(G, 0, 3)
    assert path.tolist() == [0, 3] and cost == 2.5
    path, cost = shortest_path_frames(G, 1, 3)  # undirected: 1-2-3 (2.0) beats 1-0-3 (3.5)
    assert path.tolist() == [1, 2, 3] and cost == 2.0
    path, cost = shortest_path_frames(G, 3, 1)
    assert path.tolist() == [3, 2, 1]
    with pytest.raises(DisconnectedGraphError):
        shortest_path_frames(G, 0, 4)


def test_dijkstra_on_a_chain_graph_follows_time():
    X = np.linspace(0, 1, 30)[:, None]
    G = knn_graph(cdist(X, X), 2)
    path, _ = shortest_path_frames(G, 3, 20)
    assert path.tolist() == list(range(3, 21))


def test_padding_and_frame_specs():
    p = np.array([4, 5, 9])
    assert pad_path(p, None).tolist() == [4, 5, 9]
    assert pad_path(p, 2).tolist() == [4, 5, 9]
    assert pad_path(p, 6).tolist() == [4, 5, 9, 9, 9, 9]
    assert pad_path(p, 8, "reverse").tolist() == [4, 5, 9, 5, 4, 5, 9, 5]
    assert resolve_frame(-1, 10) == 9 and resolve_frame(0.5, 11) == 5
    with pytest.raises(ValueError):
        resolve_frame(10, 10)
    assert splice([5, 9, 3], 12, 2).tolist() == [3, 4, 5, 9, 3, 4, 5]


def test_play_path_reproduces_the_original(walk):
    idx = np.arange(walk.n_frames)
    for mode in ("integrate", "absolute"):
        m = play_path(walk, idx, root=mode)
        from animsynth.kinematics import forward_kinematics

        np.testing.assert_allclose(forward_kinematics(walk.skeleton, m.values),
                                   forward_kinematics(walk.skeleton, walk.values), atol=1e-6)
    # a jump keeps the root continuous when integrating, teleports when absolute
    path = np.concatenate([np.arange(0, 50), np.arange(150, 200)])
    sk = walk.skeleton
    from animsynth.kinematics import root_translation

    ri = root_translation(sk, play_path(walk, path, "integrate").values) * sk.length_to_m
    ra = root_translation(sk, play_path(walk, path, "absolute").values) * sk.length_to_m
    step_i = np.linalg.norm(np.diff(ri[:, [0, 2]], axis=0), axis=1)
    step_a = np.linalg.norm(np.diff(ra[:, [0, 2]], axis=0), axis=1)
    assert step_i.max() < 0.05 and step_a[49] > 0.5


# ------------------------------------------------------------------ metrics
def test_pose_steps_and_jerk_of_a_constant_rotation():
    q = rot("x", np.arange(20) * 2.0)[:, None, :]
    np.testing.assert_allclose(pose_steps(q), np.deg2rad(2.0), atol=1e-12)
    np.testing.assert_allclose(jerk_magnitude(q, 100.0), 0.0, atol=1e-6)
    # a jump of 20 degrees at one frame gives jerk at the three frames around it
    ang = np.arange(20) * 2.0
    ang[10:] += 20.0
    q2 = rot("x", ang)[:, None, :]
    j = jerk_magnitude(q2, 10.0)
    assert np.count_nonzero(j > 1e-6) == 3
    assert j.max() == pytest.approx(2 * np.deg2rad(20.0) * 1000.0, rel=1e-6)


def _root_motion(xz, fps=10.0):
    """A CMU-like skeleton motion whose root follows ``xz`` (metres), facing +z."""
    sk = cmu_like_skeleton("t", 0)
    v = np.zeros((len(xz), sk.n_dof))
    v[:, 0] = xz[:, 0] / sk.length_to_m
    v[:, 2] = xz[:, 1] / sk.length_to_m
    return Motion(v, sk, fps, "root")


def test_root_reversals_count_direction_changes():
    fwd = np.stack([np.zeros(30), np.concatenate([np.arange(15), 14 - np.arange(15)]) * 0.1], axis=1)
    assert root_reversals(_root_motion(fwd), 0.1) == 1
    assert root_reversals(_root_motion(np.stack([np.zeros(30), np.arange(30) * 0.1], 1)), 0.1) == 0
    still = np.zeros((30, 2))
    assert root_reversals(_root_motion(still), 0.1) == 0


def test_foot_skate_zero_when_planted_and_speed_when_sliding():
    m = _root_motion(np.zeros((20, 2)))
    from animsynth.resequencing.metrics import foot_ground

    g = foot_ground(m)
    skate, frac = foot_skate(m, g, 0.02)
    assert skate == pytest.approx(0.0, abs=1e-9) and frac == 1.0
    slide = _root_motion(np.stack([np.arange(20) * 0.05, np.zeros(20)], axis=1), fps=10.0)  # 0.5 m/s sideways
    skate, _ = foot_skate(slide, g, 0.02)
    assert skate == pytest.approx(0.5, rel=1e-6)


def test_smoothness_of_the_original_path_is_one(walk):
    ref = Reference(walk)
    idx = np.arange(walk.n_frames)
    s = smoothness(ref, play_path(walk, idx), idx)
    assert s["jumps"] == 0 and s["jerk_events"] == 0
    for c in ("jump_mean_ratio", "jump_p95_ratio", "jump_max_ratio", "jerk_mean_ratio"):
        assert s[c] == pytest.approx(1.0, abs=1e-6)
    jump = np.concatenate([np.arange(0, 60), np.arange(130, 200)])
    s2 = smoothness(ref, play_path(walk, jump), jump)
    assert s2["jumps"] == 1 and s2["jump_max_ratio"] > 1.0 and s2["jerk_events"] >= 1


# ------------------------------------------------------------------ workflow steps (jobs)
def test_study_end_to_end_small(walk):
    cfg = full_cfg({"fixed_k_sweep": [6], "max_dim": 3, "path": {"random_pairs": 3}})
    m = prepare_motion(walk, 150, 2)
    assert m.n_frames == 75 and m.fps == walk.fps / 2
    mk, rv, emb, timing = analyse(m, "walk", "t35", False, cfg)
    assert len(mk) == 4 and (mk["components_at_min_k"] == 1).all()
    # the paper's k: every embedding at its configuration's exact min k; ST-Isomap's is 1
    assert (mk["k_used"] == mk["min_k"]).all()
    assert (mk.loc[mk["method"] == "stisomap", "min_k"] == 1).all()
    assert set(rv["dim"]) == {1, 2, 3} and set(rv["k_mode"]) == {"min_k", "fixed"}
    assert set(rv.loc[rv["k_mode"] == "fixed", "k"]) == {6}
    assert emb["isomap_l2_xy"].shape == (75, 2)
    paths, (main_path, main), per_path, per_tr = resequence(m, False, "isomap", "lee", int(mk["k_used"].iloc[2]),
                                                            cfg, seed=4)
    assert len(paths) == 3 and main_path[0] == 74 and main_path[-1] == 0
    assert main.n_frames == len(main_path)
    pairs = path_pairs(75, cfg["path"], 4)
    assert pairs == path_pairs(75, cfg["path"], 4)
    assert all(a - b >= round(0.3 * 75) for a, b in pairs)  # end before start, far enough apart
    assert (per_path["transitions"] == [len(transitions(p)) for p in paths]).all()
    assert len(per_tr) == per_path["transitions"].sum()
    for df in (per_path,):
        df.insert(0, "metric", "lee")
        df.insert(0, "method", "isomap")
        df.insert(0, "global_dof", False)
        df.insert(0, "dataset", "walk")
    summ = summarise_paths(per_path)
    assert len(summ) == 1 and summ["paths"].iloc[0] == 3
    assert summ["resequencing_paths"].iloc[0] == (per_path["path_class"] == "resequences").sum()


def test_analyse_switches_to_landmark_isomap_above_the_size_threshold(walk):
    from scipy.spatial import procrustes

    m = prepare_motion(walk, 150, 2)  # 75 frames
    base = {"fixed_k_sweep": [], "max_dim": 3, "metrics": ["l2"]}
    exact = analyse(m, "walk", "t", False, full_cfg(base))
    # threshold below the frame count -> landmark; with every frame a landmark it is exact Isomap again
    lm_cfg = full_cfg({**base, "embedding": {"exact_max_frames": 74, "n_landmarks": 75}})
    lm = analyse(m, "walk", "t", False, lm_cfg)
    assert set(exact[0]["embedding_method"]) == {"exact"} and set(lm[0]["embedding_method"]) == {"landmark"}
    assert set(lm[1]["embedding_method"]) == {"landmark"}
    assert (exact[0]["min_k"].to_numpy() == lm[0]["min_k"].to_numpy()).all()
    for key in ("isomap_l2_xy", "stisomap_l2_xy"):
        assert procrustes(exact[2][key], lm[2][key])[2] < 1e-6
    np.testing.assert_allclose(exact[1]["residual_variance"], lm[1]["residual_variance"], atol=1e-5)
    # 20 landmarks: an approximation that still follows the exact embedding
    few = analyse(m, "walk", "t", False, full_cfg({**base, "embedding": {"method": "landmark", "n_landmarks": 20}}))
    assert set(few[0]["embedding_method"]) == {"landmark"}
    assert procrustes(exact[2]["isomap_l2_xy"], few[2]["isomap_l2_xy"])[2] < 0.1
    with pytest.raises(ValueError, match="resequencing.embedding.method"):
        analyse(m, "walk", "t", False, full_cfg({**base, "embedding": {"method": "fast"}}))


def test_analyse_is_deterministic(walk):
    cfg = full_cfg({"fixed_k_sweep": [5], "max_dim": 3, "metrics": ["lee"]})
    m = prepare_motion(walk, 120, 2)
    a = analyse(m, "walk", "t", True, cfg)
    b = analyse(m, "walk", "t", True, cfg)
    assert a[0].to_csv() == b[0].to_csv() and a[1].to_csv() == b[1].to_csv()


def _published():
    return pd.DataFrame([
        {"motion": "walk", "frames": 500, "global_dof": "excluded", "method": "isomap", "metric": "l2", "min_k": 70},
        {"motion": "walk", "frames": 500, "global_dof": "excluded", "method": "isomap", "metric": "lee", "min_k": 3},
        {"motion": "walk", "frames": 500, "global_dof": "excluded", "method": "st-isomap", "metric": "lee",
         "min_k": 1}])


def test_min_k_table_fills_published_values(tmp_path):
    grid = pd.DataFrame([{"dataset": "walk", "trial": "t", "frame_step": st, "fps": 120 / st, "frames": 10,
                          "global_dof": g, "sign_mode": mode, "method": "isomap", "metric": "l2", "min_k": 3,
                          "components_at_min_k_minus_1": 2, "components_at_min_k": 1}
                         for st in (1, 4) for g in (True, False) for mode in ("matrix_naive", "continuous")])
    f = tmp_path / "t2.csv"
    _published().to_csv(f, index=False)
    pub = published_table2(f)
    assert published_table2(tmp_path / "absent.csv") is None  # missing file: no published values, no error
    t = min_k_table(grid, pub, 1)
    assert len(t) == 4 and (t["fps"] == 120).all()
    assert t["global_dof"].tolist() == [False, False, True, True]
    assert t["sign_mode"].tolist() == ["continuous", "matrix_naive"] * 2
    assert t.loc[~t["global_dof"], "min_k_paper"].tolist() == [70, 70]
    assert t.loc[t["global_dof"], "min_k_paper"].isna().all()
    # ours - paper beside the paper's value; empty where the paper has none
    cols = list(t.columns)
    assert cols[cols.index("min_k_paper") + 1] == "min_k_minus_paper"
    assert t.loc[~t["global_dof"], "min_k_minus_paper"].tolist() == [3 - 70, 3 - 70]
    assert t.loc[~t["global_dof"], "frames_minus_paper"].tolist() == [10 - 500, 10 - 500]
    assert t.loc[t["global_dof"], "min_k_minus_paper"].isna().all()
    bad = _published()
    bad.loc[1, "method"] = "lle"
    bad.to_csv(f, index=False)
    with pytest.raises(ValueError, match="line 3"):
        published_table2(f)


def test_lee_weights_beside_the_paper_and_malformed_published_files(tmp_path):
    from animsynth.published import PublishedError
    from animsynth.resequencing.tables import lee_weights_table

    f = tmp_path / "lee.csv"
    f.write_text("joint_pair,weight\nhips,1.0000\nknees,0.0900\n")
    t = lee_weights_table(f, dict(PAPER_WEIGHTS)).set_index("group")
    assert list(t.columns) == ["weight_paper", "weight_ours", "weight_minus_paper", "match"]
    assert bool(t.loc["hips", "match"]) and not bool(t.loc["knees", "match"])
    assert t.loc["knees", "weight_minus_paper"] == pytest.approx(0.0001)
    assert lee_weights_table(tmp_path / "absent.csv", dict(PAPER_WEIGHTS)) is None
    f.write_text("joint_pair,weight\nhips,one\n")
    with pytest.raises(PublishedError, match="lee.csv, line 2.*'weight'"):
        lee_weights_table(f, dict(PAPER_WEIGHTS))
    g = tmp_path / "t2.csv"
    _published().drop(columns="min_k").to_csv(g, index=False)
    with pytest.raises(PublishedError, match="line 1.*min_k"):
        published_table2(g)


def test_explanation_verdict_names_the_matching_candidate(tmp_path):
    rows = []
    for mode, l2 in (("continuous", 4), ("matrix_naive", 60)):
        for st, fac in ((1, 1), (4, 0.5)):
            for metric, k in (("l2", l2), ("lee", 3)):
                rows.append({"dataset": "walk", "frame_step": st, "fps": 120 / st, "global_dof": False,
                             "sign_mode": mode, "method": "isomap", "metric": metric,
                             "min_k": max(1, int(k * fac)) if metric == "l2" else k})
    grid = pd.DataFrame(rows)
    f = tmp_path / "t2.csv"
    _published().to_csv(f, index=False)
    v = pd.DataFrame(explanation_verdicts(grid, published_table2(f), 1))
    summary = v.iloc[0]
    assert "matrix_naive" in summary["evidence"] and summary["verdict"] == "reproduced"
    naive = v[v["claim"].str.contains(r"matrix_naive, 120")].iloc[0]
    assert naive["verdict"] == "reproduced"
    assert v[v["claim"].str.contains("lower frame rate")].iloc[0]["verdict"] == "not reproduced"
    # 60 vs 70 is within the factor; 30 (matrix_naive at 30 fps) is too
    assert v[v["claim"].str.contains("matrix_naive signs at frame_step 4")].iloc[0]["verdict"] == "reproduced"
    none = explanation_verdicts(grid, None, 1)
    assert len(none) == 1 and "not available" in none[0]["evidence"]


def test_lee_vs_l2_verdict():
    t = pd.DataFrame([{"dataset": d, "global_dof": False, "sign_mode": "continuous", "method": "isomap",
                       "metric": m, "min_k": k, "min_k_paper": np.nan}
                      for d, kl2 in (("walk", 40), ("run", 5)) for m, k in (("l2", kl2), ("lee", 4))])
    assert lee_vs_l2_verdict(t)["verdict"] == "partly"
    t.loc[(t["dataset"] == "run") & (t["metric"] == "l2"), "min_k"] = 30
    assert lee_vs_l2_verdict(t)["verdict"] == "reproduced"
    t.loc[t["metric"] == "l2", "min_k"] = 2
    assert lee_vs_l2_verdict(t)["verdict"] == "contradicted"


def _paths(values):
    """per-path rows: values[(dataset, method, metric, global, pair)] = (class, velocity_jump_ratio)."""
    rows = []
    for (ds, method, metric, g, p), (cls, v) in values.items():
        rows.append({"dataset": ds, "method": method, "metric": metric, "global_dof": g, "pair": p,
                     "root_playback": "integrate", "path_class": cls, "transitions": int(cls == "resequences"),
                     "transitions_per_100_frames": 1.0, "velocity_jump_ratio": v, "pose_jump_ratio": v,
                     "accel_jump_ratio": v, "foot_skate_ratio": v})
    return pd.DataFrame(rows)


def test_smoothness_verdicts_use_only_pairs_where_both_resequence():
    vals = {}
    for p in range(12):
        vals[("walk", "isomap", "l2", False, p)] = ("resequences", 3.0)
        vals[("walk", "stisomap", "l2", False, p)] = ("resequences", 1.0 + 0.01 * p)
    assert st_smoother_verdict(_paths(vals))["verdict"] == "reproduced"
    # ST-Isomap replays on most pairs: those pairs are left out, and 2 pairs are too few to decide
    for p in range(10):
        vals[("walk", "stisomap", "l2", False, p)] = ("replays_backwards", np.nan)
    v = st_smoother_verdict(_paths(vals))
    assert v["verdict"] == "undecided" and "both 2" in v["evidence"]
    # no pair where both re-sequence: nothing to compare, so undecided (never "not reproduced")
    for p in range(12):
        vals[("walk", "stisomap", "l2", False, p)] = ("replays", np.nan)
    assert st_smoother_verdict(_paths(vals))["verdict"] == "undecided"
    # half and half: the sign test decides nothing
    for p in range(12):
        vals[("walk", "stisomap", "l2", False, p)] = ("resequences", 2.0 if p % 2 else 4.0)
    assert st_smoother_verdict(_paths(vals))["verdict"] == "undecided"


def test_global_dof_verdict_per_dataset():
    vals = {}
    for ds in ("walk", "run", "dance"):
        for p in range(10):
            base = 2.0 + 0.1 * p
            vals[(ds, "isomap", "lee", False, p)] = ("resequences", base)
            vals[(ds, "isomap", "lee", True, p)] = ("resequences", base * (0.5 if ds == "dance" else 2.0))
    assert global_dof_verdict(_paths(vals))["verdict"] == "reproduced"
    for p in range(10):
        vals[("dance", "isomap", "lee", True, p)] = ("resequences", 10.0)
    assert global_dof_verdict(_paths(vals))["verdict"] == "partly"
    flipped = {k: (c, 1.0 / v if k[3] else v) for k, (c, v) in vals.items()}
    for ds in ("walk", "run"):
        for p in range(10):
            flipped[(ds, "isomap", "lee", True, p)] = ("resequences", 0.1)
            flipped[(ds, "isomap", "lee", False, p)] = ("resequences", 5.0)
    for p in range(10):
        flipped[("dance", "isomap", "lee", True, p)] = ("resequences", 9.0)
        flipped[("dance", "isomap", "lee", False, p)] = ("resequences", 1.0)
    assert global_dof_verdict(_paths(flipped))["verdict"] == "contradicted"
    # with the global DOF, walk and run never re-sequence while dance does: hurt by losing the ability
    lost = dict(vals)
    for ds in ("walk", "run"):
        for p in range(10):
            lost[(ds, "isomap", "lee", True, p)] = ("replays_backwards", np.nan)
    for p in range(10):
        lost[("dance", "isomap", "lee", True, p)] = ("resequences", 1.0)
    v = global_dof_verdict(_paths(lost))
    assert v["verdict"] == "reproduced" and "walk: re-sequencing paths 10/10 without vs 0/10 with" in v["ours"]
    # a run without dance (resequencing_trials a subset): the dance half is not measured, at most partly
    no_dance = {k: v for k, v in vals.items() if k[0] != "dance"}
    v = global_dof_verdict(_paths(no_dance))
    assert v["verdict"] == "partly" and "dance: not in this run" in v["ours"]


def test_the_full_size_config_is_the_schema_defaults():
    """Defaults live in config/schema.yaml only: the demo config with the real-data config's full sizes merged
    over it, as the workflow merges them, is exactly the schema's resequencing block."""
    import yaml

    from animsynth.config import validate_config

    from conftest import REPO

    cfg = full_cfg()
    assert config_block("resequencing") != cfg  # the embedded default is the demo
    schema_only = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    del schema_only["resequencing"]  # every resequencing value from the schema
    validate_config(schema_only, str(REPO / "config" / "schema.yaml"))
    assert schema_only["resequencing"] == cfg


def test_no_defaults_dict_in_the_workflow_steps():
    from animsynth.resequencing import jobs

    assert not hasattr(jobs, "DEFAULTS") and not hasattr(jobs, "with_defaults")
    with pytest.raises(KeyError):  # a step needs the whole (validated) block; nothing fills it in behind the config
        explain(generate_motion("walk_straight", 60, 0, cmu_like_skeleton("t", 1)), "walk", "t", {})


# ------------------------------------------------------- sign modes (Table 2 explanation)
def test_matrix_naive_sign_flip_gives_a_jump_of_pi_and_continuous_none():
    # rotation about x from 200 to 340 degrees: past 270 degrees |w| becomes the largest component while w < 0,
    # so the largest-component-positive conversion flips the quaternion's sign exactly once
    theta = np.linspace(200.0, 340.0, 71)
    q = rot("x", theta)
    qn = matrix_naive_quaternions(q)
    assert sign_flips(qn[:, None, :]).tolist() == [1]
    assert sign_flips(q[:, None, :]).tolist() == [0]
    step = np.deg2rad(theta[1] - theta[0]) / 2  # half-angle log of one increment
    cont = np.linalg.norm(np.diff(linearize_quaternions(q, "continuous"), axis=0), axis=1)
    naive = np.linalg.norm(np.diff(linearize_quaternions(q, "matrix_naive"), axis=0), axis=1)
    np.testing.assert_allclose(cont, step, rtol=1e-6)
    flip_at = int(np.argmax(naive))
    assert naive[flip_at] == pytest.approx(np.pi, abs=2 * step)  # the jump of about pi
    np.testing.assert_allclose(np.delete(naive, flip_at), step, rtol=1e-6)  # elsewhere the same increments
    # the flip happens where |w| overtakes |x| (270 degrees)
    assert theta[flip_at] <= 270.0 <= theta[flip_at + 1]
    # every later frame is offset by about pi from where the continuous linearisation puts it
    off = np.linalg.norm(linearize_quaternions(q, "matrix_naive") - linearize_quaternions(q, "continuous"), axis=1)
    np.testing.assert_allclose(off[:flip_at + 1], 0.0, atol=1e-9)
    np.testing.assert_allclose(off[flip_at + 1:], np.pi, atol=2 * step)
    with pytest.raises(ValueError, match="sign_mode"):
        linearize_quaternions(q, "other")


def test_explain_counts_flips_and_raises_l2_min_k_only():
    sk = cmu_like_skeleton("t05", 3)
    m = generate_motion("dance", 160, 2, sk)
    # make one joint turn round and round (large rotations: the largest quaternion component changes)
    sl = sk.dof_slices()["lhumerus"]
    ang = np.linspace(0.0, 1440.0, m.n_frames)  # four turns: w changes sign, the largest component changes
    vals = np.array(m.values, float)
    vals[:, sl] = 0.0
    vals[:, sl.start] = ang
    m = Motion(vals, sk, m.fps, "flip", {})
    cfg = full_cfg({"explanations": {"frame_steps": [1], "global_dof": [False]}})
    grid, flips = explain(m, "dance", "flip", cfg)
    f = flips.set_index("joint")
    assert f.loc["lhumerus", "flips_matrix_naive"] >= 3 and (flips["flips_continuous"] == 0).all()
    g = grid.set_index(["sign_mode", "method", "metric"])["min_k"]
    assert g[("matrix_naive", "isomap", "l2")] > g[("continuous", "isomap", "l2")]
    assert g[("matrix_naive", "isomap", "lee")] == g[("continuous", "isomap", "lee")]  # Lee is sign-invariant
    assert (grid.loc[grid["method"] == "stisomap", "min_k"] == 1).all()


# ------------------------------------------------------- ST-Isomap neighbourhoods
def test_st_isomap_on_a_single_chain_needs_k_1():
    # three tight clusters visited one after another: Isomap needs many neighbours to join them,
    # ST-Isomap keeps the adjacent temporal neighbours in every neighbourhood, so k = 1 connects the chain
    rng = np.random.default_rng(0)
    X = np.concatenate([rng.normal(c, 0.05, size=(30, 3)) for c in (0.0, 5.0, 10.0)])
    D = cdist(X, X)
    assert min_connected_k(D) > 10
    st = STIsomap(None, 2, ctn_neighbors=0, ctn_min_gap=5).fit(D)
    assert st.min_k_ == 1 and st.n_neighbors_ == 1
    gi, gj = st.graph_.nonzero()
    edges = set(zip(gi.tolist(), gj.tolist()))
    assert all((i, i + 1) in edges for i in range(len(X) - 1))  # the whole chain is in the graph
    assert np.isfinite(st.dist_matrix_).all()
    # without the always-present chain, the same adjusted distances need more than one neighbour
    assert min_connected_k(st.dist_st_) > 1
    assert min_connected_k(st.dist_st_, always=st.atn_) == 1


def test_precomputed_isomap_equals_scikit_learn_isomap_on_a_connected_graph():
    rng = np.random.default_rng(1)
    t = np.sort(rng.uniform(0, 3 * np.pi, 120))
    X = np.stack([t * np.cos(t), rng.uniform(0, 5, 120), t * np.sin(t)], axis=1)
    D = cdist(X, X)
    ours = PrecomputedIsomap(8, 2).fit(D)
    sk = Isomap(n_neighbors=8, n_components=2, metric="precomputed", path_method="D", eigen_solver="dense").fit(D)
    np.testing.assert_allclose(ours.dist_matrix_, sk.dist_matrix_, rtol=1e-9, atol=1e-9)
    for c in range(2):
        a, b = ours.embedding_[:, c], sk.embedding_[:, c]
        assert min(np.abs(a - b).max(), np.abs(a + b).max()) < 1e-6 * np.abs(b).max()


# ------------------------------------------------------- paths and transitions
def test_path_classification():
    assert classify_path(np.arange(10, 30)) == "replays"
    assert classify_path(np.arange(30, 10, -1)) == "replays_backwards"
    assert classify_path([5, 6, 7, 6, 5]) == "replays_backwards"
    assert classify_path([5, 6, 7, 40, 41]) == "resequences"
    assert classify_path([5, 6, 6, 7]) == "resequences"  # a held frame is not the next or previous one
    # with a same-pass span, skipping frames of one pass is not re-sequencing; jumping to another pass is
    assert classify_path([40, 38, 36, 35], same_pass=10) == "skips"
    assert classify_path([40, 38, 36, 12, 11], same_pass=10) == "resequences"
    assert pass_jumps([40, 38, 36, 12, 11], 10).tolist() == [3]
    assert transitions([5, 6, 7, 40, 41, 3]).tolist() == [3, 5]


def test_a_path_on_a_chain_replays_and_a_jump_resequences():
    n = 40
    chain = np.diag(np.ones(n - 1), 1)
    G = csr_matrix(chain + chain.T)
    path, _ = shortest_path_frames(G, 3, 30)
    assert classify_path(path) == "replays"
    G2 = G.tolil()
    G2[5, 25] = G2[25, 5] = 1.0  # a shortcut between two passes
    path2, _ = shortest_path_frames(G2.tocsr(), 30, 2)
    assert classify_path(path2) == "resequences" and transitions(path2).size == 1


def test_transition_measures_on_the_original_and_on_a_jump(walk):
    tref = TransitionReference(walk)
    idx = np.arange(walk.n_frames)
    assert transition_measures(tref, play_path(walk, idx), idx, 0, len(idx) - 1, 5) == []
    jump = np.concatenate([np.arange(0, 60), np.arange(130, 200)])
    tr = transition_measures(tref, play_path(walk, jump), jump, 0, len(jump) - 1, 5)
    assert len(tr) == 1 and tr[0]["from_frame"] == 59 and tr[0]["to_frame"] == 130
    assert tr[0]["pose_jump_ratio"] > 1.0 and tr[0]["velocity_jump_ratio"] > 1.0
    # a jump outside [first, last] (in the context) is not counted
    assert transition_measures(tref, play_path(walk, jump), jump, 70, len(jump) - 1, 5) == []


def test_config_cross_checks_name_the_key():
    import copy

    import yaml

    from animsynth.config import ConfigError, validate_config
    from animsynth.resequencing.settings import check

    from conftest import REPO

    base = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    validate_config(base, str(REPO / "config" / "schema.yaml"))
    check(base)

    def bad(**change):
        cfg = copy.deepcopy(base)
        for key, value in change.items():
            *path, last = key.split("__")
            d = cfg
            for k in path:
                d = d[k]
            d[last] = value
        return cfg

    with pytest.raises(ConfigError, match="resequencing.datasets"):
        check(bad(resequencing_trials={"walk": base["resequencing_trials"]["walk"]}))
    with pytest.raises(ConfigError, match="resequencing.methods.*duplicate"):
        check(bad(resequencing__methods=["isomap", "isomap"]))
    with pytest.raises(ConfigError, match="explanations.frame_steps"):
        check(bad(resequencing__frame_step=2))
    with pytest.raises(ConfigError, match="explanations.sign_modes"):
        check(bad(resequencing__explanations__sign_modes=["matrix_naive"]))


def test_smoothness_decision_separates_clear_wins_leans_and_noise():
    from animsynth.resequencing.verdicts import _decide

    assert _decide(60, 10, 1e-6, 0.75, 0.05) == "holds"         # 86 %, significant
    assert _decide(10, 60, 1e-6, 0.75, 0.05) == "opposite"
    assert _decide(49, 23, 0.003, 0.75, 0.05) == "lean"        # 68 %: significant, below the share
    assert _decide(23, 49, 0.003, 0.75, 0.05) == "lean_opposite"
    assert _decide(9, 7, 0.8, 0.75, 0.05) == "noise"
    assert _decide(0, 0, 1.0, 0.75, 0.05) == "none"


def test_explanation_claim_is_named_the_same_without_the_published_table():
    from animsynth.resequencing.verdicts import explanation_verdicts

    rows = explanation_verdicts(pd.DataFrame(), None, 1)
    assert len(rows) == 1 and rows[0]["claim"].startswith("which candidate explanation matches")
    assert rows[0]["verdict"] == "undecided" and "not available" in rows[0]["evidence"]  # no evidence


def test_the_papers_min_k_stands_only_beside_the_trials_it_measured(tmp_path):
    """Table 2 shows the paper's min k beside the CMU trials the paper used (and the synthetic stand-ins of the
    default run), not beside a user's own capture, and the verdicts do not compare a user's trial with it."""
    from pathlib import Path

    import yaml

    from animsynth.resequencing.tables import comparable_published, paper_comparable

    root = Path(__file__).resolve().parents[1] / "config"
    user = yaml.safe_load((root / "user_example.yaml").read_text())
    user["mocap_source"] = "user"
    # u35_01 and u35_17 are the CMU files 35_01.amc and 35_17.amc; u05_03 is another dance than the paper's 05_02
    assert paper_comparable(user, user["resequencing_trials"]) == {"walk": True, "run": True, "dance": False}
    cmu = yaml.safe_load((root / "cmu.yaml").read_text())
    assert set(paper_comparable(cmu, cmu["resequencing_trials"]).values()) == {True}
    mine = {"mocap_source": "user", "trials": [{"id": "w", "bvh": "me/walk.bvh"}]}
    assert paper_comparable(mine, {"walk": "w"}) == {"walk": False}
    assert paper_comparable({"mocap_source": "synthetic", "trials": []}, {"walk": "syn35_01"}) == {"walk": True}
    f = tmp_path / "t2.csv"
    _published().to_csv(f, index=False)
    pub = published_table2(f)
    grid = pd.DataFrame([{"dataset": "walk", "trial": "w", "frame_step": 1, "fps": 120, "frames": 10,
                          "global_dof": False, "sign_mode": "continuous", "method": "isomap", "metric": "l2",
                          "min_k": 3, "components_at_min_k_minus_1": 2, "components_at_min_k": 1}])
    assert comparable_published(pub, {"walk": False}) is None
    t = min_k_table(grid, comparable_published(pub, {"walk": False}), 1)
    assert t["min_k_paper"].isna().all() and t["min_k_minus_paper"].isna().all()
    t = min_k_table(grid, comparable_published(pub, {"walk": True}), 1)
    assert t["min_k_paper"].tolist() == [70]
