"""The compiled field-following loop (simplicial.kernels) against the numpy/scipy reference."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from animsynth.simplicial import kernels
from animsynth.simplicial import path as pm
from animsynth.simplicial.field import FieldStack, VectorField, training_vectors
from animsynth.simplicial.geometry import SafeDelaunay
from animsynth.simplicial.path import follow_batch, follow_field


def _walk_clips(n=4, frames=150, seed=0):
    """Noisy loops of different radii and phases: a walking-like latent set with a few hundred points."""
    rng = np.random.default_rng(seed)
    clips = []
    for i in range(n):
        ph = np.linspace(0, 4 * np.pi, frames) + rng.uniform(0, 2 * np.pi)
        r = 1.0 + 0.1 * i
        clips.append(np.stack([r * np.cos(ph), 0.7 * r * np.sin(ph)], axis=1) + rng.normal(scale=0.02, size=(frames, 2)))
    return clips


def _starts(X, n, seed, outside=2):
    rng = np.random.default_rng(seed)
    s = X[rng.integers(0, len(X), n)] + 0.03 * rng.normal(size=(n, X.shape[1]))
    if outside:
        s[:outside] = [[3.0, 2.5], [-2.6, -2.2]][:outside]  # outside the hull: k-NN fallback for Delaunay
    return s


def _reference(fields, starts, steps, which):
    return [follow_field(fields[w], s, steps, compiled=False) for s, w in zip(starts, which)]


def _assert_steps_are_the_reference(fields, which, b, atol=1e-12):
    """Every step of every path is the reference field (VectorField.__call__) at that path's point.

    Checked step by step, so float-rounding differences cannot grow along a
    path (over 100+ steps they grow chaotically on some fields, up to 1e-9
    between two reference routes).
    """
    for j, w in enumerate(which):
        pts = b.points[:, j]
        for t in range(pts.shape[0] - 1):
            v, fb = fields[w](pts[t])
            np.testing.assert_allclose(pts[t + 1] - pts[t], v, rtol=0, atol=atol, err_msg=f"path {j}, step {t}")
            assert b.fallback[t, j] == fb, (j, t)


@pytest.mark.parametrize("derivative", ["half", "forward", "central"])
def test_compiled_batch_equals_reference_one_at_a_time(derivative):
    clips = _walk_clips()
    X = np.vstack(clips)
    tri = SafeDelaunay().fit(X)
    V = training_vectors(clips, derivative)
    fields = [VectorField("delaunay", 6).fit(X, V, triangulation=tri), VectorField("knn", 6).fit(X, V, triangulation=tri)]
    starts = np.vstack([_starts(X, 12, 1), _starts(X, 12, 2)])
    which = np.repeat([0, 1], 12)
    steps = 150
    b = follow_batch(fields, starts, steps, which)
    assert pm._compiled_fields(FieldStack(fields)).all()
    _assert_steps_are_the_reference(fields, which, b)
    assert b.fallback[:, :2].any() and not b.fallback[:, 2:12].all()  # the outside starts fell back, then came in
    # whole paths: the same as following each path alone, and as the numpy batch (per-step FieldStack route)
    ref = _reference(fields, starts, 40, which)
    bn = follow_batch(fields, starts, 40, which, compiled=False)
    for j, one in enumerate(ref):
        np.testing.assert_allclose(b.points[:41, j], one.points, rtol=0, atol=1e-9, err_msg=f"path {j}")
        np.testing.assert_array_equal(b.fallback[:40, j], one.fallback)
    np.testing.assert_allclose(b.points[:41], bn.points, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(b.fallback[:40], bn.fallback)


def test_single_path_entry_points_agree():
    clips = _walk_clips(seed=3)
    X = np.vstack(clips)
    V = training_vectors(clips, "half")
    for method in ("delaunay", "knn"):
        f = VectorField(method, 8).fit(X, V)
        for start in (X[7], X[7] + 0.011, np.array([2.9, -2.4])):  # on a training point, inside, outside
            ref = follow_field(f, start, 40, compiled=False)
            b = follow_batch(f, start[None], 300)
            _assert_steps_are_the_reference([f], [0], b)
            for got in (follow_field(f, start, 300), b.path(0)):
                np.testing.assert_allclose(got.points[:41], ref.points, rtol=0, atol=1e-9)
                np.testing.assert_array_equal(got.fallback[:40], ref.fallback)


def test_parallel_serial_and_python_refill_routes_agree(monkeypatch):
    clips = _walk_clips(seed=5)
    X = np.vstack(clips)
    tri = SafeDelaunay().fit(X)
    fields = [VectorField(m, 5).fit(X, training_vectors(clips, d), triangulation=tri)
              for m in ("delaunay", "knn") for d in ("half", "central")]
    stack = FieldStack(fields)
    starts = np.repeat(_starts(X, 10, 7), 4, axis=0)
    which = np.tile(np.arange(4), 10)
    monkeypatch.setattr(pm, "PARALLEL_MIN_PATHS", 1)
    par = pm._follow_compiled(stack, starts, 120, which)
    monkeypatch.setattr(pm, "PARALLEL_MIN_PATHS", 10 ** 9)
    ser = pm._follow_compiled(stack, starts, 120, which)
    nob = pm._follow_compiled(stack, starts, 120, which, brute=False)  # uncertified k-NN steps go to Python
    # paths are independent: the thread count must not change a single bit (so checking the serial
    # route against the reference checks the parallel one too)
    np.testing.assert_array_equal(par[0], ser[0])
    np.testing.assert_array_equal(par[1], ser[1])
    for route in (ser, nob):
        _assert_steps_are_the_reference(fields, which, pm.BatchPaths(*route))
    np.testing.assert_allclose(par[0][:41], nob[0][:41], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(par[1], nob[1])


def test_certified_knn_equals_exact_knn():
    clips = _walk_clips(seed=9)
    X = np.vstack(clips)
    f = VectorField("knn", 7).fit(X, training_vectors(clips))
    tab = pm._kernel_tables(FieldStack([f]))
    tree = cKDTree(f.points_)
    rng = np.random.default_rng(4)
    k = 7
    bd, bi = np.empty(k), np.empty(k, np.int64)
    n_cert = 0
    xs = np.vstack([f.points_[rng.integers(0, len(f.points_), 300)] + 0.05 * rng.normal(size=(300, 2)),
                    rng.uniform(-3, 3, size=(100, 2))])  # near the data, and anywhere (incl. outside the hull)
    for x in xs:
        d, i = tree.query(x, k=k)
        for a in (int(i[0]), int(rng.integers(0, len(f.points_)))):  # nearest anchor, and a random one
            ok = kernels._knn_list(x, a, k, tab["nl"], tab["nc"], tab["dl"], tab["Rend"], tab["eps"], tab["pu"], bd, bi)
            if ok:
                n_cert += 1
                assert set(bi.tolist()) == set(i.tolist())
                np.testing.assert_allclose(np.sort(bd), d, rtol=1e-12)
                assert bi[0] == i[0]
        kernels._knn_brute(x, k, tab["pu"], bd, bi)
        np.testing.assert_array_equal(bi, i)
        np.testing.assert_allclose(bd, d, rtol=1e-12)
    assert n_cert > 300  # the lists certify most queries near the data


def test_a_false_certificate_is_caught():
    """The comparison has teeth: lists that claim to hold every point (Rend = inf) but hold only k give wrong paths."""
    clips = _walk_clips(seed=11)
    X = np.vstack(clips)
    f = VectorField("knn", 6).fit(X, training_vectors(clips, "forward"))
    stack = FieldStack([f])
    tab = pm._kernel_tables(stack)
    for key in ("nl", "nc", "dl"):
        tab[key] = np.ascontiguousarray(tab[key][:, :6])
    tab["Rend"] = np.full(len(tab["Rend"]), np.inf)
    starts = _starts(X, 10, 12, outside=0)
    bad = pm.BatchPaths(*pm._follow_compiled(stack, starts, 100, np.zeros(10, int)))
    with pytest.raises(AssertionError):
        _assert_steps_are_the_reference([f], np.zeros(10, int), bad)


def test_unsupported_fields_take_the_reference_route():
    clips = _walk_clips(seed=13)
    X = np.vstack(clips)
    tri = SafeDelaunay().fit(X)
    V = training_vectors(clips)
    fields = [VectorField("kdelaunay", 5).fit(X, V, triangulation=tri),
              VectorField("delaunay", weights="barycentric").fit(X, V, triangulation=tri),
              VectorField("delaunay").fit(X, V, triangulation=tri)]
    assert pm._compiled_fields(FieldStack(fields)).tolist() == [False, False, True]
    starts = np.repeat(_starts(X, 5, 14), 3, axis=0)
    which = np.tile(np.arange(3), 5)
    b = follow_batch(fields, starts, 80, which)
    _assert_steps_are_the_reference(fields, which, b)


@pytest.mark.parametrize("dim", [3, 4])
def test_compiled_route_in_higher_latent_dimensions_with_merged_duplicates(dim):
    rng = np.random.default_rng(dim)
    clips = []
    for i in range(3):
        ph = np.linspace(0, 4 * np.pi, 120) + rng.uniform(0, 2 * np.pi)
        base = np.stack([np.cos(ph), 0.7 * np.sin(ph), 0.5 * np.sin(2 * ph), 0.3 * np.cos(3 * ph)][:dim], axis=1)
        clips.append((1.0 + 0.1 * i) * base + rng.normal(scale=0.02, size=(120, dim)))
    clips.append(clips[0][:40].copy())  # exact copies: merged points that weigh m / D^2
    X = np.vstack(clips)
    tri = SafeDelaunay().fit(X)
    assert tri.n_duplicates_ >= 40
    for derivative in ("half", "forward"):
        V = training_vectors(clips, derivative)
        fields = [VectorField(m, 6).fit(X, V, triangulation=tri) for m in ("delaunay", "knn")]
        starts = X[rng.integers(0, len(X), 8)] + 0.02 * rng.normal(size=(8, dim))
        which = np.repeat([0, 1], 4)
        b = follow_batch(fields, starts, 80, which)
        assert pm._compiled_fields(FieldStack(fields)).all()
        _assert_steps_are_the_reference(fields, which, b)


def test_refitted_triangulation_drops_the_compiled_tables_of_the_old_points():
    clips = _walk_clips(seed=11)
    X = np.vstack(clips)
    tri = SafeDelaunay().fit(X)
    V = training_vectors(clips, "half")
    f = VectorField("delaunay", 6).fit(X, V, triangulation=tri)
    follow_batch(f, X[:3] + 0.01, 30)  # builds and caches the compiled tables
    clips2 = [1.7 * c[::-1] + 0.3 for c in clips]
    X2 = np.vstack(clips2)
    tri.fit(X2)  # the same object, other points
    f2 = VectorField("delaunay", 6).fit(X2, training_vectors(clips2, "half"), triangulation=tri)
    b = follow_batch(f2, X2[:3] + 0.01, 30)
    _assert_steps_are_the_reference([f2], [0, 0, 0], b)
