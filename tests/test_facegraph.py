"""Facial motion graphs: similarity, Algorithm 1, threshold search, merging,
synthesis, determinism, pre-processing and the face-graph baseline."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import OptimizeWarning
from scipy.special import expit

from animsynth.config import ConfigError
from conftest import default_config
from animsynth.facegraph import (FaceGraphBaseline, FaceGraphModel, FacePreprocessor, FaceSynthesizer,
                                 SynthesisError, load_graphs, node_similarity, pose_similarity, save_graphs, vinfl)
from animsynth.facegraph.evaluate import compare, velocity_angle_difference
from animsynth.facegraph.jobs import data_note, run_configuration, uniqueness_tables
from animsynth.facegraph.settings import config_name, configurations
from animsynth.facegraph.geometry import apply_transform_2d, fit_transform_2d
from animsynth.facegraph.merging import _rigid2d, merge_sample_graphs
from animsynth.facegraph.samplegraphs import (PoseStack, RegionData, create_sample_graphs, creation_compression,
                                              region_data, sample_nodes)
from animsynth.facegraph.preprocess import FaceDatabase, fit_sigmoid_landmarks, sigmoid
from animsynth.facegraph.regions import DEFAULT_REDUCED, DEFAULT_REGIONS, check_regions
from animsynth.facegraph.search import step_halving_search
from animsynth.facegraph.synthesis import hop_neighbours, resample
from animsynth.io.ckplus import EMOTIONS
from animsynth.synth.faces import generate_sequences


@pytest.fixture(scope="module")
def db() -> FaceDatabase:
    seqs = generate_sequences(n_subjects=5, n_sequences=14, total_frames=300, n_unlabelled=1, seed=3)
    return FacePreprocessor().fit_transform(seqs, source="synthetic test")


@pytest.fixture(scope="module")
def model(db) -> FaceGraphModel:
    return FaceGraphModel(50, 50, seed=7).fit(db)


# -- similarity (eq. 3) on hand-made poses ------------------------------------
def test_vinfl_cases_and_zero_velocity_rule():
    v = np.array([[1.0, 0.0]])
    assert vinfl(v, np.array([[2.0, 0.0]]))[0] == pytest.approx(0.0)       # parallel
    assert vinfl(v, np.array([[0.0, 3.0]]))[0] == pytest.approx(1.0)       # perpendicular
    assert vinfl(v, np.array([[-5.0, 0.0]]))[0] == pytest.approx(0.0)      # opposite: |cos| = 1
    assert vinfl(v, np.array([[1.0, 1.0]]))[0] == pytest.approx(1 - np.sqrt(0.5))
    assert vinfl(v, np.array([[0.0, 0.0]]))[0] == 0.0                      # zero velocity: no direction
    assert vinfl(v, np.array([[0.0, 0.005]]), eps=0.01)[0] == 0.0          # below eps


def test_pose_similarity_hand_made():
    da = np.array([[0.0, 0.0], [10.0, 0.0]])
    db_ = np.array([[3.0, 4.0], [10.0, 4.0]])        # distances 5 and 4
    va = np.array([[1.0, 0.0], [0.0, 1.0]])
    vb = np.array([[0.0, 2.0], [0.0, -1.0]])         # landmark 0 perpendicular, landmark 1 opposite
    assert pose_similarity(da, va, db_, vb, lam=1.0) == pytest.approx(5 * 2 + 4 * 1)
    assert pose_similarity(da, va, db_, vb, lam=0.5) == pytest.approx(5 * 1.5 + 4)
    assert pose_similarity(da, va, db_, vb, lam=0.0) == pytest.approx(9.0)
    assert pose_similarity(da, va, da, vb) == 0.0                          # same position: 0 whatever the velocity
    # node form: minimum over incoming-edge velocities
    vin_b = np.stack([vb, np.array([[1.0, 0.0], [0.0, 1.0]])])
    assert node_similarity(da, va[None], db_, vin_b) == pytest.approx(9.0)


# -- Algorithm 1 --------------------------------------------------------------
def _toy_stack(forward_x, n_landmarks=2):
    f = np.asarray(forward_x, float)
    x = np.concatenate([f, f[-2::-1]])
    T = len(x)
    X = np.zeros((1, 1, T, n_landmarks, 2))
    X[..., 0] = x[None, None, :, None]
    zeros = np.zeros((1, 1, T, n_landmarks))
    return PoseStack(("toy",), X, np.zeros_like(X), zeros, np.array([T]), np.array([len(f)]))


def test_algorithm1_toy_sequence_known_merges():
    stack = _toy_stack([0.0, 0.1, 0.2, 10.0, 10.1, 20.0])   # -> 11 poses neutral-peak-neutral
    a = create_sample_graphs(stack, [1.0])[0, 0, 0]
    # 3 nodes: {0, .1, .2} (consecutive merges, and the reversed tail folds back), {10, 10.1}, {20}
    assert a.tolist() == [0, 0, 0, 1, 1, 2, 1, 1, 0, 0, 0]
    assert len(a) - (a.max() + 1) == 8                       # 8 merges
    assert creation_compression(create_sample_graphs(stack, [1.0]), stack.forward)[0, 0] == pytest.approx(50.0)
    # threshold 0: only exact duplicates (the reversed copy) merge
    a0 = create_sample_graphs(stack, [0.0])[0, 0, 0]
    assert a0.tolist() == [0, 1, 2, 3, 4, 5, 4, 3, 2, 1, 0]
    # large threshold: one node
    assert create_sample_graphs(stack, [1e6])[0, 0, 0].max() == 0


def _reference_alg1(X, V, T, lam=1.0, eps=1e-2, Q=3):
    """Direct, unpruned Algorithm 1 for one sample (the library's reference implementation)."""
    from animsynth.facegraph.samplegraphs import create_sample_graph_reference

    return create_sample_graph_reference(X, V, T, lam=lam, eps=eps, max_entries=Q)


def test_algorithm1_vectorised_matches_reference(db):
    rd = region_data(db)
    stack = PoseStack.from_region_data(rd)
    for thr in (0.3, 1.0, 3.0):
        a = create_sample_graphs(stack, [thr] * 5)[0]
        for ri, r in enumerate(stack.regions):
            for s in (0, 5, 11):
                o = rd[r].offsets
                X = rd[r].disp[o[s]:o[s + 1]][:, rd[r].red]
                V = rd[r].vel[o[s]:o[s + 1]][:, rd[r].red]
                assert np.array_equal(a[ri, s, : len(X)], _reference_alg1(X, V, thr)), (thr, r, s)


def test_sample_nodes_visits_and_peak_duration():
    f = np.array([0.0, 0.1, 0.2, 10.0, 10.1, 20.0])
    stack = _toy_stack(f)
    x = stack.X[0, 0]
    rd = RegionData("toy", np.arange(2), np.arange(2), x, np.zeros_like(x), np.array([0, 11]), np.array([6]),
                    np.array([4]), np.zeros((2, 2)))
    nd = sample_nodes(rd, create_sample_graphs(stack, [1.0])[0, 0])
    assert nd.n == 3 and nd.count.tolist() == [6, 4, 1]
    assert nd.visit_node.tolist() == [0, 1, 2, 1, 0] and nd.visit_len.tolist() == [3, 2, 1, 2, 3]
    assert nd.peak.tolist() == [False, False, True] and nd.peak_dur[2] == 6   # neutral-to-peak frames
    np.testing.assert_allclose(nd.disp[1, :, 0], 10.05)


# -- merging ------------------------------------------------------------------
def test_merge_identical_samples_and_connectivity():
    f = np.array([0.0, 0.1, 0.2, 10.0, 10.1, 20.0])
    x = np.concatenate([f, f[-2::-1]])
    X1 = np.zeros((11, 2, 2))
    X1[..., 0] = x[:, None]
    X = np.concatenate([X1, X1, X1 + [0.0, 100.0]])  # two identical samples and one far away
    V = np.gradient(X1, axis=0)
    V = np.concatenate([V, V, V])
    rd = RegionData("toy", np.arange(2), np.arange(2), X, V, np.array([0, 11, 22, 33]), np.array([6, 6, 6]),
                    np.array([5, 7, 4]), np.array([[0.0, 0.0], [1.0, 0.0]]))
    stack = PoseStack(("toy",), np.stack([X[:11], X[11:22], X[22:]])[None], *[None] * 2,
                      np.array([11, 11, 11]), np.array([6, 6, 6]))
    stack.U, stack.ok = np.zeros_like(stack.X), np.zeros(stack.X.shape[:-1])
    nd = sample_nodes(rd, create_sample_graphs(stack, [1.0])[0, 0])
    assert nd.n == 9
    g = merge_sample_graphs(rd, nd, 0.5, np.array([0, 1, 2]))
    assert g.n_nodes == 6                              # sample 2 absorbed entirely, sample 3 kept apart
    assert g.start_of_sample.tolist() == [0, 0, 3] and g.peak_of_sample.tolist() == [2, 2, 5]
    assert g.peak_mask[2] == (1 << 5) | (1 << 7) and g.peak_mask[5] == 1 << 4
    assert g.visits.tolist() == [4, 4, 2, 2, 2, 1] and g.merge_count[0] == pytest.approx(3.0)
    assert sorted(map(tuple, g.edges.tolist())) == [(0, 1), (1, 0), (1, 2), (2, 1), (3, 4), (4, 3), (4, 5), (5, 4)]
    assert np.all(g.weights > 0)
    assert merge_sample_graphs(rd, nd, 0.5, np.array([0, 1, 2]), count_only=True) == g.n_nodes
    # everything merges with a huge threshold
    assert merge_sample_graphs(rd, nd, 1e9, np.array([0, 1, 2]), count_only=True) == 1
    # synthesis on a graph that is not strongly connected: sample 3 (fear) is unreachable from the
    # shared neutral node 0, so the region restarts from sample 3's neutral node (logged, recorded)
    syn = FaceSynthesizer({"toy": g}, sigmoid_weight=0.0)
    assert syn.start_nodes() == {"toy": 0}
    anim = syn.synthesize(["surprise", "fear"], rng=0)
    assert anim.paths["toy"][0].tolist() == [0, 1, 2]
    assert anim.jumps == [(1, "toy", 2, 3)] and anim.paths["toy"][1].tolist() == [3, 4, 5]
    g2 = merge_sample_graphs(rd, nd, 0.5, np.array([0, 1, 2]))
    g2.start_of_sample = np.array([0, 0, 0])  # no neutral node reaches the fear peak any more
    with pytest.raises(SynthesisError, match="nor from any neutral node"):
        FaceSynthesizer({"toy": g2}).synthesize(["fear"], rng=0)


def test_procrustes_fits():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(12, 2))
    th = 0.3
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    b = a @ R.T + [5.0, -2.0]
    R2, t2 = _rigid2d(a, b)
    np.testing.assert_allclose(R2, R, atol=1e-12)
    np.testing.assert_allclose(a @ R2.T + t2, b, atol=1e-12)
    Rs, s, t = fit_transform_2d(a, 2.5 * b, scale=True)
    np.testing.assert_allclose(apply_transform_2d(a, Rs, s, t), 2.5 * b, atol=1e-10)
    assert float(s) == pytest.approx(2.5)
    with pytest.raises(ValueError, match="degenerate"):
        fit_transform_2d(np.zeros((4, 2)), b[:4], scale=True)


# -- threshold search -----------------------------------------------------------
def test_step_halving_search_on_known_curve():
    calls = []

    def comp(T):
        calls.append(T.copy())
        return 100.0 * T / (1.0 + T)  # compression 50 % at T = 1, 80 % at T = 4

    res = step_halving_search(comp, 80.0, 0.5, t0=[0.2, 9.0], step0=[0.5, 0.5], max_iter=60)
    assert res.converged.all()
    assert np.all(np.abs(res.compression - 80.0) <= 0.5)
    np.testing.assert_allclose(res.threshold, 4.0, rtol=0.05)
    # a step function that jumps over the target cannot converge: closest value reported, flagged
    res = step_halving_search(lambda T: np.where(T < 1.0, 10.0, 90.0), 50.0, 1.0, [0.5], [0.3], max_iter=20)
    assert not res.converged[0] and res.compression[0] in (10.0, 90.0) and res.iterations[0] == 20
    with pytest.raises(ValueError):
        step_halving_search(comp, 50, 1, [-1.0], [1.0])


@pytest.mark.parametrize("creation, merge", [(30, 70), (60, 40)])
def test_global_threshold_search_reaches_targets(db, creation, merge):
    m = FaceGraphModel(creation, merge, tolerance=1.0, seed=1, thresholds="global").fit(db)
    s = m.search_
    assert s.creation_converged.all() and s.merge_converged.all()
    assert np.all(np.abs(s.creation_achieved_pct - creation) <= 1.0)
    assert np.all(np.abs(s.merge_achieved_pct - merge) <= 1.0)
    for r, g in m.graphs_.items():  # achieved merge compression is that of the returned graph
        row = s.set_index("region").loc[r]
        assert row.merge_achieved_pct == pytest.approx(100 * (1 - g.n_nodes / row.sample_nodes))
    assert m.timings_["creation_cpu_s"] > 0


def test_fixed_thresholds_skip_search(db, model):
    m = FaceGraphModel(seed=7, creation_thresholds=model.creation_thresholds_,
                       merge_thresholds=model.merge_thresholds_).fit(db)
    for r in model.graphs_:
        assert m.graphs_[r].n_nodes == model.graphs_[r].n_nodes
        np.testing.assert_array_equal(m.graphs_[r].edges, model.graphs_[r].edges)


def test_node_data(db, model):
    for r, g in model.graphs_.items():
        assert g.disp.shape == (g.n_nodes, len(DEFAULT_REGIONS[r]), 2)
        assert np.all(g.merge_count >= 1) and g.pose_count.sum() == sum(2 * db.lengths - 1)
        pk = np.flatnonzero(g.peak_mask)
        assert np.all(np.isfinite(g.peak_dur_mean[pk])) and np.all(np.isnan(g.peak_dur_mean[g.peak_mask == 0]))
        assert np.all(np.isfinite(g.peak_dur_std[pk]))
        # each peak node stores the durations of exactly the samples that peak there
        held = np.bincount(g.peak_of_sample, minlength=g.n_nodes)
        np.testing.assert_array_equal(g.peak_dur_n[pk], held[pk])
        # every sample's peak node carries its label
        for s in range(db.n_samples):
            assert g.peak_mask[g.peak_of_sample[s]] & (1 << db.emotions[s])
            assert g.label_mask[g.start_of_sample[s]] & (1 << db.emotions[s])


def test_save_load_graphs(tmp_path, model):
    save_graphs(tmp_path / "g.npz", model.graphs_, meta={"config": "c50_m50"})
    back, meta = load_graphs(tmp_path / "g.npz")
    assert meta == {"config": "c50_m50"} and list(back) == list(model.graphs_)
    for r, g in model.graphs_.items():
        for k in g._ARRAYS:
            np.testing.assert_array_equal(getattr(back[r], k), getattr(g, k))
        assert back[r].info == g.info


# -- synthesis ------------------------------------------------------------------
def test_dijkstra_synthesis_reaches_requested_label(db, model):
    syn = FaceSynthesizer(model.graphs_)
    for label in sorted(set(db.label_names())):
        anim = syn.synthesize([label], rng=1)
        assert anim.disp.shape[1:] == (68, 2) and anim.n_frames >= 2 and np.all(np.isfinite(anim.disp))
        code = EMOTIONS.index(label)
        for r, g in model.graphs_.items():
            path = anim.paths[r][0]
            assert g.peak_mask[path[-1]] & (1 << code), (label, r)
            # a real Dijkstra path: consecutive nodes are edges of the graph
            A = g.csr()
            assert all(A[a, b] > 0 for a, b in zip(path[:-1], path[1:]))
        # the last frame is close to the peak nodes' mean displacements (smoothing aside)
        peak = np.zeros((68, 2))
        for r, g in model.graphs_.items():
            peak[g.landmarks] = g.disp[anim.paths[r][0][-1]]
        assert np.abs(anim.disp[-1] - peak).max() < 0.5 * np.abs(peak).max() + 0.5


def test_chained_labels_and_errors(db, model):
    syn = FaceSynthesizer(model.graphs_, noise_share=0.3, duration_noise=True)
    anim = syn.synthesize(["fear", "surprise", "happy"], rng=3)
    assert [s[2] for s in anim.segments] == ["fear", "surprise", "happy"]
    assert anim.segments[0][0] == 0 and anim.segments[-1][1] == anim.n_frames
    for r, g in model.graphs_.items():
        assert [bool(g.peak_mask[p[-1]] & (1 << EMOTIONS.index(lab)))
                for p, lab in zip(anim.paths[r], ["fear", "surprise", "happy"])] == [True] * 3
        jump = {si: (a, b) for si, rr, a, b in anim.jumps if rr == r}
        if 1 in jump:  # no surprise peak reachable from the fear peak: logged restart from a neutral node
            assert jump[1][0] == anim.raw_paths[r][0][-1] and anim.paths[r][1][0] == jump[1][1]
            assert g.start_of_sample.tolist().count(jump[1][1]) >= 1
        else:
            assert anim.paths[r][1][0] == anim.raw_paths[r][0][-1]  # next segment starts at the previous peak
    with pytest.raises(ValueError, match="unknown CK\\+ emotion"):
        syn.synthesize(["joy"])
    missing = [e for e in range(1, 8) if e not in set(db.emotions.tolist())]
    if missing:
        with pytest.raises(SynthesisError, match="no peak node"):
            syn.synthesize([missing[0]])


def test_coherent_noise_replaces_with_same_label_neighbours(model):
    g = model.graphs_["mouth"]
    syn = FaceSynthesizer({"mouth": g}, noise_share=1.0, noise_hops=2)
    rng = np.random.default_rng(0)
    long = None
    for s in range(5):  # a path with interior nodes from an actual synthesis
        p = FaceSynthesizer({"mouth": g}).synthesize(["surprise"], rng=s).paths["mouth"][0]
        if len(p) > 3:
            long = p
            break
    assert long is not None
    noisy = syn._coherent_noise(g, long, rng)
    assert noisy[0] == long[0] and noisy[-1] == long[-1]
    changed = 0
    for old, new in zip(long[1:-1], noisy[1:-1]):
        if old != new:
            changed += 1
            assert new in hop_neighbours(g, old, 2) and g.label_mask[new] & g.label_mask[old]
    assert changed >= 1  # noise_share = 1: interior nodes are replaced where a candidate exists
    # hop neighbourhoods on the undirected graph
    u = g.undirected()
    one = hop_neighbours(g, long[1], 1)
    assert set(one.tolist()) == set(u.indices[u.indptr[long[1]]:u.indptr[long[1] + 1]].tolist()) - {long[1]}
    assert set(one.tolist()) <= set(hop_neighbours(g, long[1], 2).tolist())


def test_determinism_under_seed(db):
    a = FaceGraphModel(50, 50, seed=11).fit(db)
    b = FaceGraphModel(50, 50, seed=11).fit(db)
    for r in a.graphs_:
        for k in a.graphs_[r]._ARRAYS:
            np.testing.assert_array_equal(getattr(a.graphs_[r], k), getattr(b.graphs_[r], k))
    sa = FaceSynthesizer(a.graphs_, noise_share=0.3, duration_noise=True)
    sb = FaceSynthesizer(b.graphs_, noise_share=0.3, duration_noise=True)
    x = sa.synthesize(["happy", "anger"], rng=5).disp
    np.testing.assert_array_equal(x, sb.synthesize(["happy", "anger"], rng=5).disp)
    assert not np.array_equal(x, sa.synthesize(["happy", "anger"], rng=6).disp)
    c = FaceGraphModel(50, 50, seed=12).fit(db)
    assert c.seed_sample_ != a.seed_sample_ or not np.array_equal(c.order_, a.order_)


def test_motion_recovery_steps(model):
    g = model.graphs_["eyebrows"]
    syn = FaceSynthesizer({"eyebrows": g}, sigmoid_weight=0.0)
    path = None
    for s in range(10):
        p = syn.synthesize(["surprise"], rng=s).paths["eyebrows"][0]
        if len(p) >= 3:
            path = p
            break
    traj = syn._expand(g, path, True)
    n = np.maximum(1, np.rint(g.merge_count[path]).astype(int))
    n[-1] = 1
    assert len(traj) == n.sum()                                  # step 1 frame counts
    np.testing.assert_allclose(traj[-1], g.disp[path[-1]])       # ends on the peak pose
    # node centre: the frames of node k are centred on its mean displacement, and clamped at the midpoints
    k0 = 0
    for k in range(len(path) - 1):
        seg = traj[k0:k0 + n[k]]
        if n[k] % 2 == 1:
            np.testing.assert_allclose(seg[n[k] // 2], g.disp[path[k]], atol=1e-9)
        half = 0.5 * np.sqrt(((g.disp[path[k + 1]] - g.disp[path[k]]) ** 2).sum(-1))
        assert np.all(np.sqrt(((seg - g.disp[path[k]]) ** 2).sum(-1)) <= np.maximum(
            half, 0.5 * np.sqrt(((g.disp[path[max(k - 1, 0)]] - g.disp[path[k]]) ** 2).sum(-1))) + 1e-9)
        k0 += n[k]
    np.testing.assert_allclose(resample(np.arange(5.0)[:, None], 9)[:, 0], np.arange(9) / 2)


def test_synthesised_duration_matches_peak_node_duration(db):
    m = FaceGraphModel(20, 70, creation_tolerance=10, merge_tolerance=20, seed=3).fit(db)
    syn = FaceSynthesizer(m.graphs_)
    for s in range(0, db.n_samples, 3):
        own = {r: int(g.peak_of_sample[s]) for r, g in m.graphs_.items()}
        anim = syn.synthesize([int(db.emotions[s])], start=syn.start_nodes(sample=s), peak_nodes=own)
        want = np.mean([m.graphs_[r].peak_dur_mean[own[r]] for r in own])
        assert anim.n_frames == max(1, int(np.rint(want)))
        # a peak node holding only this sample's peak stores exactly its duration
        for r, g in m.graphs_.items():
            if g.peak_dur_n[own[r]] == 1:
                assert g.peak_dur_mean[own[r]] == db.lengths[s]


def test_per_sample_thresholds_hit_each_samples_band(db):
    m = FaceGraphModel(30, 60, creation_tolerance=10, merge_tolerance=25, seed=1).fit(db)
    smp = m.samples_
    c_in = (smp.creation_pct - 30).abs() <= 10
    assert c_in.mean() >= 0.9                                   # nearly every sample in its own band
    merged = smp.dropna(subset=["merge_pct"])
    assert ((merged.merge_pct - 60).abs() <= 25).mean() >= 0.9
    # thresholds differ between samples (per sample), unlike the global mode
    assert smp.groupby("region").creation_threshold.nunique().min() > 1
    glob = FaceGraphModel(30, 60, creation_tolerance=10, merge_tolerance=25, seed=1, thresholds="global").fit(db)
    assert glob.samples_.groupby("region").creation_threshold.nunique().max() == 1


def test_angle_measure_perpendicular_is_100_percent():
    t = np.linspace(0, 1, 11)
    a = np.zeros((11, 3, 2))
    a[..., 0] = 5 * t[:, None]
    b = np.zeros_like(a)
    b[..., 1] = 5 * t[:, None]
    assert velocity_angle_difference(a, b) == pytest.approx(100.0)


def test_database_with_huge_coordinate_is_refused(db):
    bad = FaceDatabase(list(db.names), db.emotions, db.lengths, db.disp.copy(), db.neutral, db.mean_neutral,
                       db.regions, db.reduced)
    bad.disp[3, 10, 0] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        FaceGraphModel(20, 70, creation_tolerance=10, merge_tolerance=20).fit(bad)
    seqs = generate_sequences(n_subjects=3, n_sequences=6, total_frames=90, n_unlabelled=0, seed=2)
    seqs[1].landmarks[2, 5, 0] = 1e300
    with pytest.raises(ValueError, match="non-finite or huge"):
        FacePreprocessor().fit_transform(seqs)


def test_region_beyond_the_compiled_sum_limit_is_refused_with_its_size(db):
    regions = dict(db.regions)
    name = next(iter(regions))
    regions[name] = np.tile(np.asarray(regions[name]), 300 // len(regions[name]) + 1)[:300]
    big = FaceDatabase(list(db.names), db.emotions, db.lengths, db.disp, db.neutral, db.mean_neutral,
                       regions, db.reduced)
    with pytest.raises(ValueError, match=f"more than 240 landmarks.*'{name}': 300"):
        FaceGraphModel(20, 70, creation_tolerance=10, merge_tolerance=20).fit(big)


# -- pre-processing -------------------------------------------------------------
def test_sigmoid_fit_recovers_known_sigmoid():
    t = np.arange(25.0)
    d = np.zeros((25, 3, 2))
    d[:, 0, 0] = sigmoid(t, 0.2, 8.0, 0.6, 12.0)
    d[:, 0, 1] = sigmoid(t, -0.1, -3.0, 0.6, 12.0)
    d[:, 1, :] = 0.01 * np.sin(t)[:, None]                 # static landmark
    d[:, 2, 1] = sigmoid(t, 0.0, 5.0, 1.3, 6.0)
    fit, status = fit_sigmoid_landmarks(d, min_range=0.5)
    assert status == ["fit", "static", "fit"]
    np.testing.assert_allclose(fit[:, [0, 2]], d[:, [0, 2]], atol=1e-5)
    np.testing.assert_allclose(fit[:, 1], np.broadcast_to(d[:, 1].mean(0), (25, 2)))
    # a one-frame jump (jitter of a still landmark) is not fitted by a step: the grid's onset is kept
    step = np.zeros((25, 1, 2))
    step[20:, 0, 1] = 2.0
    fit, status = fit_sigmoid_landmarks(step, min_range=0.5)
    assert status == ["grid"] and np.abs(np.diff(fit[:, 0, 1])).max() < 1.5


def _old_sigmoid_xy(tt, ax, ay, bx, by, k, c):
    # the model curve_fit was given: x displacements then y displacements, shared timing (k, c)
    n = tt.size // 2
    s = expit(k * (tt[:n] - c))
    return np.concatenate([ax + bx * s, ay + by * s])


def _old_sigmoid_xy_jac(tt, ax, ay, bx, by, k, c):
    n = tt.size // 2
    t = tt[:n]
    s = expit(k * (t - c))
    ds = s * (1.0 - s)
    one, zero = np.ones(n), np.zeros(n)
    jx = np.stack([one, zero, s, zero, bx * ds * (t - c), -bx * ds * k], 1)
    jy = np.stack([zero, one, zero, s, by * ds * (t - c), -by * ds * k], 1)
    return np.concatenate([jx, jy], 0)


def _old_curve_fit(t, y, p0):
    """The refinement as fit_sigmoid_landmarks called it before it called leastsq itself."""
    from scipy.optimize import curve_fit

    popt, _ = curve_fit(_old_sigmoid_xy, np.concatenate([t, t]), y, p0=p0, jac=_old_sigmoid_xy_jac, maxfev=400)
    return popt


def _curve_fit_reference(d, monkeypatch):
    """fit_sigmoid_landmarks as it was with ``scipy.optimize.curve_fit``: the production function with its refinement
    (``_sigmoid_xy_fit``) replaced by curve_fit on the model it was given. Returns the fitted displacements, the
    statuses and, per refined landmark, (data, start, curve_fit's parameters or the type of the exception it raised)."""
    from animsynth.facegraph import preprocess

    calls = []

    def refine(t, y, p0, jac):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", OptimizeWarning)
                popt = _old_curve_fit(t, y, p0)
        except (RuntimeError, ValueError) as e:
            calls.append((y, p0, type(e)))
            raise
        calls.append((y, p0, popt))
        return popt

    with monkeypatch.context() as m:
        m.setattr(preprocess, "_sigmoid_xy_fit", refine)
        out, status = preprocess.fit_sigmoid_landmarks(d)
    refined = [i for i, s in enumerate(status) if s != "static"]  # refined in landmark order, the static ones not
    assert len(refined) == len(calls)
    return out, status, dict(zip(refined, calls))


def test_sigmoid_fit_is_curve_fits_bit_for_bit(monkeypatch):
    # fit_sigmoid_landmarks calls scipy's leastsq itself (no covariance, no curve_fit wrappers): the fitted
    # displacements, statuses and parameters are curve_fit's exactly (np.array_equal, not a tolerance)
    from animsynth.facegraph.preprocess import _sigmoid_xy_fit, _sigmoid_xy_jac_buffer

    samples = []
    for kw in (dict(seed=3), dict(seed=4, jitter_px=2.5, head_rotation_deg=4.0)):  # real-shaped; noisy
        seqs = generate_sequences(n_subjects=2, n_sequences=4, total_frames=100, n_unlabelled=0, **kw)
        samples += [s.landmarks - s.landmarks[0] for s in seqs]
    t = np.arange(25.0)
    toy = np.zeros((25, 4, 2))
    toy[:, 0, 0] = sigmoid(t, 0.2, 8.0, 0.6, 12.0)
    toy[:, 0, 1] = sigmoid(t, -0.1, -3.0, 0.6, 12.0)
    toy[:, 1, :] = 0.01 * np.sin(t)[:, None]                        # static
    toy[20:, 2, 1] = 2.0                                             # a one-frame step: the grid sigmoid is kept
    toy[:, 3] = np.random.default_rng(0).normal(0.0, 1.5, (25, 2))  # noise only
    samples.append(toy)
    seen, n_params, n_raised = set(), 0, 0
    for d in samples:
        fit, status = fit_sigmoid_landmarks(d)
        ref, ref_status, fits = _curve_fit_reference(d, monkeypatch)
        assert status == ref_status
        assert np.array_equal(fit, ref)
        seen.update(status)
        td = np.arange(len(d), dtype=float)
        jac = _sigmoid_xy_jac_buffer(len(d))
        for i, (y, p0, ref_p) in fits.items():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                if isinstance(ref_p, type):  # curve_fit raised (maxfev reached): so does the leastsq path
                    with pytest.raises(ref_p):
                        _sigmoid_xy_fit(td, y, p0, jac)
                    n_raised += 1
                elif status[i] == "fit":
                    # parameters of the kept fits; those of rejected ones are discarded and, in rank-deficient
                    # steps, depend on memory scipy 1.17's MINPACK reads past its Jacobian copy (curve_fit's too)
                    assert np.array_equal(_sigmoid_xy_fit(td, y, p0, jac), ref_p)
                    n_params += 1
    assert seen == {"fit", "grid", "static"} and n_params > 350 and n_raised > 10
    # non-finite data: both raise ValueError (the landmark keeps its grid sigmoid)
    y, p0, _ = fits[0]
    y = np.where(np.arange(50) == 7, np.nan, y)
    with pytest.raises(ValueError):
        _old_curve_fit(t, y, p0)
    with pytest.raises(ValueError):
        _sigmoid_xy_fit(t, y, p0, _sigmoid_xy_jac_buffer(25))


def test_preprocessing_alignment_and_reversal(db):
    seqs = generate_sequences(n_subjects=2, n_sequences=3, total_frames=60, n_unlabelled=0, seed=9,
                              jitter_px=0.0, head_rotation_deg=0.0, head_translation_px=0.0)
    base = FacePreprocessor().fit_transform(seqs)
    # adding a rigid head motion changes nothing after stage-1/2 alignment (up to the sigmoid fit)
    moved = []
    for s in seqs:
        lm = s.landmarks.copy()
        th = np.deg2rad(np.linspace(0, 4, len(lm)))
        c = lm[0].mean(0)
        for i in range(len(lm)):
            R = np.array([[np.cos(th[i]), -np.sin(th[i])], [np.sin(th[i]), np.cos(th[i])]])
            lm[i] = (lm[i] - c) @ R.T + c + [3.0 * i / len(lm), -2.0 * i / len(lm)]
        moved.append(type(s)(s.subject, s.sequence, lm, s.emotion))
    other = FacePreprocessor().fit_transform(moved)
    assert np.abs(other.disp - base.disp).max() < 0.5
    assert np.abs(base.disp).max() > 5  # expressions are kept
    # displacement form and neutral-peak-neutral samples
    assert np.all(base.forward(0)[0] == 0)
    x, v = base.npn(0)
    F = base.lengths[0]
    assert len(x) == 2 * F - 1 and np.array_equal(x[F - 1 + 3], x[F - 1 - 3])
    np.testing.assert_allclose(v[F - 1], 0.0, atol=1e-12)  # the peak has zero velocity
    # database round trip
    assert db.n_samples == 14 and db.disp.shape == (int(db.lengths.sum()), 68, 2)


def test_preprocessor_checks(tmp_path, db):
    with pytest.raises(ValueError, match="at least 2 labelled"):
        FacePreprocessor().fit_transform(generate_sequences(n_subjects=1, n_sequences=1, total_frames=20,
                                                            n_unlabelled=2, seed=0)[:1])
    db.save_npz(tmp_path / "db.npz")
    back = FaceDatabase.load_npz(tmp_path / "db.npz")
    np.testing.assert_array_equal(back.disp, db.disp)
    assert back.names == db.names and back.source == "synthetic test"


def test_region_config_checks():
    r, red, rig = check_regions(None, None, None)
    assert sum(len(v) for v in r.values()) == 68
    bad = dict(DEFAULT_REGIONS, nose=[i for i in DEFAULT_REGIONS["nose"] if i != 34])
    with pytest.raises(ConfigError, match=r"landmarks \[34\] belong to no region"):
        check_regions(bad, DEFAULT_REDUCED)
    with pytest.raises(ConfigError, match="in both"):
        check_regions(dict(DEFAULT_REGIONS, eyes=DEFAULT_REGIONS["eyes"] + [27]), DEFAULT_REDUCED)
    with pytest.raises(ConfigError, match="reduced_landmarks.mouth"):
        check_regions(DEFAULT_REGIONS, dict(DEFAULT_REDUCED, mouth=[48, 1]))


def test_facegraph_config_checks():
    from animsynth.facegraph.settings import check

    config = default_config()
    cfg = config["facegraph"]
    check(config)

    def with_fg(**change):
        return dict(config, facegraph=dict(cfg, **change))

    with pytest.raises(ConfigError, match="duplicate configuration"):
        check(with_fg(configurations=[{"creation": 0.5, "creation_tolerance": 0.1, "merge": 0.5,
                                       "merge_tolerance": 0.1}] * 2))
    with pytest.raises(ConfigError, match="uniqueness.labels"):
        check(with_fg(uniqueness={"labels": ["joy"], "runs": 3}))
    with pytest.raises(ConfigError, match="ckplus_dir"):
        check(with_fg(ckplus_dir="/nonexistent/ck"))
    with pytest.raises(ConfigError, match="facegraph.synthesis.savgol_window"):
        check(with_fg(synthesis=dict(cfg["synthesis"], savgol_window=6)))
    with pytest.raises(ConfigError, match="facegraph.figures.trajectory_landmarks"):
        check(with_fg(figures=dict(cfg["figures"], trajectory_landmarks=[70])))
    assert config_name(0.5, 0.125) == "c0.5_m0.125"
    assert config_name(0.2, 0.7, 0.1, 0.3) == "c0.2t0.1_m0.7t0.3"
    assert len({c["name"] for c in configurations(cfg)}) == 15
    assert "not the paper's CK+ data" in data_note("synthetic CK+-layout database (animsynth.synth.faces)")
    assert "real CK+ landmarks" in data_note("CK+ at /data/CK+")


# -- evaluation, experiments, baseline ------------------------------------------------
def test_measures_on_known_inputs():
    t = np.linspace(0, 1, 21)
    a = np.zeros((21, 2, 2))
    a[:, :, 0] = 10 * t[:, None]
    assert velocity_angle_difference(a, a) == 0.0
    assert velocity_angle_difference(a, -a) == pytest.approx(200.0)   # 90 degrees = 100 %
    b = a.copy()
    b[:, :, 1] = 10 * t[:, None]               # 45 degrees off
    assert velocity_angle_difference(a, b) == pytest.approx(50.0)
    c = compare(a, a[::2] + [0.0, 3.0])        # half as long (same span), shifted by 3 px
    assert c["duration_diff"] == 10 and c["landmark_diff_px"] == pytest.approx(3.0, abs=1e-9)


def test_face_graph_baseline_on_a_line():
    x = np.zeros((4, 68, 2))
    x[:, :, 0] = np.arange(4.0)[:, None]
    db = FaceDatabase(["S1_001", "S1_002"], np.array([1, 2]), np.array([2, 2]), x, np.zeros((2, 68, 2)),
                      np.zeros((68, 2)), {k: np.array(v) for k, v in DEFAULT_REGIONS.items()},
                      {k: np.array(v) for k, v in DEFAULT_REDUCED.items()})
    plain = FaceGraphBaseline(power=1).fit(db)
    anim, secs, paths = plain.synthesize(0, 3)
    assert paths["face"].tolist() == [0, 3] and len(anim) == 2   # triangle inequality: direct jump
    sq = FaceGraphBaseline(power=2).fit(db)
    assert sq.synthesize(0, 3)[2]["face"].tolist() == [0, 1, 2, 3]           # squared L2: small steps
    reg = FaceGraphBaseline(power=2, per_region=True).fit(db)
    assert len(reg.graphs_) == 5 and reg.synthesize(3, 0)[2]["mouth"].tolist() == [3, 2, 1, 0]
    assert plain.nbytes() == 4 * (16 + 4 * 136) and reg.n_edges == 5 * 12


def test_table1_row_uniqueness_and_connectivity(db):
    fg = default_config()["facegraph"]
    cfg = {"graph": fg["graph"], "synthesis": dict(fg["synthesis"], noise_share=0.3, duration_noise=True),
           "evaluation": dict(fg["evaluation"], noise=False),
           "uniqueness": dict(fg["uniqueness"], labels=["happy", "surprise"], runs=4)}
    conf = {"name": "c0.3t0.1_m0.5t0.2", "creation": 0.3, "creation_tolerance": 0.1, "merge": 0.5,
            "merge_tolerance": 0.2}
    row, timing, thr, model, per = run_configuration(db, conf, cfg, seed=4)
    assert row["config"] == conf["name"] and len(per) == db.n_samples and len(thr) == 5
    frames = int(db.lengths.sum())
    assert row["node_compression_pct"] == pytest.approx(100 * (1 - row["nodes"] / frames), abs=1e-4)
    assert not any(k.startswith("timing") or k.endswith("_s") for k in row)   # timings live in the timing row
    assert timing["creation_cpu_s"] > 0
    # every sample's peak node is reachable from its neutral node in every region
    for g in model.graphs_.values():
        from scipy.sparse.csgraph import dijkstra

        d = dijkstra(g.csr(), indices=g.start_of_sample)
        assert np.isfinite(d[np.arange(db.n_samples), g.peak_of_sample]).all()
    again = run_configuration(db, conf, cfg, seed=4)[0]
    assert row == again
    summary, pairs = uniqueness_tables(model.graphs_, cfg, seed=2)
    assert summary["distinct"].iloc[0] == 1                        # fixed peaks, no noise: all runs equal
    assert summary["distinct"].iloc[2] == 4                        # node + duration noise: all runs differ
    assert len(pairs) == 4 * 6 and pairs[pairs.setting == summary.setting.iloc[0]].identical.all()
    # the verdicts of these tables: the common format, words of the common vocabulary
    from animsynth import verdicts as common
    from animsynth.facegraph.jobs import assemble_table1, baseline_table
    from animsynth.facegraph.verdicts import build_verdicts

    table1 = assemble_table1([row], [row["config"]])
    base, _ = baseline_table(db, model.graphs_, dict(cfg, baseline=dict(fg["baseline"], max_queries=3)), 4,
                             row["config"])
    v = build_verdicts(table1, base, summary, "synthetic test")
    assert tuple(v.columns) == common.COLUMNS and len(v) >= 8
    common.check(v)
    assert set(v.verdict) <= set(common.VOCABULARY)
    assert v.data.eq("synthetic CK+-layout, 1 configurations").all()
    # one configuration: no rank correlation to test, so the trend is undecided (no evidence is never "not reproduced")
    assert (v.loc[v.claim == "Landmark error rises with compression", "verdict"] == "undecided").all()


# -- the published Table 1 (animsynth.published.read_table, mapped to configuration names) ---------------
def test_published_table1_maps_rows_to_configuration_names(tmp_path, caplog):
    from animsynth.facegraph.settings import PAPER_COLUMNS, published_table1
    from animsynth.published import PublishedError
    from conftest import PAPERS

    fixture = PAPERS / "s4_table1.csv"
    got = published_table1(fixture)
    raw = pd.read_csv(fixture)
    assert len(got) == len(raw)
    first = raw.iloc[0]
    name = config_name(first.creation_target, first.merge_target, first.creation_tolerance, first.merge_tolerance)
    assert got[name]["row"] == int(first["row"])
    assert got[name]["node_compression_pct"] == first["nodes_compression_pct"]
    assert set(got[name]) == set(PAPER_COLUMNS) | {"row"}
    # no file: {} and a WARNING naming the path
    with caplog.at_level("WARNING", logger="animsynth.published"):
        assert published_table1(tmp_path / "absent.csv") == {}
    assert "absent.csv" in caplog.text and "published.facegraph.table1" in caplog.text
    # malformed: the file and the line
    bad = tmp_path / "bad.csv"
    bad.write_text(fixture.read_text().replace("\n2,", "\nx,", 1))
    with pytest.raises(PublishedError, match=r"bad\.csv, line 3: column 'row'"):
        published_table1(bad)
    lines = fixture.read_text().splitlines()
    dup = tmp_path / "dup.csv"
    dup.write_text("\n".join(lines + [lines[1]]) + "\n")
    with pytest.raises(PublishedError, match=rf"dup\.csv, line {len(lines) + 1}: configuration {name} already"):
        published_table1(dup)
    no_col = tmp_path / "no_col.csv"
    no_col.write_text(raw.drop(columns="landmark_diff_px").to_csv(index=False))
    with pytest.raises(PublishedError, match=r"no_col\.csv, line 1: .*landmark_diff_px"):
        published_table1(no_col)
