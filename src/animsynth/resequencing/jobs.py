"""The re-sequencing workflow steps: one function per step (scripts stay thin).

A *configuration* is dataset x global-DOF flag x method (``isomap``,
``stisomap``) x metric (``l2``, ``lee``). :func:`analyse` handles every
method x metric of one dataset x global flag at the paper's k -- each
configuration's exact minimum connected k -- (distances, Isomap / ST-Isomap
fit, residual variance, 2-D embedding) plus the labelled fixed-k sweep;
:func:`explain` computes the minimum k over the candidate explanations of the
paper's Table 2 (sign mode x frame rate x global DOF) and the quaternion sign
flips; :func:`resequence` makes and measures the re-sequenced motions and
:func:`summarise_paths` sums them up per configuration.

The configuration dictionary ``cfg`` is the ``resequencing`` block of the
workflow config as validated by ``config/schema.yaml`` (every key present; the
schema holds the defaults, ``docs/config_resequencing.md`` the meanings). Each
step reads the methods' arguments from it once (:func:`.settings.method_params`)
and passes them on; the helpers below take those, not the block.

The family's other concerns live beside this module: the config adapters
(method and metric names, global-DOF wildcards, sign mode, ST-Isomap
parameters) in :mod:`.settings`; the paper's Table 2 and Lee weights beside
ours (:func:`~.tables.published_table2`, :func:`~.tables.lee_weights_table`,
:func:`~.tables.min_k_table`) in :mod:`.tables`; the method as one estimator (the graph and its Dijkstra
paths), :class:`~.generator.Resequencer`, in :mod:`.generator`: :func:`resequence` fits it per configuration
(:func:`config_resequencer`), as do the one-call route with explicit keyword arguments (CLI, notebooks),
:func:`~.quick.resequence_motion` in :mod:`.quick`, and the comparison's rows. The minimum-k scans and
embeddings of :func:`analyse` and :func:`explain` read the same distances (:func:`base_distances`,
:func:`method_distances`) and stay here: no generator scans k or embeds. The cost curves of
:mod:`animsynth.scale` in :mod:`.cost` (:func:`~.cost.scale_steps`, named by the family registry,
:mod:`animsynth.families`).
"""

from __future__ import annotations

import logging
import time

import numpy as np
import pandas as pd

from ..limits import DEFAULT_MEMORY_BUDGET_GIB, check_budget
from ..generator import play_path
from ..motion import Motion
from .embedding import (PrecomputedIsomap, graph_components, knn_graph, min_connected_k, neighbor_ranks,
                        residual_variance)
from .generator import Resequencer, frame_distances, method_matrix
from .landmark import EMBED_METHODS, embed
from .features import matrix_naive_quaternions, motion_features, sign_flips
from .metrics import (Reference, TransitionReference, classify_path, jerk_magnitude, joint_quats, pass_jumps,
                      transition_measures)
from .paths import pad_path, resolve_frame
from .settings import METHODS, METRICS, MethodParams, gdof_name, method_params

log = logging.getLogger("animsynth.resequencing")

#: N x N float64 arrays the distance steps hold at once (base distances,
#: method distances, geodesics, the centred kernel / path graph).
DISTANCE_MATRICES = 4


def check_distance_budget(n_frames: int, trial: str, budget_gib: float | None = None) -> None:
    """Refuse, before any distance matrix is built, a trial whose ``n_frames``
    x ``n_frames`` matrices would exceed the memory budget.

    Parameters
    ----------
    n_frames : int
        Frames after ``max_frames`` / ``frame_step``.
    trial : str
        Named in the error.
    budget_gib : float, optional
        The config's ``memory_budget_gib`` (default
        :data:`~animsynth.limits.DEFAULT_MEMORY_BUDGET_GIB`).

    Raises
    ------
    animsynth.limits.BudgetError
        Naming the trial, the frame count and the estimate.
    """
    check_budget(f"re-sequencing trial {trial!r}: {n_frames} frames ({DISTANCE_MATRICES} distance matrices of "
                 f"{n_frames} x {n_frames}; lower config key 'resequencing.max_frames')",
                 8.0 * DISTANCE_MATRICES * float(n_frames) ** 2,
                 DEFAULT_MEMORY_BUDGET_GIB if budget_gib is None else float(budget_gib))


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


def base_distances(features, metric: str, include_global: bool, params: MethodParams,
                   sign_mode: str | None = None) -> np.ndarray:
    """The frame distance matrix of one metric (``params``: :func:`.settings.method_params` of the resequencing
    block): :func:`.generator.frame_distances`, the distances the study's :class:`~.generator.Resequencer` builds
    its graph on.

    ``sign_mode`` (default: ``params.sign_mode``) applies to the L2
    features only; the Lee metric is sign-invariant."""
    if metric not in METRICS:
        raise ValueError(f"unknown metric {metric!r} (expected one of {METRICS})")
    mode = (params.sign_mode if sign_mode is None else sign_mode) if metric == "l2" else "continuous"  # Lee: unused
    return frame_distances(features, metric, include_global, mode, params.translation_scale, params.lee)


def method_distances(D: np.ndarray, method: str, params: MethodParams, fps: float):
    """The matrix a method builds its k-NN graph on, and the edges it always keeps
    (:func:`.generator.method_matrix` with the ST-Isomap parameters of ``params`` at ``fps``).

    Isomap: ``(D, None, 0)``. ST-Isomap: the spatio-temporally adjusted ``D``,
    the adjacent-temporal-neighbour matrix (always in the neighbourhood) and
    the number of common-temporal-neighbour pairs."""
    if method == "isomap":
        return D, None, 0
    if method == "stisomap":
        Dst, atn, ctn = method_matrix(D, method, params.st(fps))
        return Dst, atn, int(np.count_nonzero(np.triu(ctn)))
    raise ValueError(f"unknown method {method!r} (expected one of {METHODS})")


def checked_min_k(Dm, always=None, what: str = "") -> tuple[int, int, int, np.ndarray]:
    """Exact min k cross-checked with ``connected_components``: ``(min_k, components at
    min_k - 1, components at min_k, ranks)``; components at ``k = 0`` count the
    always-present edges alone (the bare frames when there are none)."""
    R = neighbor_ranks(Dm)
    kmin = min_connected_k(Dm, ranks=R, always=always)
    below = graph_components(Dm, kmin - 1, ranks=R, always=always)
    at = graph_components(Dm, kmin, ranks=R, always=always)
    if at != 1 or (kmin > 1 and below <= 1):
        raise RuntimeError(f"min-k cross-check failed for {what}: {below} components at k={kmin - 1}, "
                           f"{at} at k={kmin}")
    return kmin, below, at, R


def nontrivial_edge_fraction(graph, min_gap: int) -> float:
    """Fraction of graph edges joining frames more than ``min_gap`` frames apart
    (links between different passes of the motion: what lets a path re-sequence)."""
    i, j = graph.nonzero()
    if i.size == 0:
        return float("nan")
    return float(np.mean(np.abs(i - j) > min_gap))


def fit_embedding(Dm, k: int, always, max_dim: int, emb_cfg: dict):
    """Isomap of an (adjusted) distance matrix at ``k``: exact or landmark by size.

    ``emb_cfg`` is the ``embedding`` config block: ``method`` "auto" runs exact
    Isomap up to ``exact_max_frames`` frames and Landmark Isomap
    (:func:`.landmark.embed`, geodesics from ``n_landmarks`` frames only) above.

    Returns
    -------
    method : "exact" or "landmark" (what ran)
    embedding : array (frames, max_dim)
    graph : sparse (frames, frames), the k-NN graph (plus ``always`` edges)
    residual_variance : array (max_dim,); on all frame pairs (exact) or landmark pairs
    """
    n = Dm.shape[0]
    method = emb_cfg["method"]
    if method not in EMBED_METHODS:
        raise ValueError(f"config key 'resequencing.embedding.method' must be one of {EMBED_METHODS}, got {method!r}")
    run = method if method != "auto" else ("exact" if n <= int(emb_cfg["exact_max_frames"]) else "landmark")
    if run == "exact":
        iso = PrecomputedIsomap(k, max_dim).fit(Dm, always=always)
        return "exact", iso.embedding_, iso.graph_, residual_variance(iso.dist_matrix_, iso.embedding_)
    graph = knn_graph(Dm, k, always=always)
    res = embed(graph, max_dim, "landmark", n_landmarks=min(int(emb_cfg["n_landmarks"]), n),
                landmarks=emb_cfg["landmarks"], seed=int(emb_cfg["seed"]))
    return "landmark", res.embedding, graph, np.asarray(res.residual_variance)


def analyse(motion: Motion, dataset: str, trial: str, include_global: bool, cfg: dict,
            budget_gib: float | None = None):
    """Min k, residual variance and 2-D embeddings of every method x metric of one dataset x global flag.

    The embeddings, residual variance (``k_mode = "min_k"``) and the paths use
    the paper's k: each configuration's exact minimum connected k. The
    ``fixed_k_sweep`` values give extra residual-variance rows labelled
    ``k_mode = "fixed"`` (skipped, and logged, where a fixed k leaves the graph
    disconnected).

    Returns
    -------
    min_k : DataFrame, one row per method x metric
    rv : DataFrame, residual variance per method x metric x k x dimension
    embeddings : dict of arrays for the Fig. 2 plots (``<method>_<metric>_xy``, ``..._edges``)
    timings : DataFrame (machine-dependent seconds)

    Raises
    ------
    animsynth.limits.BudgetError
        The distance matrices would exceed ``budget_gib`` (:func:`check_distance_budget`).
    """
    check_distance_budget(motion.n_frames, trial, budget_gib)
    params = method_params(cfg)
    feats = motion_features(motion)
    n = feats.n_frames
    gap = params.st(motion.fps)["ctn_min_gap"]
    mode = params.sign_mode
    rows, rv_rows, t_rows, emb = [], [], [], {}
    max_dim = min(int(cfg["max_dim"]), n - 2)
    for metric in cfg["metrics"]:
        t0 = time.perf_counter()
        D = base_distances(feats, metric, include_global, params)
        t_dist = time.perf_counter() - t0
        for method in cfg["methods"]:
            t0 = time.perf_counter()
            Dm, always, n_ctn = method_distances(D, method, params, motion.fps)
            kmin, below, at, R = checked_min_k(Dm, always, f"{dataset}/{method}/{metric}")
            t_mink = time.perf_counter() - t0
            t0, c0 = time.perf_counter(), time.process_time()
            how, Y, graph, rv_min_k = fit_embedding(Dm, kmin, always, max_dim, cfg["embedding"])
            t_fit, c_fit = time.perf_counter() - t0, time.process_time() - c0
            key = f"{method}_{metric}"
            emb[f"{key}_xy"] = Y[:, :2]
            gi, gj = graph.nonzero()
            up = gi < gj
            emb[f"{key}_edges"] = np.stack([gi[up], gj[up]], axis=1).astype(np.int32)
            emb[f"{key}_k"] = np.int64(kmin)
            rows.append({
                "dataset": dataset, "trial": trial, "frames": n, "fps": motion.fps, "global_dof": include_global,
                "sign_mode": mode, "method": method, "metric": metric, "min_k": kmin,
                "components_at_min_k_minus_1": below, "components_at_min_k": at,
                "k_used": kmin, "ctn_pairs": n_ctn if method == "stisomap" else np.nan,
                "nontrivial_edge_fraction": round(nontrivial_edge_fraction(graph, gap), 6),
                "embedding_method": how,
            })
            fits = [("min_k", kmin, how, rv_min_k)]
            for kf in cfg["fixed_k_sweep"] or []:
                kf = int(kf)
                if kf > n - 1 or graph_components(Dm, kf, ranks=R, always=always) > 1:
                    log.warning("%s %s/%s: fixed k=%d leaves the graph disconnected (min k %d); skipped",
                                dataset, method, metric, kf, kmin)
                    continue
                how_f, _, _, rv_f = fit_embedding(Dm, kf, always, max_dim, cfg["embedding"])
                fits.append(("fixed", kf, how_f, rv_f))
            for k_mode, k, how_k, rv in fits:
                for d, r in enumerate(rv, start=1):
                    rv_rows.append({"dataset": dataset, "global_dof": include_global, "method": method,
                                    "metric": metric, "k_mode": k_mode, "k": k, "dim": d,
                                    "residual_variance": round(float(r), 6), "embedding_method": how_k})
            t_rows.append({"dataset": dataset, "global_dof": include_global, "method": method, "metric": metric,
                           "frames": n, "seconds_distances": t_dist, "seconds_min_k": t_mink,
                           "seconds_geodesics_embedding": t_fit, "cpu_seconds_geodesics_embedding": c_fit})
            log.info("%s global=%s %s/%s: min k %d (components %d at k-1), fit %.2fs",
                     dataset, include_global, method, metric, kmin, below, t_fit)
    return pd.DataFrame(rows), pd.DataFrame(rv_rows), emb, pd.DataFrame(t_rows)


def explain(motion: Motion, dataset: str, trial: str, cfg: dict, budget_gib: float | None = None):
    """Minimum k over the candidate explanations of the paper's Table 2, and sign flips.

    ``motion`` is the trial *before* ``frame_step`` (``max_frames`` applied
    here). For every ``explanations.frame_steps`` x ``explanations.global_dof``
    x ``explanations.sign_modes`` x method x metric: the exact minimum k,
    cross-checked. The Lee metric does not depend on the sign mode (it is
    computed once per frame step x global flag and repeated in both rows).

    Returns
    -------
    grid : DataFrame, one row per condition x method x metric
    flips : DataFrame, sign flips per joint (root included) of the ``matrix_naive``
        quaternions per frame step (``continuous`` has none by construction)

    Raises
    ------
    animsynth.limits.BudgetError
        The distance matrices of the smallest frame step would exceed
        ``budget_gib`` (:func:`check_distance_budget`); checked before any is built.
    """
    ex = cfg["explanations"]
    check_distance_budget(prepare_motion(motion, cfg["max_frames"], int(min(ex["frame_steps"]))).n_frames, trial,
                          budget_gib)
    params = method_params(cfg)
    rows, flip_rows = [], []
    for step in ex["frame_steps"]:
        m = prepare_motion(motion, cfg["max_frames"], int(step))
        feats = motion_features(m)
        qall = np.concatenate([feats.root_quat[:, None, :], feats.quats], axis=1)
        names = ["root"] + list(feats.joint_names)
        fl = sign_flips(matrix_naive_quaternions(qall))
        cont = sign_flips(qall)
        for j, name in enumerate(names):
            flip_rows.append({"dataset": dataset, "trial": trial, "frame_step": int(step), "fps": m.fps,
                              "frames": m.n_frames, "joint": name, "flips_matrix_naive": int(fl[j]),
                              "flips_continuous": int(cont[j])})
        for g in ex["global_dof"]:
            g = bool(g)
            for metric in cfg["metrics"]:
                modes = ex["sign_modes"]
                D_lee = base_distances(feats, "lee", g, params) if metric == "lee" else None
                for mode in modes:
                    D = D_lee if metric == "lee" else base_distances(feats, "l2", g, params, sign_mode=mode)
                    for method in cfg["methods"]:
                        Dm, always, _ = method_distances(D, method, params, m.fps)
                        kmin, below, at, _ = checked_min_k(Dm, always, f"{dataset}/{step}/{g}/{mode}/{method}/{metric}")
                        rows.append({"dataset": dataset, "trial": trial, "frame_step": int(step), "fps": m.fps,
                                     "frames": m.n_frames, "global_dof": g, "sign_mode": mode, "method": method,
                                     "metric": metric, "min_k": kmin, "components_at_min_k_minus_1": below,
                                     "components_at_min_k": at})
        log.info("%s frame_step %d: matrix_naive flips %s", dataset, step,
                 {nm: int(c) for nm, c in zip(names, fl) if c})
    return pd.DataFrame(rows), pd.DataFrame(flip_rows)


def path_pairs(n: int, path_cfg: dict, seed: int) -> list[tuple[int, int]]:
    """The measured start/end pairs: ``random_pairs`` seeded pairs whose *end comes
    before the start* by at least ``min_separation * n`` frames.

    Why: a path that only steps to the next frame can never reach an earlier
    frame, so every such pair forces the shortest path to leave the original
    order -- it either jumps between passes (re-sequences) or plays the capture
    backwards (classified ``replays_backwards``). With ``min_separation`` 0.3
    the two frames lie about a cycle or more apart on the CMU walk (358
    frames, about 1 s per cycle) and run (167 frames, about 0.7 s per cycle).
    The same pairs are used for every method, metric and global flag of a dataset.
    """
    count = int(path_cfg["random_pairs"])
    sep = max(2, int(round(float(path_cfg["min_separation"]) * n)))
    if count > 0 and sep >= n:
        raise ValueError(f"config key 'resequencing.path.min_separation': no pair of {n} frames is {sep} apart")
    rng = np.random.default_rng(seed)
    pairs = []
    while len(pairs) < count:
        a, b = (int(x) for x in rng.integers(0, n, size=2))
        if a - b >= sep:
            pairs.append((a, b))
    return pairs


def main_pair(n: int, path_cfg: dict) -> tuple[int, int]:
    """The configured start/end of the main path (BVH and GIF)."""
    start = resolve_frame(path_cfg["start"], n, "config key 'resequencing.path.start'")
    end = resolve_frame(path_cfg["end"], n, "config key 'resequencing.path.end'")
    if start == end:
        raise ValueError("config keys 'resequencing.path.start' and '.end' name the same frame")
    return start, end


def splice(path, n: int, context: int) -> np.ndarray:
    """The path with up to ``context`` original frames before its start and after its end."""
    path = np.asarray(path, dtype=np.int64)
    pre = np.arange(max(0, path[0] - context), path[0])
    post = np.arange(path[-1] + 1, min(n, path[-1] + 1 + context))
    return np.concatenate([pre, path, post])


def config_resequencer(motion: Motion, include_global: bool, method: str, metric: str, k: int,
                       params: MethodParams) -> Resequencer:
    """The fitted :class:`~.generator.Resequencer` of a configuration: the dense graph of ``motion`` under its
    metric, global DOF, sign mode and ST-Isomap block (``params``: :func:`.settings.method_params`), at ``k``
    (checked: the graph must connect)."""
    return Resequencer(method, k=int(k), stisomap=params.stisomap if method == "stisomap" else None,
                       neighbours="dense", metric=metric, global_dof=include_global, sign_mode=params.sign_mode,
                       translation_scale=params.translation_scale, lee=params.lee).fit([motion])


#: Per-transition measures (ratios to the capture; 1 = an ordinary step of the capture, larger = rougher).
TRANSITION_MEASURES = ["pose_jump_ratio", "velocity_jump_ratio", "accel_jump_ratio", "foot_skate_ratio"]


def resequence(motion: Motion, include_global: bool, method: str, metric: str, k: int, cfg: dict, seed: int = 0,
               budget_gib: float | None = None):
    """Re-sequence one configuration: Dijkstra paths on the method's graph, played and measured.

    Every pair of :func:`path_pairs` gives one path. Each path is played inside
    its context (``path.context_s`` seconds of the original before the start
    and after the end, so a transition near an end is judged with real
    neighbours) with the root ``path.root_playback`` (the same whatever the
    global-DOF flag). Per path: frames played, non-temporal transitions (and
    per 100 frames played), backward steps, its class
    (:func:`~.metrics.classify_path`), jerk events per 100 frames played
    (frames of the path -- not of the context -- jerkier than the capture's
    jerkiest) and the mean of each per-transition measure
    (:func:`~.metrics.transition_measures`).

    Returns
    -------
    paths : list of int arrays, the Dijkstra paths of the measured pairs
    main : (int array, Motion), the main path (padded to ``path.pad_to``) and the motion it plays
    per_path : DataFrame, one row per pair
    per_transition : DataFrame, one row per transition

    Raises
    ------
    animsynth.limits.BudgetError
        The distance matrices would exceed ``budget_gib`` (:func:`check_distance_budget`).
    """
    n = motion.n_frames
    check_distance_budget(n, motion.name, budget_gib)
    params = method_params(cfg)
    est = config_resequencer(motion, include_global, method, metric, k, params)
    pc = cfg["path"]
    mode = pc["root_playback"]
    if mode not in ("absolute", "integrate"):
        raise ValueError(f"config key 'resequencing.path.root_playback': {mode!r} is not absolute or integrate")
    sm = cfg["smoothness"]
    ref = Reference(motion, float(sm["contact_height_m"]), float(sm["reversal_speed_mps"]))
    tref = TransitionReference(motion, float(sm["contact_height_m"]))
    context = int(round(float(pc["context_s"]) * motion.fps))
    window = max(1, int(round(float(pc["transition_window_s"]) * motion.fps)))
    same_pass = params.st(motion.fps)["ctn_min_gap"]  # frames closer in time: the same pass
    paths, rows, trows = [], [], []
    for p, (a, b) in enumerate(path_pairs(n, pc, seed)):
        path, cost = est.path(a, b, return_cost=True)
        paths.append(path)
        full = splice(path, n, context)
        first = int(a - max(0, a - context))  # position of the path's first frame in ``full``
        last = first + path.size - 1
        played = play_path(motion, full, root=mode, same_pass=same_pass)
        tr = transition_measures(tref, played, full, first, last, window)
        jm = jerk_magnitude(joint_quats(played), played.fps)
        lo, hi = max(0, first - 1), max(0, last - 1)  # jerk i spans frames i..i+3: centre inside the path
        jerk_events = int(np.count_nonzero(jm[lo:hi] > ref.jerk.max())) if jm.size else 0
        nt = len(tr)
        row = {"pair": p, "start": a, "end": b, "frames_played": int(path.size), "path_cost": cost,
               "transitions": nt, "transitions_per_100_frames": 100.0 * nt / path.size,
               "pass_jumps": int(pass_jumps(path, same_pass).size),
               "backward_steps": int(np.count_nonzero(np.diff(path) < 0)),
               "path_class": classify_path(path, same_pass),
               "jerk_events_per_100_frames": 100.0 * jerk_events / path.size}
        for c in TRANSITION_MEASURES:
            vals = np.array([t[c] for t in tr], float)
            row[c] = float(np.nanmean(vals)) if nt and np.isfinite(vals).any() else np.nan
        rows.append(row)
        for i, t in enumerate(tr):
            trows.append({"pair": p, "transition": i, **t})
    a, b = main_pair(n, pc)
    main_path = est.path(a, b)
    padded = pad_path(main_path, pc["pad_to"], pc["pad_mode"])
    main = play_path(motion, padded, root=mode, name=f"{motion.name}_{method}_{metric}_{gdof_name(include_global)}",
                     same_pass=same_pass)
    per_path = pd.DataFrame(rows)
    per_path.insert(0, "root_playback", mode)
    per_path.insert(0, "k", k)
    per_tr = pd.DataFrame(trows, columns=["pair", "transition", "position", "from_frame", "to_frame", "lag",
                                          *TRANSITION_MEASURES])
    per_tr.insert(per_tr.columns.get_loc("lag") + 1, "kind",
                  np.where(per_tr["lag"].abs() > same_pass, "pass_jump", "skip"))
    return paths, (padded, main), per_path, per_tr


CONFIG_KEYS = ["dataset", "global_dof", "method", "metric"]


def summarise_paths(per_path: pd.DataFrame) -> pd.DataFrame:
    """One smoothness row per configuration.

    Counts over all measured pairs (paths, share re-sequencing -- at least one
    jump to another pass --, replaying, backward-replaying and frame-skipping
    paths, mean transitions per path and per 100 frames played, pass jumps per
    path); smoothness means over the *re-sequencing* paths only (replaying
    paths have no transitions to judge)."""
    keys = CONFIG_KEYS + ["k", "root_playback"]
    out = []
    for key, g in per_path.groupby(keys, sort=False):
        rs = g[g["path_class"] == "resequences"]
        row = dict(zip(keys, key))
        row.update({
            "paths": len(g), "resequencing_paths": len(rs),
            "share_resequencing": round(len(rs) / len(g), 6),
            "replaying_paths": int((g["path_class"] == "replays").sum()),
            "backward_replaying_paths": int((g["path_class"] == "replays_backwards").sum()),
            "skipping_paths": int((g["path_class"] == "skips").sum()),
            "frames_played_mean": round(float(g["frames_played"].mean()), 3),
            "transitions_per_path": round(float(g["transitions"].mean()), 4),
            "transitions_per_100_frames": round(float(g["transitions_per_100_frames"].mean()), 4),
            "pass_jumps_per_path": round(float(g["pass_jumps"].mean()), 4),
        })
        for c in TRANSITION_MEASURES + ["jerk_events_per_100_frames"]:
            row[f"{c}_resequencing_mean"] = round(float(rs[c].mean()), 6) if len(rs) else np.nan
        out.append(row)
    return pd.DataFrame(out)


