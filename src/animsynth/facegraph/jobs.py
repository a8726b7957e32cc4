"""Workflow steps of the facegraph family (the scripts in workflow/scripts only call these): Table 1 rows
and their assembly, the face-graph baseline, the uniqueness study, table notes, and the family's scale steps.

Each function takes plain config dicts (sub-blocks of the ``facegraph`` block of the workflow config,
validated against ``config/schema.yaml``, which fills every default) and returns deterministic tables
(numbers rounded so that the same config gives byte-identical CSV files) and, separately, timing tables
(machine-dependent: CPU and wall time). The claims checked against these tables are in :mod:`.verdicts`.
"""

from __future__ import annotations

import hashlib
import itertools
import logging
import time

import numpy as np
import pandas as pd
from scipy.sparse.csgraph import connected_components, dijkstra
from threadpoolctl import threadpool_limits

from ..io.ckplus import EMOTIONS, emotion_code
from ..tables import add_paper_differences
from .baseline import FaceGraphBaseline
from .evaluate import compare, evaluate_resynthesis, summarise
from .model import FaceGraphModel
from .preprocess import FaceDatabase, FacePreprocessor
from .regiongraph import RegionGraph
from .synthesis import FaceSynthesizer, resample

log = logging.getLogger("animsynth.facegraph.jobs")

#: Rounding of reported (non-timing) numbers.
DECIMALS = 4


def graph_kwargs(graph_cfg: dict) -> dict:
    """:class:`FaceGraphModel` keyword arguments from the ``facegraph.graph`` config block."""
    return {
        "tolerance": float(graph_cfg["tolerance"]),
        "lam": float(graph_cfg["lambda"]),
        "velocity_eps": float(graph_cfg["velocity_eps"]),
        "max_iterations": int(graph_cfg["max_iterations"]),
        "procrustes": bool(graph_cfg["procrustes"]),
        "thresholds": str(graph_cfg["thresholds"]),
        "min_step_fraction": float(graph_cfg["min_step_fraction"]),
    }


def synth_kwargs(synth_cfg: dict, noise: bool = True) -> dict:
    """:class:`FaceSynthesizer` keyword arguments from the ``facegraph.synthesis`` config block;
    ``noise=False`` switches the coherent node noise and the duration noise off."""
    return {
        "savgol_window": int(synth_cfg["savgol_window"]),
        "savgol_order": int(synth_cfg["savgol_order"]),
        "sigmoid_weight": float(synth_cfg["sigmoid_weight"]),
        "noise_share": float(synth_cfg["noise_share"]) if noise else 0.0,
        "noise_hops": int(synth_cfg["noise_hops"]),
        "duration_noise": bool(synth_cfg["duration_noise"]) if noise else False,
        "peak_weights": tuple(synth_cfg["peak_weights"]),
    }


def model_for(conf: dict, cfg: dict, seed: int) -> FaceGraphModel:
    """The estimator of one configuration (``conf`` from :func:`.settings.configurations`, fractions;
    ``cfg`` holds the ``graph`` block)."""
    return FaceGraphModel(100.0 * conf["creation"], 100.0 * conf["merge"], seed=seed,
                          creation_tolerance=100.0 * conf["creation_tolerance"],
                          merge_tolerance=100.0 * conf["merge_tolerance"], **graph_kwargs(cfg["graph"]))


def _r(x):
    return float(np.round(float(x), DECIMALS)) if np.isfinite(x) else float("nan")


ACCURACY_KEYS = {  # Table 1 / baseline column -> summary key
    "duration_diff": "duration_diff_frames", "duration_diff_sd": "duration_diff_frames_sd",
    "duration_signed": "duration_signed_frames",
    "landmark_diff_px": "landmark_diff_px", "landmark_diff_sd": "landmark_diff_px_sd",
    "velocity_angle_diff_pct": "velocity_angle_diff_pct", "velocity_angle_diff_sd": "velocity_angle_diff_pct_sd",
}


def _accuracy(sm, prefix: str = "") -> dict:
    """The re-synthesis accuracy measures of a summary, rounded (same columns in Table 1 and the baseline)."""
    return {prefix + k: _r(sm.get(prefix + v, np.nan)) for k, v in ACCURACY_KEYS.items()}


def original_nbytes(db: FaceDatabase) -> int:
    """The original landmark data: frames x 68 x 2 coordinates as float32."""
    return int(db.lengths.sum()) * 68 * 2 * 4


def warm_up(db: FaceDatabase, conf: dict, cfg: dict, seed: int, max_poses: int = 200) -> None:
    """Fit ``conf`` once on a small subset of ``db`` (at most ``max_poses`` poses), untimed.

    numba compiles the creation loops (empty cache) or loads them from its cache
    on the first fit of a process; a warm-up makes the creation times of the
    configurations that follow in the same process comparable with one another.
    """
    with threadpool_limits(1):
        model_for(conf, cfg, seed).fit(subset_database(db, max_poses, seed))


def run_configuration(db: FaceDatabase, conf: dict, cfg: dict, seed: int):
    """Build the region graphs for one compression configuration and evaluate them.

    ``conf``: a dict of :func:`.settings.configurations` (fractions); ``cfg``: the
    ``graph``, ``synthesis`` and ``evaluation`` blocks of the facegraph config. Returns
    (Table 1 row, timing row, per-region threshold table, fitted model,
    per-sample table). Only the timing row holds machine-dependent numbers.
    """
    ev = cfg["evaluation"]
    with threadpool_limits(1):
        model = model_for(conf, cfg, seed).fit(db)
        synth = FaceSynthesizer(model.graphs_, **synth_kwargs(cfg["synthesis"], noise=bool(ev["noise"])))
        per = evaluate_resynthesis(db, synth, seed=seed, min_speed=float(ev["min_speed"]))
    sm = summarise(per)
    frames = int(db.lengths.sum())
    graphs = model.graphs_
    conn = connectivity(db, graphs)
    nodes = sum(g.n_nodes for g in graphs.values())
    s = model.search_
    row = {
        "config": conf["name"],
        "creation_target": conf["creation"], "creation_tolerance": conf["creation_tolerance"],
        "merge_target": conf["merge"], "merge_tolerance": conf["merge_tolerance"],
        "threshold_mode": str(s["threshold_mode"].iloc[0]),
        "creation_achieved": _r(s["creation_achieved_pct"].mean() / 100.0),
        "merge_achieved": _r(s["merge_achieved_pct"].mean() / 100.0),
        "creation_in_band_pct": _r(s["creation_in_band_pct"].mean()),
        "merge_in_band_pct": _r(s["merge_in_band_pct"].mean()),
        "thresholds_converged": bool(s["creation_converged"].all() and s["merge_converged"].all()),
        "poses": frames,
        "nodes": int(nodes),
        "edges": int(sum(g.n_edges for g in graphs.values())),
        "strong_components_max": conn["strong_components_max"],
        "reachable_peaks_mean": _r(conn["reachable_peaks_mean"]),
        "shared_peak_pct": _r(100.0 * np.mean([g.peak_dur_n[g.peak_of_sample] > 1 for g in graphs.values()])),
        "node_compression_pct": _r(100.0 * (1.0 - nodes / frames)),
        "data_compression_pct": _r(100.0 * (1.0 - sum(g.nbytes() for g in graphs.values()) / original_nbytes(db))),
        **_accuracy(sm), **_accuracy(sm, "random_"), **_accuracy(sm, "linear_"),
    }
    timing = {
        "config": conf["name"],
        "creation_cpu_s": float(model.timings_["creation_cpu_s"]),
        "creation_wall_s": float(model.timings_["creation_wall_s"]),
        "synthesis_ms": float(sm["timing_synthesis_ms"]),
        "synthesis_ms_sd": float(sm["timing_synthesis_ms_sd"]),
    }
    thr = s.copy()
    thr.insert(0, "config", row["config"])
    for c in ("creation_threshold", "creation_achieved_pct", "merge_threshold", "merge_achieved_pct",
              "creation_in_band_pct", "merge_in_band_pct"):
        thr[c] = thr[c].map(lambda v: float(np.round(v, 6)))
    return row, timing, thr, model, per


def connectivity(db: FaceDatabase, graphs: dict[str, RegionGraph]) -> dict:
    """Largest number of strongly connected components over the region graphs,
    and the mean number of peak nodes of a sample's label reachable from its
    neutral node (over samples and regions): the choice the random peak
    selection has in re-synthesis (1 = only one peak reachable)."""
    comps, reach = [], []
    for g in graphs.values():
        comps.append(int(connected_components(g.csr(), directed=True, connection="strong")[0]))
        starts = np.unique(g.start_of_sample)
        dist = dijkstra(g.csr(), directed=True, indices=starts)
        row = {int(s): i for i, s in enumerate(starts)}
        for s in range(db.n_samples):
            pk = g.peak_nodes(int(db.emotions[s]))
            reach.append(int(np.isfinite(dist[row[int(g.start_of_sample[s])], pk]).sum()))
    return {"strong_components_max": max(comps), "reachable_peaks_mean": float(np.mean(reach))}


#: Table 1 measures shown with the published value beside ours.
_PAPER_BESIDE = ["node_compression_pct", "data_compression_pct", "duration_diff", "duration_diff_sd",
                 "landmark_diff_px", "landmark_diff_sd", "velocity_angle_diff_pct", "velocity_angle_diff_sd"]
#: Table 1 column order (deterministic: no timings); ``paper_*`` from the published table (empty if unknown).
TABLE1_COLUMNS = (
    ["paper_row", "config", "creation_target", "creation_tolerance", "merge_target", "merge_tolerance",
     "threshold_mode", "creation_achieved", "merge_achieved", "creation_in_band_pct", "merge_in_band_pct",
     "thresholds_converged", "poses", "nodes", "edges", "strong_components_max", "reachable_peaks_mean",
     "shared_peak_pct"]
    + [c for k in _PAPER_BESIDE for c in (k, "paper_" + k, k + "_minus_paper")]
    + ["duration_signed"]
    + [p + k for p in ("random_", "linear_") for k in ACCURACY_KEYS]
)
#: ``table1_timing.csv`` columns (machine-dependent; CPU and wall time, the paper's beside).
TIMING_COLUMNS = ["config", "creation_cpu_s", "creation_wall_s", "paper_creation_time_s", "creation_cpu_over_paper",
                  "synthesis_ms", "synthesis_ms_sd", "paper_synthesis_time_s", "paper_synthesis_time_sd",
                  "synthesis_over_paper"]


def assemble_table1(rows: list[dict], order: list[str], paper: dict | None = None) -> pd.DataFrame:
    """Rows in config order; ``paper``: config name -> published values (:func:`.settings.published_table1`)."""
    by = {r["config"]: dict(r) for r in rows}
    out = []
    for name in order:
        r = by[name]
        pv = (paper or {}).get(name, {})
        r["paper_row"] = pv.get("row", np.nan)
        for k in _PAPER_BESIDE:
            r["paper_" + k] = pv.get(k, np.nan)
        out.append(r)
    df = add_paper_differences(pd.DataFrame(out), {k: "paper_" + k for k in _PAPER_BESIDE})
    return df[TABLE1_COLUMNS]


def assemble_timing(rows: list[dict], order: list[str], paper: dict | None = None) -> pd.DataFrame:
    """Timing rows in config order with the published times beside ours and ours / paper ratios."""
    by = {r["config"]: dict(r) for r in rows}
    out = []
    for name in order:
        r = by[name]
        pv = (paper or {}).get(name, {})
        r["paper_creation_time_s"] = pv.get("creation_time_s", np.nan)
        r["paper_synthesis_time_s"] = pv.get("synthesis_time_s", np.nan)
        r["paper_synthesis_time_sd"] = pv.get("synthesis_time_sd", np.nan)
        # times compare as ratios (ours / paper's; different machines and languages)
        r["creation_cpu_over_paper"] = r["creation_cpu_s"] / r["paper_creation_time_s"]
        r["synthesis_over_paper"] = r["synthesis_ms"] / 1000.0 / r["paper_synthesis_time_s"]
        out.append(r)
    return pd.DataFrame(out)[TIMING_COLUMNS]


# ---------------------------------------------------------------------------
def _query_samples(db: FaceDatabase, max_queries: int | None, seed: int) -> np.ndarray:
    S = db.n_samples
    if not max_queries or max_queries >= S:
        return np.arange(S)
    return np.sort(np.random.default_rng(seed).choice(S, size=int(max_queries), replace=False))


def face_graph_nbytes(n_poses: int, n_parts: int) -> int:
    """Memory of complete face graph(s) on ``n_poses`` poses as float32 weights
    (N^2 per graph) plus the poses (float32) - what :meth:`FaceGraphBaseline.nbytes` reports."""
    return int(4 * (n_parts * n_poses * n_poses + n_poses * 68 * 2))


def baseline_table(db: FaceDatabase, graphs: dict[str, RegionGraph], cfg: dict, seed: int,
                   showcase: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Face graph (holistic, per region; each weight power) vs region graphs on the same queries.

    Every query re-synthesises a database sample from its neutral pose to its
    own peak (the Table 1 counterpart). A face graph with more poses than
    ``baseline.max_nodes`` is not built: its memory is computed from its size
    and its path time extrapolated (Dijkstra on a complete graph is O(N^2)) from
    a complete graph on a seeded subset of ``max_nodes`` poses; the ``built``
    column says which. ``cfg``: the ``baseline``, ``synthesis`` and ``evaluation`` blocks of the
    facegraph config. Returns (deterministic table, timing table).
    """
    bcfg = cfg["baseline"]
    ev = cfg["evaluation"]
    min_speed = float(ev["min_speed"])
    max_nodes = bcfg["max_nodes"]  # None: always build
    queries = _query_samples(db, bcfg["max_queries"], seed)
    rows, trows = [], []
    with threadpool_limits(1):
        synth = FaceSynthesizer(graphs, **synth_kwargs(cfg["synthesis"], noise=bool(ev["noise"])))
        per = evaluate_resynthesis(db, synth, seed=seed, min_speed=min_speed, samples=queries, extras=False)
        pf = []
        for s in queries:
            start = synth.start_nodes(sample=int(s))
            t0 = time.perf_counter()
            for r, g in graphs.items():
                dijkstra(g.csr(), directed=True, indices=start[r], return_predecessors=True)
            pf.append(time.perf_counter() - t0)
        sm = summarise(per)
        nodes = sum(g.n_nodes for g in graphs.values())
        name = f"region graphs ({showcase})"
        rows.append(_baseline_row(name, "5 region graphs", nodes, sum(g.n_edges for g in graphs.values()),
                                  sum(g.nbytes() for g in graphs.values()), sm, len(queries), True))
        trows.append(_timing_row(name, "5 region graphs", pf, False, np.nan))
        o = db.offsets
        N = int(db.lengths.sum())
        for per_region in (False, True):
            kind = "per region (5 graphs)" if per_region else "holistic (1 graph)"
            parts = 5 if per_region else 1
            for power in bcfg["weight_powers"]:
                wname = "L2" if float(power) == 1.0 else f"L2^{float(power):g}"
                name = f"face graph, Zhang et al. 2004 ({wname})"
                if max_nodes is not None and N > int(max_nodes):
                    sub = subset_database(db, int(max_nodes), seed)
                    base = FaceGraphBaseline(power=float(power), per_region=per_region).fit(sub)
                    so = sub.offsets
                    times = [base.synthesize(int(so[k]), int(so[k + 1] - 1))[1]
                             for k in range(min(sub.n_samples, len(queries)))]
                    scale = (N / sub.lengths.sum()) ** 2
                    rows.append(_baseline_row(name, kind, N, parts * N * (N - 1), face_graph_nbytes(N, parts),
                                              {}, len(queries), False))
                    trows.append(_timing_row(name, kind, np.asarray(times) * scale, True, 1.9))
                    del base
                    continue
                base = FaceGraphBaseline(power=float(power), per_region=per_region).fit(db)
                recs, times = [], []
                for s in queries:
                    anim, secs, _ = base.synthesize(int(o[s]), int(o[s + 1] - 1))
                    recs.append(compare(db.forward(int(s)), anim, min_speed))
                    times.append(secs)
                rows.append(_baseline_row(name, kind, base.n_nodes_, base.n_edges, base.nbytes(),
                                          summarise(pd.DataFrame(recs)), len(queries), True))
                trows.append(_timing_row(name, kind, times, False, 1.9))
                del base
    return pd.DataFrame(rows), pd.DataFrame(trows)


def subset_database(db: FaceDatabase, max_poses: int, seed: int) -> FaceDatabase:
    """Whole samples (seeded order) holding at most ``max_poses`` poses."""
    order = np.random.default_rng(seed).permutation(db.n_samples)
    keep = order[np.cumsum(db.lengths[order]) <= max_poses]
    keep = np.sort(keep if keep.size >= 2 else order[:2])
    o = db.offsets
    return FaceDatabase([db.names[k] for k in keep], db.emotions[keep], db.lengths[keep],
                        np.concatenate([db.disp[o[k]:o[k + 1]] for k in keep]), db.neutral[keep], db.mean_neutral,
                        db.regions, db.reduced, db.source)


def _baseline_row(method, structure, nodes, edges, nbytes, sm, n_queries, built) -> dict:
    return {
        "method": method,
        "structure": structure,
        "queries": int(n_queries),
        "built": bool(built),
        "nodes": int(nodes),
        "edges": int(edges),
        "memory_mb": _r(nbytes / 1e6),
        **_accuracy(sm),
    }


def _timing_row(method, structure, times, estimated, paper_s) -> dict:
    t = np.asarray(times, float) * 1000.0
    return {"method": method, "structure": structure, "pathfinding_ms": float(t.mean()),
            "pathfinding_ms_sd": float(t.std()), "estimated": bool(estimated), "paper_pathfinding_s": paper_s,
            "pathfinding_over_paper": float(t.mean()) / 1000.0 / paper_s if paper_s else np.nan}


# ---------------------------------------------------------------------------
def _fingerprint(disp: np.ndarray) -> str:
    return hashlib.sha256(np.round(disp, 3).astype(np.float64).tobytes() + str(disp.shape).encode()).hexdigest()


def uniqueness_tables(graphs: dict[str, RegionGraph], cfg: dict, seed: int):
    """How many distinct animations N runs of one label sequence give, and their distances.

    Settings (run k uses generator seeds derived from ``seed`` and k):

    1. fixed peak nodes (one peak generator for all runs), no noise;
    2. fixed peak nodes + coherent node noise;
    3. fixed peak nodes + node noise + duration noise;
    4. random peak nodes + node noise + duration noise (the full synthesis).

    Distances: mean landmark distance (px) after resampling both animations to
    100 frames over the same time span. ``cfg``: the ``uniqueness`` and ``synthesis``
    blocks of the facegraph config. Returns (summary table, pairwise table).
    """
    ucfg = cfg["uniqueness"]
    labels = [EMOTIONS[emotion_code(x)] for x in ucfg["labels"]]
    runs = int(ucfg["runs"])
    scfg = cfg["synthesis"]
    full = synth_kwargs(scfg, noise=True)
    settings = [
        ("fixed peaks, no noise", dict(synth_kwargs(scfg, noise=False)), True),
        ("fixed peaks + node noise", dict(full, duration_noise=False), True),
        ("fixed peaks + node + duration noise", dict(full), True),
        ("random peaks + node + duration noise", dict(full), False),
    ]
    summary, pairs = [], []
    with threadpool_limits(1):
        for name, kw, fixed in settings:
            synth = FaceSynthesizer(graphs, **kw)
            anims = []
            for k in range(runs):
                peak = np.random.default_rng([int(seed), 0]) if fixed else None
                anims.append(synth.synthesize(labels, rng=np.random.default_rng([int(seed), 1, k]), peak_rng=peak).disp)
            prints = [_fingerprint(a) for a in anims]
            rs = [resample(a, 100) for a in anims]
            d = []
            for i, j in itertools.combinations(range(runs), 2):
                dist = float(np.sqrt(((rs[i] - rs[j]) ** 2).sum(-1)).mean())
                d.append(dist)
                pairs.append({"setting": name, "run_a": i, "run_b": j, "distance_px": _r(dist),
                              "identical": prints[i] == prints[j]})
            d = np.asarray(d) if d else np.array([np.nan])
            lens = np.array([len(a) for a in anims])
            summary.append({
                "labels": " -> ".join(labels), "setting": name, "random_peaks": not fixed,
                "noise_share": kw["noise_share"], "noise_hops": kw["noise_hops"], "duration_noise": kw["duration_noise"],
                "runs": runs, "distinct": len(set(prints)),
                "frames_min": int(lens.min()), "frames_max": int(lens.max()),
                "distance_mean_px": _r(np.nanmean(d)), "distance_sd_px": _r(np.nanstd(d)),
                "distance_min_px": _r(np.nanmin(d)), "distance_max_px": _r(np.nanmax(d)),
            })
    return pd.DataFrame(summary), pd.DataFrame(pairs)


def data_note(source: str) -> str:
    """How a table's data relates to the paper's (for table notes)."""
    if source.startswith("synthetic"):
        return f"Data: {source} - synthetic CK+-layout data, not the paper's CK+ data."
    return f"Data: {source} (real CK+ landmarks; the paper's exact sequence selection may differ)."


# ----------------------------------------------------------------------------- cost curves (animsynth.scale)
def scale_steps(recorder, n: int, seed: int = 0, creation: float = 50.0, merge: float = 30.0, frames_per_sequence: int = 26):
    """Facial motion graphs of ``n`` synthetic sequences: pre-processing, then creation + merging
    including both threshold searches."""
    from ..synth.faces import generate_sequences

    seqs = generate_sequences(n_subjects=max(1, n // 4), n_sequences=n, total_frames=n * frames_per_sequence,
                              n_unlabelled=0, min_frames=10, max_frames=60, seed=seed)
    S = recorder("facegraph", n)
    with S.step("preprocess"):
        db = FacePreprocessor().fit_transform(seqs, source="synthetic")
    with S.step("creation_incl_search") as info, threadpool_limits(1):
        model = FaceGraphModel(creation, merge, seed=seed).fit(db)
        info["nodes"] = int(sum(g.n_nodes for g in model.graphs_.values()))
    for r in S.rows:
        r["frames"] = int(db.lengths.sum())
    return S.rows
