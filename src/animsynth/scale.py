"""Cost curves: CPU time, wall time and peak memory of each family's main steps vs size.

Each measurement (one family at one size) runs in a **fresh child process**
(``multiprocessing`` with the ``spawn`` start method, so the child shares no
memory with the parent). Inside it every step is timed with
``time.process_time`` (CPU seconds of all the process's threads, BLAS included)
and ``time.perf_counter`` (wall), and its peak memory is the child's peak
resident set size *during that step*: before the step the kernel's high-water
mark is reset (``echo 5 > /proc/self/clear_refs``) and after it ``VmHWM`` is
read from ``/proc/self/status``. That peak includes everything resident in the
child at the time (the interpreter and libraries, ~100-150 MB, and data of
earlier steps still held). Where the reset is not possible the value is
``getrusage(RUSAGE_SELF).ru_maxrss`` of the child, the peak since it started
(column ``peak_kind`` says which).

The families' public entry points are called (the highest-level stable ones):

* simplicial: :func:`animsynth.simplicial.experiment.run_fold` (PCA, Delaunay
  complex, motion graph, vector field and a 1,000-step generated path), on
  synthetic walking trials totalling ``n`` training frames.
* resequencing: :mod:`animsynth.resequencing.sparse` /
  :mod:`animsynth.resequencing.landmark` (neighbours, exact minimum k,
  embedding, one Dijkstra path) on a database of ``n`` frames.
* facegraph: :class:`animsynth.facegraph.graph.FaceGraphModel` ``fit``
  (sample-graph creation and merging with both threshold searches) on ``n``
  synthetic CK+-layout sequences.
* meshdetail: :class:`animsynth.meshdetail.models.HybridModel` ``fit`` (the
  GP detail model) on ``n`` frames of the synthetic skirt character at a given
  mesh resolution (vertices recorded in ``vertices``).
"""

from __future__ import annotations

import logging
import os
import resource
import time
from contextlib import contextmanager

import numpy as np
import pandas as pd

log = logging.getLogger("animsynth.scale")

COLUMNS = ["family", "step", "n", "cpu_s", "wall_s", "peak_mb"]
FAMILIES = ("simplicial", "resequencing", "facegraph", "meshdetail")


# ----------------------------------------------------------------------------- measuring


def _reset_peak() -> bool:
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def _peak_mb(reset_ok: bool) -> float:
    if reset_ok:
        try:
            with open("/proc/self/status") as f:
                for line in f:
                    if line.startswith("VmHWM:"):
                        return int(line.split()[1]) / 1024.0
        except OSError:
            pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # KiB on Linux


class Steps:
    """Collects one row per timed step (use :meth:`step` as a context manager)."""

    def __init__(self, family: str, n: int, **extra):
        self.family, self.n, self.extra, self.rows = family, int(n), extra, []

    @contextmanager
    def step(self, name: str, **info):
        ok = _reset_peak()
        c0, w0 = time.process_time(), time.perf_counter()
        yield info
        c1, w1 = time.process_time(), time.perf_counter()
        self.rows.append({"family": self.family, "step": name, "n": self.n, "cpu_s": c1 - c0, "wall_s": w1 - w0,
                          "peak_mb": _peak_mb(ok), "peak_kind": "step VmHWM" if ok else "process ru_maxrss",
                          **self.extra, **info})


def _child_main():
    """Entry point of the measuring process: JSON ``{"target", "kwargs"}`` on stdin, rows as JSON on stdout."""
    import json
    import sys

    from threadpoolctl import threadpool_limits

    req = json.loads(sys.stdin.read())
    kwargs = req["kwargs"]
    with threadpool_limits(limits=int(kwargs.pop("blas_threads", 1)), user_api="blas"):
        rows = globals()[req["target"]](**kwargs)
    sys.stdout.write("\n" + json.dumps(rows, default=float) + "\n")


def measure(target: str, timeout: float | None = None, **kwargs) -> list[dict]:
    """Run ``target(**kwargs)`` (a step function of this module) in a fresh Python process; its rows.

    The child is a new interpreter (``subprocess``), so it shares no memory with
    the caller and its peak memory is its own.
    """
    import json
    import subprocess
    import sys

    if target not in STEP_FUNCTIONS:
        raise ValueError(f"unknown measurement {target!r}; one of {sorted(STEP_FUNCTIONS)}")
    cmd = [sys.executable, "-c", "from animsynth.scale import _child_main; _child_main()"]
    res = subprocess.run(cmd, input=json.dumps({"target": target, "kwargs": kwargs}), capture_output=True,
                         text=True, timeout=timeout)
    if res.returncode != 0:
        raise RuntimeError(f"{target}{kwargs} failed in the measuring process (exit code {res.returncode}; "
                           f"-9 = killed, e.g. out of memory):\n{res.stderr[-4000:]}")
    for line in res.stderr.splitlines():
        log.info("[%s] %s", target, line)
    return json.loads(res.stdout.strip().splitlines()[-1])


# ----------------------------------------------------------------------------- databases


def synthetic_motions(n_frames: int, trial_frames: int = 1000, seed: int = 0, kinds=None):
    """Synthetic CMU-skeleton trials (:mod:`animsynth.synth.mocap`) totalling ``n_frames``.

    Trial ``t`` has kind ``kinds[t % len(kinds)]`` and seed ``seed * 100003 + t``;
    the last trial is shortened to hit ``n_frames`` exactly.
    """
    from .synth.mocap import KINDS, cmu_like_skeleton, generate_motion

    kinds = list(kinds or KINDS)
    sk = cmu_like_skeleton("synscale", seed)
    out, left, t = [], int(n_frames), 0
    while left > 0:
        n = min(int(trial_frames), left)
        if n < 10:  # the generator needs >= 10 frames: fold the remainder into the previous trial
            break
        out.append(generate_motion(kinds[t % len(kinds)], n, seed * 100003 + t, sk, name=f"syn{t:04d}"))
        left -= n
        t += 1
    return out


def cmu_motions(mirror: str, n_frames: int, subjects=None):
    """Trials of a CMU mirror (``subjects/<s>/<s>_<t>.amc``), in sorted order, until ``n_frames``
    frames (the last trial cut). ``subjects``: restrict to these subject folders."""
    from .io import read_amc, read_asf

    root = os.path.join(mirror, "subjects")
    if not os.path.isdir(root):
        raise FileNotFoundError(f"config key 'cmu_mirror': {mirror} has no subjects/ folder")
    subs = sorted(os.listdir(root)) if not subjects else [str(s) for s in subjects]
    out, total = [], 0
    for s in subs:
        d = os.path.join(root, s)
        asf = os.path.join(d, f"{s}.asf")
        if not os.path.isfile(asf):
            continue
        sk = read_asf(asf)
        for f in sorted(os.listdir(d)):
            if not f.endswith(".amc"):
                continue
            m = read_amc(os.path.join(d, f), sk, 120.0)
            take = min(m.n_frames, int(n_frames) - total)
            if take < 12:
                return out
            if take < m.n_frames:
                from .io.amc import Motion

                m = Motion(np.asarray(m.values)[:take], m.skeleton, m.fps, m.name, dict(m.meta))
            out.append(m)
            total += take
            if total >= n_frames:
                return out
    if total < n_frames:
        log.warning("CMU mirror %s has only %d frames (asked for %d)", mirror, total, n_frames)
    return out


# ----------------------------------------------------------------------------- step functions (run in a child)


def resequencing_steps(n: int, metric: str = "l2", method: str = "isomap", n_candidates: int = 20, k=None,
                       embedding: str = "landmark", exact_max_frames: int = 4000, n_landmarks: int = 500,
                       landmarks: str = "maxmin", n_components: int = 2, seed: int = 0, trial_frames: int = 1000,
                       cmu_mirror: str | None = None, algorithm: str = "kd_tree", st: dict | None = None,
                       lee: dict | None = None):
    """Re-sequencing of an ``n``-frame database: neighbours, exact min k, embedding, one path."""
    from .resequencing import landmark as lm
    from .resequencing import sparse as sp
    from .resequencing.features import motion_features

    motions = cmu_motions(cmu_mirror, n) if cmu_mirror else synthetic_motions(n, trial_frames, seed)
    feats = [motion_features(m) for m in motions]
    feats, seq = sp.concat_features(feats)
    n = int(seq.size)
    S = Steps("resequencing", n, metric=metric, method=method)
    lee = lee or {}
    with S.step("neighbours", candidates=n_candidates):
        if metric == "l2":
            X = np.vstack([f.linearised(False) for f in feats])
            dist, idx = sp.l2_neighbours(X, n_candidates, algorithm=algorithm)
            pair = lambda i, j: np.linalg.norm(X[i] - X[j], axis=1)  # noqa: E731
        elif metric == "lee":
            kw = {"weights": lee.get("weights"), "nu": float(lee.get("nu", 0.01)), "sqrt": bool(lee.get("sqrt", False))}
            dist, idx = sp.lee_neighbours(feats, n_candidates, algorithm=algorithm, **kw)
            parts = sp._lee_parts(feats, kw["weights"], kw["nu"], False)
            pair = lambda i, j: sp.lee_pair_metric(parts, i, j, kw["sqrt"])  # noqa: E731
        else:
            raise ValueError(f"unknown metric {metric!r} (l2, lee)")
        always = None
        if method == "stisomap":
            st = dict(st or {})
            dist, idx, _ = sp.st_neighbours(dist, idx, seq, pair_distance=pair, **st)
            always = sp.st_always_edges(seq, st.get("temporal_window", 1), st.get("c_atn", 10.0), pair)
        elif method != "isomap":
            raise ValueError(f"unknown method {method!r} (isomap, stisomap)")
    with S.step("min_k") as info:
        kmin = sp.sparse_min_connected_k(idx, always=None if always is None else always[0])
        info["min_k"] = kmin
    kk = max(kmin, int(k or kmin))
    G = sp.sparse_knn_graph(dist, idx, kk, always=always)
    with S.step("embedding") as info:
        res = lm.embed(G, n_components, embedding, exact_max_frames, n_landmarks, landmarks, seed)
        info.update(embedding_method=res.method, rv_d2=float(res.residual_variance[min(1, n_components - 1)]))
    with S.step("path") as info:
        path, cost = sp.shortest_path(G, 0, n - 1)
        info.update(path_frames=int(path.size))
    for r in S.rows:
        r["k"] = kk
    return S.rows


def simplicial_steps(n: int, seed: int = 0, steps: int = 1000, trial_frames: int = 200, method: str = "delaunay",
                     k: int = 8, latent_dim: int = 3):
    """One simplicial fold on ``n`` synthetic training frames plus a ``steps``-step path."""
    from .simplicial import experiment as ex

    motions = synthetic_motions(n + trial_frames, trial_frames, seed, kinds=["walk_straight", "walk_turn"])
    angles = [np.asarray(m.without_root(), float) for m in motions]
    test, train = angles[0], angles[1:]
    S = Steps("simplicial", sum(len(a) for a in train), method=method)
    var = ex.Variant(method, method=method, k=k, latent_dim=latent_dim, derivative="forward",
                     weights="idw" if method != "delaunay" else "barycentric").check()
    with S.step("fold_build_and_path", path_steps=steps):
        ex.run_fold(train, test, var, steps=int(steps))
    return S.rows


def facegraph_steps(n: int, seed: int = 0, creation: float = 50.0, merge: float = 30.0, frames_per_sequence: int = 26):
    """Facial motion graphs of ``n`` synthetic sequences: pre-processing, then creation + merging
    including both threshold searches."""
    from threadpoolctl import threadpool_limits

    from .facegraph.model import FaceGraphModel
    from .facegraph.preprocess import FacePreprocessor
    from .synth.faces import generate_sequences

    seqs = generate_sequences(n_subjects=max(1, n // 4), n_sequences=n, total_frames=n * frames_per_sequence,
                              n_unlabelled=0, min_frames=10, max_frames=60, seed=seed)
    S = Steps("facegraph", n)
    with S.step("preprocess"):
        db = FacePreprocessor().fit_transform(seqs, source="synthetic")
    with S.step("creation_incl_search") as info, threadpool_limits(1):
        model = FaceGraphModel(creation, merge, seed=seed).fit(db)
        info["nodes"] = int(sum(g.n_nodes for g in model.graphs_.values()))
    for r in S.rows:
        r["frames"] = int(db.lengths.sum())
    return S.rows


def meshdetail_steps(n: int, resolution: float = 1.0, seed: int = 0, level: float = 5.0, iterations: int = 100,
                     latent_dim: int = 4):
    """The hybrid (GP detail) model trained on ``n`` frames of the synthetic skirt character."""
    from .meshdetail.models import HybridModel, MeshContext
    from .meshdetail.jobs import driving_motion
    from .skinning import rebase, rebase_pose
    from .synth.character import SkirtParams, build_character, simulate

    cfg = {"driver": "cmu_synthetic", "motion": "dance", "frames": int(n), "fps": 30.0}
    rig, rt, A = driving_motion(cfg, seed)
    ch = build_character(rig, resolution)
    V = simulate(ch, rt, A, 30.0, SkirtParams())
    rig0 = rebase(rig, rt[0], A[0])
    ang = rebase_pose(rig, rt, A, A[0])
    ctx = MeshContext(V[0], ch.faces, rig0, ch.weights, max_level=max(level, 5.0))
    S = Steps("meshdetail", n, vertices=int(V.shape[1]), resolution=resolution)
    with S.step("training"):
        HybridModel(level=level, latent_dim=latent_dim, iterations=iterations).fit(ctx, V, rt, ang)
    return S.rows


STEP_FUNCTIONS = {"resequencing_steps", "simplicial_steps", "facegraph_steps", "meshdetail_steps"}


# ----------------------------------------------------------------------------- curves


def fit_exponent(n, t) -> float:
    """Least-squares slope of log(t) on log(n) (NaN with fewer than two positive points)."""
    n = np.asarray(n, float)
    t = np.asarray(t, float)
    ok = (n > 0) & (t > 0) & np.isfinite(t)
    if ok.sum() < 2 or np.unique(n[ok]).size < 2:
        return float("nan")
    return float(np.polyfit(np.log(n[ok]), np.log(t[ok]), 1)[0])


def exponents(curves: pd.DataFrame) -> pd.DataFrame:
    """Fitted exponent of CPU time and of peak memory per family x step (x resolution, metric, method,
    embedding method); NaN where a curve has fewer than two sizes."""
    # embedding_method: the re-sequencing embedding switches from exact to landmark at a size;
    # one exponent across the switch would describe neither
    keys = [c for c in ("family", "step", "resolution", "metric", "method", "embedding_method") if c in curves.columns]
    rows = []
    for key, g in curves.groupby(keys, dropna=False, sort=False):
        key = key if isinstance(key, tuple) else (key,)
        rows.append({**dict(zip(keys, key)), "sizes": int(g["n"].nunique()), "n_min": int(g["n"].min()),
                     "n_max": int(g["n"].max()), "cpu_exponent": round(fit_exponent(g["n"], g["cpu_s"]), 3),
                     "peak_mb_exponent": round(fit_exponent(g["n"], g["peak_mb"]), 3)})
    return pd.DataFrame(rows)


def plot_curves(curves: pd.DataFrame, path) -> None:
    """Log-log CPU seconds vs size, one panel per family, one line per step, exponent in the legend."""
    import matplotlib.pyplot as plt

    fams = [f for f in FAMILIES if f in set(curves["family"])]
    fig, axes = plt.subplots(1, max(1, len(fams)), figsize=(4.2 * max(1, len(fams)), 3.6), squeeze=False)
    for ax, fam in zip(axes[0], fams):
        g = curves[curves["family"] == fam]
        keys = [c for c in ("step", "resolution", "metric", "method", "embedding_method")
                if c in g.columns and g[c].notna().any()]
        for key, h in g.groupby(keys, dropna=False, sort=False):
            key = key if isinstance(key, tuple) else (key,)
            h = h.sort_values("n")
            e = fit_exponent(h["n"], h["cpu_s"])
            label = " ".join(str(k) for k in key if str(k) != "nan") + f" (n^{e:.2f})"
            ax.loglog(h["n"], h["cpu_s"], "o-", label=label)
        ax.set_title(fam)
        ax.set_xlabel({"facegraph": "sequences", "meshdetail": "frames", "simplicial": "training frames"}
                      .get(fam, "frames"))
        ax.set_ylabel("CPU s")
        ax.legend(fontsize=7)
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ----------------------------------------------------------------------------- landmark vs exact


def landmark_vs_exact(n: int, metric: str = "l2", method: str = "isomap", n_candidates: int = 20, k=10,
                      n_landmarks=(50, 100, 200), seeds=(0, 1, 2), max_dim: int = 5, pairs: int = 10, seed: int = 0,
                      trial_frames: int = 1000, cmu_mirror: str | None = None, st: dict | None = None):
    """Landmark vs exact Isomap on an ``n``-frame database small enough for N x N.

    * The graph uses ``max(k, minimum k)`` neighbours: at the minimum k itself
      a database graph is often a chain, whose geodesics are 1-D, and a 2-D
      Procrustes comparison would compare rounding noise.
    * The dense pipeline (:mod:`.resequencing.embedding`: full distance matrix,
      exact min k) and the sparse one (:mod:`.resequencing.sparse`) must give the
      same minimum k and the same path costs (``pairs`` seeded start/end pairs).
    * On the sparse graph, exact Isomap vs Landmark Isomap for each number of
      landmarks x landmark seed: Procrustes disparity of the 2-D embeddings
      (scipy; 0 = identical up to rotation, scale and reflection), residual
      variance per dimension (exact: all frame pairs; landmark: landmark pairs).

    Returns
    -------
    summary : DataFrame, one row per landmarks x seed
    rv : DataFrame, residual-variance curves (long: dim, rv_exact, rv_landmark)
    """
    from scipy.spatial import procrustes

    from .resequencing import landmark as lm
    from .resequencing import sparse as sp
    from .resequencing.distances import l2_distances
    from .resequencing.embedding import knn_graph, min_connected_k, spatio_temporal_distances, temporal_adjacency
    from .resequencing.features import motion_features
    from .resequencing.paths import shortest_path_frames

    motions = cmu_motions(cmu_mirror, n) if cmu_mirror else synthetic_motions(n, trial_frames, seed)
    feats, seq = sp.concat_features([motion_features(m) for m in motions])
    n = int(seq.size)
    if metric != "l2":
        raise ValueError("landmark_vs_exact compares on the L2 metric (the dense Lee metric of a multi-trial "
                         "database would mix velocities across trial boundaries)")
    X = np.vstack([f.linearised(False) for f in feats])
    dist, idx = sp.l2_neighbours(X, n_candidates, algorithm="kd_tree")
    D = l2_distances(X)
    if method == "stisomap":
        if len(feats) != 1:
            raise ValueError("the dense ST-Isomap adjustment handles one sequence; use one trial for stisomap")
        st = dict(st or {})
        pair = lambda i, j: np.linalg.norm(X[i] - X[j], axis=1)  # noqa: E731
        dist, idx, _ = sp.st_neighbours(dist, idx, seq, pair_distance=pair, **st)
        always = sp.st_always_edges(seq, st.get("temporal_window", 1), st.get("c_atn", 10.0), pair)
        D = spatio_temporal_distances(D, **st)[0]
        always_dense = temporal_adjacency(n, st.get("temporal_window", 1))
    else:
        always, always_dense = None, None
    kmin_sparse = sp.sparse_min_connected_k(idx, always=None if always is None else always[0])
    kmin_dense = min_connected_k(D, always=always_dense)
    kk = max(kmin_sparse, int(k or kmin_sparse))
    G = sp.sparse_knn_graph(dist, idx, kk, always=always)
    Gd = knn_graph(D, kk, always=always_dense)
    rng = np.random.default_rng(seed)
    ab = [tuple(int(x) for x in rng.choice(n, 2, replace=False)) for _ in range(int(pairs))]
    cs = np.array([sp.shortest_path(G, a, b)[1] for a, b in ab])
    cd = np.array([shortest_path_frames(Gd, a, b)[1] for a, b in ab])
    exact = lm.embed(G, max_dim, "exact")
    rows, rv_rows = [], []
    for nl in n_landmarks:
        for s in seeds:
            res = lm.embed(G, max_dim, "landmark", n_landmarks=int(nl), seed=int(s))
            disp = procrustes(exact.embedding[:, :2], res.embedding[:, :2])[2]
            rows.append({"n": n, "metric": metric, "method": method, "k": kk, "min_k_dense": kmin_dense,
                         "min_k_sparse": kmin_sparse, "n_landmarks": int(nl), "landmark_seed": int(s),
                         "procrustes_2d": float(disp), "rv_exact_d2": float(exact.residual_variance[1]),
                         "rv_landmark_d2": float(res.residual_variance[1]), "rv_landmark_on": res.rv_on,
                         "path_pairs": len(ab), "path_cost_dense_mean": float(cd.mean()),
                         "path_cost_sparse_mean": float(cs.mean()),
                         "path_cost_max_rel_diff": float(np.max(np.abs(cs - cd) / np.maximum(cd, 1e-300)))})
            for d in range(max_dim):
                rv_rows.append({"n": n, "method": method, "n_landmarks": int(nl), "landmark_seed": int(s),
                                "dim": d + 1, "rv_exact": float(exact.residual_variance[d]),
                                "rv_landmark": float(res.residual_variance[d])})
    return pd.DataFrame(rows), pd.DataFrame(rv_rows)
