"""One estimator per method: the paper pipeline, the one-call route (CLI) and the comparison's rows call the same
code, so their numbers agree exactly; every estimator keeps the scikit-learn conventions."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import numpy as np
import pytest

from animsynth.compare.generators import names as N
from animsynth.compare.generators import registry as G
from animsynth.compare import settings
from animsynth.motion import Motion
from animsynth.resequencing import jobs as rjobs
from animsynth.resequencing.generator import Resequencer
from animsynth.resequencing.quick import resequence_motion
from animsynth.resequencing.settings import st_parameters
from animsynth.simplicial import folds as fl
from animsynth.simplicial.generate import generate_from_trials
from animsynth.simplicial.generator import FieldFollower
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

from conftest import config_block


# the fixtures cfg (the generator jobs' config) and est_walks (the synthetic walks) live in conftest.py


@pytest.fixture(scope="module")
def capture():
    return generate_motion("walk_straight", 200, 5, cmu_like_skeleton("est", 1), name="capture")


def _start(m: Motion, n: int = 8) -> Motion:
    return Motion(m.values[:n].copy(), m.skeleton, m.fps, "start")


# ----------------------------------------------------------------------------- simplicial


@pytest.mark.parametrize("method", ["delaunay", "knn"])
def test_compare_row_and_the_cli_route_give_the_same_poses(est_walks, cfg, method):
    """The comparison's delaunay / knn row (no jitter) and generate_from_trials (the CLI) from the same start:
    the same PCA, field and steps, so the same joint angles, bit for bit."""
    field = dict(cfg["field"], jitter=0.0)
    gen = G.make_generator(method, dict(cfg, field=field)).fit(est_walks[1:])
    assert isinstance(gen, FieldFollower)
    start, length = _start(est_walks[0]), 20
    out = gen.generate(start, length, seed=3)
    n_root = 6
    angles, _ = generate_from_trials([w.without_root() for w in est_walks[1:]], method=method, k=field["k"],
                                     latent_dim=field["latent_dim"], derivative=field["derivative"],
                                     steps=length * gen.steps_per_frame_, start=start.values[-1, n_root:])
    spf = gen.steps_per_frame_
    np.testing.assert_array_equal(out.values[:, n_root:], angles[spf::spf])


@pytest.mark.parametrize("variant", [fl.Variant("delaunay"), fl.Variant("knn", method="knn", k=4),
                                     fl.Variant("fw", derivative="forward", weights="barycentric", latent_dim=3)])
def test_a_paper_fold_follows_the_estimator(est_walks, variant):
    """run_fold's latent path, field and training vectors are those of the estimator fitted on the training trials."""
    trials = [w.without_root() for w in est_walks]
    res = fl.run_fold(trials[1:], trials[0], variant)
    est = FieldFollower(variant.method, variant.latent_dim, variant.k, variant.derivative,
                        weights=variant.weights).fit_angles(trials[1:])
    np.testing.assert_array_equal(res.vectors, est.vectors_)
    np.testing.assert_array_equal(res.test_latent, est.encode(trials[0]))
    path = est.follow(est.encode(trials[0])[0], len(trials[0]))  # the held-out trial's first latent frame
    np.testing.assert_array_equal(res.path.points, path.points)
    np.testing.assert_array_equal(res.path.fallback, path.fallback)


def test_the_compare_pca_is_the_family_pca(est_walks):
    """fit(database) fits PCA on the stacked joint angles: an independent scikit-learn PCA written out here."""
    from sklearn.decomposition import PCA

    est = FieldFollower().fit(est_walks)
    pca = PCA(n_components=est.latent_dim, svd_solver="full").fit(np.vstack([w.without_root() for w in est_walks]))
    np.testing.assert_array_equal(est.pca_.components_, pca.components_)
    np.testing.assert_array_equal(est.pca_.mean_, pca.mean_)


def test_a_shared_latent_space_must_have_the_same_dimension(est_walks):
    space = FieldFollower(latent_dim=2).fit_latent([w.without_root() for w in est_walks])
    with pytest.raises(ValueError, match="latent_dim 3"):
        FieldFollower(latent_dim=3).fit_field(space=space)


# ----------------------------------------------------------------------------- resequencing


@pytest.mark.parametrize("method", ["isomap", "stisomap"])
@pytest.mark.parametrize("metric", ["l2", "lee"])
def test_the_estimator_path_is_the_method_written_out(capture, method, metric):
    """Resequencer (dense) and resequence_motion against the method's steps written out here: the frame
    distances, the ST-Isomap adjustment, the smallest connecting k, the k-NN graph and Dijkstra."""
    from animsynth.resequencing.distances import l2_distances, lee_distances
    from animsynth.resequencing.embedding import checked_graph, min_connected_k, spatio_temporal_distances
    from animsynth.resequencing.features import motion_features
    from animsynth.resequencing.paths import shortest_path_frames

    feats = motion_features(capture)
    D = l2_distances(feats.linearised(False, "continuous")) if metric == "l2" else lee_distances(feats)
    Dm, always = (D, None) if method == "isomap" else spatio_temporal_distances(D)[:2]
    k = min_connected_k(Dm, always=always)
    expected, cost = shortest_path_frames(checked_graph(Dm, k, always), 150, 20)
    est = Resequencer(method, neighbours="dense", metric=metric).fit([capture])
    assert est.k_ == k
    p, c = est.path(150, 20, return_cost=True)
    np.testing.assert_array_equal(p, expected)
    assert c == cost
    np.testing.assert_array_equal(resequence_motion(capture, 150, 20, method=method, metric=metric)[0], expected)


@pytest.mark.parametrize("method", ["isomap", "stisomap"])
def test_the_study_paths_are_the_cli_route_paths(capture, method):
    """The paper study's measured paths (jobs.resequence) and resequence_motion with the same settings (L2, the
    config's ST-Isomap block in frames, the same k) run on the same graph."""
    cfg = config_block("resequencing")
    k = 12
    paths, (main, _), _, _ = rjobs.resequence(capture, False, method, "l2", k, cfg, seed=3)
    st = st_parameters(cfg["stisomap"], capture.fps)
    for (a, b), p in zip(rjobs.path_pairs(capture.n_frames, cfg["path"], 3), paths):
        q, _ = resequence_motion(capture, a, b, method=method, metric="l2", k=k, st=st,
                                 sign_mode=cfg["linearisation"]["sign_mode"])
        np.testing.assert_array_equal(p, q)


def test_the_sparse_and_dense_graphs_agree_on_the_smallest_k_of_one_capture(capture):
    """Both neighbourhoods of one capture under L2 (Isomap) connect at the same smallest k."""
    dense = Resequencer("isomap", neighbours="dense").fit([capture])
    sparse = Resequencer("isomap", neighbours="sparse").fit([capture])
    assert sparse.min_k_ == dense.min_k_


def test_dense_needs_one_clip_and_sparse_needs_l2(est_walks):
    with pytest.raises(ValueError, match="one capture"):
        Resequencer(neighbours="dense").fit(est_walks[:2])
    with pytest.raises(ValueError, match="l2 metric"):
        Resequencer(metric="lee").fit(est_walks[:2])


# ----------------------------------------------------------------------------- the conventions


def _unfitted(name, cfg, est_walks):
    return G.make_generator(name, cfg)


@pytest.mark.parametrize("name", [n for n in N.GENERATORS if n not in N.FAIRMOTION_ROWS] + ["fairmotion"])
def test_estimator_conventions(name, cfg, est_walks):
    """Parameters stored as given in __init__, fit returns self, everything fit adds ends in ``_`` (a private
    fitted attribute is ``_name_``)."""
    if settings.unavailable(name):
        pytest.skip(f"{name}: {settings.unavailable(name)}")
    gen = _unfitted(name, cfg, est_walks)
    params = [p for p in inspect.signature(type(gen).__init__).parameters if p != "self"]
    for p in params:
        assert hasattr(gen, p), f"{name}: parameter {p!r} is not stored on the estimator"
    before = set(vars(gen))
    assert gen.fit(est_walks[1:]) is gen
    added = sorted(set(vars(gen)) - before)
    assert added and all(a.endswith("_") for a in added), (name, added)


@pytest.mark.parametrize("name", [n for n in N.GENERATORS if n not in N.FAIRMOTION_ROWS] + ["fairmotion"])
def test_every_generator_declares_what_the_runner_reads(name, cfg, est_walks):
    """The interface (animsynth.generator.Generator) declares each thing the compare runner reads: ``query``,
    ``native_fps``, ``entry_seam``, ``run_notes``, ``outside_cost``, ``set_label``; every ``fit`` takes
    ``native_clips`` and every ``generate`` ``native_start``; a generator without a native rate gives the same
    motion with them ``None`` as without them."""
    from animsynth.compare import protocol, runner
    from animsynth.generator import QUERY_FUTURE_TRAJECTORY, QUERY_START, Generator

    if settings.unavailable(name):
        pytest.skip(f"{name}: {settings.unavailable(name)}")
    gen = _unfitted(name, cfg, est_walks)
    assert isinstance(gen, Generator) and gen.query in (QUERY_START, QUERY_FUTURE_TRAJECTORY)
    assert gen.entry_seam is (name != "replay") and (gen.native_fps is None) is (name != "fairmotion")
    assert "native_clips" in inspect.signature(gen.fit).parameters
    assert "native_start" in inspect.signature(gen.generate).parameters
    assert gen.outside_cost() == {"cpu_s": 0.0, "rss_mb": 0.0} and gen.set_label("w/t@0") is None
    clip = protocol.Clip("w/t@0", "w", "leave one out", "t", est_walks[0], est_walks[1:], 8, 12)
    fit_kw, gen_kw = runner.native_inputs(gen, clip)  # the clip carries no native rate: None for both
    assert fit_kw == {"native_clips": None} and gen_kw == {"native_start": None}
    if name == "fairmotion":
        return  # its fit and walk are tested with and without native clips in test_compare_motiongraph.py
    query = runner.generation_query(gen, clip)
    a = gen.fit(est_walks[1:], **fit_kw).generate(_start(est_walks[0]), 12, 3, **query, **gen_kw)
    b = _unfitted(name, cfg, est_walks).fit(est_walks[1:]).generate(_start(est_walks[0]), 12, 3, **query)
    assert np.array_equal(a.values, b.values)


def test_the_runner_reads_no_generator_attribute_by_getattr_and_no_row_by_name():
    """The compare runner reads what the interface declares: no getattr/hasattr on a generator, no row name
    compared in the runner or in scoring; the harness reads row names from the leaf module names.py."""
    root = Path(__file__).resolve().parents[1] / "src" / "animsynth" / "compare"
    for f in ("runner.py", "scoring.py", "jobs.py"):
        text = (root / f).read_text()
        assert "getattr(gen" not in text and "hasattr(gen" not in text, f
        assert '"replay"' not in text and '"fairmotion' not in text, f
    for f in ("tables.py", "plots.py", "verdicts.py", "settings.py", "runner.py", "jobs.py"):
        assert "generators.registry import" not in (root / f).read_text().replace("from .generators.registry import "
                                                                                  "make_generator", ""), f


def test_the_family_estimators_add_only_trailing_underscore_attributes(est_walks, capture):
    for est, data in ((FieldFollower(), est_walks), (Resequencer("stisomap", stisomap=config_block("resequencing")
                                                              ["stisomap"]), est_walks),
                      (Resequencer(neighbours="dense", metric="lee"), [capture])):
        before = set(vars(est))
        est.fit(data)
        added = set(vars(est)) - before
        assert added and all(a.endswith("_") and not a.startswith("_") for a in added), added


def test_the_registry_holds_no_method_code():
    """compare/generators/registry.py names estimators and reads their settings; it defines no class."""
    src = Path(G.__file__).read_text()
    classes = [n.name for n in ast.walk(ast.parse(src)) if isinstance(n, ast.ClassDef)]
    assert classes == []
    assert G.FieldFollower is FieldFollower and G.Resequencer is Resequencer


def _imports_from(path: Path, root: Path, text: str):
    """(module, names) of every ``from module import names`` in a file: relative imports of a module under src
    resolved to their absolute name; a Python file parsed, any other file (Markdown code blocks, rules) read by
    pattern."""
    import re

    if path.suffix != ".py":
        for m in re.finditer(r"from\s+([\w.]+)\s+import\s+(?:\(([^)]*)\)|([\w ,]+))", text):
            yield m.group(1), {n.split(" as ")[0].strip() for n in (m.group(2) or m.group(3)).split(",")}
        return
    parts = path.relative_to(root).with_suffix("").parts
    package = list(parts[1:-1] if parts[0] == "src" else parts[:-1])  # a module's package, or an __init__'s own
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            module = ".".join(base + ([node.module] if node.module else []))
            yield module, {a.name for a in node.names}


def _exported(tree: ast.AST) -> set[str]:
    """The names a module's ``__all__`` lists, or a package's lazy ``_EXPORTS`` maps (its ``__all__``)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id in ("__all__", "_EXPORTS")
                                                for t in node.targets):
            values = node.value.keys if isinstance(node.value, ast.Dict) else getattr(node.value, "elts", [])
            names |= {v.value for v in values if isinstance(v, ast.Constant) and isinstance(v.value, str)}
    return names


def test_the_interface_has_one_import_path():
    """Generator, Database, align_root, check_generated, play_path and the queries are imported from
    animsynth.generator alone: there is no compare.base, nothing imports a name of animsynth.generator from
    another module, and no other module exports one (in its ``__all__``); nothing imports a name from the
    registry (compare.generators.registry) that the registry does not export; it exports none of the interface."""
    import re

    import animsynth.generator as interface

    root = Path(__file__).resolve().parents[1]
    assert not (root / "src" / "animsynth" / "compare" / "base.py").exists()
    assert not set(interface.__all__) & set(G.__all__)
    files = [p for d in ("src", "tests", "workflow", "benchmarks", "docs") for p in sorted((root / d).rglob("*"))
             if p.suffix in (".py", ".smk", ".md", ".rst") and p.is_file() and p != Path(__file__).resolve()]
    files += [p for p in (root / "README.md", root / "Snakefile") if p.exists()]
    bad = []
    for p in files:
        text = p.read_text(errors="replace")
        if p.name == "library.md":  # its one note that the module is gone, for a reader of old code
            text = text.replace("`animsynth.compare.base` is gone", "")
        if re.search(r"compare\.base\b|from \.base import|compare import [^\n]*\bbase\b", text):
            bad.append((str(p.relative_to(root)), "compare.base"))
        for m in re.finditer(r"from (?:(?:animsynth\.compare|\.)?\.?generators)?\.registry import (?:\(([^)]*)\)|([\w ,]+))",
                             text):
            names = {n.strip() for n in (m.group(1) or m.group(2)).split(",") if n.strip()}
            if names - set(G.__all__):
                bad.append((str(p.relative_to(root)), sorted(names - set(G.__all__))))
    interface_names = set(interface.__all__)
    interface_file = root / "src" / "animsynth" / "generator.py"
    for p in files + [Path(__file__).resolve()]:
        text = p.read_text(errors="replace")
        for module, names in _imports_from(p, root, text):
            if names & interface_names and module != "animsynth.generator":
                bad.append((str(p.relative_to(root)), module, sorted(names & interface_names)))
        if p.suffix == ".py" and p != interface_file and _exported(ast.parse(text)) & interface_names:
            bad.append((str(p.relative_to(root)), "exports", sorted(_exported(ast.parse(text)) & interface_names)))
    assert not bad


# ----------------------------------------------------------------------------- golden numbers

# Integer results (frame paths, source frames, k, nearest-frame indices, step counts) of the code before the
# one-estimator refactor (commit ffbda55) on this file's synthetic walks (est_walks, conftest.py): the refactor keeps
# them exactly. Only integers are pinned (docs/testing.md: no float pinned across machines).
GOLDEN_RESEQUENCE = {  # resequence_motion(capture, 150, 20, method, metric="l2")
    "isomap": (
        150, 149, 148, 147, 146, 145, 144, 143, 142, 141, 140, 139, 138, 137, 136, 135, 134, 133, 132, 131, 130,
        129, 128, 127, 126, 125, 124, 123, 122, 121, 120, 119, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14,
        15, 16, 17, 18, 19, 20),
    "stisomap": list(range(150, 19, -1)),
}
GOLDEN_MIN_K = {"isomap": 3, "stisomap": 1}  # compare's rows on est_walks[1:]
GOLDEN_SOURCES = {  # compare's rows on est_walks[1:]: generate(est_walks[0][:8], 20, seed) source_frames
    ("isomap", 0): (
        [1, 15], [1, 13], [1, 11], [1, 9], [1, 8], [1, 7], [1, 6], [1, 4], [1, 2], [0, 0], [2, 1], [2, 2], [2, 31],
        [2, 58], [2, 32], [2, 33], [2, 34], [2, 7], [2, 8], [2, 9]),
    ("isomap", 1): (
        [1, 18], [1, 20], [1, 22], [1, 24], [1, 26], [1, 28], [1, 29], [1, 30], [1, 32], [1, 34], [1, 36], [1, 38],
        [1, 40], [1, 38], [1, 36], [1, 34], [1, 32], [1, 30], [1, 29], [1, 27]),
    ("stisomap", 0): (
        [1, 15], [1, 14], [1, 13], [1, 12], [1, 11], [1, 10], [1, 9], [1, 8], [1, 7], [1, 6], [1, 5], [1, 4],
        [1, 3], [1, 2], [1, 1], [1, 0], [0, 0], [2, 0], [2, 1], [2, 2]),
    ("stisomap", 1): (
        [1, 17], [1, 18], [1, 19], [1, 20], [1, 21], [1, 22], [1, 23], [1, 24], [1, 25], [1, 26], [1, 27], [1, 28],
        [1, 29], [1, 30], [1, 31], [1, 32], [1, 33], [1, 34], [1, 35], [1, 36]),
}
GOLDEN_FOLD_NEAREST = {  # run_fold(est_walks[1:], est_walks[0]): nearest training latent frame of every 6th path point,
    # and the fallback steps
    "delaunay": ([156, 62, 67, 70, 75, 84, 88, 93, 96, 99, 102], 0),
    "fw": ([156, 160, 164, 117, 47, 22, 160, 165, 117, 175, 155], 1),
}


@pytest.mark.parametrize("method", ["isomap", "stisomap"])
def test_golden_resequence_motion_paths(capture, method):
    path, _ = resequence_motion(capture, 150, 20, method=method, metric="l2")
    assert path.tolist() == list(GOLDEN_RESEQUENCE[method])


@pytest.mark.parametrize("method", ["isomap", "stisomap"])
def test_golden_compare_rows(est_walks, cfg, method):
    gen = G.make_generator(method, cfg).fit(est_walks[1:])
    assert gen.min_k_ == GOLDEN_MIN_K[method]
    for seed in (0, 1):
        out = gen.generate(_start(est_walks[0]), 20, seed=seed)
        assert out.meta["source_frames"].tolist() == [list(p) for p in GOLDEN_SOURCES[method, seed]], seed


@pytest.mark.parametrize("variant", [fl.Variant("delaunay"),
                                     fl.Variant("fw", derivative="forward", weights="barycentric", latent_dim=3)])
def test_golden_fold_paths(est_walks, variant):
    from scipy.spatial import cKDTree

    trials = [w.without_root() for w in est_walks]
    res = fl.run_fold(trials[1:], trials[0], variant)
    nearest = cKDTree(np.vstack(res.train_latent)).query(res.path.points[::6])[1]
    assert (nearest.tolist(), int(res.path.fallback_steps)) == (GOLDEN_FOLD_NEAREST[variant.name][0],
                                                                 GOLDEN_FOLD_NEAREST[variant.name][1])
