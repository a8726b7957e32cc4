"""The comparison's tables: the generator jobs' metrics read back, medians and spreads, which generator wins which
metric, the cost, the skating sensitivity, the budget sweep, the claims' tables and the family's summary page
(``compare/summary.md``), assembled from the generator jobs' files (:func:`family_tables`)."""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from .generators.names import GENERATORS, REFERENCES
from .measures.metric_table import (LONG_RESULT_METRICS, METRIC_NAMES, RESULT_METRICS, SENSITIVITY_METRICS,
                                    SENSITIVITY_SPEEDS, SWEEP_METRICS, at_speed, metric)
from .claim_stats import pair_outcomes
from .claims import track_claims

log = logging.getLogger("animsynth.compare.tables")

__all__ = ["read_metrics", "sweep_runs", "family_tables", "summary_table", "winners_table", "cost_table",
           "data_label", "summary_markdown", "sensitivity_table", "sweep_table", "results_markdown"]


def _better(name: str) -> str:
    return metric(name).better


def _unit(name: str) -> str:
    return metric(name).unit


def read_metrics(paths) -> pd.DataFrame:
    """The generator jobs' metrics files as one table (``note``: '' where a row has none)."""
    m = pd.concat([pd.read_csv(p, dtype={"note": str}, keep_default_na=False, na_values=[""]) for p in paths],
                  ignore_index=True)
    m["note"] = m["note"].fillna("")
    return m


def sweep_runs(default: pd.DataFrame, paths, default_budget: float, budgets, generators) -> dict:
    """``{budget: metrics of the graph generators}``: the default run's rows of ``generators`` at
    ``default_budget`` and the metrics files of every further budget (``paths``, budget by budget: each budget's
    files for every generator and subject, the same number per budget)."""
    runs = {float(default_budget): default[default["generator"].isin(generators)]}
    paths, budgets = list(paths), list(budgets)
    per = len(paths) // len(budgets) if budgets else 0
    if not budgets or per * len(budgets) != len(paths) or per % max(1, len(list(generators))):
        if budgets or paths:
            raise ValueError(f"budget sweep: {len(paths)} metrics files for {len(budgets)} budgets x "
                             f"{len(list(generators))} generators")
    for i, b in enumerate(budgets):
        runs[float(b)] = read_metrics(paths[i * per:(i + 1) * per])
    return runs


def family_tables(inp: dict, generators, left_out: dict, cfg: dict, source: str, sweep: dict | None = None) -> dict:
    """The family's tables from the generator jobs' files (``inp``: ``clips``, ``metrics``, ``timing`` lists;
    optional ``sweep``: the budget sweep's metrics files).

    Returns ``{name: DataFrame}``: ``metrics`` (every row, in the clips' and the config's generator order),
    ``metrics_timing``, ``summary``, ``winners``, ``cost``, ``verdicts`` (the declared claims, ``cfg["claims"]``),
    ``claims_stats`` (their numbers), ``exploratory`` (every other pair, no verdict), ``sanity``, ``sensitivity``;
    and ``summary_md``: the family's page (text); ``data``: what the run is on (the verdicts' ``data``). The claims
    decided are the 2-s track's (the long track's: :func:`animsynth.compare.long_tables.with_long_track`).

    ``sweep``: ``{"default": transitions_per_s, "budgets": [...], "generators": [...]}`` describing
    ``inp["sweep"]`` (:func:`sweep_runs`); the claims against the peer quote the sweep as evidence."""
    from .claim_stats import no_values
    from .groups import independent_groups
    from .verdicts import decide_claims, exploratory_table, sanity_checks

    order = list(cfg["generators"])
    metrics = read_metrics(inp["metrics"])
    metrics["_g"] = metrics["generator"].map({g: i for i, g in enumerate(order)})
    clips = pd.read_csv(inp["clips"], dtype={"held_out": str})
    metrics["_c"] = metrics["clip"].map({c: i for i, c in enumerate(clips["clip"])})
    metrics = metrics.sort_values(["_c", "_g", "seed"], kind="stable").drop(columns=["_g", "_c"])
    timing = pd.concat([pd.read_csv(p) for p in inp["timing"]], ignore_index=True)
    summary = summary_table(metrics, order)
    winners = winners_table(metrics, summary, order)
    clips_full = pd.read_csv(inp["clips"], dtype=str)
    n_groups = len(set(independent_groups(clips_full, cfg["verdicts"].get("grouping", "subject")).values()))
    data = data_label(source, clips, cfg["seeds"]) + f" in {n_groups} independent groups"
    # the claims are the family's own: a user generator (compare.user_generators) is in every table, not in them
    own = metrics[metrics["generator"].isin(GENERATORS)]
    sweep_tab = None
    if sweep and sweep.get("budgets") and inp.get("sweep"):
        sweep_tab = sweep_table(sweep_runs(metrics, inp["sweep"], sweep["default"], sweep["budgets"],
                                           sweep["generators"]), order)
    seed = int(cfg.get("seed", 0))
    declared = track_claims(cfg.get("claims"), "short")  # the long track's claims: their own Holm family
    verdicts, claims_stats = decide_claims(own, cfg["verdicts"], data, left_out, clips_full, sweep=sweep_tab,
                                           claims=declared, seed=seed)
    exploratory = exploratory_table(own, cfg["verdicts"], clips_full, claims=declared, order=order, seed=seed,
                                    left_out=left_out)
    sanity = sanity_checks(own, cfg["verdicts"], data, left_out, clips_full, seed=seed)
    not_built = metrics.loc[metrics["note"] != "", ["generator", "clip", "note"]].drop_duplicates()
    failed = set(not_built.loc[not_built["note"].str.startswith("failed: "), "generator"])  # said on their own line
    empty = {g: no_values(metrics, g) for g in order_generators(metrics["generator"].unique(), order) if g not in failed}
    log.info("%d rows (%d clips x %d generators x %d seeds), %d not built, %d verdicts: %s", len(metrics),
             metrics["clip"].nunique(), metrics["generator"].nunique(), int(cfg["seeds"]), len(not_built),
             len(verdicts), ", ".join(verdicts["verdict"]))
    out = {"metrics": metrics, "metrics_timing": timing, "summary": summary, "winners": winners,
           "cost": cost_table(timing, order), "verdicts": verdicts, "claims_stats": claims_stats,
           "exploratory": exploratory, "sanity": sanity, "sensitivity": sensitivity_table(metrics, order),
           "summary_md": summary_markdown(clips, winners, verdicts, generators, left_out, data, cfg, not_built,
                                          sanity, {g: w for g, w in empty.items() if w})}
    out["data"] = data  # what the run is on: the long track's tables say it too
    return out


def order_generators(names, order) -> list[str]:
    """``names`` in the order of ``order`` (the config's generator list)."""
    return [g for g in order if g in set(names)]


def summary_table(metrics: pd.DataFrame, order, names=METRIC_NAMES) -> pd.DataFrame:
    """Per generator and metric (``names``: the track's columns, the short track's by default): n (clip x seed rows
    with a value), median, IQR and 5-95 % range."""
    out = []
    for g in order_generators(metrics["generator"].unique(), order):
        sub = metrics[metrics["generator"] == g]
        for m in names:
            x = pd.to_numeric(sub[m], errors="coerce").to_numpy(float)
            x = x[np.isfinite(x)]
            q = np.percentile(x, [5, 25, 50, 75, 95]) if x.size else np.full(5, np.nan)
            out.append({"generator": g, "metric": m, "unit": _unit(m), "better": _better(m), "n": int(x.size),
                        "median": q[2], "q25": q[1], "q75": q[3], "p05": q[0], "p95": q[4]})
    return pd.DataFrame(out, columns=["generator", "metric", "unit", "better", "n", "median", "q25", "q75", "p05",
                                      "p95"])


def winners_table(metrics: pd.DataFrame, summary: pd.DataFrame, order) -> pd.DataFrame:
    """Per metric with a direction: the best and the second-best generator (reference rows aside) by
    median, the margin, whether the IQRs are apart ("beyond the spread"), the share of clip x seed pairs
    in which the best beats the second, and the two reference rows' medians."""
    rows = []
    for m in METRIC_NAMES:
        better = _better(m)
        if not better:
            continue
        s = summary[(summary["metric"] == m) & ~summary["generator"].isin(REFERENCES) & (summary["n"] > 0)]
        if len(s) < 2:
            continue
        s = s.sort_values("median", ascending=(better == "lower"), kind="stable")
        a, b = s.iloc[0], s.iloc[1]
        apart = (a["q75"] < b["q25"]) if better == "lower" else (a["q25"] > b["q75"])
        outcome = pair_outcomes(metrics, a["generator"], b["generator"], m, better)["outcome"]
        wins, losses, ties = int((outcome > 0).sum()), int((outcome < 0).sum()), int((outcome == 0).sum())
        ref = {g: summary[(summary["metric"] == m) & (summary["generator"] == g)]["median"] for g in REFERENCES}
        rows.append({"metric": m, "unit": _unit(m), "better": better, "best": a["generator"],
                     "best_median": a["median"], "best_q25": a["q25"], "best_q75": a["q75"],
                     "second": b["generator"], "second_median": b["median"], "second_q25": b["q25"],
                     "second_q75": b["q75"], "margin": abs(a["median"] - b["median"]),
                     "beyond_spread": bool(apart),
                     "best_wins_share": wins / (wins + losses) if wins + losses else np.nan,
                     "pairs": wins + losses + ties,
                     **{f"{g}_median": (float(v.iloc[0]) if len(v) else np.nan) for g, v in ref.items()}})
    return pd.DataFrame(rows)


def cost_table(timing: pd.DataFrame, order) -> pd.DataFrame:
    """Per generator: builds (databases it was built on, each serving its clips), median and total build CPU and
    wall seconds, generation
    frames per CPU and wall second, the generator job's peak resident memory (MB: the whole job, Python and
    scoring included; a child process, such as a pool a user generator starts, by its largest). Machine-dependent
    (a timing table)."""
    rows = []
    for g in order_generators(timing["generator"].unique(), order):
        t = timing[timing["generator"] == g]
        frames = float(t["frames_generated"].sum())
        rows.append({"generator": g, "builds": int(t["build_cpu_s"].notna().sum()),
                     "build_cpu_s_median": float(t["build_cpu_s"].median()),
                     "build_wall_s_median": float(t["build_wall_s"].median()),
                     "build_cpu_s_total": float(t["build_cpu_s"].sum()),
                     "build_wall_s_total": float(t["build_wall_s"].sum()),
                     "generate_fps_cpu": frames / float(t["generate_cpu_s"].sum()) if t["generate_cpu_s"].sum() > 0
                     else np.nan,
                     "generate_fps_wall": frames / float(t["generate_wall_s"].sum())
                     if t["generate_wall_s"].sum() > 0 else np.nan,
                     "peak_rss_mb": float(pd.to_numeric(t["peak_rss_mb"], errors="coerce").max())})
    return pd.DataFrame(rows)


def sensitivity_table(metrics: pd.DataFrame, order) -> pd.DataFrame:
    """Skating against its speed threshold: per generator and speed
    (:data:`animsynth.compare.measures.metric_table.SENSITIVITY_SPEEDS`) the median of each
    :data:`~animsynth.compare.measures.metric_table.SENSITIVITY_METRICS` (the skate share, ours, and the GMD-style skating
    ratio) over clips x seeds, and each generator's rank (1 = skates least, reference rows aside) by each, so a
    reader sees whether the order holds."""
    rows = []
    gens = order_generators(metrics["generator"].unique(), order)
    for v in SENSITIVITY_SPEEDS:
        med = {}
        for g in gens:
            sub = metrics[metrics["generator"] == g]
            med[g] = {k: float(np.nanmedian(pd.to_numeric(sub[at_speed(k, v)], errors="coerce")))
                      if sub[at_speed(k, v)].notna().any() else np.nan for k in SENSITIVITY_METRICS}
        ranks = {k: pd.Series({g: med[g][k] for g in gens if g not in REFERENCES}).rank(method="min")
                 for k in SENSITIVITY_METRICS}
        for g in gens:
            row = {"speed_m_s": v, "generator": g}
            for k in SENSITIVITY_METRICS:
                row.update({f"{k}_median": med[g][k], f"{k}_rank": ranks[k].get(g, np.nan)})
            rows.append(row)
    return pd.DataFrame(rows)


def sweep_table(runs: dict, order) -> pd.DataFrame:
    """The transition budget sweep: ``runs`` = {budget (transitions per second of database): metrics of the
    graph generators at that budget}; per generator and budget the clips it could not be built on and the
    median of :data:`SWEEP_METRICS` over the seeds of the clips that every graph generator was built on at that
    budget (``clips_compared``), so that the generators are compared on the same clips."""
    rows = []
    for budget in sorted(runs):
        m = runs[budget]
        failed = set(m.loc[m["note"].fillna("") != "", "clip"])
        common = m[~m["clip"].isin(failed)]
        for g in order_generators(m["generator"].unique(), order):
            sub = common[common["generator"] == g]
            row = {"transitions_per_s": float(budget), "generator": g,
                   "clips_not_built": int(m.loc[(m["generator"] == g) & (m["note"].fillna("") != ""), "clip"].nunique()),
                   "clips_compared": int(sub["clip"].nunique())}
            for k in SWEEP_METRICS:
                x = pd.to_numeric(sub[k], errors="coerce")
                row[f"{k}_median"] = float(x.median()) if x.notna().any() else np.nan
            rows.append(row)
    return pd.DataFrame(rows)


# ----------------------------------------------------------------------------- the family's summary


def data_label(source: str, clips: pd.DataFrame, seeds: int) -> str:
    """What the comparison ran on, e.g. ``CMU mocap: 19 held-out clips x 5 seeds``."""
    kind = {"cmu": "CMU mocap", "synthetic": "synthetic mocap", "user": "user mocap"}.get(source, source)
    return f"{kind}: {len(clips)} held-out clips x {int(seeds)} seeds"


def summary_markdown(clips: pd.DataFrame, winners: pd.DataFrame, verdicts: pd.DataFrame, generators, left_out: dict,
                     data: str, cfg: dict, not_built: pd.DataFrame | None = None,
                     sanity: pd.DataFrame | None = None, did_not_run: dict | None = None) -> str:
    """``compare/summary.md``: the protocol in numbers, which generator wins which metric, the verdicts.
    Generated from the tables (no timing: cost is in ``cost_timing.csv``). ``did_not_run``: {generator: why} of the
    generators with no value on any clip (not ranked; their claims "did not run")."""
    from ..tables import to_markdown

    out = ["# The generators side by side", "",
           f"Data: {data}. Working rate {_num(cfg['fps'])} fps; start = the held-out clip's first "
           f"{cfg['context']} frames; up to {cfg['length']} frames generated from it; generators: "
           + ", ".join(generators) + ".", ""]
    if left_out:
        out += ["Left out: " + "; ".join(f"**{g}**: {why}" for g, why in left_out.items()) + ".", ""]
    if "motion_matching_traj" in generators:
        out += ["Query protocol: **motion_matching_traj** is given the held-out future as its query trajectory "
                "(where the capture went next), information no other generator sees; its scores against the ground "
                "truth are not comparable with those of the rows that see the start alone (docs/compare/generators.md, "
                "Motion matching).", ""]
    if did_not_run:
        out += ["Did not run (no value on any clip, so in no ranking; their claims read \"did not run\"): "
                + "; ".join(f"**{g}**: {why.split(': ', 1)[-1]}" for g, why in did_not_run.items()) + ".", ""]
    if not_built is not None and len(not_built):
        failed = not_built[not_built["note"].str.startswith("failed: ")].drop_duplicates("generator")
        not_built = not_built[~not_built["note"].str.startswith("failed: ")]
        if len(failed):  # a user generator that could not run: one line each, its rows empty
            out += ["Failed (no values at all): " + "; ".join(
                f"**{r.generator}**: {r.note.removeprefix('failed: ')}" for r in failed.itertuples()) + ".", ""]
    if not_built is not None and len(not_built):
        out += ["Not built (no values for these clips): " + "; ".join(
            f"**{r.generator}** on {r.clip} ({r.note.removeprefix('not built: ')})"
            for r in not_built.itertuples()) + ".", ""]
    user = [g for g in generators if g not in GENERATORS]
    if user:
        out += ["Your own generators (compare.user_generators): " + ", ".join(f"**{g}**" for g in user) + ". They "
                "run on the same clips, seeds and metrics and are in every table and figure; the verdicts and sanity "
                "checks below are the family's own claims, decided without them.", ""]
    out += ["## Which generator wins which metric", "",
            "Best and second-best by median over clips x seeds (the reference rows replay and concat aside); "
            "`beyond_spread`: the two IQRs do not overlap; `best_wins_share`: share of clip x seed pairs in "
            "which the best beats the second.", ""]
    if winners.empty:
        out += ["(no metric with two generators)", ""]
    else:
        cols = ["metric", "better", "best", "best_median", "second", "second_median", "margin", "beyond_spread",
                "best_wins_share", "replay_median", "concat_median"]
        out += [to_markdown(winners[[c for c in cols if c in winners]]), ""]
    out += ["## Verdicts", "", "The claims declared in advance (compare.claims), each decided over independent "
            "groups of clips (subjects) by an exact sign-flip test of the mean group effect (Holm over the declared "
            "claims only), its margin and its 90 % interval for equivalence (docs/compare/verdicts.md; numbers: "
            "`claims_stats.csv`; every other pair of generators, without a verdict: `exploratory.csv`).", "",
            to_markdown(verdicts[["claim", "ours", "verdict", "evidence"]]), ""]
    if sanity is not None and len(sanity):
        out += ["## Sanity checks", "", "Claims true by construction, decided the same way; not findings.", "",
                to_markdown(sanity[["claim", "ours", "verdict", "evidence"]]), ""]
    out += [
            "## Clips", "", to_markdown(clips[[c for c in ("clip", "subject", "group", "protocol", "held_out", "database",
                                                          "length", "note") if c in clips]]), "",
            "Per clip x seed values: `metrics.csv`; medians and spreads: `summary.csv`; build time, generation "
            "speed and memory: `cost_timing.csv` (machine-dependent, not shown here).", ""]
    return "\n".join(out)


def _num(x) -> str:
    from ..verdicts import fmt

    return fmt(x, 4)


def results_markdown(compare_dir) -> str:
    """The results page docs/compare/results.md, generated from a run's tables (``compare_dir``: e.g.
    ``results/paper/compare``): medians (IQR) per generator, the findings, the sanity checks, the skating
    sensitivity and, when present, the budget sweep and the long track's medians. Every number comes from those
    files."""
    from pathlib import Path

    from ..tables import to_markdown

    d = Path(compare_dir)
    summary = pd.read_csv(d / "summary.csv")
    out = ["Medians over clips x seeds, interquartile range in brackets (`summary.csv`):", "",
           to_markdown(_medians_table(summary, RESULT_METRICS, lambda m: metric(m).label)), ""]
    v = pd.read_csv(d / "verdicts.csv", keep_default_na=False)
    out += ["**Findings** (`verdicts.csv`):", "", to_markdown(v[["claim", "verdict", "ours", "evidence"]]), ""]
    if (d / "claims_stats.csv").exists():
        out += ["**The declared claims' numbers** (`claims_stats.csv`):", "",
                to_markdown(pd.read_csv(d / "claims_stats.csv")), ""]
    if (d / "sanity_checks.csv").exists():
        sc = pd.read_csv(d / "sanity_checks.csv", keep_default_na=False)
        out += ["**Sanity checks** (`sanity_checks.csv`):", "", to_markdown(sc[["claim", "verdict", "evidence"]]), ""]
    if (d / "skating_sensitivity.csv").exists():
        out += ["**Skating against its threshold** (`skating_sensitivity.csv`):", "",
                to_markdown(pd.read_csv(d / "skating_sensitivity.csv")), ""]
    if (d / "budget_sweep.csv").exists():
        out += ["**Transition budget sweep** (`budget_sweep.csv`, figure `budget_sweep.png`):", "",
                to_markdown(pd.read_csv(d / "budget_sweep.csv")), ""]
    if (d / "metrics_long.csv").exists():  # the long track's medians, from its rows
        long = pd.read_csv(d / "metrics_long.csv")
        order = list(dict.fromkeys(summary["generator"])) + [g for g in dict.fromkeys(long["generator"])
                                                              if g not in set(summary["generator"])]
        table = summary_table(long, order, list(LONG_RESULT_METRICS))
        out += ["**The long track** (`metrics_long.csv`: medians over its contexts x seeds, interquartile range in "
                "brackets, \"-\" where a generator did not run (its rows' note says why); every measure in "
                "`metrics_long.md`; its claims are the findings above whose source is `compare/metrics_long.csv`; "
                "preview `long_strips.png`):", "", to_markdown(_medians_table(table, LONG_RESULT_METRICS, str)), ""]
    return "\n".join(out)


def _medians_table(summary: pd.DataFrame, metrics, heading) -> pd.DataFrame:
    """One row per generator of ``summary`` (:func:`summary_table`'s long form): ``median (q25-q75)`` of each of
    ``metrics`` under ``heading(metric)``, "-" without a value."""
    from ..verdicts import fmt

    rows = []
    for g in dict.fromkeys(summary["generator"]):
        row = {"generator": g + (" (bound)" if g in REFERENCES else "")}
        for m in metrics:
            r = summary[(summary["generator"] == g) & (summary["metric"] == m)]
            row[heading(m) or m] = (f"{fmt(r['median'].iloc[0])} ({fmt(r['q25'].iloc[0])}-{fmt(r['q75'].iloc[0])})"
                                    if len(r) and r["n"].iloc[0] > 0 else "-")
        rows.append(row)
    return pd.DataFrame(rows)
