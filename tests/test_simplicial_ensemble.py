"""Batched field following, ensembles of starts, duplicate weighting, published values and verdicts."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from animsynth.simplicial import folds as fl, stats as st, tables as tb
from animsynth.simplicial.field import FieldStack, VectorField, training_vectors
from animsynth.simplicial.geometry import SafeDelaunay
from animsynth.simplicial.path import follow_batch, follow_field
from animsynth.published import PublishedError
from animsynth.simplicial.settings import paper_claim_from, read_paper_table2
from animsynth.simplicial.verdicts import build_verdicts
from animsynth.verdicts import COLUMNS, VOCABULARY, VerdictError

VOCAB = set(VOCABULARY)


def _loop_data(n=3, frames=60, seed=0):
    rng = np.random.default_rng(seed)
    clips = []
    for i in range(n):
        ph = np.linspace(0, 2 * np.pi, frames, endpoint=False) + 0.1 * i
        r = 1.0 + 0.05 * rng.normal()
        clips.append(np.stack([r * np.cos(ph), r * np.sin(ph)], axis=1) + rng.normal(scale=0.01, size=(frames, 2)))
    return clips


def _trials(n=3, frames=50, seed=2):
    rng = np.random.default_rng(seed)
    mix = rng.normal(size=(3, 8))
    out = {}
    for i in range(n):
        ph = np.linspace(0, 4 * np.pi, frames) + rng.uniform(0, 2 * np.pi)
        base = np.stack([np.cos(ph), np.sin(ph), 0.1 * np.cos(2 * ph)], axis=1)
        out[f"t{i}"] = 20 * base @ mix + rng.normal(scale=1e-3, size=(frames, 8))
    return out


@pytest.mark.parametrize("method,weights", [("delaunay", "idw"), ("knn", "idw"), ("kdelaunay", "idw"),
                                            ("delaunay", "barycentric")])
def test_batched_equals_one_at_a_time(method, weights):
    clips = _loop_data()
    X = np.vstack(clips)
    V = training_vectors(clips, "half")
    f = VectorField(method, 5, weights).fit(X, V)
    rng = np.random.default_rng(1)
    starts = X[rng.integers(0, len(X), 7)] + 0.02 * rng.normal(size=(7, 2))
    starts[0] = [3.0, 3.0]  # outside the hull: k-NN fallback for the simplex methods
    b = follow_batch(f, starts, 40)
    assert b.points.shape == (41, 7, 2) and b.fallback.shape == (40, 7)
    for j in range(7):
        one = follow_field(f, starts[j], 40, compiled=False)
        np.testing.assert_allclose(b.points[:, j], one.points, rtol=0, atol=1e-9)
        assert (b.fallback[:, j] == one.fallback).all()
    if method != "knn":
        assert b.fallback[:, 0].any()  # the outside start really fell back


def test_batched_mixed_fields_share_one_triangulation():
    clips = _loop_data()
    X = np.vstack(clips)
    tri = SafeDelaunay().fit(X)
    fields = [VectorField(m, 4).fit(X, training_vectors(clips, d), triangulation=tri)
              for m in ("delaunay", "knn") for d in ("half", "forward")]
    starts = np.repeat(X[:3], len(fields), axis=0)
    which = np.tile(np.arange(len(fields)), 3)
    b = follow_batch(fields, starts, 25, which)
    for j in range(len(starts)):
        one = follow_field(fields[which[j]], starts[j], 25, compiled=False)
        np.testing.assert_allclose(b.points[:, j], one.points, rtol=0, atol=1e-9)
    with pytest.raises(ValueError, match="same triangulation"):
        FieldStack([fields[0], VectorField("knn").fit(X, training_vectors(clips))])


def test_duplicate_group_weighs_m_over_d2():
    # point A is a group of 3 coincident frames, B a single one; the query is twice as far from A as from B
    pts = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [3.0, 0.0], [10.0, 10.0]])
    vec = np.array([[1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0], [5.0, 5.0]])
    q = np.array([2.0, 0.0])
    f = VectorField("knn", k=2).fit(pts, vec)
    assert f.counts_.tolist() == [3.0, 1.0, 1.0]
    wa, wb = 3 / 2.0 ** 2, 1 / 1.0 ** 2  # m / D^2
    want = (wa * vec[0] + wb * vec[3]) / (wa + wb)
    np.testing.assert_allclose(f(q)[0], want)
    np.testing.assert_allclose(f.evaluate(q[None])[0][0], want)
    # the same as 1/D^2 over the original, unmerged points (the 3 copies + B)
    d = np.linalg.norm(pts[:4] - q, axis=1)
    w = 1 / d ** 2
    np.testing.assert_allclose(f(q)[0], (w @ vec[:4]) / w.sum())
    # and differs from the old 1/D^2 over merged points
    assert not np.allclose(f(q)[0], (vec[0] / 4 + vec[3]) / (1 / 4 + 1))


def test_zero_jitter_reproduces_the_single_path():
    trials = _trials()
    ids = list(trials)
    train = [trials[t] for t in ids[1:]]
    variants = [fl.Variant("delaunay"), fl.Variant("knn", method="knn", k=4)]
    rows, members = fl.run_fold_ensemble(train, trials[ids[0]], variants, n_starts=3, jitter=0.0, seed=5)
    assert len(members) == 2 * 4 and set(members["member"]) == {0, 1, 2, 3}
    for v, r in zip(variants, rows):
        single = fl.run_fold(train, trials[ids[0]], v).row
        for c in ("error_a", "error_f", "error_a_norm", "error_a_pose", "fallback_steps", "length_ratio"):
            assert r[c] == pytest.approx(single[c], rel=1e-9, abs=1e-12), c
        m = members[members["variant"] == v.name]
        assert np.ptp(m["error_a_norm"]) < 1e-12  # every member is the same path
        assert (m["sep_final_rel"] == 0).all()
        assert r["ens_error_a_norm_q25"] == pytest.approx(r["ens_error_a_norm_q75"])


def test_jittered_starts_are_seeded_and_at_the_given_distance():
    s = np.array([1.0, 2.0, 3.0])
    a = fl.jittered_starts(s, 5, 1e-3, 10.0, seed=7)
    np.testing.assert_array_equal(a, fl.jittered_starts(s, 5, 1e-3, 10.0, seed=7))
    assert not np.allclose(a, fl.jittered_starts(s, 5, 1e-3, 10.0, seed=8))
    np.testing.assert_array_equal(a[0], s)
    np.testing.assert_allclose(np.linalg.norm(a[1:] - s, axis=1), 1e-2)
    with pytest.raises(ValueError, match="simplicial.ensemble"):
        fl.jittered_starts(s, 2, -1.0, 1.0, seed=0)


def test_missing_paper_file_means_no_published_values(tmp_path, caplog):
    with caplog.at_level("WARNING", logger="animsynth.published"):
        assert read_paper_table2(tmp_path / "absent.csv") is None
    assert "absent.csv" in caplog.text and "published.simplicial.table2" in caplog.text
    assert read_paper_table2(None) is None
    assert paper_claim_from(None, "knn_better") == "knn_better"
    trials = _trials()
    folds, members = fl.run_subset(trials, [fl.Variant("delaunay"), fl.Variant("knn", method="knn", k=4)],
                                   dataset="w1", ensemble={"n_starts": 2, "jitter": 1e-6}, seed=3)
    t2 = tb.table2(folds, ["w1"], paper=None)
    assert t2[["paper_w1", "paper_all"]].isna().all().all() and t2[["w1", "all"]].notna().all().all()
    t2e = tb.table2_ensemble(members, ["w1"], paper=None)
    assert t2e["paper_delaunay"].isna().all() and (t2e["paper_ordering"] == "").all()


def test_paper_file_is_read_and_knn16_maps_to_knn(tmp_path):
    p = tmp_path / "t2.csv"
    p.write_text("metric,method,w1,w2,r1,r2,all\nerror_a,delaunay,0.02,,0.1,0.1,0.068\n"
                 "error_a,knn16,0.03,0.1,0.1,0.1,0.079\nerror_f,delaunay,0.02,0.1,0.1,0.1,0.041\n"
                 "error_f,knn16,0.05,0.1,0.1,0.1,0.042\n")
    paper = read_paper_table2(p)
    assert paper["method"].tolist() == ["delaunay", "knn", "delaunay", "knn"]
    assert paper["paper_method"].tolist() == ["delaunay", "knn16", "delaunay", "knn16"]
    assert paper.loc[0, "all"] == 0.068 and np.isnan(paper.loc[0, "w2"])  # an empty cell: no published value
    assert paper_claim_from(paper, "unknown") == "delaunay_better"
    for name, text, where in [
        ("number", "metric,method,w1,w2,r1,r2,all\nerror_a,delaunay,zero,1,1,1,1\n", r"number.csv, line 2: column 'w1'"),
        ("metric", "metric,method,w1,w2,r1,r2,all\nerror_a,knn,1,1,1,1,1\nerror_z,knn,1,1,1,1,1\n",
         r"metric.csv, line 3: metric must be one of"),
        ("column", "metric,method,w1,all\nerror_a,delaunay,1,1\n", r"column.csv, line 1: .*lacks column"),
    ]:
        bad = tmp_path / f"{name}.csv"
        bad.write_text(text)
        with pytest.raises(PublishedError, match=where):
            read_paper_table2(bad)


def test_ensemble_tables_and_verdicts_on_toy_data(tmp_path):
    trials = _trials(4, 60)
    folds, members = fl.run_subset(trials, [fl.Variant("delaunay"), fl.Variant("knn", method="knn", k=4)],
                                   dataset="w1", ensemble={"n_starts": 3, "jitter": 1e-6}, seed=3)
    assert list(folds.columns) == fl.FOLD_COLUMNS and list(members.columns) == fl.MEMBER_COLUMNS
    assert (folds["n_members"] == 4).all() and len(members) == 2 * 4 * 4
    paper = pd.DataFrame([{"metric": m, "method": k, "w1": v, "all": v}
                          for m, k, v in (("error_a", "delaunay", 0.01), ("error_a", "knn", 0.02),
                                          ("error_f", "delaunay", 0.01), ("error_f", "knn", 0.02))])
    t2 = tb.table2(folds, ["w1"], paper=paper)
    t2e = tb.table2_ensemble(members, ["w1"], paper=paper)
    fe = tb.fold_ensemble(members, ["w1"])
    assert len(fe) == 4 * 2 and fe["a_lower_share"].between(0, 1).all()
    # the share is the fraction of members whose subset median is lower for delaunay
    mm = st.member_medians(members, ["w1"], "method", ("delaunay", "knn"), "error_a_norm")
    want = np.mean(mm[("delaunay", "w1")] < mm[("knn", "w1")])
    assert t2e.set_index(["metric", "dataset"]).loc[("error_a", "w1"), "a_lower_share"] == pytest.approx(want)
    pc = st.paired_comparison(folds, n_boot=100)
    vs = fl.derivative_variants(["half", "forward"], ["delaunay", "knn"], 4, 2)
    dfold, dmem = fl.run_subset(trials, vs, dataset="w1", ensemble={"n_starts": 2, "jitter": 1e-6}, seed=3)
    ds = st.derivative_summary(dfold, members=dmem, n_boot=100)
    assert ds["stability_a"].str.match(r"stable|within start-noise \(share \d+ %\)").all()
    v = build_verdicts(table2=t2, table2_ens=t2e, members=members, paired=pc, deriv=ds, folds=folds,
                       claim="delaunay_better", main_derivative="half", baseline="delaunay_idw_d2", datasets=["w1"],
                       data="synthetic w1")
    assert list(v.columns) == list(COLUMNS) and set(v["verdict"]) <= VOCAB
    overall = v[v["claim"].str.startswith("Overall median Error A")].iloc[0]
    share = float(t2e.set_index(["metric", "dataset"]).loc[("error_a", "all"), "a_lower_share"])
    assert overall["verdict"] == ("reproduced" if share == 1 else "contradicted" if share == 0 else "within noise")
    assert "ensemble members" in overall["evidence"]
    assert v["claim"].str.contains("five of the eight").any()
    assert v["claim"].str.contains("paper's range").any()


@pytest.mark.parametrize("method", ["delaunay", "knn"])
def test_single_path_fast_route_equals_follow_field(method):
    clips = _loop_data(seed=4)
    X = np.vstack(clips)
    V = training_vectors(clips, "half")
    f = VectorField(method, 6).fit(X, V)
    for start in (X[5], X[5] + 0.013, np.array([2.5, -2.5])):  # on a training point, inside, outside the hull
        one = follow_field(f, start, 60, compiled=False)
        b = follow_batch(f, start[None], 60)
        np.testing.assert_allclose(b.points[:, 0], one.points, rtol=0, atol=1e-9)
        assert (b.fallback[:, 0] == one.fallback).all()


def test_k_not_below_the_training_frames_is_refused_with_the_key(monkeypatch):
    from animsynth.simplicial import jobs

    trials = _trials(n=2, frames=10)
    monkeypatch.setattr(jobs, "load_trials", lambda paths, ids: (trials, {}))
    with pytest.raises(ValueError, match=r"'simplicial.k' = 16 must be below the 10 training frames of fold w1/t1"):
        jobs.run_main_fold([], ["t0", "t1"], "w1", "t1", {"k": 16}, seed=1)


def test_simplicial_verdicts_refuse_a_word_outside_the_vocabulary(monkeypatch):
    """build_verdicts builds its rows with animsynth.verdicts.row: a verdict word outside the vocabulary (here
    the ordering rule made to answer "yes") stops the table instead of reaching verdicts.csv."""
    from animsynth.simplicial import verdicts as sv

    trials = _trials(3, 50)
    folds, members = fl.run_subset(trials, [fl.Variant("delaunay"), fl.Variant("knn", method="knn", k=4)],
                                   dataset="w1", ensemble={"n_starts": 2, "jitter": 1e-6}, seed=3)
    vs = fl.derivative_variants(["half"], ["delaunay", "knn"], 4, 2)
    dfold, dmem = fl.run_subset(trials, vs, dataset="w1", ensemble={"n_starts": 2, "jitter": 1e-6}, seed=3)
    kw = dict(table2=tb.table2(folds, ["w1"]), table2_ens=tb.table2_ensemble(members, ["w1"]), members=members,
              paired=st.paired_comparison(folds, n_boot=100),
              deriv=st.derivative_summary(dfold, members=dmem, n_boot=100), folds=folds, claim="delaunay_better",
              main_derivative="half", baseline="delaunay_idw_d2", datasets=["w1"], data="synthetic w1")
    assert set(build_verdicts(**kw)["verdict"]) <= VOCAB
    monkeypatch.setattr(sv, "agreement_verdict", lambda share: "yes")
    with pytest.raises(VerdictError, match="'yes'"):
        build_verdicts(**kw)
