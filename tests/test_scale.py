"""Re-sequencing at scale: sparse neighbour lists, exact minimum k on them, Landmark
Isomap, and the embed front end -- each checked against the dense implementation
on data small enough for N x N."""

from __future__ import annotations

import os

import numpy as np
import pytest
from scipy.spatial import procrustes

from animsynth.families import scaled
from animsynth.resequencing import landmark, sparse, sparse_st
from animsynth.resequencing.distances import l2_distances, lee_distances
from animsynth.resequencing.embedding import (DisconnectedGraphError, knn_graph, min_connected_k, neighbor_ranks,
                                              spatio_temporal_distances, temporal_adjacency)
from animsynth.resequencing.features import motion_features
from animsynth.resequencing.paths import shortest_path_frames
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion


@pytest.fixture(scope="module")
def database():
    """Three short synthetic trials of different kinds (a database of several sequences)."""
    sk = cmu_like_skeleton()
    return [motion_features(generate_motion(kind, 150, seed=s, skeleton=sk))
            for s, kind in enumerate(("walk_straight", "run_turn", "dance"))]


def _dense_lists(D, m):
    R = neighbor_ranks(D)
    idx = np.argsort(R, axis=1, kind="stable")[:, 1:m + 1]
    return np.take_along_axis(D, idx, 1), idx


def _swiss_roll(n, seed):
    rng = np.random.default_rng(seed)
    t = 1.5 * np.pi * (1 + 2 * rng.random(n))
    h = 10 * rng.random(n)
    return np.column_stack([t * np.cos(t), h, t * np.sin(t)])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_l2_lists_are_the_dense_nearest_frames(seed):
    X = np.random.default_rng(seed).normal(size=(300, 5))
    dist, idx = sparse.l2_neighbours(X, 12)
    ddist, didx = _dense_lists(l2_distances(X), 12)
    np.testing.assert_array_equal(idx, didx)
    np.testing.assert_allclose(dist, ddist, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("margin", [1.0, 2.0])
def test_lee_candidates_find_the_exact_nearest_frames_of_one_motion(database, margin):
    f = database[2]
    dist, idx, stats = sparse.lee_neighbours(f, 10, margin=margin, return_stats=True)
    D = lee_distances(f)
    ddist, didx = _dense_lists(D, 10)
    np.testing.assert_array_equal(idx, didx)
    np.testing.assert_allclose(dist, ddist, rtol=1e-9, atol=1e-12)
    assert stats["first_pass"] + stats["rows_requeried"] >= f.n_frames


def test_lee_certificate_requeries_when_the_margin_is_too_small(database):
    """margin=1 keeps no slack: some rows fail the certificate, are re-queried, and the result stays exact."""
    dist, idx, stats = sparse.lee_neighbours(database, 8, margin=1.0, return_stats=True)
    assert stats["rows_requeried"] > 0
    parts = sparse._lee_parts(database, None, 0.01, False)
    n = idx.shape[0]
    ii, jj = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    D = sparse.lee_pair_metric(parts, ii, jj)
    np.fill_diagonal(D, 0.0)
    ddist, didx = _dense_lists(D, 8)
    np.testing.assert_array_equal(idx, didx)


def test_lee_index_distance_bounds_the_metric(database):
    E = sparse.lee_index_vectors(database)
    parts = sparse._lee_parts(database, None, 0.01, False)
    rng = np.random.default_rng(0)
    i, j = rng.integers(0, E.shape[0], size=(2, 2000))
    e2 = np.sum((E[i] - E[j]) ** 2, axis=1)
    lee = sparse.lee_pair_metric(parts, i, j)
    assert np.all(e2 <= lee * (1 + 1e-9) + 1e-12)
    assert np.all(lee <= sparse.LEE_INDEX_RATIO * e2 * (1 + 1e-9) + 1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_sparse_min_k_equals_the_dense_exact_min_k(seed):
    rng = np.random.default_rng(seed)
    # clusters joined only by long edges: the minimum k is well above 1
    X = np.vstack([rng.normal(size=(60, 3)) + 8 * c for c in rng.normal(size=(4, 3))])
    D = l2_distances(X)
    dist, idx = sparse.l2_neighbours(X, X.shape[0] - 1)
    assert sparse.sparse_min_connected_k(idx) == min_connected_k(D) > 1
    # fewer candidates than needed: a clear error, not a wrong number
    with pytest.raises(sparse.CandidateCountError, match="more than"):
        sparse.sparse_min_connected_k(idx[:, : min_connected_k(D) - 1])
    # exactly as many as needed is enough
    k = min_connected_k(D)
    assert sparse.sparse_min_connected_k(idx[:, :k]) == k


def test_sparse_min_k_of_a_motion_database(database):
    X = np.vstack([f.linearised(False) for f in database])
    dist, idx = sparse.l2_neighbours(X, 60)
    assert sparse.sparse_min_connected_k(idx) == min_connected_k(l2_distances(X))


def test_sparse_graph_is_the_dense_knn_graph():
    X = np.random.default_rng(5).normal(size=(200, 4))
    dist, idx = sparse.l2_neighbours(X, 15)
    for k in (1, 4, 15):
        G = sparse.sparse_knn_graph(dist, idx, k).toarray()
        np.testing.assert_allclose(G, knn_graph(l2_distances(X), k).toarray(), rtol=1e-12)
    with pytest.raises(sparse.CandidateCountError, match="exceeds the 15 candidates"):
        sparse.sparse_knn_graph(dist, idx, 16)


def test_st_lists_give_the_dense_st_isomap_graph(database):
    f = database[0]
    X = f.linearised(False)
    D = l2_distances(X)
    n = X.shape[0]
    kw = dict(temporal_window=1, c_atn=10.0, c_ctn=10.0, ctn_neighbors=4, ctn_min_gap=30, ctn_tolerance=2,
              ctn_reach=6)
    Dst, _, ctn = spatio_temporal_distances(D, **kw)
    dist, idx = sparse.l2_neighbours(X, n - 1)  # all frames: the candidate search cannot miss a CTN
    def pair(i, j):
        return np.linalg.norm(X[i] - X[j], axis=1)

    sd, si, n_ctn = sparse_st.st_neighbours(dist, idx, np.zeros(n, int), pair_distance=pair, **kw)
    assert n_ctn == int(np.count_nonzero(np.triu(ctn)))
    assert sparse.sparse_min_connected_k(si) == min_connected_k(Dst)
    for k in (2, 5):
        np.testing.assert_allclose(sparse.sparse_knn_graph(sd, si, k).toarray(), knn_graph(Dst, k).toarray(),
                                   rtol=1e-12)


def test_sparse_st_isomap_keeps_the_adjacent_temporal_edges_like_the_dense_one(database):
    f = database[0]
    X = f.linearised(False)
    n = X.shape[0]
    kw = dict(temporal_window=1, c_atn=10.0, c_ctn=10.0, ctn_neighbors=4, ctn_min_gap=30, ctn_tolerance=2,
              ctn_reach=6)
    Dst = spatio_temporal_distances(l2_distances(X), **kw)[0]
    dist, idx = sparse.l2_neighbours(X, n - 1)
    def pair(i, j):
        return np.linalg.norm(X[i] - X[j], axis=1)

    sd, si, _ = sparse_st.st_neighbours(dist, idx, np.zeros(n, int), pair_distance=pair, **kw)
    pairs, w = sparse_st.st_always_edges(np.zeros(n, int), 1, 10.0, pair)
    assert pairs.shape == (n - 1, 2) and np.all(pairs[:, 1] - pairs[:, 0] == 1)
    always = temporal_adjacency(n, 1)
    # one sequence is a chain of always-present edges: connected at k = 1, as in the dense version
    assert sparse.sparse_min_connected_k(si, always=pairs) == min_connected_k(Dst, always=always) == 1
    for k in (1, 3):
        np.testing.assert_allclose(sparse.sparse_knn_graph(sd, si, k, always=(pairs, w)).toarray(),
                                   knn_graph(Dst, k, always=always).toarray(), rtol=1e-12)
    # with 2 candidates per frame the lists alone may miss a temporal neighbour; the always edges never do
    G = sparse.sparse_knn_graph(sd[:, :1], si[:, :1], 1, always=(pairs, w)).toarray()
    assert np.all(G[np.arange(n - 1), np.arange(1, n)] > 0)
    # two sequences: each chains itself, so min k is what joins them (not 1 unless a listed pair does)
    X2 = np.vstack([database[0].linearised(False), database[1].linearised(False)])
    seq = np.repeat([0, 1], [database[0].n_frames, database[1].n_frames])
    d2, i2 = sparse.l2_neighbours(X2, 30)
    p2 = sparse_st.temporal_pairs(seq, 1)
    assert not np.any(seq[p2[:, 0]] != seq[p2[:, 1]]) and len(p2) == len(seq) - 2
    k2 = sparse.sparse_min_connected_k(i2, always=p2)
    A2 = np.zeros((len(seq), len(seq)), bool)
    A2[p2[:, 0], p2[:, 1]] = True
    assert k2 == min_connected_k(l2_distances(X2), always=A2)  # the dense answer with the same always-edges
    assert k2 <= sparse.sparse_min_connected_k(i2)
    with pytest.raises(ValueError, match="two different frames"):
        sparse.sparse_min_connected_k(i2, always=[[0, 0]])


def test_st_temporal_neighbours_stay_inside_each_sequence(database):
    X = np.vstack([f.linearised(False) for f in database])
    seq = np.concatenate([np.full(f.n_frames, s) for s, f in enumerate(database)])
    dist, idx = sparse.l2_neighbours(X, 20)
    def pair(i, j):
        return np.linalg.norm(X[i] - X[j], axis=1)

    sd, si, _ = sparse_st.st_neighbours(dist, idx, seq, c_atn=1e6, c_ctn=10.0, pair_distance=pair)
    # with a huge c_atn the nearest is a temporal neighbour, never across a boundary (except
    # for exact copies at distance 0: every linearised trial starts at the zero vector)
    first = si[:, 0]
    fine = dist[:, 0] > 0
    assert fine.sum() > 0.9 * len(seq)
    assert np.all(seq[first][fine] == seq[fine])
    assert np.all(np.abs(first - np.arange(len(seq)))[fine] == 1)
    ends = np.flatnonzero(np.diff(seq))  # last frame of a sequence: its one temporal neighbour is the previous
    assert np.all(first[ends] == ends - 1)


def test_landmark_with_every_frame_a_landmark_is_exact_isomap():
    X = _swiss_roll(400, 0)
    dist, idx = sparse.l2_neighbours(X, 10)
    G = sparse.sparse_knn_graph(dist, idx, 10)
    Ye, lam_e, _ = landmark.exact_isomap(G, 2)
    li = landmark.LandmarkIsomap(2, n_landmarks=400).fit(G)
    np.testing.assert_allclose(li.eigenvalues_, lam_e, rtol=1e-8)
    assert procrustes(Ye, li.embedding_)[2] < 1e-10


@pytest.mark.parametrize("seed,how", [(0, "maxmin"), (1, "random")])
def test_landmark_embedding_agrees_with_exact_on_small_data(seed, how):
    X = _swiss_roll(1000, seed)
    dist, idx = sparse.l2_neighbours(X, 10)
    G = sparse.sparse_knn_graph(dist, idx, 10)
    exact = landmark.embed(G, 2, method="exact")
    lm = landmark.embed(G, 2, method="landmark", n_landmarks=100, landmarks=how, seed=seed)
    assert exact.method == "exact" and lm.method == "landmark" and lm.landmarks.size == 100
    assert procrustes(exact.embedding, lm.embedding)[2] < 0.01
    # the 2-D roll unrolls: residual variance at d=2 is small for both, and estimated on landmarks for lm
    assert exact.residual_variance[1] < 0.05 and lm.residual_variance[1] < 0.05
    assert lm.rv_on.startswith("landmark pairs")


def test_landmark_on_a_chain_graph_is_one_dimensional_not_noise():
    """A k-NN graph of points on a line has 1-D geodesics: the second component has eigenvalue ~0 and must be 0,
    not rounding noise divided by sqrt(eigenvalue)."""
    t = np.linspace(0, 1, 300) + np.random.default_rng(0).uniform(-1e-4, 1e-4, 300)
    X = np.column_stack([t, np.zeros_like(t)])
    dist, idx = sparse.l2_neighbours(X, 4)
    G = sparse.sparse_knn_graph(dist, idx, sparse.sparse_min_connected_k(idx))
    li = landmark.LandmarkIsomap(2, n_landmarks=20).fit(G)
    assert np.all(li.embedding_[:, 1] == 0) and li.eigenvalues_[1] == 0
    assert abs(np.corrcoef(li.embedding_[:, 0], t)[0, 1]) > 1 - 1e-9
    assert li.residual_variance_[0] < 1e-9


def test_maxmin_landmarks_spread_over_the_graph():
    X = _swiss_roll(800, 3)
    dist, idx = sparse.l2_neighbours(X, 10)
    G = sparse.sparse_knn_graph(dist, idx, 10)
    lm, geo = landmark.choose_landmarks(G, 30, "maxmin", seed=0)
    assert len(set(lm.tolist())) == 30
    cover = geo.min(axis=0).max()  # farthest any frame is from its nearest landmark
    lr, geo_r = landmark.choose_landmarks(G, 30, "random", seed=0)
    assert cover < geo_r.min(axis=0).max()


def test_embed_auto_switches_at_the_threshold_and_refuses_disconnected_graphs():
    X = _swiss_roll(300, 1)
    dist, idx = sparse.l2_neighbours(X, 8)
    G = sparse.sparse_knn_graph(dist, idx, 8)
    assert landmark.embed(G, 2, exact_max_frames=300).method == "exact"
    r = landmark.embed(G, 2, exact_max_frames=299, n_landmarks=50)
    assert r.method == "landmark" and r.rv_on == "landmark pairs (50)"
    with pytest.raises(ValueError, match="embedding method"):
        landmark.embed(G, 2, method="fast")
    two = np.vstack([X, X + 1000.0])
    d2, i2 = sparse.l2_neighbours(two, 8)
    with pytest.raises(DisconnectedGraphError):
        landmark.embed(sparse.sparse_knn_graph(d2, i2, 8), 2, method="landmark", n_landmarks=20)


def test_sparse_path_costs_equal_dense_path_costs():
    X = _swiss_roll(500, 2)
    dist, idx = sparse.l2_neighbours(X, 8)
    k = max(sparse.sparse_min_connected_k(idx), 4)
    Gs = sparse.sparse_knn_graph(dist, idx, k)
    Gd = knn_graph(l2_distances(X), k)
    for a, b in ((0, 499), (17, 250), (300, 3)):
        ps, cs = sparse.shortest_path(Gs, a, b)
        pd_, cd = shortest_path_frames(Gd, a, b)
        assert cs == pytest.approx(cd, rel=1e-12)
        assert ps[0] == a and ps[-1] == b


def test_bad_input_gives_clear_errors():
    X = np.random.default_rng(0).normal(size=(20, 3))
    with pytest.raises(sparse.CandidateCountError, match="needs more than 20 frames"):
        sparse.l2_neighbours(X, 20)
    X[3, 1] = np.nan
    with pytest.raises(ValueError, match="frame 3 has a non-finite feature"):
        sparse.l2_neighbours(X, 5)


# ----------------------------------------------------------------------------- workflow


SMOKE = {
    "scale": {
        "enabled": True,
        "trial_frames": 300,
        "resequencing": {"sizes": [600, 1200], "n_landmarks": 60, "exact_max_frames": 800},
        "simplicial": {"sizes": [200, 400], "path_steps": 50, "trial_frames": 100},
        "facegraph": {"sizes": [8, 16]},
        "meshdetail": {"sizes": [20, 40], "resolutions": [0.5], "iterations": 5},
        "landmark_vs_exact": {"sizes": [600], "n_landmarks": [30, 60], "landmark_seeds": 2, "max_dim": 3, "pairs": 4},
        "benchmark": {"frames": 2000},
    }
}


@pytest.mark.workflow
@pytest.mark.scale
@pytest.mark.skipif(os.environ.get("ANIMSYNTH_SCALE_TEST") != "1",
                    reason="opt-in: set ANIMSYNTH_SCALE_TEST=1 for the scale-config smoke run (several minutes; "
                           ".ci/run sets it)")
def test_scale_workflow_builds_curves_landmark_table_and_benchmark_rows(tmp_path):
    import pandas as pd
    import yaml

    from conftest import copy_workflow, run_snakemake

    wd = copy_workflow(tmp_path)
    (wd / "config" / "scale_smoke.yaml").write_text(yaml.safe_dump(SMOKE, sort_keys=False))
    res = run_snakemake(wd, "--configfile", "config/scale.yaml", "config/scale_smoke.yaml")
    assert res.returncode == 0, (res.stdout + res.stderr)[-5000:]
    out = wd / "results" / "scale"
    # only the scale outputs are built with the scale config
    assert not (wd / "results" / "simplicial").exists()
    curves = pd.read_csv(out / "cost_curves.csv")
    assert list(curves.columns[:6]) == ["family", "step", "n", "cpu_s", "wall_s", "peak_mb"]
    measured = {f.name for f in scaled()}  # every family the scale study measures
    assert set(curves["family"]) == measured
    assert set(curves.loc[curves.family == "resequencing", "step"]) == {"neighbours", "min_k", "embedding", "path"}
    emb = curves[(curves.family == "resequencing") & (curves.step == "embedding")].set_index("n")
    assert emb.loc[600, "embedding_method"] == "exact" and emb.loc[1200, "embedding_method"] == "landmark"
    assert (curves["peak_mb"] > 50).all()  # a Python process with numpy holds more than 50 MB
    ex = pd.read_csv(out / "cost_exponents.csv")
    emb_rows = ex["step"] == "embedding"  # exact at 600 frames, landmark at 1200: one point per curve
    assert (ex.loc[~emb_rows, "sizes"] == 2).all() and (ex.loc[emb_rows, "sizes"] == 1).all()
    assert ex.loc[emb_rows, "cpu_exponent"].isna().all() and ex.loc[~emb_rows, "cpu_exponent"].notna().all()
    lve = pd.read_csv(out / "landmark_vs_exact.csv")
    assert len(lve) == 4 and (lve["min_k_dense"] == lve["min_k_sparse"]).all()
    assert (lve["path_cost_max_rel_diff"] < 1e-9).all()
    assert (lve["procrustes_2d"] < 0.1).all()
    bench = pd.read_csv(out / "benchmarks.csv")
    assert list(bench["benchmark"]) == ["reseq_2k_frames_total_s", "reseq_2k_frames_peak_mb"]
    assert (bench["family"] == "resequencing").all()
    # the same rows, with the machine, join the project-wide benchmark table
    project = pd.read_csv(wd / "results" / "benchmarks.csv")
    joined = project[project["benchmark"].isin(bench["benchmark"])].set_index("benchmark")
    assert list(joined.index) == list(bench["benchmark"])
    assert (joined["family"] == "resequencing").all() and joined["machine"].str.contains("cores").all()
    assert measured <= set(project["family"])
    assert (out / "cost_curves.png").stat().st_size > 5000
