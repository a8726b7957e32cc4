"""Verdicts on the re-sequencing paper's claims, in the common verdict format (:mod:`animsynth.verdicts`).

Every row is built with :func:`animsynth.verdicts.row` (columns ``claim, paper_value, ours, data,
verdict, evidence, source``; ``verdict`` a word of :data:`animsynth.verdicts.VOCABULARY`).

* **Table 2 explanations** (:func:`explanation_verdicts`): which condition
  -- quaternion signs from rotation matrices (``matrix_naive``), a lower frame
  rate, the global DOF -- brings our Isomap-L2 minimum k to the paper's order
  of magnitude (within a factor ``magnitude_factor``, default sqrt(10): half a
  decade) while the Lee metric's stays small (``<= lee_small_max``, the
  paper's largest Lee value being 7).
* **Lee needs far fewer neighbours than L2** (:func:`lee_vs_l2_verdict`):
  Isomap min k, L2 over Lee, at least ``magnitude_factor`` per dataset x
  global flag.
* **ST-Isomap smoother than Isomap** (:func:`st_smoother_verdict`) and
  **global DOF hurt locomotion but help dance** (:func:`global_dof_verdict`):
  per start/end pair, only pairs where *both* arms re-sequence; the share of
  pairs in which one arm is smoother (per-transition velocity discontinuity,
  the measure of a visible jerk; other measures in the evidence) with a
  two-sided sign test. For the global DOF, when that comparison is not clear,
  the pairs where only one arm re-sequences decide (losing the ability to
  re-sequence is the plainest way to be hurt). Both are decided by the common
  rule for "A beats B over units" (:func:`animsynth.verdicts.a_beats_b`, the
  pairs the units, tied pairs dropped): a claim holds when the share is at
  least ``share`` and the sign test gives p < ``alpha``; the opposite when the
  other arm's share is at least ``share`` with p < ``alpha``; a significant lead
  short of the share is "partly"; otherwise "undecided".

Every word comes from an outcome through :func:`animsynth.verdicts.word` (the
ladders of the min-k claims through :func:`animsynth.verdicts.ladder`), so the
same outcome reads the same in every family; a claim with nothing to compare
is "undecided", never "not reproduced".
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import verdicts as V

__all__ = ["explanation_verdicts", "lee_vs_l2_verdict", "paired_share", "st_smoother_verdict",
           "global_dof_verdict", "build_verdicts"]

PRIMARY = "velocity_jump_ratio"
SECONDARY = ["pose_jump_ratio", "accel_jump_ratio", "foot_skate_ratio"]


def _row(claim, paper_value, ours, data, verdict, evidence, source):
    return V.row(claim, verdict, evidence, paper_value=paper_value, ours=ours, data=data, source=source)


def _pick(grid, dataset, step, gdof, mode, method, metric):
    m = grid[(grid["dataset"] == dataset) & (grid["frame_step"] == step) & (grid["global_dof"] == gdof)
             & (grid["sign_mode"] == mode) & (grid["method"] == method) & (grid["metric"] == metric)]
    return int(m["min_k"].iloc[0]) if len(m) else None


def explanation_verdicts(grid: pd.DataFrame, published: pd.DataFrame | None, frame_step: int,
                         factor: float = 3.16, lee_max: int = 7, data: str = "",
                         source: str = "resequencing/min_k_explanations.csv") -> list[dict]:
    """One verdict per candidate explanation of the paper's Isomap-L2 minimum k, and a summary row.

    Each candidate is a condition applied to every dataset at the paper's
    global-DOF setting for that motion: ``matrix_naive`` signs; each other
    frame step of the grid; the global DOF included everywhere; and (for
    reference) our method as run. A dataset *matches* when our Isomap-L2 min k
    is within ``factor`` of the paper's and our Isomap-Lee min k is at most
    ``lee_max``.
    """
    claim0 = "the paper's Isomap-L2 min k (tens to about a hundred) is explained by"
    which = "which candidate explanation matches the paper's Table 2 (Isomap-L2 min k, with Lee staying small)"
    if published is None or published.empty:
        return [_row(which, "", "", data, V.word("none"),
                     "the published Table 2 file was not available, so no candidate can be checked",
                     source)]
    pub = published[(published["method"] == "isomap")]
    paper = {r.dataset: (bool(r.global_dof), int(r.min_k_paper)) for r in pub[pub["metric"] == "l2"].itertuples()}
    paper_lee = {r.dataset: int(r.min_k_paper) for r in pub[pub["metric"] == "lee"].itertuples()}
    datasets = [d for d in paper if d in set(grid["dataset"])]
    steps = sorted(set(int(s) for s in grid["frame_step"]))
    modes = list(dict.fromkeys(grid["sign_mode"]))
    base_mode = "continuous" if "continuous" in modes else modes[0]
    fps = {int(r.frame_step): r.fps for r in grid.drop_duplicates(["dataset", "frame_step"]).itertuples()}
    cands = [("our method as run (continuous signs, %g fps)" % fps.get(frame_step, np.nan),
              base_mode, frame_step, None)]
    if "matrix_naive" in modes:
        cands.append(("quaternion signs from rotation matrices (matrix_naive, %g fps)" % fps.get(frame_step, np.nan),
                      "matrix_naive", frame_step, None))
    for st in steps:
        if st != frame_step:
            cands.append((f"a lower frame rate (frame_step {st}, {fps.get(st, np.nan):g} fps, continuous signs)",
                          base_mode, st, None))
            if "matrix_naive" in modes:
                cands.append((f"matrix_naive signs at frame_step {st} ({fps.get(st, np.nan):g} fps)",
                              "matrix_naive", st, None))
    if set(grid["global_dof"]) >= {True}:
        cands.append(("the global DOF included for every motion (continuous signs)", base_mode, frame_step, True))
    paper_txt = "; ".join(f"{d} L2 {paper[d][1]}, Lee {paper_lee.get(d, '?')}" for d in datasets)
    rows, scored = [], []
    for label, mode, st, gforce in cands:
        parts, n_l2, n_all = [], 0, 0
        for d in datasets:
            g = paper[d][0] if gforce is None else gforce
            l2 = _pick(grid, d, st, g, mode, "isomap", "l2")
            lee = _pick(grid, d, st, g, mode, "isomap", "lee")
            if l2 is None or lee is None:
                parts.append(f"{d}: not computed")
                continue
            p = paper[d][1]
            ok_l2 = p / factor <= l2 <= p * factor
            ok_lee = lee <= lee_max
            n_l2 += ok_l2
            n_all += ok_l2 and ok_lee
            parts.append(f"{d} ({'global in' if g else 'global out'}): L2 {l2} vs paper {p} "
                         f"({'within' if ok_l2 else 'outside'} x{factor:g}), Lee {lee}")
        verdict = V.ladder([(n_all == len(datasets), "holds"), (n_l2 > 0, "split")], "short",
                           evidence=bool(datasets))
        ours = "; ".join(parts)
        scored.append((n_all, n_l2, label, verdict, ours))
        rows.append(_row(f"{claim0} {label}", paper_txt, ours, data, verdict,
                         f"{n_all} of {len(datasets)} motions match (Isomap-L2 min k within a factor {factor:g} of "
                         f"the paper's and Isomap-Lee min k <= {lee_max}); {n_l2} match on L2 alone.", source))
    best = max(scored[1:] or scored, key=lambda x: (x[0], x[1]))
    matching = [s[2] for s in scored[1:] if s[3] == "reproduced"]
    rows.insert(0, _row(
        which,
        paper_txt, best[4], data, best[3],
        ("matching: " + "; ".join(matching) if matching else f"no candidate matches on every motion; closest: {best[2]}")
        + f". Each candidate was tested the same way on every motion (factor {factor:g}, Lee <= {lee_max}).",
        source))
    return rows


def lee_vs_l2_verdict(table2: pd.DataFrame, factor: float = 3.16, data: str = "",
                      source: str = "resequencing/table2_min_k.csv") -> dict:
    """The Lee metric needs far fewer neighbours than L2 (Isomap, our continuous linearisation)."""
    claim = "the Lee metric needs far fewer neighbours than L2 (Isomap min k)"
    t = table2[(table2["method"] == "isomap")]
    paper = t[t["min_k_paper"].notna()]
    paper_txt = "; ".join(f"{r.dataset} {r.metric} {int(r.min_k_paper)}" for r in paper.itertuples()
                          if r.sign_mode == "continuous")
    rows = []
    for (d, g, mode), grp in t.groupby(["dataset", "global_dof", "sign_mode"], sort=False):
        k = dict(zip(grp["metric"], grp["min_k"]))
        if "l2" in k and "lee" in k:
            rows.append((d, bool(g), mode, int(k["l2"]), int(k["lee"])))
    cont = [r for r in rows if r[2] == "continuous"]
    if not cont:
        return _row(claim, paper_txt, "", data, V.word("none"), "no configuration has both metrics", source)
    far = sum(l2 >= factor * lee for *_, l2, lee in cont)
    worse = sum(lee > l2 for *_, l2, lee in cont)
    verdict = V.ladder([(far == len(cont), "holds"), (worse > len(cont) / 2, "opposite"), (far > 0, "split")],
                       "short")
    ours = "; ".join(f"{d} {'global' if g else 'noglobal'} L2 {l2} / Lee {lee}" for d, g, _, l2, lee in cont)
    naive = [r for r in rows if r[2] == "matrix_naive"]
    nfar = sum(l2 >= factor * lee for *_, l2, lee in naive)
    ev = (f"continuous signs (our method): L2 at least {factor:g}x Lee in {far} of {len(cont)} dataset x global "
          f"configurations, Lee larger in {worse}.")
    if naive:
        ev += f" With matrix_naive signs the L2 min k is {factor:g}x Lee or more in {nfar} of {len(naive)}."
    return _row(claim, paper_txt, ours, data, verdict, ev, source)


def paired_share(a: pd.Series, b: pd.Series) -> tuple[int, int, int, float]:
    """Pairs where ``b < a`` (b smoother), where ``b > a``, ties; two-sided sign-test p (ties dropped).

    Each pair is a unit voting by the sign of ``a - b`` (:func:`animsynth.verdicts.unit_votes`, no minimum
    effect); the p is :func:`animsynth.verdicts.sign_test`."""
    ok = a.notna() & b.notna()
    a, b = a[ok].astype(float), b[ok].astype(float)
    votes = V.unit_votes(a.to_numpy() - b.to_numpy())
    lo, hi = int((votes > 0).sum()), int((votes < 0).sum())
    ties = int(len(a) - lo - hi)
    return lo, hi, ties, V.sign_test(lo, hi)


def _decide(lo: int, hi: int, p: float, share: float, alpha: float) -> str:
    """:func:`animsynth.verdicts.a_beats_b` over pairs (``lo`` for the claim, ``hi`` against; ties dropped)."""
    return V.a_beats_b(lo, hi, share=share, alpha=alpha, p=p)


def st_smoother_verdict(per_path: pd.DataFrame, share: float = 0.75, alpha: float = 0.05, data: str = "",
                        source: str = "resequencing/smoothness_paths.csv") -> dict:
    """ST-Isomap gives smoother re-sequenced motion than Isomap, on pairs where both re-sequence."""
    claim = "ST-Isomap re-sequences more smoothly than Isomap (fewer jerks)"
    paper_value = "qualitative (by eye)"
    keys = ["dataset", "global_dof", "metric", "pair"]
    iso = per_path[per_path["method"] == "isomap"].set_index(keys)
    st = per_path[per_path["method"] == "stisomap"].set_index(keys)
    common = iso.index.intersection(st.index)
    both = [i for i in common if iso.loc[i, "path_class"] == "resequences" and st.loc[i, "path_class"] == "resequences"]
    n_iso = int((iso.loc[common, "path_class"] == "resequences").sum())
    n_st = int((st.loc[common, "path_class"] == "resequences").sum())
    counts = (f"of {len(common)} pairs, Isomap re-sequences {n_iso}, ST-Isomap {n_st}, both {len(both)} "
              f"(transitions per 100 frames played: Isomap {iso.loc[common, 'transitions_per_100_frames'].mean():.2f}, "
              f"ST-Isomap {st.loc[common, 'transitions_per_100_frames'].mean():.2f})")
    if not both:
        return _row(claim, paper_value, counts, data, V.word("none"),
                    "no pair where both methods re-sequence, so smoothness cannot be compared; " + counts, source)
    lo, hi, ties, p = paired_share(iso.loc[both, PRIMARY], st.loc[both, PRIMARY])
    verdict = V.word(_decide(lo, hi, p, share, alpha))
    others = []
    for c in SECONDARY:
        l2, h2, _, p2 = paired_share(iso.loc[both, c], st.loc[both, c])
        if l2 + h2:
            others.append(f"{c} smoother in {l2}/{l2 + h2} (p={p2:.2g})")
    ours = (f"ST-Isomap has the smaller mean per-transition velocity discontinuity in {lo} of {lo + hi} pairs "
            f"where both re-sequence ({100 * lo / max(lo + hi, 1):.0f} %, sign test p={p:.2g}, {ties} ties)")
    ev = (f"{ours}; {'; '.join(others)}. Replaying pairs are left out: {counts}. Holds when the share is >= "
          f"{100 * share:.0f} % with p < {alpha:g}.")
    return _row(claim, paper_value, ours, data, verdict, ev, source)


def global_dof_verdict(per_path: pd.DataFrame, share: float = 0.75, alpha: float = 0.05, data: str = "",
                       source: str = "resequencing/smoothness_paths.csv") -> dict:
    """Global DOF hurt cyclic locomotion (walk, run) but help dance.

    Per dataset, over the pairs of every method x metric:

    1. *smoothness*: on pairs where both arms re-sequence, the share where the
       global arm has the smaller mean per-transition velocity discontinuity;
    2. *ability to re-sequence*: on pairs where exactly one arm re-sequences,
       the share where it is the global arm (a path that can only replay or
       skip frames cannot re-sequence at all).

    Each is decided by the share / sign-test rule of the module; the
    smoothness comparison decides when it is clear, else the ability
    comparison. A dataset agrees with the claim when walk/run are hurt and
    dance is helped.
    """
    claim = "including the global DOF hurts cyclic locomotion (walk, run) but helps dance"
    paper_value = "qualitative (by eye)"
    keys = ["dataset", "method", "metric", "pair"]
    out = per_path[~per_path["global_dof"].astype(bool)].set_index(keys)
    inn = per_path[per_path["global_dof"].astype(bool)].set_index(keys)
    common = out.index.intersection(inn.index)
    if len(common) == 0:
        return _row(claim, paper_value, "", data, V.word("none"),
                    "not measured: needs both global-DOF flags for the same configurations", source)
    roots = sorted(set(per_path["root_playback"]))
    want = {"walk": "hurt", "run": "hurt", "dance": "help"}
    agree, against, parts = 0, 0, []
    datasets = list(dict.fromkeys(i[0] for i in common))
    for ds in datasets:
        idx = [i for i in common if i[0] == ds]
        rs_out = np.array([out.loc[i, "path_class"] == "resequences" for i in idx])
        rs_in = np.array([inn.loc[i, "path_class"] == "resequences" for i in idx])
        both = [i for i, a, b in zip(idx, rs_out, rs_in) if a and b]
        # smoothness: "lo" = pairs where the global arm is smoother
        lo, hi, _, p = paired_share(out.loc[both, PRIMARY], inn.loc[both, PRIMARY]) if both else (0, 0, 0, 1.0)
        eff_s = {"holds": "help", "opposite": "hurt"}.get(_decide(lo, hi, p, share, alpha), "no clear effect")
        only_in, only_out = int((rs_in & ~rs_out).sum()), int((rs_out & ~rs_in).sum())
        p_a = V.sign_test(only_in, only_out)
        eff_a = {"holds": "help", "opposite": "hurt"}.get(_decide(only_in, only_out, p_a, share, alpha),
                                                          "no clear effect")
        effect = eff_s if eff_s != "no clear effect" else eff_a
        expected = want.get(ds)
        if expected is not None and effect == expected:
            agree += 1
        elif expected is not None and effect in ("help", "hurt"):
            against += 1
        parts.append(f"{ds}: re-sequencing paths {int(rs_out.sum())}/{len(idx)} without vs {int(rs_in.sum())}/"
                     f"{len(idx)} with global DOF (only without {only_out}, only with {only_in}, p={p_a:.2g}: "
                     f"{eff_a}); where both re-sequence the global arm is smoother in {lo} of {lo + hi} pairs "
                     f"(p={p:.2g}: {eff_s}) -> {effect}")
    n = len([d for d in datasets if d in want])
    missing = [d for d in want if d not in datasets]
    if missing:  # resequencing_trials without them: that half of the claim is not measured
        parts.append(f"{', '.join(missing)}: not in this run (no trial in resequencing_trials), not measured")
    # a dataset whose comparisons decide nothing (no clear effect) leaves the claim undecided there
    verdict = V.ladder([(n and agree == n and not missing, "holds"), (agree > 0, "split"), (against > 0, "opposite")],
                       "noise")
    ours = "; ".join(parts)
    ev = (f"{ours}. Smoothness measure: mean per-transition velocity discontinuity; root playback "
          f"{', '.join(roots)} in both arms; an effect needs >= {100 * share:.0f} % of the deciding pairs to agree "
          f"with p < {alpha:g} (smoothness first, else the ability to re-sequence).")
    return _row(claim, paper_value, ours, data, verdict, ev, source)


def build_verdicts(table2, grid, published, per_path, frame_step: int, cfg: dict, data_min_k: str = "",
                 data_paths: str = "") -> pd.DataFrame:
    """Every verdict row of the family (``cfg``: the resequencing block with defaults)."""
    ex = cfg["explanations"]
    f = float(ex["magnitude_factor"])
    rows = explanation_verdicts(grid, published, frame_step, f, int(ex["lee_small_max"]), data_min_k)
    rows.append(lee_vs_l2_verdict(table2, f, data_min_k))
    rows.append(st_smoother_verdict(per_path, float(cfg["verdict_share"]), float(cfg["verdict_alpha"]), data_paths))
    rows.append(global_dof_verdict(per_path, float(cfg["verdict_share"]), float(cfg["verdict_alpha"]), data_paths))
    return V.table(rows)
