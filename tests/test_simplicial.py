"""Unit tests of the simplicial family on hand-made inputs with known answers."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.spatial import QhullError

from animsynth.simplicial import folds as fl, stats as st, tables as tb
from animsynth.simplicial import geometry
from animsynth.simplicial.field import VectorField, idw_weights, training_vectors
from animsynth.simplicial.geometry import SafeDelaunay, merge_duplicates
from animsynth.simplicial.graph import MotionGraph, clip_edges, knn_pairs, orient_pairs
from animsynth.simplicial.metrics import error_a, error_f, point_polyline_distance
from animsynth.simplicial.path import TargetPlanner, follow_field

# A triangle with one interior point: Delaunay = 3 triangles, 6 edges (no co-circular ambiguity).
TRI4 = np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 4.0], [1.0, 1.0]])


# ----------------------------------------------------------------------------- graph construction
def test_delaunay_edges_triangle_with_interior_point():
    tri = SafeDelaunay().fit(TRI4)
    assert tri.status_ == "ok" and tri.rank_ == 2
    assert tri.simplices_.shape == (3, 3)
    assert sorted(map(tuple, tri.edges())) == [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]


def test_knn_pairs_union_rule_on_a_line():
    # gaps 1, 2, 4, 8 -> no ties
    x = np.array([[0.0], [1.0], [3.0], [7.0], [15.0]])
    assert sorted(map(tuple, knn_pairs(x, 1))) == [(0, 1), (1, 2), (2, 3), (3, 4)]
    # k=2: (1, 3) exists only because 1 is among 3's two nearest (not vice versa)
    assert sorted(map(tuple, knn_pairs(x, 2))) == [(0, 1), (0, 2), (1, 2), (1, 3), (2, 3), (2, 4), (3, 4)]
    # fewer points than k+1: everything connected, no self loops
    assert len(knn_pairs(x[:3], 16)) == 3


def test_knn_pairs_with_duplicates_keep_k_others():
    x = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [5.0, 0.0]])
    e = knn_pairs(x, 1)
    assert all(a != b for a, b in e)
    assert set(e.ravel().tolist()) == {0, 1, 2, 3}  # every point has a neighbour other than itself
    assert sum(3 in p for p in e.tolist()) == 1  # the far point lists exactly one duplicate, nobody lists it


def test_clip_edges_and_graph_edge_counts():
    assert clip_edges([3, 1, 2]).tolist() == [[0, 1], [1, 2], [4, 5]]
    x = TRI4
    v = np.array([[1.0, 0.1]] * 4)  # no pair is perpendicular to it: no ties
    g = MotionGraph("delaunay").fit(x, v, [2, 2])
    # 2 clip edges + 6 Delaunay pairs, each oriented once; the clip edges 0->1 and 2->3 coincide with two of them
    assert g.n_clip_edges_ == 2 and g.n_added_pairs_ == 6 and g.n_ties_ == 0
    assert sorted(map(tuple, g.edges_.tolist())) == [(0, 1), (0, 2), (0, 3), (2, 1), (2, 3), (3, 1)]
    gk = MotionGraph("knn", k=1).fit(x, v, [2, 2])
    assert gk.n_added_pairs_ == len(knn_pairs(x, 1)) == 3  # 0-3, 1-3, 2-3
    gd = MotionGraph("kdelaunay", k=1).fit(x, v, [2, 2])
    assert gd.n_added_pairs_ == 6  # the k-NN pairs are all Delaunay edges here


def test_edge_direction_follows_mean_training_vector():
    x = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    v = np.array([[1.0, 0.0], [1.0, 0.0], [0.0, -1.0], [0.0, 0.0]])
    pairs = np.array([[0, 1], [0, 2], [0, 3]])
    edges, ties = orient_pairs(x, v, pairs)
    got = sorted(map(tuple, edges.tolist()))
    # 0->1 along +x; 2->0 because the mean vector (0.5, -0.5) points from 2 towards 0;
    # 0 and 3 coincide (zero-length edge): both directions
    assert got == [(0, 1), (0, 3), (2, 0), (3, 0)]
    assert ties == 1


def test_connectivity_split_and_loop():
    a = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [100.0, 0.0], [101.0, 0.0], [102.0, 0.0]])
    v = np.tile([1.0, 0.0], (6, 1))
    c = MotionGraph("knn", k=1).fit(a, v, [3, 3]).connectivity()
    assert c["scc"] == 6 and not c["undirected_connected"] and not c["h_connected"]
    t = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    loop = np.stack([np.cos(t), np.sin(t)], axis=1)
    tang = np.stack([-np.sin(t), np.cos(t)], axis=1)
    c2 = MotionGraph("knn", k=2).fit(loop, tang, [8]).connectivity()
    assert c2["scc"] == 1 and c2["undirected_connected"] and c2["h_connected"]
    # two clips on the same loop, each half of it: H connected through G'
    c3 = MotionGraph("knn", k=2).fit(loop, tang, [4, 4]).connectivity()
    assert c3["h_connected"] and c3["h_edges"] == 2


# ----------------------------------------------------------------------------- training vectors, weights, field
def test_training_vector_variants():
    clip = np.array([[0.0], [1.0], [3.0]])
    assert training_vectors([clip], "half")[:, 0].tolist() == [0.5, 1.0, 1.0]
    assert training_vectors([clip], "forward")[:, 0].tolist() == [1.0, 2.0, 2.0]
    assert training_vectors([clip], "central")[:, 0].tolist() == [1.0, 1.5, 2.0]
    two = training_vectors([clip, clip * 2], "forward")
    assert two.shape == (6, 1) and two[3:, 0].tolist() == [2.0, 4.0, 4.0]
    with pytest.raises(ValueError, match="at least 2 frames"):
        training_vectors([clip[:1]])
    with pytest.raises(ValueError, match="derivative"):
        training_vectors([clip], "backward")


def test_idw_weights_known_values_and_exact_hit():
    w = idw_weights(np.array([[1.0, 2.0], [0.0, 2.0], [1.0, np.inf]]), hit_tol=1e-12)
    np.testing.assert_allclose(w, [[0.8, 0.2], [1.0, 0.0], [1.0, 0.0]])


def test_field_knn_and_delaunay_values():
    v = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    q = np.array([1.0, 0.5])
    f = VectorField("knn", k=2).fit(TRI4, v)
    d = np.linalg.norm(TRI4 - q, axis=1)
    nn = np.argsort(d)[:2]
    w = 1 / d[nn] ** 2
    np.testing.assert_allclose(f(q)[0], (w / w.sum()) @ v[nn])
    np.testing.assert_allclose(f.evaluate(q[None])[0][0], f(q)[0])
    fd = VectorField("delaunay").fit(TRI4, v)
    s, _ = fd.triangulation_.find(q[None])
    verts = fd.triangulation_.simplices_[s[0]]
    w = 1 / d[verts] ** 2
    np.testing.assert_allclose(fd(q)[0], (w / w.sum()) @ v[verts])
    np.testing.assert_allclose(fd.evaluate(q[None])[0][0], fd(q)[0])
    # exact hit on a training point returns its vector
    np.testing.assert_allclose(fd(TRI4[3])[0], v[3])
    np.testing.assert_allclose(f(TRI4[1])[0], v[1])


def test_barycentric_weights_are_linear_interpolation():
    v = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    f = VectorField("delaunay", weights="barycentric").fit(TRI4, v)
    # centroid of triangle (0, 1, 3)
    q = TRI4[[0, 1, 3]].mean(axis=0)
    got, fb = f(q)
    assert not fb
    tri = f.triangulation_
    verts = tri.simplices_[tri.find(q[None])[0][0]]
    assert sorted(verts.tolist()) == [0, 1, 3]
    np.testing.assert_allclose(got, v[[0, 1, 3]].mean(axis=0), atol=1e-12)
    with pytest.raises(ValueError, match="barycentric"):
        VectorField("knn", weights="barycentric").fit(TRI4, v)


def test_kdelaunay_union_has_no_double_counting():
    v = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    f = VectorField("kdelaunay", k=4).fit(TRI4, v)
    q = np.array([1.0, 0.5])
    # union of the containing simplex and all 4 points = all 4 points, each once
    d = np.linalg.norm(TRI4 - q, axis=1)
    w = 1 / d ** 2
    np.testing.assert_allclose(f.evaluate(q[None])[0][0], (w / w.sum()) @ v)


def test_outside_hull_falls_back_to_knn_and_is_counted():
    v = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    fd = VectorField("delaunay", k=2).fit(TRI4, v)
    fk = VectorField("knn", k=2).fit(TRI4, v)
    q = np.array([10.0, 10.0])
    got, fb = fd(q)
    assert fb
    np.testing.assert_allclose(got, fk(q)[0])
    V, FB = fd.evaluate(np.array([[10.0, 10.0], [1.0, 0.5]]))
    assert FB.tolist() == [True, False]
    # a constant field pushing out of the hull: every step after leaving is a fallback step
    const = VectorField("delaunay", k=2).fit(TRI4, np.tile([1.0, 0.0], (4, 1)))
    p = follow_field(const, [1.0, 1.0], 10)
    np.testing.assert_allclose(p.points[-1], [11.0, 1.0])
    assert p.steps == 10 and p.fallback_steps == 7  # x = 1, 2, 3 are inside (x + y <= 4), then outside


def test_find_simplex_minus_one_guard(monkeypatch):
    """scipy issue 21279: find_simplex may return -1 for an inside point; we retry and find it."""
    tri = SafeDelaunay().fit(TRI4)
    real = tri._tri.find_simplex
    calls = {"plain": 0}

    def flaky(xi, bruteforce=False, tol=None):
        if not bruteforce:
            calls["plain"] += 1
            return np.full(np.atleast_2d(xi).shape[0], -1, dtype=np.intc)
        return real(xi, bruteforce=True)

    monkeypatch.setattr(tri._tri, "find_simplex", flaky)
    s, bary = tri.find(np.array([[1.0, 0.5], [10.0, 10.0]]))
    assert s[0] >= 0 and s[1] == -1 and calls["plain"] == 1
    np.testing.assert_allclose(bary[0].sum(), 1.0)
    assert tri.find_one(np.array([1.0, 0.5])) >= 0


# ----------------------------------------------------------------------------- errors
def test_error_a_and_f_known_answers():
    line = np.stack([np.arange(11.0), np.zeros(11)], axis=1)
    shifted = line + [0.0, 1.0]
    a, t2g, g2t = error_a(line, shifted)
    assert a == pytest.approx(1.0) and t2g == pytest.approx(1.0) and g2t == pytest.approx(1.0)
    assert error_f(line, shifted) == pytest.approx(1.0)
    half = line[:6]
    a, t2g, g2t = error_a(line, half)
    assert t2g == pytest.approx(15 / 11) and g2t == pytest.approx(0.0) and a == pytest.approx(15 / 22)
    assert error_f(line, half) == pytest.approx(5.0)
    # closest point is inside a segment, not a vertex
    assert point_polyline_distance([[0.5, 2.0]], [[0.0, 0.0], [1.0, 0.0]])[0] == pytest.approx(2.0)
    # a one-point "polyline" and a zero-length segment
    assert point_polyline_distance([[3.0, 4.0]], [[0.0, 0.0]])[0] == pytest.approx(5.0)
    assert point_polyline_distance([[3.0, 4.0]], [[0.0, 0.0], [0.0, 0.0]])[0] == pytest.approx(5.0)


def test_polyline_distance_chunking_matches():
    rng = np.random.default_rng(0)
    p, line = rng.normal(size=(50, 5)), rng.normal(size=(40, 5))
    np.testing.assert_allclose(point_polyline_distance(p, line), point_polyline_distance(p, line, max_elems=7))


# ----------------------------------------------------------------------------- degenerate input
def test_duplicates_are_merged_not_crashing():
    x = np.vstack([TRI4, TRI4[[3, 3]]])  # two extra copies of the interior point
    rep, uniq = merge_duplicates(x, 1e-12)
    assert rep.tolist() == [0, 1, 2, 3, 3, 3] and uniq.tolist() == [0, 1, 2, 3]
    tri = SafeDelaunay().fit(x)
    assert tri.n_duplicates_ == 2 and tri.status_ == "ok"
    e = set(map(tuple, tri.edges().tolist()))
    assert {(3, 4), (3, 5), (4, 5), (0, 4), (1, 5)} <= e
    v = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, 2.0], [0.0, 4.0], [0.0, 0.0]])
    f = VectorField("delaunay").fit(x, v)
    np.testing.assert_allclose(f(TRI4[3])[0], [0.0, 2.0])  # mean of the three coincident vectors
    g = MotionGraph("delaunay").fit(x, v, [3, 3])
    assert g.connectivity()["n_tie_edges"] >= 3


def test_collinear_points_use_their_affine_hull():
    x = np.stack([np.arange(5.0), 2 * np.arange(5.0)], axis=1)
    tri = SafeDelaunay().fit(x)
    assert tri.status_ == "reduced_rank" and tri.rank_ == 1
    assert sorted(map(tuple, tri.edges().tolist())) == [(0, 1), (1, 2), (2, 3), (3, 4)]
    s, bary = tri.find(np.array([[1.5, 3.0], [1.5, 0.0], [9.0, 18.0]]))
    assert s[0] >= 0 and s[1] == -1 and s[2] == -1
    np.testing.assert_allclose(bary[0], [0.5, 0.5])
    v = np.tile([1.0, 2.0], (5, 1))
    f = VectorField("delaunay").fit(x, v)
    assert f([1.5, 3.0])[1] is False and f([1.5, 0.0])[1] is True


@pytest.mark.parametrize("pts, rank, status", [
    (np.array([[0.0, 0.0], [1.0, 1.0]]), 1, "reduced_rank"),  # fewer than d+1 points
    (np.array([[2.0, 2.0]]), 0, "single_point"),
    (np.array([[1.0, 1.0], [1.0, 1.0], [1.0, 1.0]]), 0, "single_point"),
    (np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), 2, "reduced_rank"),  # 3 points in 3-D
    (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.3, 0.4, 0]], float), 2, "reduced_rank"),  # coplanar
])
def test_rank_deficient_inputs(pts, rank, status):
    tri = SafeDelaunay().fit(pts)
    assert tri.rank_ == rank and tri.status_ == status and tri.notes_
    v = np.ones_like(pts)
    f = VectorField("delaunay", k=2).fit(pts, v)
    got, _ = f(pts.mean(axis=0))
    np.testing.assert_allclose(got, np.ones(pts.shape[1]))
    MotionGraph("delaunay").fit(pts, v, [len(pts)]).connectivity()


def test_qhull_failure_is_retried_then_falls_back(monkeypatch):
    real = geometry.Delaunay
    seen = []

    def fail_first(points, qhull_options=None):
        seen.append(qhull_options)
        if qhull_options is None:
            raise QhullError("QH6154 simulated failure")
        return real(points, qhull_options=qhull_options)

    monkeypatch.setattr(geometry, "Delaunay", fail_first)
    tri = SafeDelaunay().fit(TRI4)
    assert tri.status_ == "joggled" and seen[-1].startswith("QJ") and "Qz" not in seen[-1] and tri.simplices_.shape[0] >= 3

    def always_fail(points, qhull_options=None):
        raise QhullError("QH6154 simulated failure")

    monkeypatch.setattr(geometry, "Delaunay", always_fail)
    tri = SafeDelaunay().fit(TRI4)
    assert tri.status_ == "failed" and tri.simplices_.shape[0] == 0
    f = VectorField("delaunay", k=2).fit(TRI4, np.ones((4, 2)), triangulation=tri)
    assert f([1.0, 0.5])[1] is True  # every query falls back to k-NN


def test_bad_input_is_rejected_clearly():
    with pytest.raises(ValueError, match="NaN"):
        SafeDelaunay().fit(np.array([[0.0, np.nan], [1.0, 1.0]]))
    with pytest.raises(ValueError, match="non-empty"):
        SafeDelaunay().fit(np.zeros((0, 2)))
    with pytest.raises(ValueError, match="latent_dim"):
        fl.fit_pca([np.zeros((3, 4))], 5)
    with pytest.raises(ValueError, match="simplicial.steps"):
        fl.steps_for(0, 10)


# ----------------------------------------------------------------------------- planning, folds, tables
def test_target_planner_follows_the_graph():
    t = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    loop = np.stack([np.cos(t), np.sin(t)], axis=1)
    tang = np.stack([-np.sin(t), np.cos(t)], axis=1)
    g = MotionGraph("knn", k=2).fit(loop, tang, [12])
    path, info = TargetPlanner().fit(g).plan(loop[0], loop[3])
    assert info["reached"] and info["nodes"] == 4
    np.testing.assert_allclose(path.points[-1], loop[3])
    # edges only run counter-clockwise: going "back" one node takes 11 hops (single-source mode too)
    _, info2 = TargetPlanner(max_all_pairs=1).fit(g).plan(loop[1], loop[0])
    assert info2["reached"] and info2["nodes"] == 12
    # unreachable target: stop at the reachable node closest to it, and say so
    line = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [100.0, 0.0], [101.0, 0.0]])
    g2 = MotionGraph("knn", k=1).fit(line, np.tile([1.0, 0.0], (5, 1)), [3, 2])
    p3, info3 = TargetPlanner().fit(g2).plan(line[0], line[4])
    assert not info3["reached"] and info3["target_node"] == 2 and len(p3.points) == 4


def _toy_trials(n_trials=3, n=60, seed=0):
    """Trials on one closed latent loop (a gait-like cycle) embedded in 8 "joint angles"."""
    rng = np.random.default_rng(seed)
    mix = rng.normal(size=(3, 8))
    out = {}
    for i in range(n_trials):
        ph = np.linspace(0, 4 * np.pi, n) + rng.uniform(0, 1)
        r = 1.0 + 0.05 * rng.normal()
        base = np.stack([r * np.cos(ph), r * np.sin(ph), 0.1 * np.cos(2 * ph)], axis=1)
        out[f"t{i}"] = 20 * base @ mix + rng.normal(scale=1e-3, size=(n, 8))
    return out


def test_run_fold_and_tables_on_toy_data():
    trials = _toy_trials()
    df = fl.run_subset(trials, [fl.Variant("delaunay"), fl.Variant("knn", method="knn", k=4)], dataset="w1")
    assert list(df.columns) == fl.FOLD_COLUMNS and len(df) == 6
    assert np.isfinite(df[["error_a", "error_f", "error_a_pose", "pose_floor"]].to_numpy(float)).all()
    assert (df["pose_floor"] >= 0).all()
    assert (df["steps"] == 60).all() and (df["latent_dim"] == 2).all()
    # a latent loop traversed with the printed 1/2 covers about half the arc
    assert df["length_ratio"].between(0.3, 0.7).all()
    paper = pd.DataFrame([{"metric": "error_a", "method": "delaunay", "w1": 1.5, "all": 2.0}])
    t2 = tb.table2(df, ["w1"], paper=paper)
    assert list(t2.columns) == ["metric", "method", "w1", "all", "paper_w1", "paper_all", "w1_minus_paper",
                                "all_minus_paper"]
    assert t2[["metric", "method"]].values.tolist() == [["error_a", "delaunay"], ["error_a", "knn"],
                                                        ["error_f", "delaunay"], ["error_f", "knn"]]
    assert t2.loc[0, "paper_w1"] == 1.5 and np.isnan(t2.loc[1, "paper_w1"]) and np.isnan(t2.loc[3, "paper_all"])
    assert t2.loc[0, "w1_minus_paper"] == pytest.approx(t2.loc[0, "w1"] - 1.5)
    assert np.isnan(t2.loc[1, "w1_minus_paper"])
    d = df[df["method"] == "knn"]
    assert t2.loc[3, "w1"] == pytest.approx(d["error_f_norm"].median())
    pc = st.paired_comparison(df, n_boot=200, seed=1)
    assert set(pc["verdict"]) <= {"delaunay_better", "knn_better", "no_significant_difference"}
    again = st.paired_comparison(df, n_boot=200, seed=1)
    pd.testing.assert_frame_equal(pc, again)  # deterministic given the seed


def test_target_variant_and_verdicts():
    trials = _toy_trials(3, 50, seed=2)
    vs = fl.derivative_variants(["half", "forward"], ["delaunay", "knn"], 4, 2)
    d = fl.run_subset(trials, vs, dataset="w1")
    ds = st.derivative_summary(d, claim="delaunay_better", n_boot=100)
    assert set(ds["derivative"]) == {"half", "forward"}
    half = ds.set_index("derivative").loc["half"]
    assert 0.3 < half["delaunay_length_ratio"] < 0.7
    bv = fl.beyond_variants({"latent_dims": [2, 3], "k_values": [4], "barycentric": True, "kdelaunay": True,
                             "target_directed": True}, 4, "forward")
    names = [v.name for v in bv]
    assert "target_delaunay_d2" in names and "delaunay_bary_d3" in names and len(names) == len(set(names))
    b = fl.run_subset(trials, bv, dataset="w1")
    tgt = b[b["generation"] == "target"]
    assert (tgt["fallback_steps"] == 0).all() and tgt["target_reached"].isin([True, False]).all()
    bs = st.summarise_variants(b, "delaunay_idw_d2", ["w1"], n_boot=100)
    assert sorted(bs["variant"]) == sorted(names) and bs["error_a_pose"].is_monotonic_increasing
    assert bs.set_index("variant").loc["delaunay_idw_d2", "rel_change_vs_baseline"] == 0.0
    assert "half" in ds["derivative"].tolist()
