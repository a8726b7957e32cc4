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

from ..config import derive_seed
from ..kinematics import translated_joints
from ..motion import Motion
from ..atomic import atomic_write_text
from ..tables import write_table
from .folds import (FOLD_COLUMNS, MEMBER_COLUMNS, Variant, beyond_variants, derivative_variants, order_folds,
                    run_fold, run_fold_ensemble, run_subset, to_jsonable)
from .settings import check_figure_folds, paper_claim_from, read_paper_table1, read_paper_table2
from .stats import derivative_summary, paired_comparison, summarise_variants
from .table1 import datasets_table
from .tables import fold_ensemble, table2, table2_ensemble, table2_units

log = logging.getLogger("animsynth.simplicial.jobs")


def load_trials(paths, ids) -> tuple[dict, dict]:
    """Parsed trials of one subset -> (id -> 56 joint-angle columns, id -> Motion), in the given order.

    The subset's trials share one database in every fold, so they are put on one skeleton and one angle branch
    first: every trial on the first trial's skeleton (:func:`animsynth.retarget.retarget`: the same skeleton,
    rest offsets within 1 mm, is kept as it is; other rest offsets are retargeted with a logged warning, or
    refused naming both trials), each trial's angles continuous along time and on the branch of the first
    trial's (:func:`animsynth.retarget.continuous_clips`). A trial that needs neither keeps its values bit
    for bit.
    """
    from ..retarget import continuous_clips
    from ..retarget import retarget

    if len(paths) != len(ids):
        raise ValueError(f"{len(paths)} trial files for {len(ids)} trial ids")
    loaded = []
    for p, tid in zip(paths, ids):
        stem = os.path.splitext(os.path.basename(os.fspath(p)))[0]
        if stem != tid:
            raise ValueError(f"trial file {p} does not match trial id {tid!r}")
        loaded.append(Motion.load_npz(p))
    if loaded:
        first = loaded[0]
        loaded = continuous_clips([first] + [retarget(m, first.skeleton, f"trial {tid}", f"trial {ids[0]}")
                                             for m, tid in zip(loaded[1:], ids[1:])])
    angles, motions = {}, {}
    for p, tid, m in zip(paths, ids, loaded):
        a = np.asarray(m.without_root(), float)
        moved = translated_joints(m.skeleton)
        if moved:
            log.info("trial %s: joint(s) %s move against their parent; their translation DOF (file length units) are "
                     "columns of the pose vector beside the joint angles, as the root's are not", tid,
                     ", ".join(moved))
        if not np.all(np.isfinite(a)):
            raise ValueError(f"trial file {p}: joint angles contain NaN/inf")
        angles[tid], motions[tid] = a, m
    return angles, motions


def table1_job(trial_paths, subsets: dict, source: str, out: dict, paper_table1=None, paper_label=None) -> None:
    """Gauch & Peters Table I of the run's subsets, the published lengths beside ours (``out["csv"]`` + ``.md``).

    Parameters
    ----------
    trial_paths : parsed trials (``<trial id>.npz``) of every subset
    subsets : subset name -> trial ids, in order
    source : ``synthetic``, ``cmu`` or ``user``
    paper_table1 : the published Table I file, or None (no published lengths: the ``paper_*`` columns stay
        empty); ``paper_label`` names it in the note (the configured path).
    """
    motions = {os.path.splitext(os.path.basename(os.fspath(p)))[0]: Motion.load_npz(p) for p in trial_paths}
    paper = read_paper_table1(paper_table1)
    df = datasets_table(subsets, motions, source, paper if paper is not None else {})
    if paper:
        diff = [f"{r.dataset}: {r.length_match}" for r in df.itertuples()
                if r.length_match and not r.length_match.startswith("all")]
        note = (f"`paper_*`: Gauch & Peters Table I, read from {paper_label}. "
                + ("Subsets whose lengths differ from the paper's (same position): " + "; ".join(diff) + "."
                   if diff else "Every trial has the paper's length."))
    else:
        note = f"No published Table I at {paper_label!r}: paper columns left empty."
    write_table(df, out["csv"], md=True, title=f"Table I: datasets ({source} data)", note=note)
    log.info("wrote Table I with %d subsets", len(df))


def main_variant(cfg: dict, method: str) -> Variant:
    """The paper's configuration for ``method`` (config keys of the main table)."""
    return Variant(method, method=method, k=int(cfg["k"]), latent_dim=int(cfg["latent_dim"]),
                   derivative=cfg["derivative"], weights=cfg["weights"] if method == "delaunay" else "idw").check()


def run_main_fold(paths, ids, dataset: str, fold: str, cfg: dict, seed: int):
    """One dataset x fold job of the main table: every method from the same ensemble of starts, followed together.

    Returns
    -------
    rows : list of dict (one per method), members : DataFrame
    """
    angles, _ = load_trials(paths, ids)
    if fold not in angles:
        raise ValueError(f"fold {fold!r} is not a trial of subset {dataset!r} ({ids})")
    train = [angles[t] for t in ids if t != fold]
    n_train = sum(len(a) for a in train)
    if int(cfg["k"]) >= n_train:
        raise ValueError(f"config key 'simplicial.k' = {cfg['k']} must be below the {n_train} training frames "
                         f"of fold {dataset}/{fold}")
    ens = cfg["ensemble"]
    variants = [main_variant(cfg, m) for m in cfg["methods"]]
    rows, members = run_fold_ensemble(
        train, angles[fold], variants, n_starts=int(ens["n_starts"]), jitter=float(ens["jitter"]),
        seed=derive_seed(seed, dataset, fold), dataset=dataset, held_out=fold, fold=ids.index(fold),
        steps=cfg["steps"], dup_tol=float(cfg["dup_tol"]), rank_tol=float(cfg["rank_tol"]))
    for r in rows:
        log.info("fold %s/%s/%s: error_a_norm=%.4g error_f_norm=%.4g steps=%d fallback=%d (%.0f %%) SCC=%d; "
                 "ensemble of %d: error_a_norm median %.4g IQR %.4g-%.4g, separation growth 10^%.2f", dataset,
                 r["method"], fold, r["error_a_norm"], r["error_f_norm"], r["steps"], r["fallback_steps"],
                 100 * r["fallback_share"], r["components"], r["n_members"], r["ens_error_a_norm_median"],
                 r["ens_error_a_norm_q25"], r["ens_error_a_norm_q75"], r["sep_growth_log10"])
    return rows, members


def write_fold_json(path, rows: list, members) -> None:
    """Fold rows and ensemble members (one DataFrame, or a list of them, one per fold) -> one JSON file."""
    if isinstance(members, pd.DataFrame):
        members = [members]
    payload = {"rows": [to_jsonable(r) for r in rows],
               "members": [to_jsonable(r) for m in members for r in m.to_dict("records")]}
    atomic_write_text(path, json.dumps(payload, indent=0) + "\n")


def read_fold_jsons(paths) -> tuple[pd.DataFrame, pd.DataFrame]:
    rows, members = [], []
    for p in paths:
        with open(p, encoding="utf-8") as f:
            d = json.load(f)
        rows += d["rows"]
        members += d["members"]
    return pd.DataFrame(rows, columns=FOLD_COLUMNS), pd.DataFrame(members, columns=MEMBER_COLUMNS)


def _fallback_note(folds: pd.DataFrame, method: str = "delaunay") -> str:
    s = folds[(folds["method"] == method) & (folds["fallback_steps"] > 0)]
    if not len(s):
        return f"{method} never left the hull (no k-NN fallback steps)."
    parts = [f"{r['dataset']}/{r['held_out']} {100 * r['fallback_share']:.0f} %" for _, r in s.iterrows()]
    return f"Share of {method} steps outside the hull (k-NN fallback), held-out start, per fold: " + ", ".join(parts) + "."


def table_job(fold_paths, datasets, methods, cfg: dict, out: dict, paper_table2=None, paper_label=None) -> None:
    """folds.csv, members.csv, table2 (paper layout), table2_units, table2_ensemble, fold_ensemble, paired.

    ``paper_table2`` is the published Table II file (None: none; see
    :func:`~animsynth.simplicial.settings.read_paper_table2`), ``paper_label`` how the notes name it
    (the configured path).
    """
    folds, members = read_fold_jsons(fold_paths)
    folds = order_folds(folds, datasets)
    members = order_folds(members, datasets)
    write_table(folds, out["folds"], md=False)
    write_table(members, out["members"], md=False)
    paper = read_paper_table2(paper_table2)
    src = (f"`paper_*`: the paper's Table II, read from {paper_label} (its `knn16` row is our `knn`)"
           if paper is not None else f"`paper_*` empty: no published values file at {paper_label!r}")
    ens = cfg["ensemble"]
    fb = _fallback_note(folds, methods[0])
    t2 = table2(folds, datasets, methods, paper)
    write_table(t2, out["table2"], md=True, title="Gauch & Peters Table II (reproduction)", note=(
        "Medians over the leave-one-sequence-out folds (one per trial of a subset; `all` = all folds), from the held-out "
        "trial's first latent frame as in the paper. Error A: mean closest-point distance between held-out and "
        "generated latent polylines, both directions averaged; Error F: closest approach of the generated path to "
        "the held-out final point; both divided by the diagonal of the fold's latent bounding box (the paper does "
        f"not state its unit). {src}. Spread over {int(ens['n_starts'])} jittered starts: table2_ensemble.csv. "
        f"Other units: table2_units.csv. {fb}"))
    write_table(table2_units(folds, datasets, methods), out["table2_units"], md=False)
    t2e = table2_ensemble(members, datasets, methods, paper)
    write_table(t2e, out["table2_ensemble"], md=True, title="Table II over the ensemble of starts", note=(
        f"Every cell of Table II recomputed for each of {int(ens['n_starts']) + 1} starts per fold (the held-out "
        f"start and {int(ens['n_starts'])} copies moved by {float(ens['jitter']):g} of the latent diagonal): median "
        f"and IQR over members, `a_lower_share` = share of members in which {methods[0]} has the lower cell, "
        f"`stability` = stable only when that holds in every member, `agree_share` = share agreeing with the "
        f"paper's ordering. {fb}"))
    fe = fold_ensemble(members, datasets, methods)
    write_table(fe, out["fold_ensemble"], md=False)
    pc = paired_comparison(folds, methods[0], methods[1], n_boot=int(cfg["bootstrap"]), seed=int(cfg["seed_value"]),
                           alpha=float(cfg["alpha"]))
    write_table(pc, out["paired"], md=True, title=f"Paired comparison {methods[0]} vs {methods[1]} over folds",
                note="Wilcoxon signed-rank test (two-sided) on per-fold differences (held-out start); bootstrap "
                     "percentile CI of the median difference (a - b < 0: a has the lower error). `_pose` metrics "
                     "are in degrees of joint angle (inverse PCA of the generated path vs the held-out trial).")


def grid_variants(grid: str, cfg: dict) -> list:
    if grid == "derivative":
        return derivative_variants(cfg["derivatives"], cfg["methods"], int(cfg["k"]), int(cfg["latent_dim"]),
                                   cfg["weights"])
    if grid == "beyond":
        return beyond_variants(cfg["beyond"], int(cfg["k"]), cfg["beyond"]["derivative"])
    raise ValueError(f"unknown grid {grid!r}")


def grid_job(paths, ids, dataset: str, grid: str, cfg: dict, seed: int, out: dict) -> None:
    """The derivative-variant grid or the beyond-the-paper grid for one subset (fold rows and member rows)."""
    angles, _ = load_trials(paths, ids)
    variants = grid_variants(grid, cfg)
    # pose-space errors of every member where the verdicts compare across latent dimensions
    d0 = min(v.latent_dim for v in variants)
    pose = [v.name for v in variants if v.latent_dim != d0 or (v.method == "delaunay" and v.weights == "idw"
                                                                and v.generation == "field")]
    # target-directed variants (shortest paths in G') are only in the beyond grid
    plan = {"max_all_pairs": int(cfg["beyond"]["max_all_pairs"])} if grid == "beyond" else {}
    df, members = run_subset(angles, variants, dataset=dataset, steps=cfg["steps"], dup_tol=float(cfg["dup_tol"]),
                             rank_tol=float(cfg["rank_tol"]), ensemble=cfg["ensemble"], seed=seed,
                             member_pose=pose if grid == "beyond" else False, **plan)
    log.info("%s grid on %s: %d variants x %d folds x %d starts", grid, dataset, len(variants), len(ids),
             int(cfg["ensemble"]["n_starts"]) + 1)
    write_table(df, out["folds"], md=False)
    write_table(members, out["members"], md=False)


def summary_job(deriv_paths, beyond_paths, main: dict, datasets, cfg: dict, out: dict, paper_table2=None) -> None:
    """derivative.csv, beyond.csv, beyond_folds.csv, verdicts.csv and their figures.

    ``paper_table2``: the published Table II file (None: none); its overall medians give the paper's
    ordering, else config ``simplicial.paper_claim``.
    """
    from .plots import plot_beyond, plot_derivative
    from .verdicts import build_verdicts

    def cat(paths):
        return pd.concat([pd.read_csv(p, keep_default_na=False, na_values=[""]) for p in paths], ignore_index=True)

    def read(p):
        return pd.read_csv(p, keep_default_na=False, na_values=[""])

    dfold = order_folds(cat(deriv_paths["folds"]), datasets)
    dmem = order_folds(cat(deriv_paths["members"]), datasets)
    bfold = order_folds(cat(beyond_paths["folds"]), datasets)
    bmem = order_folds(cat(beyond_paths["members"]), datasets)
    seed, n_boot, alpha = int(cfg["seed_value"]), int(cfg["bootstrap"]), float(cfg["alpha"])
    methods = tuple(cfg["methods"])
    paper = read_paper_table2(paper_table2)
    claim = paper_claim_from(paper, cfg["paper_claim"], methods)
    ens = cfg["ensemble"]
    dsum = derivative_summary(dfold, methods, claim, n_boot=n_boot, seed=seed, members=dmem)
    write_table(dsum, out["derivative"], md=True, title="Training-vector derivative variants",
                note="Medians over all folds (held-out start). `half` = (x[i+1]-x[i])/2 as printed in the paper; "
                     "`forward` = x[i+1]-x[i]; `central` = (x[i+1]-x[i-1])/2. `reproduces_claim` compares the "
                     f"held-out-start ordering with the paper's conclusion ({claim}); `*_lower_share_a/f` = share of "
                     f"the {int(ens['n_starts']) + 1} ensemble members (starts moved by {float(ens['jitter']):g} of the "
                     "latent diagonal) in which the first method has the lower all-fold median; `stability_*` says "
                     "stable only when that holds in every member. `*_sep_growth_log10` = median log10 of "
                     "|x_j(T)-x_0(T)| / |x_j(0)-x_0(0)| (separation growth of nearby paths over the path); "
                     "`*_sep_final_rel` = median final separation / latent diagonal.")
    d0 = int(cfg["beyond"]["latent_dims"][0])
    baseline = f"delaunay_idw_d{d0}"
    bsum = summarise_variants(bfold, baseline, datasets, n_boot=n_boot, seed=seed, members=bmem)
    write_table(bfold, out["beyond_folds"], md=False)
    best = bsum.iloc[0]
    write_table(bsum, out["beyond"], md=True, title="Beyond the paper: variants ranked by median pose-space Error A",
                note=f"Derivative '{cfg['beyond']['derivative']}'. error_*_pose: degrees of joint angle (comparable "
                     "across latent dimensions; pose_floor = the same error for a perfect latent path, i.e. PCA "
                     f"reconstruction loss); *_norm: latent units / bbox diagonal. Baseline {baseline} = the paper's "
                     f"method. `lower_share_vs_baseline`: share of ensemble members in which the variant's all-fold "
                     f"median (`share_metric`) is below the baseline's. Best: {best['variant']} "
                     f"({100 * best['rel_change_vs_baseline']:.1f}% vs baseline, Wilcoxon p={best['p_vs_baseline']:.3g}).")
    folds = read(main["folds"])
    members = read(main["members"])
    paired = read(main["paired"])
    t2 = read(main["table2"])
    t2e = read(main["table2_ensemble"])
    n_folds = int(folds.groupby("method").size().max()) if len(folds) else 0
    data = f"{cfg['data_label']} {' '.join(datasets)} ({n_folds} folds x {int(ens['n_starts']) + 1} starts)".strip()
    verdicts = build_verdicts(table2=t2, table2_ens=t2e, members=members, paired=paired, deriv=dsum, folds=folds,
                              beyond=bsum, beyond_folds=bfold, beyond_members=bmem, claim=claim,
                              main_derivative=cfg["derivative"], baseline=baseline, datasets=datasets, data=data,
                              methods=methods, magnitude_factor=float(cfg["magnitude_factor"]), alpha=alpha)
    write_table(verdicts, out["verdicts"], md=True, title="Simplicial family: claims and verdicts")
    plot_derivative(dfold, out["derivative_png"], methods)
    plot_beyond(bsum, bfold, out["beyond_png"], baseline)


def figures_job(paths, ids, dataset: str, cfg: dict, out: dict) -> None:
    """Figs 1-6: G' (k-NN, Delaunay) for three folds, both fields, held-out vs generated paths."""
    from .plots import plot_field, plot_graphs, plot_paths

    angles, _ = load_trials(paths, ids)
    fig = cfg["figures"]
    check_figure_folds(fig, len(ids), dataset)
    graph_folds = [int(i) for i in fig["folds"]]
    results = {}
    for m in ("knn", "delaunay"):
        v = main_variant(cfg, m)
        results[m] = [run_fold([angles[t] for t in ids if t != tid], angles[tid], v, dataset=dataset, held_out=tid,
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
    check_figure_folds(fig, len(ids), dataset)
    i = int(fig["walk_fold"])
    tid = ids[i]
    res = run_fold([angles[t] for t in ids if t != tid], angles[tid], main_variant(cfg, fig["walk_method"]),
                   dataset=dataset, held_out=tid, fold=i, steps=cfg["steps"], dup_tol=float(cfg["dup_tol"]),
                   rank_tol=float(cfg["rank_tol"]))
    motion = walk_motion(res, motions[tid], name=f"simplicial {fig['walk_method']} walk, {dataset} held out {tid}")
    held = motions[tid]
    held_in_place = Motion(held.values.copy(), held.skeleton, held.fps, tid)
    n_root = len(held.skeleton.joints[0].dofs)
    held_in_place.values[:, :n_root] = in_place_root(held)  # same in-place root as the generated walk
    motion_previews(motion, gif_path=out["gif"], bvh_path=out["bvh"], png_path=out["png"], original=held_in_place,
                    titles=[f"held out {tid}", f"generated ({fig['walk_method']})"], fps=float(fig["gif_fps"]))


# ----------------------------------------------------------------------------- cost curves (animsynth.scale)


def scale_steps(recorder, n: int, seed: int = 0, steps: int = 1000, trial_frames: int = 200, method: str = "delaunay",
                k: int = 8, latent_dim: int = 3):
    """One simplicial fold on ``n`` synthetic training frames plus a ``steps``-step path."""
    from ..synth.mocap import synthetic_motions

    motions = synthetic_motions(n + trial_frames, trial_frames, seed, kinds=["walk_straight", "walk_turn"])
    angles = [np.asarray(m.without_root(), float) for m in motions]
    test, train = angles[0], angles[1:]
    S = recorder("simplicial", sum(len(a) for a in train), method=method)
    var = Variant(method, method=method, k=k, latent_dim=latent_dim, derivative="forward",
                  weights="idw" if method != "delaunay" else "barycentric").check()
    with S.step("fold_build_and_path", path_steps=steps):
        run_fold(train, test, var, steps=int(steps))
    return S.rows
