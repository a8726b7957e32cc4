"""The re-sequencing study: one function per workflow step (scripts stay thin).

A *configuration* is dataset x global-DOF flag x method (``isomap``,
``stisomap``) x metric (``l2``, ``lee``). :func:`analyse` handles every
method x metric of one dataset x global flag (distances, exact minimum k,
Isomap / ST-Isomap fit, residual variance, 2-D embedding);
:func:`resequence` makes and measures one re-sequenced motion;
:func:`min_k_table`, :func:`verdicts` aggregate.

The configuration dictionary ``cfg`` is the ``resequencing`` block of the
workflow config (``docs/config_resequencing.md``); :data:`DEFAULTS` holds
the same defaults for library use.
"""

from __future__ import annotations

import copy
import logging
import time

import numpy as np
import pandas as pd

from ..motion import Motion
from .distances import PAPER_WEIGHTS, l2_distances, lee_distances
from .embedding import (DisconnectedGraphError, PrecomputedIsomap, graph_components, knn_graph,
                        min_connected_k, neighbor_ranks, residual_variance, spatio_temporal_distances)
from .features import motion_features
from .metrics import Reference, smoothness
from .paths import pad_path, play_path, resolve_frame, shortest_path_frames

log = logging.getLogger("animsynth.resequencing")

METHODS = ("isomap", "stisomap")
METRICS = ("l2", "lee")
GDOF = {"noglobal": False, "global": True}
METHOD_LABEL = {"isomap": "Isomap", "stisomap": "ST-Isomap"}
METRIC_LABEL = {"l2": "L2", "lee": "Lee"}

DEFAULTS = {
    "datasets": ["walk", "run", "dance"],
    "methods": list(METHODS),
    "metrics": list(METRICS),
    "global_dof": [False, True],
    "max_frames": 800,
    "frame_step": 1,
    "n_neighbors": 10,
    "max_dim": 10,
    "lee": {"weights": dict(PAPER_WEIGHTS), "nu": 0.01, "sqrt": False},
    "stisomap": {"temporal_window": 1, "c_ctn": 10.0, "c_cctn": 10.0, "ctn_neighbors": 4,
                 "ctn_min_gap_s": 0.25, "ctn_tolerance": 2, "ctn_reach_s": 0.05},
    "path": {"start": 0, "end": -1, "random_pairs": 20, "min_separation": 0.25, "context_s": 0.25,
             "pad_to": None, "pad_mode": "hold", "root_playback": "auto"},
    "smoothness": {"contact_height_m": 0.02, "reversal_speed_mps": 0.1},
    "verdict_margin": 0.1,
    "gif_fps": 30,
    "published_min_k": [],
}


def with_defaults(cfg: dict | None) -> dict:
    """``cfg`` completed with :data:`DEFAULTS` (nested dicts merged one level deep)."""
    out = copy.deepcopy(DEFAULTS)
    for k, v in copy.deepcopy(cfg or {}).items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k].update(v)  # one level: e.g. lee.weights given -> replaces the default weights
        else:
            out[k] = v
    return out


def gdof_flag(name: str) -> bool:
    try:
        return GDOF[name]
    except KeyError:
        raise ValueError(f"global-DOF wildcard must be one of {sorted(GDOF)}, got {name!r}") from None


def gdof_name(flag: bool) -> str:
    return "global" if flag else "noglobal"


def prepare_motion(motion: Motion, max_frames: int | None = None, frame_step: int = 1) -> Motion:
    """Keep every ``frame_step``-th frame of the first ``max_frames`` frames (fps adjusted)."""
    if frame_step < 1:
        raise ValueError(f"config key 'resequencing.frame_step' must be >= 1, got {frame_step}")
    v = np.asarray(motion.values, float)
    if max_frames is not None:
        v = v[: int(max_frames)]
    v = v[::frame_step]
    if v.shape[0] < 12:
        raise ValueError(f"trial {motion.name!r}: {v.shape[0]} frames after max_frames/frame_step; need >= 12")
    return Motion(v, motion.skeleton, motion.fps / frame_step, motion.name, dict(motion.meta))


def st_kwargs(st: dict, fps: float) -> dict:
    """Keyword arguments of :func:`spatio_temporal_distances` from the config block."""
    tw = int(st["temporal_window"])
    return {
        "temporal_window": tw,
        "c_ctn": float(st["c_ctn"]),
        "c_cctn": float(st["c_cctn"]),
        "ctn_neighbors": int(st["ctn_neighbors"]),
        "ctn_min_gap": max(tw, int(round(float(st["ctn_min_gap_s"]) * fps))),
        "ctn_tolerance": int(st["ctn_tolerance"]),
        "ctn_reach": max(1, int(round(float(st["ctn_reach_s"]) * fps))),
    }


def base_distances(features, metric: str, include_global: bool, lee: dict) -> np.ndarray:
    """The frame distance matrix of one metric."""
    if metric == "l2":
        return l2_distances(features.linearised(include_global))
    if metric == "lee":
        return lee_distances(features, lee["weights"], float(lee["nu"]), include_global, bool(lee["sqrt"]))
    raise ValueError(f"unknown metric {metric!r} (expected one of {METRICS})")


def method_distances(D: np.ndarray, method: str, cfg: dict, fps: float):
    """The matrix a method builds its k-NN graph on: ``D`` (Isomap) or the ST-adjusted ``D`` (ST-Isomap).

    Returns ``(matrix, n_ctn_pairs)`` (``n_ctn_pairs`` is 0 for Isomap)."""
    if method == "isomap":
        return D, 0
    if method == "stisomap":
        Dst, _, ctn = spatio_temporal_distances(D, **st_kwargs(cfg["stisomap"], fps))
        return Dst, int(np.count_nonzero(np.triu(ctn)))
    raise ValueError(f"unknown method {method!r} (expected one of {METHODS})")


def k_to_use(min_k: int, n_neighbors) -> int:
    """``n_neighbors`` (or the minimum k if null); raised to the minimum k when smaller (logged)."""
    if n_neighbors is None:
        return int(min_k)
    if n_neighbors < min_k:
        log.warning("n_neighbors=%d leaves the graph disconnected; using the minimum connected k=%d",
                    n_neighbors, min_k)
        return int(min_k)
    return int(n_neighbors)


def nontrivial_edge_fraction(graph, min_gap: int) -> float:
    """Fraction of graph edges joining frames more than ``min_gap`` frames apart
    (links between different passes of the motion: what lets a path re-sequence)."""
    i, j = graph.nonzero()
    if i.size == 0:
        return float("nan")
    return float(np.mean(np.abs(i - j) > min_gap))


def analyse(motion: Motion, dataset: str, trial: str, include_global: bool, cfg: dict):
    """Minimum k, residual variance and 2-D embeddings of every method x metric of one dataset x global flag.

    Returns
    -------
    min_k : DataFrame, one row per method x metric
    rv : DataFrame, residual variance per method x metric x dimension
    embeddings : dict of arrays for the Fig. 2 plots (``<method>_<metric>_xy``, ``..._edges``)
    timings : DataFrame (machine-dependent seconds)
    """
    cfg = with_defaults(cfg)
    feats = motion_features(motion)
    n = feats.n_frames
    gap = st_kwargs(cfg["stisomap"], motion.fps)["ctn_min_gap"]
    rows, rv_rows, t_rows, emb = [], [], [], {}
    max_dim = min(int(cfg["max_dim"]), n - 2)
    for metric in cfg["metrics"]:
        t0 = time.perf_counter()
        D = base_distances(feats, metric, include_global, cfg["lee"])
        t_dist = time.perf_counter() - t0
        for method in cfg["methods"]:
            t0 = time.perf_counter()
            Dm, n_ctn = method_distances(D, method, cfg, motion.fps)
            R = neighbor_ranks(Dm)
            kmin = min_connected_k(Dm, ranks=R)
            t_mink = time.perf_counter() - t0
            below = graph_components(Dm, kmin - 1, ranks=R) if kmin > 1 else n
            at = graph_components(Dm, kmin, ranks=R)
            if at != 1 or below <= 1:
                raise RuntimeError(f"min-k cross-check failed for {dataset}/{method}/{metric}: "
                                   f"{below} components at k={kmin - 1}, {at} at k={kmin}")
            k = k_to_use(kmin, cfg["n_neighbors"])
            t0 = time.perf_counter()
            iso = PrecomputedIsomap(k, max_dim).fit(Dm)
            t_fit = time.perf_counter() - t0
            rv = residual_variance(iso.dist_matrix_, iso.embedding_)
            key = f"{method}_{metric}"
            emb[f"{key}_xy"] = iso.embedding_[:, :2]
            gi, gj = iso.graph_.nonzero()
            up = gi < gj
            emb[f"{key}_edges"] = np.stack([gi[up], gj[up]], axis=1).astype(np.int32)
            emb[f"{key}_k"] = np.int64(k)
            rows.append({
                "dataset": dataset, "trial": trial, "frames": n, "global_dof": include_global,
                "method": method, "metric": metric, "min_k": kmin,
                "components_at_min_k_minus_1": below, "components_at_min_k": at,
                "k_used": k, "ctn_pairs": n_ctn if method == "stisomap" else np.nan,
                "nontrivial_edge_fraction": round(nontrivial_edge_fraction(iso.graph_, gap), 6),
            })
            for d, r in enumerate(rv, start=1):
                rv_rows.append({"dataset": dataset, "global_dof": include_global, "method": method,
                                "metric": metric, "k": k, "dim": d, "residual_variance": round(float(r), 6)})
            t_rows.append({"dataset": dataset, "global_dof": include_global, "method": method, "metric": metric,
                           "frames": n, "seconds_distances": t_dist, "seconds_min_k": t_mink,
                           "seconds_geodesics_embedding": t_fit})
            log.info("%s global=%s %s/%s: min k %d (components %d at k-1), k used %d, RV(2)=%.4f, fit %.2fs",
                     dataset, include_global, method, metric, kmin, below, k, rv[min(1, len(rv) - 1)], t_fit)
    return pd.DataFrame(rows), pd.DataFrame(rv_rows), emb, pd.DataFrame(t_rows)


def path_pairs(n: int, path_cfg: dict, seed: int) -> list[tuple[int, int]]:
    """Start/end frame pairs: the configured pair first, then ``random_pairs`` seeded
    random pairs whose frames are at least ``min_separation * n`` apart."""
    start = resolve_frame(path_cfg["start"], n, "config key 'resequencing.path.start'")
    end = resolve_frame(path_cfg["end"], n, "config key 'resequencing.path.end'")
    if start == end:
        raise ValueError("config keys 'resequencing.path.start' and '.end' name the same frame")
    pairs = [(start, end)]
    count = int(path_cfg["random_pairs"])
    sep = max(1, int(round(float(path_cfg["min_separation"]) * n)))
    if count > 0 and sep >= n:
        raise ValueError(f"config key 'resequencing.path.min_separation': no pair of {n} frames is {sep} apart")
    rng = np.random.default_rng(seed)
    while len(pairs) < count + 1:
        a, b = (int(x) for x in rng.integers(0, n, size=2))
        if abs(a - b) >= sep:
            pairs.append((a, b))
    return pairs


def splice(path, n: int, context: int) -> np.ndarray:
    """The path with up to ``context`` original frames before its start and after its end."""
    path = np.asarray(path, dtype=np.int64)
    pre = np.arange(max(0, path[0] - context), path[0])
    post = np.arange(path[-1] + 1, min(n, path[-1] + 1 + context))
    return np.concatenate([pre, path, post])


def resequence(motion: Motion, include_global: bool, method: str, metric: str, k: int, cfg: dict, seed: int = 0):
    """Re-sequence one configuration: Dijkstra paths on the method's k-NN graph, played and measured.

    Every start/end pair of :func:`path_pairs` gives one path. Each path is
    played inside its context (``path.context_s`` seconds of the original
    before the start and after the end, so a transition is judged where it
    happens) and measured against the original (:func:`~.metrics.smoothness`).

    Returns
    -------
    paths : list of int arrays (the Dijkstra paths, unpadded, pair 0 first)
    main : Motion, the motion of pair 0's path (padded to ``path.pad_to`` if set)
    per_path : DataFrame, one row of measures per pair
    """
    cfg = with_defaults(cfg)
    feats = motion_features(motion)
    n = feats.n_frames
    D = base_distances(feats, metric, include_global, cfg["lee"])
    Dm, _ = method_distances(D, method, cfg, motion.fps)
    ncomp = graph_components(Dm, k)
    if ncomp > 1:
        raise DisconnectedGraphError(f"{method}/{metric}: the {k}-NN graph has {ncomp} components")
    G = knn_graph(Dm, k)
    pc = cfg["path"]
    mode = pc["root_playback"]
    if mode == "auto":
        mode = "absolute" if include_global else "integrate"
    sm = cfg["smoothness"]
    ref = Reference(motion, float(sm["contact_height_m"]), float(sm["reversal_speed_mps"]))
    context = int(round(float(pc["context_s"]) * motion.fps))
    paths, rows = [], []
    for p, (a, b) in enumerate(path_pairs(n, pc, seed)):
        path, cost = shortest_path_frames(G, a, b)
        paths.append(path)
        full = splice(path, n, context)
        played = play_path(motion, full, root=mode)
        row = {"pair": p, "start": a, "end": b, "path_frames": int(path.size), "path_cost": cost}
        row.update(smoothness(ref, played, full))
        rows.append(row)
    padded = pad_path(paths[0], pc["pad_to"], pc["pad_mode"])
    main = play_path(motion, padded, root=mode,
                     name=f"{motion.name}_{method}_{metric}_{gdof_name(include_global)}")
    per_path = pd.DataFrame(rows)
    per_path.insert(0, "root_playback", mode)
    per_path.insert(0, "k", k)
    return paths, main, per_path


#: Columns of smoothness.csv averaged over the pairs of a configuration.
SMOOTH_MEANS = ["path_frames", "jumps", "backward_steps", "jump_mean_ratio", "jump_p95_ratio", "jump_max_ratio",
                "jerk_mean_ratio", "jerk_events", "root_reversals", "foot_skate_mps"]


def summarise_paths(per_path: pd.DataFrame) -> pd.DataFrame:
    """One smoothness row per configuration: means over its start/end pairs (NaN-aware),
    plus the original's reference values."""
    keys = ["dataset", "global_dof", "method", "metric", "k", "root_playback"]
    g = per_path.groupby(keys, sort=False)
    out = g[SMOOTH_MEANS].mean()
    out.insert(0, "paths", g.size())
    out["root_reversals_per_s_original"] = g["root_reversals_per_s_original"].first()
    out["foot_skate_original_mps"] = g["foot_skate_original_mps"].first()
    out = out.reset_index()
    for c in SMOOTH_MEANS + ["root_reversals_per_s_original", "foot_skate_original_mps"]:
        out[c] = out[c].astype(float).round(6)
    return out


def min_k_table(min_k: pd.DataFrame, published=None) -> pd.DataFrame:
    """The paper's Table 2 layout (long form) with the published values beside ours.

    ``published``: list of ``{dataset, global_dof, method, metric, min_k}``;
    missing values stay empty (we do not know the paper's numbers unless given).
    """
    df = min_k.copy()
    df["min_k_paper"] = np.nan
    for rec in published or []:
        m = ((df["dataset"] == rec["dataset"]) & (df["global_dof"] == bool(rec["global_dof"]))
             & (df["method"] == rec["method"]) & (df["metric"] == rec["metric"]))
        df.loc[m, "min_k_paper"] = rec["min_k"]
    order = {"walk": 0, "run": 1, "dance": 2}
    df["_o"] = df["dataset"].map(lambda d: order.get(d, 9))
    df = df.sort_values(["_o", "dataset", "global_dof", "method", "metric"], kind="stable").drop(columns="_o")
    cols = ["dataset", "trial", "frames", "global_dof", "method", "metric", "min_k", "min_k_paper",
            "components_at_min_k_minus_1", "components_at_min_k", "k_used", "ctn_pairs", "nontrivial_edge_fraction"]
    return df[cols].reset_index(drop=True)


def _pct(x: float) -> str:
    if not np.isfinite(x):
        return "+inf %" if x > 0 else "n/a"
    return f"{100 * x:+.0f} %"


def _change(a: float, b: float) -> float:
    """Relative change a -> b; +inf when a == 0 < b, 0 when both are 0."""
    if a > 0:
        return b / a - 1.0
    return 0.0 if b <= 0 else float("inf")


#: (column, label) of the measures behind the verdicts; larger = worse for all.
VERDICT_MEASURES = [("jerk_events", "jerk events per path"), ("jump_p95_ratio", "pose jumps (p95 ratio)"),
                    ("root_reversals", "root reversals per path"), ("foot_skate_mps", "foot skate (m/s)")]


def verdicts(smooth: pd.DataFrame, margin: float = 0.1) -> pd.DataFrame:
    """Verdicts on the paper's qualitative claims, computed from ``smoothness.csv`` rows
    (each a configuration's mean over its start/end pairs).

    * **ST-Isomap gives fewer jerks than Isomap**: jerk events (frames jerkier
      than anything in the capture) summed over the configurations present for
      both methods (dataset x metric x global flag). "yes, by x %" when
      ST-Isomap's total is more than ``margin`` below Isomap's, "no" when more
      than ``margin`` above, "no clear difference" otherwise.
    * **Global DOF hurt cyclic locomotion but not dance**: for each dataset,
      each measure of :data:`VERDICT_MEASURES` is summed over method x metric
      with and without the global DOF; the dataset is *hurt* when at least
      three of the four get worse by more than ``margin``. "yes" when walk and
      run are hurt and dance is not.
    """
    cols = ["claim", "verdict", "evidence"]
    if smooth.empty:
        return pd.DataFrame(columns=cols)
    rows = []
    keys = ["dataset", "metric", "global_dof"]
    iso = smooth[smooth["method"] == "isomap"].set_index(keys)
    st = smooth[smooth["method"] == "stisomap"].set_index(keys)
    common = iso.index.intersection(st.index)
    for col, label in [("jerk_events", "jerks"), ("jerk_mean_ratio", "mean jerk"),
                       ("jump_p95_ratio", "pose jumps (p95)")]:
        claim = f"ST-Isomap gives fewer {label} than Isomap"
        if len(common) == 0:
            rows.append({"claim": claim, "verdict": "not measured", "evidence": "no configuration has both methods"})
            continue
        a = iso.loc[common, col].astype(float)
        b = st.loc[common, col].astype(float)
        ok = a.notna() & b.notna()
        a, b = a[ok], b[ok]
        ta, tb = float(a.sum()), float(b.sum())
        ch = _change(ta, tb)
        if ch < -margin:
            verdict = f"yes, by {abs(ch) * 100:.0f} %"
        elif ch > margin:
            verdict = f"no: {ch * 100:.0f} % more" if np.isfinite(ch) else "no: Isomap has none, ST-Isomap some"
        else:
            verdict = f"no clear difference ({_pct(ch)}, within +-{margin * 100:.0f} %)"
        per = "; ".join(f"{d} {m} {'global' if g else 'noglobal'} {x:.3g} vs {y:.3g}"
                        for (d, m, g), x, y in zip(a.index, a.values, b.values))
        rows.append({"claim": claim, "verdict": verdict,
                     "evidence": f"{col} summed over {len(a)} configurations: Isomap {ta:.4g}, ST-Isomap {tb:.4g} "
                                 f"({_pct(ch)}); ST-Isomap lower in {int((b < a).sum())}, higher in "
                                 f"{int((b > a).sum())}; per configuration (Isomap vs ST-Isomap): {per}"})
    keys_g = ["dataset", "method", "metric"]
    without = smooth[~smooth["global_dof"].astype(bool)].set_index(keys_g)
    with_ = smooth[smooth["global_dof"].astype(bool)].set_index(keys_g)
    both = without.index.intersection(with_.index)
    hurt, parts = {}, []
    per_measure = {col: [] for col, _ in VERDICT_MEASURES}
    for ds in dict.fromkeys(both.get_level_values(0)):
        idx = [i for i in both if i[0] == ds]
        worse, desc = 0, []
        for col, label in VERDICT_MEASURES:
            a = without.loc[idx, col].astype(float)
            b = with_.loc[idx, col].astype(float)
            ok = a.notna() & b.notna()
            ta, tb = float(a[ok].sum()), float(b[ok].sum())
            ch = _change(ta, tb)
            worse += ch > margin
            desc.append(f"{label} {ta:.3g} -> {tb:.3g} ({_pct(ch)})")
            per_measure[col].append(f"{ds} {ta:.3g} -> {tb:.3g} ({_pct(ch)})")
        hurt[ds] = worse >= 3
        parts.append(f"{ds}: {'hurt' if hurt[ds] else 'not hurt'}, {worse}/4 measures worse with global DOF "
                     f"[{'; '.join(desc)}]")
    for col, label in VERDICT_MEASURES:  # supporting rows: each measure on its own
        if per_measure[col]:
            rows.append({"claim": f"including the global DOF increases {label}", "verdict": "see evidence",
                         "evidence": "sum over method x metric, without -> with global DOF: "
                                     + "; ".join(per_measure[col])})
    claim = "global DOF hurt cyclic locomotion but not dance"
    loco = [d for d in ("walk", "run") if d in hurt]
    if loco and "dance" in hurt:
        verdict = "yes" if all(hurt[d] for d in loco) and not hurt["dance"] else "no"
        verdict += " (" + ", ".join(f"{d} {'hurt' if h else 'not hurt'}" for d, h in hurt.items()) + ")"
    else:
        verdict = "not measured (needs walk or run, and dance, with both global flags)"
    rows.insert(1, {"claim": claim, "verdict": verdict,
                    "evidence": f"sums over method x metric without -> with global DOF; hurt = at least 3 of 4 "
                                f"measures worse by more than {margin * 100:.0f} %. " + " | ".join(parts)})
    return pd.DataFrame(rows, columns=cols)


def resequence_motion(motion: Motion, start: int, end: int, method: str = "stisomap", metric: str = "l2",
                      k: int | None = None, global_dof: bool = False, length: int | None = None,
                      cfg: dict | None = None) -> tuple[np.ndarray, Motion]:
    """One-call re-sequencing (CLI, notebooks): Dijkstra from ``start`` to ``end``.

    ``k`` defaults to the smallest k giving one connected component of the
    method's k-NN graph. Returns the frame index path (padded to ``length``
    if given) and the motion it plays.
    """
    method = {"st-isomap": "stisomap"}.get(method, method)
    cfg = with_defaults(cfg)
    feats = motion_features(motion)
    n = feats.n_frames
    a, b = resolve_frame(start, n, "start"), resolve_frame(end, n, "end")
    D = base_distances(feats, metric, global_dof, cfg["lee"])
    Dm, _ = method_distances(D, method, cfg, motion.fps)
    kmin = min_connected_k(Dm)
    k = kmin if k is None else int(k)
    ncomp = graph_components(Dm, k)
    if ncomp > 1:
        raise DisconnectedGraphError(f"{method}/{metric}: the {k}-NN graph has {ncomp} components "
                                     f"(the smallest connected k is {kmin})")
    path, _ = shortest_path_frames(knn_graph(Dm, k), a, b)
    path = pad_path(path, length, "hold")
    return path, play_path(motion, path, root="absolute" if global_dof else "integrate", name="resequenced")
