"""The declared side-by-side claims, decided over subjects: exact sign-flip test, interval, honest labels."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from animsynth.compare.measures import metric_table
from animsynth.compare import verdicts as CV
from animsynth.scoreboard import VERDICT_COLOURS, scoreboard_counts
from animsynth.verdicts import VOCABULARY

VC = {"alpha": 0.05, "min_groups": 3, "novelty_copy_m": 0.01, "min_contact_share": 0.05, "permutations": 20000,
      "min_effect": {"skate_share": 0.02, "transition_skate_share": 0.02, "velocity_jump_p95": 0.1, "l2p": 0.25,
                     "novelty_median_m": 0.005, "coverage": 0.02}}
GRAPH = "the classic motion graph skates less than ST-Isomap re-sequencing"


def build(effects, clips: int = 3, seeds: int = 2, pair=("motion_graph", "stisomap"), metric: str = "skate_share",
          noise: float = 0.002, contact: dict | None = None, extra: dict | None = None, seed: int = 0):
    """Metrics and clips tables: one subject per entry of ``effects`` (its true effect: ``b - a`` on ``metric``),
    ``clips`` clips x ``seeds`` seeds each, the pair's values ``0.2`` and ``0.2 + effect`` plus seeded noise of
    scale ``noise``; ``contact``: {generator: contact_share} (default 0.4); ``extra``: {generator: effect against
    ``a``} for further generators on the same metric."""
    rng = np.random.default_rng(seed)
    gens = {pair[0]: 0.0, pair[1]: None, **(extra or {})}
    rows, crow = [], []
    for si, eff in enumerate(effects):
        subject = 10 + si
        trials = [f"{subject}_{i:02d}" for i in range(clips)]
        for i, t in enumerate(trials):
            clip = f"s{si}/{t}"
            crow.append({"clip": clip, "group": f"s{si}", "held_out": t,
                         "database": " ".join(x for x in trials if x != t)})
            for s in range(seeds):
                for g, e in gens.items():
                    row = {"clip": clip, "group": f"s{si}", "protocol": "leave one out", "generator": g, "seed": s}
                    row.update({m: np.nan for m in metric_table.METRIC_NAMES})
                    value = 0.2 + (eff if e is None else e) + noise * rng.standard_normal()
                    row[metric] = value
                    row["contact_share"] = (contact or {}).get(g, 0.4)
                    rows.append(row)
    return pd.DataFrame(rows), pd.DataFrame(crow)


def decide(effects, claim=GRAPH, **kw):
    metrics, clips = build(effects, **kw)
    v, stats = CV.decide_claims(metrics, VC, "test data", {}, clips)
    return v.set_index("claim").loc[claim], stats.set_index("claim_id")


def test_twelve_subjects_with_a_true_effect_decide_it():
    row, stats = decide([0.05] * 12)
    assert row["verdict"] == "reproduced"
    s = stats.loc["graph_vs_stisomap_skating"]
    assert s["n_groups"] == 12 and s["p"] == pytest.approx(2 / 2 ** 12) and s["p_holm"] < 0.05
    assert s["ci_low"] > 0.02 and s["mean_effect"] == pytest.approx(0.05, abs=0.002)
    assert "12 subjects" in row["ours"] and "Holm p" in row["ours"]


def test_four_subjects_with_the_same_effect_are_undecided():
    row, stats = decide([0.05] * 4)
    assert row["verdict"] == "undecided"
    assert row["ours"].startswith("undecided (4 subjects): ")
    for part in ("95 % t interval", "sign-flip p = 0.12", "Holm p = 0.12"):
        assert part in row["ours"], part
    assert stats.loc["graph_vs_stisomap_skating", "p"] == pytest.approx(0.125)  # 2 / 2^4: no test can go lower


def test_three_equal_effects_do_not_give_p_zero():
    assert CV.sign_flip_p([0.033] * 3) == pytest.approx(2 / 8)
    assert CV.sign_flip_p([0.0] * 3) == 1.0
    row, stats = decide([0.033] * 3, noise=0.0)
    assert stats.loc["graph_vs_stisomap_skating", "p"] == pytest.approx(0.25)
    assert row["verdict"] == "undecided"
    # beyond 16 groups the seeded random flips: never 0, the same for the same seed
    big = np.full(20, 0.01)
    assert CV.sign_flip_p(big, seed=3, draws=5000) == CV.sign_flip_p(big, seed=3, draws=5000) > 0


def test_partly_only_for_a_significant_split_between_subjects():
    # 6 subjects for and 6 against, each with 10 clips all one way: every per-subject sign test over clips decides
    # (2 / 2^10, Holm over 12 subjects 0.023)
    row, _ = decide([0.05] * 6 + [-0.05] * 6, clips=10, seeds=2)
    assert row["verdict"] == "partly" and "significant split: 6 subjects significantly for and 6" in row["evidence"]
    # 4 clips x 5 seeds per subject: 20 clip x seed effects one way would look significant, but the seeds of a clip
    # are not independent: 4 clips give p = 0.125 at best, so no partly
    row, _ = decide([0.05] * 6 + [-0.05] * 6, clips=4, seeds=5)
    assert row["verdict"] == "within noise" and "6 of 12 hold, 6 of 12 the opposite" in row["evidence"]
    # the same split with one clip x 2 seeds per subject: no per-subject test can decide (p >= 0.5), so no partly
    row, _ = decide([0.05] * 6 + [-0.05] * 6, clips=1, seeds=2)
    assert row["verdict"] == "within noise" and "6 of 12 hold, 6 of 12 the opposite" in row["evidence"]


def test_one_significant_opposite_part_contradicts_the_capture_claim():
    """The capture skates less than motion_graph in no subject and more in all 12, while against stisomap it is
    noise: "less than every generator" is refuted by the one significant opposite part (Bonferroni over the
    parts), not hidden behind the largest p of the intersection-union test."""
    claim = "the held-out capture skates less than every generator (the realism upper bound holds for this metric)"
    row, stats = decide([0.0] * 12, claim=claim, pair=("replay", "stisomap"), extra={"motion_graph": -0.05},
                        noise=0.01, seed=5)
    s = stats.loc["capture_skates_least"]
    assert row["verdict"] == "contradicted", row["evidence"]
    assert "Tested for a contradiction" in row["evidence"] and s["p"] == pytest.approx(min(1.0, 2 * 2 / 2 ** 12))
    assert s["mean_effect"] < -0.02


def test_a_blocked_claim_does_not_enter_the_holm_correction():
    """A skating claim blocked by floating feet is not a finding: its p is NaN and Holm counts one claim fewer."""
    metrics, clips = build([0.05] * 12, contact={"stisomap": 0.01})
    _, stats = CV.decide_claims(metrics, VC, "test data", {}, clips)
    s = stats.set_index("claim_id").loc["graph_vs_stisomap_skating"]
    assert s["verdict"] == "not reproduced" and not np.isfinite(s["p"]) and not np.isfinite(s["p_holm"])


def test_a_significant_effect_below_the_minimum_and_an_interval_inside_it_are_not_reproduced():
    row, _ = decide([0.01] * 12)  # significant, but 0.01 < 0.02
    assert row["verdict"] == "not reproduced" and "below the minimum effect" in row["evidence"]
    row, _ = decide([0.004, -0.003, 0.002, -0.004, 0.003, -0.002, 0.001, -0.001], noise=0.0005)
    assert row["verdict"] == "not reproduced" and "interval lies inside" in row["evidence"]


def test_a_generator_whose_feet_do_not_touch_does_not_win_a_skating_claim():
    row, stats = decide([0.05] * 12, contact={"motion_graph": 0.01})
    assert row["verdict"] == "not reproduced"
    assert "motion_graph's feet do not touch the floor (median contact_share 0.01" in row["evidence"]
    s = stats.loc["graph_vs_stisomap_skating"]
    assert s["a_contact_share"] == pytest.approx(0.01) and s["b_contact_share"] == pytest.approx(0.4)
    assert "contact_share (share of foot joint-frames) median motion_graph 0.01, stisomap 0.4" in row["ours"]
    # feet on the floor: the same numbers decide it
    assert decide([0.05] * 12)[0]["verdict"] == "reproduced"


def test_holm_runs_over_the_declared_claims_only():
    metrics, clips = build([0.05] * 12)
    _, alone = CV.decide_claims(metrics, VC, "d", {}, clips)
    more, clips2 = build([0.05] * 12, extra={"isomap": 0.1, "knn": -0.1, "genmm_like": 0.08})
    _, stats = CV.decide_claims(more, VC, "d", {}, clips2)
    key = "graph_vs_stisomap_skating"
    assert stats.set_index("claim_id").loc[key, "p_holm"] == alone.set_index("claim_id").loc[key, "p_holm"]
    ex = CV.exploratory_table(more, VC, clips2)
    assert len(ex) >= 6 and (ex["p"] < 0.01).all()  # strong exploratory pairs: counted in Holm they would move it
    assert not ((ex["a"] == "motion_graph") & (ex["b"] == "stisomap") & (ex["metric"] == "skate_share")).any()
    # dropping the claim from the declared list makes its pair exploratory
    rest = [c for c in CV.DEFAULT_CLAIMS if c["id"] != key]
    ex2 = CV.exploratory_table(more, VC, clips2, claims=rest)
    assert ((ex2["a"] == "motion_graph") & (ex2["b"] == "stisomap") & (ex2["metric"] == "skate_share")).sum() == 1
    v, _ = CV.decide_claims(more, VC, "d", {}, clips2, claims=rest)
    assert GRAPH not in set(v["claim"])


def test_the_exploratory_table_has_no_verdict_word_the_scoreboard_counts():
    more, clips = build([0.05] * 12, extra={"isomap": 0.1, "knn": -0.1})
    ex = CV.exploratory_table(more, VC, clips)
    assert list(ex.columns) == list(CV.EXPLORATORY_COLUMNS) and "verdict" not in ex
    assert set(ex["label"]) == {"exploratory"}
    assert not any(w in set(ex[c].astype(str)) for c in ex.columns for w in VOCABULARY)
    v, _ = CV.decide_claims(more, VC, "d", {}, clips)
    claims = v.assign(family="compare", paper="side by side", real=True)
    counts = scoreboard_counts(claims)
    assert int(counts["claims"].iloc[0]) == len(v) == len(CV.DEFAULT_CLAIMS)  # the declared claims, no more
    from conftest import REPO

    smk = (REPO / "workflow" / "rules" / "compare.smk").read_text()
    verdict_files = re.search(r"COMPARE_VERDICTS = \[(.*)\]", smk).group(1)
    assert "exploratory" not in verdict_files and "claims_stats" not in verdict_files


def test_undecided_is_a_vocabulary_word_with_its_own_colour_and_count():
    assert "undecided" in VOCABULARY and "undecided" in VERDICT_COLOURS
    assert VERDICT_COLOURS["undecided"] != VERDICT_COLOURS["within noise"]
    claims = pd.DataFrame({"family": ["compare"] * 2, "paper": ["p"] * 2, "verdict": ["undecided", "reproduced"],
                           "real": [True, True]})
    counts = scoreboard_counts(claims)
    assert int(counts["undecided"].iloc[0]) == 1 and int(counts["reproduced"].iloc[0]) == 1


def test_every_declared_claim_has_a_row_and_a_missing_generator_did_not_run():
    metrics, clips = build([0.05] * 12)
    v, stats = CV.decide_claims(metrics, VC, "d", {"fairmotion": "its package is not installed"}, clips)
    assert list(v["claim"]) == [c["claim"] for c in CV.DEFAULT_CLAIMS]
    assert list(stats.columns) == list(CV.STATS_COLUMNS) and len(stats) == len(v)
    traj = v.set_index("claim").loc["motion matching (queried with the held-out future trajectory) skates less "
                                    "than the motion graph"]
    assert traj["verdict"] == "not reproduced" and "motion_matching_traj did not run" in traj["evidence"]
    fm = v.set_index("claim").loc["our motion graph's transitions skate less than fairmotion 0.0.4's as released "
                                  "(at its native 60 fps)"]
    assert fm["verdict"] == "not reproduced" and "its package is not installed" in fm["evidence"]


def test_the_capture_claims_parts_show_numbers_not_verdict_words():
    metrics, clips = build([0.05] * 12, pair=("replay", "motion_graph"),
                           extra={"stisomap": 0.1, "floaty": 0.2}, contact={"floaty": 0.0})
    v, stats = CV.decide_claims(metrics, VC, "d", {}, clips)
    cap = v.set_index("claim").loc[CV.DEFAULT_CLAIMS[-1]["claim"]]
    ev = cap["evidence"]
    parts = re.findall(r"(\w+): (\d+)/(\d+)/(\d+), mean effect ([-0-9.e]+) \[95 % t interval [^]]+\], p = ([0-9.e-]+)",
                       ev)
    assert {p[0] for p in parts} == {"motion_graph", "stisomap"}
    per = ev[ev.index("per generator"):]
    assert not any(w in per for w in ("reproduced", "contradicted", "partly", "undecided"))
    assert "floaty left out: floaty's feet do not touch the floor" in ev
    s = stats.set_index("claim_id").loc["capture_skates_least"]
    assert s["p"] == pytest.approx(max(float(p[5]) for p in parts), rel=0.02)  # the intersection-union p
    assert s["b"] == "every generator" and cap["verdict"] == "reproduced"


def test_the_declared_list_in_the_config_is_the_modules():
    from conftest import default_config

    declared = default_config()["compare"]["claims"]
    filled = [dict({"paper_value": "", "note": ""}, **c) for c in CV.DEFAULT_CLAIMS]
    assert declared == filled


def test_a_claim_is_a_skating_claim_by_its_metrics_record_unless_it_says():
    """The skating flag is written once, in the metric table: a declared claim on skate_share is a skating claim
    without a ``skating`` key, one on l2p is not, and an explicit key overrides the table."""
    base = {"id": "x", "claim": "x", "a": "a", "b": "b", "direction": "lower", "min_effect": 0.0}
    assert CV.skating_claim(dict(base, metric="skate_share"))
    assert CV.skating_claim(dict(base, metric="transition_skate_share"))
    assert not CV.skating_claim(dict(base, metric="l2p"))
    assert not CV.skating_claim(dict(base, metric="skate_share", skating=False))
    assert CV.skating_claim(dict(base, metric="l2p", skating=True))
    assert not any("skating" in c for c in CV.DEFAULT_CLAIMS)
