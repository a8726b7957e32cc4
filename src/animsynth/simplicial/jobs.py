"""One function per workflow job, so that the Snakemake scripts stay thin.

Every function takes plain paths and config dicts (what the rule passes in
``params``) and writes its outputs atomically. None reads the global config.
"""

from __future__ import annotations

import json
import logging
import os

import numpy as np
import pandas as pd

from ..motion import Motion
from ..io.atomic import atomic_write_text
from ..tables import write_table
from . import experiment as ex

log = logging.getLogger("animsynth.simplicial.jobs")


def load_trials(paths, ids) -> tuple[dict, dict]:
    """Parsed trials -> (id -> 56 joint-angle columns, id -> Motion), in the given order."""
    if len(paths) != len(ids):
        raise ValueError(f"{len(paths)} trial files for {len(ids)} trial ids")
    angles, motions = {}, {}
    for p, tid in zip(paths, ids):
        stem = os.path.splitext(os.path.basename(os.fspath(p)))[0]
        if stem != tid:
            raise ValueError(f"trial file {p} does not match trial id {tid!r}")
        m = Motion.load_npz(p)
        a = np.asarray(m.without_root(), float)
        if not np.all(np.isfinite(a)):
            raise ValueError(f"trial file {p}: joint angles contain NaN/inf")
        angles[tid], motions[tid] = a, m
    return angles, motions


def main_variant(cfg: dict, method: str) -> ex.Variant:
    """The paper's configuration for ``method`` (config keys of the main table)."""
    return ex.Variant(method, method=method, k=int(cfg["k"]), latent_dim=int(cfg["latent_dim"]),
                      derivative=cfg["derivative"], weights=cfg["weights"] if method == "delaunay" else "idw").check()


def run_main_fold(paths, ids, dataset: str, method: str, fold: str, cfg: dict):
    """One dataset x method x fold job of the main table; returns the FoldResult."""
    angles, _ = load_trials(paths, ids)
    if fold not in angles:
        raise ValueError(f"fold {fold!r} is not a trial of subset {dataset!r} ({ids})")
    train = [angles[t] for t in ids if t != fold]
    res = ex.run_fold(train, angles[fold], main_variant(cfg, method), dataset=dataset, held_out=fold,
                      fold=ids.index(fold), steps=cfg["steps"], dup_tol=float(cfg["dup_tol"]),
                      rank_tol=float(cfg["rank_tol"]))
    for note in res.field.triangulation_.notes_:
        log.info("fold %s/%s/%s: %s", dataset, method, fold, note)
    log.info("fold %s/%s/%s: error_a=%.4g error_f=%.4g steps=%d fallback=%d SCC=%d", dataset, method, fold,
             res.row["error_a"], res.row["error_f"], res.row["steps"], res.row["fallback_steps"], res.row["components"])
    return res


def write_fold_json(path, row: dict) -> None:
    atomic_write_text(path, json.dumps(ex.to_jsonable(row), indent=1) + "\n")


def read_fold_jsons(paths) -> pd.DataFrame:
    rows = []
    for p in paths:
        with open(p, encoding="utf-8") as f:
            rows.append(json.load(f))
    return pd.DataFrame(rows, columns=ex.FOLD_COLUMNS)


TABLE2_NOTE = (
    "Medians over leave-one-sequence-out folds (4 per subset; `all` = all folds). Error A: mean closest-point "
    "distance between held-out and generated latent polylines, averaged over both directions; Error F: closest "
    "approach of the generated path to the held-out final point. Latent units, and `_norm` = divided by the "
    "diagonal of the fold's latent bounding box. `paper_*` columns: the paper's published Table II values{paper}."
)


def table_job(fold_paths, datasets, methods, cfg: dict, out: dict) -> None:
    """folds.csv, table2.csv/.md and paired.csv/.md from the fold JSONs."""
    folds = ex.order_folds(read_fold_jsons(fold_paths), datasets)
    write_table(folds, out["folds"], md=False)
    paper = cfg.get("paper_table2") or {}
    t2 = ex.table2(folds, datasets, methods, paper)
    has_paper = any(bool(v) for v in paper.values())
    note = TABLE2_NOTE.format(paper=" (from config `simplicial.paper_table2`)" if has_paper else
                              " - EMPTY: the paper's values were not available to us and are not invented; "
                              "fill `simplicial.paper_table2` from the paper to show them")
    write_table(t2, out["table2"], md=True, title="Gauch & Peters Table II (reproduction)", note=note)
    pc = ex.paired_comparison(folds, methods[0], methods[1], n_boot=int(cfg["bootstrap"]), seed=int(cfg["seed_value"]),
                              alpha=float(cfg["alpha"]))
    write_table(pc, out["paired"], md=True, title=f"Paired comparison {methods[0]} vs {methods[1]} over folds",
                note="Wilcoxon signed-rank test (two-sided) on per-fold differences; bootstrap percentile CI "
                     "of the median difference (a - b < 0: a has the lower error). `_pose` metrics are in degrees "
                     "of joint angle (inverse PCA of the generated path vs the held-out trial).")


def grid_job(paths, ids, dataset: str, grid: str, cfg: dict, out_csv) -> None:
    """The derivative-variant grid or the beyond-the-paper grid for one subset."""
    angles, _ = load_trials(paths, ids)
    if grid == "derivative":
        variants = ex.derivative_variants(cfg["derivatives"], cfg["methods"], int(cfg["k"]), int(cfg["latent_dim"]),
                                          cfg["weights"])
    elif grid == "beyond":
        variants = ex.beyond_variants(cfg["beyond"], int(cfg["k"]), cfg["beyond"]["derivative"])
    else:
        raise ValueError(f"unknown grid {grid!r}")
    df = ex.run_subset(angles, variants, dataset=dataset, steps=cfg["steps"], dup_tol=float(cfg["dup_tol"]),
                       rank_tol=float(cfg["rank_tol"]),
                       max_all_pairs=int(cfg.get("beyond", {}).get("max_all_pairs", 4000)))
    log.info("%s grid on %s: %d variants x %d folds", grid, dataset, len(variants), len(ids))
    write_table(df, out_csv, md=False)


def summary_job(deriv_paths, beyond_paths, folds_csv, paired_csv, datasets, cfg: dict, out: dict) -> None:
    """derivative.csv, beyond.csv, beyond_folds.csv, verdicts.csv and their figures."""
    from .plots import plot_beyond, plot_derivative

    def cat(paths):
        return pd.concat([pd.read_csv(p, keep_default_na=False, na_values=[""]) for p in paths], ignore_index=True)

    dfold = ex.order_folds(cat(deriv_paths), datasets)
    bfold = ex.order_folds(cat(beyond_paths), datasets)
    seed, n_boot, alpha = int(cfg["seed_value"]), int(cfg["bootstrap"]), float(cfg["alpha"])
    methods = tuple(cfg["methods"])
    dsum = ex.derivative_summary(dfold, methods, cfg["paper_claim"], n_boot=n_boot, seed=seed)
    write_table(dsum, out["derivative"], md=True, title="Training-vector derivative variants",
                note="Medians over all folds. `half` = (x[i+1]-x[i])/2 as printed in the paper; `forward` = "
                     "x[i+1]-x[i]; `central` = (x[i+1]-x[i-1])/2. `reproduces_claim` compares the Delaunay-vs-k-NN "
                     f"ordering of median Error A and Error F with the configured paper claim ({cfg['paper_claim']}).")
    d0 = int(cfg["beyond"]["latent_dims"][0])
    baseline = f"delaunay_idw_d{d0}"
    bsum = ex.summarise_variants(bfold, baseline, datasets, n_boot=n_boot, seed=seed)
    write_table(bfold, out["beyond_folds"], md=False)
    best = bsum.iloc[0]
    write_table(bsum, out["beyond"], md=True, title="Beyond the paper: variants ranked by median pose-space Error A",
                note=f"Derivative '{cfg['beyond']['derivative']}'. error_*_pose: degrees of joint angle (comparable "
                     f"across latent dimensions; pose_floor = the same error for a perfect latent path, i.e. PCA reconstruction loss); *_norm: latent units / bbox diagonal. Baseline {baseline} = the "
                     f"paper's method. Best: {best['variant']} ({100 * best['rel_change_vs_baseline']:.1f}% vs baseline, "
                     f"Wilcoxon p={best['p_vs_baseline']:.3g}).")
    folds = pd.read_csv(folds_csv, keep_default_na=False, na_values=[""])
    paired = pd.read_csv(paired_csv, keep_default_na=False, na_values=[""])
    verdicts = ex.build_verdicts(paired, dsum, folds, bsum, bfold, claim=cfg["paper_claim"],
                                 main_derivative=cfg["derivative"], baseline=baseline, alpha=alpha)
    write_table(verdicts, out["verdicts"], md=True, title="Simplicial family: claims and verdicts")
    plot_derivative(dfold, out["derivative_png"], methods)
    plot_beyond(bsum, bfold, out["beyond_png"], baseline)


def figures_job(paths, ids, dataset: str, cfg: dict, out: dict) -> None:
    """Figs 1-6: G' (k-NN, Delaunay) for three folds, both fields, held-out vs generated paths."""
    from .plots import plot_field, plot_graphs, plot_paths

    angles, _ = load_trials(paths, ids)
    fig = cfg["figures"]
    graph_folds = [int(i) for i in fig["folds"]]
    for i in graph_folds + [int(fig["field_fold"])]:
        if not 0 <= i < len(ids):
            raise ValueError(f"config key 'simplicial.figures': fold index {i} outside 0..{len(ids) - 1}")
    results = {}
    for m in ("knn", "delaunay"):
        v = main_variant(cfg, m)
        results[m] = [ex.run_fold([angles[t] for t in ids if t != tid], angles[tid], v, dataset=dataset, held_out=tid,
                                  fold=i, steps=cfg["steps"], dup_tol=float(cfg["dup_tol"]), rank_tol=float(cfg["rank_tol"]))
                      for i, tid in enumerate(ids)]
    lab = {"knn": f"k-NN (k={cfg['k']})", "delaunay": "Delaunay"}
    for n, m in ((1, "knn"), (2, "delaunay")):
        plot_graphs([results[m][i] for i in graph_folds], out[f"fig{n}"], f"Fig {n}: G' with {lab[m]} edges, subset {dataset}")
    for n, m in ((3, "knn"), (4, "delaunay")):
        r = results[m][int(fig["field_fold"])]
        plot_field(r, out[f"fig{n}"], f"Fig {n}: {lab[m]} vector field, subset {dataset}, held out {r.row['held_out']} "
                                      f"(derivative '{cfg['derivative']}')")
    for n, m in ((5, "knn"), (6, "delaunay")):
        plot_paths(results[m], out[f"fig{n}"], f"Fig {n}: held-out vs generated paths, {lab[m]}, subset {dataset}")


def walk_job(paths, ids, dataset: str, cfg: dict, out: dict) -> None:
    """Fig 7: a generated walk reprojected to a stick figure (filmstrip PNG, BVH, GIF)."""
    from ..viz import motion_previews
    from .plots import in_place_root, walk_motion

    angles, motions = load_trials(paths, ids)
    fig = cfg["figures"]
    i = int(fig["walk_fold"])
    if not 0 <= i < len(ids):
        raise ValueError(f"config key 'simplicial.figures.walk_fold': {i} outside 0..{len(ids) - 1}")
    tid = ids[i]
    res = ex.run_fold([angles[t] for t in ids if t != tid], angles[tid], main_variant(cfg, fig["walk_method"]),
                      dataset=dataset, held_out=tid, fold=i, steps=cfg["steps"], dup_tol=float(cfg["dup_tol"]),
                      rank_tol=float(cfg["rank_tol"]))
    motion = walk_motion(res, motions[tid], name=f"simplicial {fig['walk_method']} walk, {dataset} held out {tid}")
    held = motions[tid]
    held_in_place = Motion(held.values.copy(), held.skeleton, held.fps, tid)
    n_root = len(held.skeleton.joints[0].dofs)
    held_in_place.values[:, :n_root] = in_place_root(held)  # same in-place root as the generated walk
    motion_previews(motion, gif_path=out["gif"], bvh_path=out["bvh"], png_path=out["png"], original=held_in_place,
                    titles=[f"held out {tid}", f"generated ({fig['walk_method']})"], fps=float(fig["gif_fps"]))
