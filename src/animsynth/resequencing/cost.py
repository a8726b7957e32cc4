"""The re-sequencing family's cost curves (:mod:`animsynth.scale`): its measured steps on an ``n``-frame
database (:func:`scale_steps`) and Landmark vs exact Isomap where N x N still fits (:func:`landmark_vs_exact`).

The databases are CMU mirror trials or synthetic ones (:func:`animsynth.synth.mocap.synthetic_motions`); the
readers are imported inside the functions, so the workflow steps do not load them.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["scale_steps", "landmark_vs_exact"]


def scale_steps(recorder, n: int, metric: str = "l2", method: str = "isomap", n_candidates: int = 20, k=None,
                       embedding: str = "landmark", exact_max_frames: int = 4000, n_landmarks: int = 500,
                       landmarks: str = "maxmin", n_components: int = 2, seed: int = 0, trial_frames: int = 1000,
                       cmu_mirror: str | None = None, algorithm: str = "kd_tree", st: dict | None = None,
                       lee: dict | None = None):
    """Re-sequencing of an ``n``-frame database: neighbours, exact min k, embedding, one path.

    The graph is the estimator's (:func:`.sparse.sparse_graph`, as :class:`.generator.Resequencer` builds it)
    with the harness's deliberate differences, as parameters: one listing of ``n_candidates`` (no doubling:
    the harness measures one), the Lee metric through :func:`.sparse.lee_neighbours` besides L2, and ST-Isomap's
    parameters ``st`` in frames with their defaults where absent (the estimator reads the study's block).
    """
    from ..io.cmu_mirror import read_mirror_motions
    from ..synth.mocap import synthetic_motions
    from . import landmark as lm
    from . import sparse as sp
    from .features import motion_features

    motions = read_mirror_motions(cmu_mirror, n) if cmu_mirror else synthetic_motions(n, trial_frames, seed)
    feats = [motion_features(m) for m in motions]
    feats, seq = sp.concat_features(feats)
    n = int(seq.size)
    S = recorder("resequencing", n, metric=metric, method=method)
    lee = lee or {}
    if metric == "l2":
        def neighbours(m):
            X = np.vstack([f.linearised(False) for f in feats])
            return (*sp.l2_neighbours(X, m, algorithm=algorithm),
                    lambda i, j: np.linalg.norm(X[i] - X[j], axis=1))
    elif metric == "lee":
        kw = {"weights": lee.get("weights"), "nu": float(lee.get("nu", 0.01)), "sqrt": bool(lee.get("sqrt", False))}

        def neighbours(m):
            dist, idx = sp.lee_neighbours(feats, m, algorithm=algorithm, **kw)
            parts = sp._lee_parts(feats, kw["weights"], kw["nu"], False)
            return dist, idx, lambda i, j: sp.lee_pair_metric(parts, i, j, kw["sqrt"])
    else:
        raise ValueError(f"unknown metric {metric!r} (l2, lee)")
    # one listing of n_candidates, timed as the steps "neighbours" (listing + ST adjustment) and "min_k"
    g = sp.sparse_graph(neighbours, seq, method, n_candidates, k, st=st, grow=False, step=S.step)
    kk, G = g.k, g.graph
    with S.step("embedding") as info:
        res = lm.embed(G, n_components, embedding, exact_max_frames, n_landmarks, landmarks, seed)
        info.update(embedding_method=res.method, rv_d2=float(res.residual_variance[min(1, n_components - 1)]))
    with S.step("path") as info:
        path, cost = sp.shortest_path(G, 0, n - 1)
        info.update(path_frames=int(path.size))
    for r in S.rows:
        r["k"] = kk
    return S.rows


def landmark_vs_exact(n: int, metric: str = "l2", method: str = "isomap", n_candidates: int = 20, k=10,
                      n_landmarks=(50, 100, 200), seeds=(0, 1, 2), max_dim: int = 5, pairs: int = 10, seed: int = 0,
                      trial_frames: int = 1000, cmu_mirror: str | None = None, st: dict | None = None):
    """Landmark vs exact Isomap on an ``n``-frame database small enough for N x N.

    * The graph uses ``max(k, minimum k)`` neighbours: at the minimum k itself
      a database graph is often a chain, whose geodesics are 1-D, and a 2-D
      Procrustes comparison would compare rounding noise.
    * The dense pipeline (:mod:`.embedding`: full distance matrix,
      exact min k) and the sparse one (:func:`.sparse.sparse_graph`, one listing
      of ``n_candidates``, no doubling) must give the
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

    from ..io.cmu_mirror import read_mirror_motions
    from ..synth.mocap import synthetic_motions
    from . import landmark as lm
    from . import sparse as sp
    from .distances import l2_distances
    from .embedding import knn_graph, min_connected_k, spatio_temporal_distances, temporal_adjacency
    from .features import motion_features
    from .paths import shortest_path_frames

    motions = read_mirror_motions(cmu_mirror, n) if cmu_mirror else synthetic_motions(n, trial_frames, seed)
    feats, seq = sp.concat_features([motion_features(m) for m in motions])
    n = int(seq.size)
    if metric != "l2":
        raise ValueError("landmark_vs_exact compares on the L2 metric (the dense Lee metric of a multi-trial "
                         "database would mix velocities across trial boundaries)")
    X = np.vstack([f.linearised(False) for f in feats])
    D = l2_distances(X)
    always_dense = None
    if method == "stisomap":
        if len(feats) != 1:
            raise ValueError("the dense ST-Isomap adjustment handles one sequence; use one trial for stisomap")
        st = dict(st or {})
        D = spatio_temporal_distances(D, **st)[0]
        always_dense = temporal_adjacency(n, st.get("temporal_window", 1))
    pair = lambda i, j: np.linalg.norm(X[i] - X[j], axis=1)  # noqa: E731
    g = sp.sparse_graph(lambda m: (*sp.l2_neighbours(X, m, algorithm="kd_tree"), pair), seq, method,
                        n_candidates, k, st=st, grow=False)
    kmin_sparse, kk, G = g.min_k, g.k, g.graph
    kmin_dense = min_connected_k(D, always=always_dense)
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
