"""The declared side-by-side claims, decided over subjects: each word of the ladder reached on constructed metrics,
never "reproduced" without evidence; the per-clip contact guard; subjects on a generic figure; the claims read from
the config alone."""

from __future__ import annotations

import re
import subprocess

import numpy as np
import pandas as pd
import pytest

from animsynth.compare import claim_stats as CS
from animsynth.compare import verdicts as CV
from animsynth.compare.measures import metric_table
from animsynth.scoreboard import VERDICT_COLOURS, scoreboard_counts
from animsynth.verdicts import VOCABULARY

from conftest import REPO, default_config

CMP = default_config()["compare"]
#: the shipped rule's settings (margins from the metric table), fewer random flips for speed
VC = dict(CMP["verdicts"], permutations=20000)
#: a claim made up for the rule's tests (the shipped list is the config's, tested apart below)
SKATE = {"id": "t_skate", "claim": "the motion graph skates less than ST-Isomap (test)", "a": "motion_graph",
         "b": "stisomap", "metric": "skate_share", "direction": "lower"}
CAPTURE = {"id": "t_capture", "claim": "the capture skates less than every generator (test)", "a": "replay", "b": "*",
           "metric": "skate_share", "direction": "lower"}
MARGIN = metric_table.metric("skate_share").margin


def build(effects, clips: int = 3, seeds: int = 2, pair=("motion_graph", "stisomap"), metric: str = "skate_share",
          noise: float = 0.002, contact: dict | None = None, extra: dict | None = None, seed: int = 0,
          figure: dict | None = None):
    """Metrics and clips tables: one subject per entry of ``effects`` (its true effect: ``b - a`` on ``metric``),
    ``clips`` clips x ``seeds`` seeds each, the pair's values ``0.2`` and ``0.2 + effect`` plus seeded noise of
    scale ``noise``; ``contact``: {generator: contact_share, or {clip: share}} (default 0.4); ``extra``:
    {generator: effect against ``a``} for further generators on the same metric; ``figure``: {subject index:
    "generic"} (the clips table's figure column; None: no such column)."""
    rng = np.random.default_rng(seed)
    gens = {pair[0]: 0.0, pair[1]: None, **(extra or {})}
    rows, crow = [], []
    for si, eff in enumerate(effects):
        subject = 10 + si
        trials = [f"{subject}_{i:02d}" for i in range(clips)]
        for i, t in enumerate(trials):
            clip = f"s{si}/{t}"
            crow.append({"clip": clip, "group": f"s{si}", "held_out": t,
                         "database": " ".join(x for x in trials if x != t)}
                        | ({"figure": (figure or {}).get(si, "own")} if figure is not None else {}))
            for s in range(seeds):
                for g, e in gens.items():
                    row = {"clip": clip, "group": f"s{si}", "protocol": "leave one out", "generator": g, "seed": s}
                    row.update({m: np.nan for m in metric_table.METRIC_NAMES})
                    row[metric] = 0.2 + (eff if e is None else e) + noise * rng.standard_normal()
                    c = (contact or {}).get(g, 0.4)
                    row["contact_share"] = c.get(clip, 0.4) if isinstance(c, dict) else c
                    rows.append(row)
    return pd.DataFrame(rows), pd.DataFrame(crow)


def decide(effects, claim=SKATE, claims=None, left_out=None, **kw):
    metrics, clips = build(effects, **kw)
    v, stats = CV.decide_claims(metrics, VC, "test data", left_out or {}, clips, claims=claims or [claim])
    return v.set_index("claim").loc[claim["claim"]], stats.set_index("claim_id").loc[claim["id"]]


# ------------------------------------------------------------------------------------------- each word reached
def test_twelve_subjects_with_a_true_effect_beyond_the_margin_reproduce_it():
    row, s = decide([0.08] * 12)
    assert row["verdict"] == "reproduced"
    assert s["n_groups"] == 12 and s["p"] == pytest.approx(2 / 2 ** 12) and s["p_holm"] < 0.05
    assert s["ci_low"] > MARGIN and s["mean_effect"] == pytest.approx(0.08, abs=0.002) and s["margin"] == MARGIN
    assert s["ci90_low"] > s["ci_low"] and s["ci90_high"] < s["ci_high"]
    assert "12 subjects" in row["ours"] and "Holm p" in row["ours"]


def test_the_same_the_other_way_contradicts_it():
    row, s = decide([-0.08] * 12)
    assert row["verdict"] == "contradicted" and s["mean_effect"] < -MARGIN


def test_an_interval_inside_the_margins_is_no_material_difference():
    row, s = decide([0.004, -0.003, 0.002, -0.004, 0.003, -0.002, 0.001, -0.001, 0.0, 0.002, -0.002, 0.001],
                    noise=0.0005)
    assert row["verdict"] == "no material difference", row["evidence"]
    assert -MARGIN < s["ci90_low"] and s["ci90_high"] < MARGIN and "two one-sided tests" in row["evidence"]
    # a consistent effect below the margin with a tight interval: equivalent too (it matters to no one)
    assert decide([0.01] * 12)[0]["verdict"] == "no material difference"


def test_a_significant_effect_below_the_margin_whose_interval_reaches_beyond_it_is_undecided():
    row, s = decide(list(np.linspace(-0.01, 0.09, 12)))
    assert s["p_holm"] < 0.05 and 0 < s["mean_effect"] < MARGIN and s["ci90_high"] > MARGIN
    assert row["verdict"] == "undecided" and "below the margin" in row["evidence"]


def test_partly_only_for_a_significant_split_between_subjects():
    # 6 subjects for and 6 against, each with 10 clips all one way: every per-subject sign test over clips decides
    # (2 / 2^10, Holm over 12 subjects 0.023)
    row, _ = decide([0.3] * 6 + [-0.3] * 6, clips=10, seeds=2)
    assert row["verdict"] == "partly" and "significant split: 6 subjects significantly for and 6" in row["evidence"]
    # 4 clips x 5 seeds per subject: the seeds of a clip are not independent, 4 clips give p = 0.125 at best: the
    # same split decides nothing
    row, _ = decide([0.3] * 6 + [-0.3] * 6, clips=4, seeds=5)
    assert row["verdict"] == "undecided" and "neither significant" in row["evidence"]
    # a split whose mean is equivalent: equivalence comes first in the ladder, and the reason names the split
    row, _ = decide([0.08] * 6 + [-0.08] * 6, clips=10, seeds=2)
    assert row["verdict"] == "no material difference" and "but the subjects split: 6 significantly for" in \
        row["evidence"]


def test_four_subjects_with_the_same_effect_are_undecided_with_the_subjects_power_would_need():
    row, s = decide([0.08, 0.06, 0.1, 0.07])
    assert row["verdict"] == "undecided" and row["ours"].startswith("undecided (4 subjects): ")
    for part in ("95 % t interval", "sign-flip p = 0.12", "Holm p = 0.12", "subjects for 80 % power at this effect"):
        assert part in row["ours"], part
    assert s["p"] == pytest.approx(0.125)  # 2 / 2^4: no test can go lower
    assert 2 <= int(s["subjects_for_80_power"]) <= 6


def test_a_generator_with_no_value_did_not_run_and_says_why():
    metrics, clips = build([0.08] * 12)
    metrics.loc[metrics["generator"] == "stisomap", "skate_share"] = np.nan
    metrics.loc[metrics["generator"] == "stisomap", "note"] = "not built: estimated 2000 CPU s above max_cpu_s"
    v, s = CV.decide_claims(metrics, VC, "d", {}, clips, claims=[SKATE])
    assert v["verdict"].tolist() == ["did not run"] and "above max_cpu_s" in v["evidence"].iloc[0]
    assert s["n_groups"].tolist() == [0] and not np.isfinite(s["p"]).any()
    v, _ = CV.decide_claims(metrics[metrics["generator"] != "stisomap"], VC, "d", {"stisomap": "not installed"},
                            clips, claims=[SKATE])
    assert v["verdict"].tolist() == ["did not run"] and "stisomap did not run: not installed" in v["evidence"].iloc[0]


def test_no_evidence_is_never_reproduced_nor_not_reproduced():
    # both generators ran, but on different clips: nothing to compare
    metrics, clips = build([0.08] * 12)
    half = metrics["clip"].isin(sorted(set(metrics["clip"]))[::2])
    metrics.loc[half & (metrics["generator"] == "stisomap"), "skate_share"] = np.nan
    metrics.loc[~half & (metrics["generator"] == "motion_graph"), "skate_share"] = np.nan
    v, s = CV.decide_claims(metrics, VC, "d", {}, clips, claims=[SKATE])
    assert v["verdict"].tolist() == ["undecided"] and v["ours"].iloc[0] == "undecided (0 subjects)"
    assert "no clip x seed with a skate_share value for both" in v["evidence"].iloc[0]


def test_a_claim_without_a_margin_is_refused_by_the_library_too():
    metrics, clips = build([0.08] * 4)
    bare = dict(SKATE, metric="velocity_jump_max")  # no margin in the metric table, no min_effect
    with pytest.raises(ValueError, match="'t_skate': metric 'velocity_jump_max' needs a margin"):
        CV.decide_claims(metrics, VC, "d", {}, clips, claims=[bare])


def test_three_equal_effects_do_not_give_p_zero():
    assert CS.sign_flip_p([0.033] * 3) == pytest.approx(2 / 8)
    assert CS.sign_flip_p([0.0] * 3) == 1.0
    row, s = decide([0.08] * 3, noise=0.0)
    assert s["p"] == pytest.approx(0.25) and row["verdict"] == "undecided"
    # beyond 16 groups the seeded random flips: never 0, the same for the same seed
    big = np.full(20, 0.01)
    assert CS.sign_flip_p(big, seed=3, draws=5000) == CS.sign_flip_p(big, seed=3, draws=5000) > 0


# ------------------------------------------------------------------------------------------- the contact guard
def test_a_skating_claim_compares_only_clips_where_both_generators_feet_touch():
    # motion_graph hovers on one clip of each of the first 4 subjects (contact 0.029) and on every clip of subject 11
    hover = {f"s{si}/{10 + si}_00": 0.029 for si in range(4)} | {f"s11/21_{i:02d}": 0.0 for i in range(3)}
    row, s = decide([0.08] * 12, contact={"motion_graph": hover})
    assert row["verdict"] == "reproduced" and s["n_groups"] == 11  # subject 11 has no clip left: it drops out
    assert "7 clips left out (7 clips of motion_graph" in row["evidence"] and "s0/10_00" in row["evidence"]
    # a clip where one generator floats can neither win nor lose: its effect (here the opposite) is not counted
    metrics, clips = build([0.08] * 12)
    floaty = metrics["clip"].isin([f"s{si}/{10 + si}_00" for si in range(12)]) & (metrics["generator"] == "stisomap")
    metrics.loc[floaty, ["skate_share", "contact_share"]] = [0.0, 0.01]
    v, s = CV.decide_claims(metrics, VC, "d", {}, clips, claims=[SKATE])
    assert v["verdict"].iloc[0] == "reproduced" and "12 clips left out" in v["evidence"].iloc[0]


def test_a_skating_claim_with_no_clip_where_both_touch_is_undecided():
    row, s = decide([0.08] * 12, contact={"motion_graph": 0.01})
    assert row["verdict"] == "undecided" and "no clip on which both motion_graph's and stisomap's feet touch" in \
        row["evidence"]
    assert s["a_contact_share"] == pytest.approx(0.01) and s["b_contact_share"] == pytest.approx(0.4)
    assert not np.isfinite(s["p"]) and not np.isfinite(s["p_holm"])  # no test: not in Holm


# ------------------------------------------------------------------------------------------- generic figures
def test_subjects_on_a_generic_figure_leave_the_test_and_show_as_a_sensitivity_line():
    effects = [0.08] * 10 + [-0.5, -0.5]
    row, s = decide(effects, figure={10: "generic", 11: "generic"})
    assert row["verdict"] == "reproduced" and s["n_groups"] == 10
    line = row["evidence"][row["evidence"].index("sensitivity, with the 6 clips of subjects on a generic figure"):]
    assert "12 subjects" in line and "not Holm-adjusted" in line
    assert "sensitivity" not in decide(effects, figure={})[0]["evidence"]  # every subject on its own skeleton
    # a clips table without the column: every subject its own
    without, _ = decide(effects)
    assert without["verdict"] == decide(effects, figure={})[0]["verdict"] and "sensitivity" not in without["evidence"]


def test_a_subject_with_fewer_clips_than_the_minimum_is_no_unit_of_the_tests():
    """clips.csv's enough_clips (compare.min_clips_per_subject): a subject below the minimum leaves the claims,
    the sanity checks and the exploratory table, and the data column names it."""
    effects = [0.08] * 10 + [-0.5, -0.5]
    metrics, clips = build(effects)
    clips["subject"] = clips["held_out"].str.split("_").str[0]
    clips["enough_clips"] = ~clips["group"].isin(["s10", "s11"])  # the two opposite subjects: too few clips
    v, stats = CV.decide_claims(metrics, VC, "test data", {}, clips, claims=[SKATE])
    assert stats.set_index("claim_id").loc["t_skate", "n_groups"] == 10
    assert v.iloc[0]["verdict"] == "reproduced"
    assert "fewer clips than compare.min_clips_per_subject: subject 20 (3 clips), subject 21 (3 clips)" in \
        v.iloc[0]["data"]
    both, _ = CV.decide_claims(metrics, VC, "test data", {}, clips.assign(enough_clips=True), claims=[SKATE])
    assert "fewer clips" not in both.iloc[0]["data"]
    ex = CV.exploratory_table(metrics, VC, clips, claims=[], order=["motion_graph", "stisomap"])
    assert set(ex.loc[ex["label"] == "exploratory", "n_groups"]) == {10}


# ------------------------------------------------------------------------------------------- the capture claim
def test_one_significant_opposite_part_contradicts_the_capture_claim():
    """The capture skates less than motion_graph in no subject and more in all 12, while against stisomap it is
    noise: "less than every generator" is refuted by the one significant opposite part (Bonferroni over the
    parts), not hidden behind the largest p of the intersection-union test."""
    row, s = decide([0.0] * 12, claim=CAPTURE, pair=("replay", "stisomap"), extra={"motion_graph": -0.08},
                    noise=0.01, seed=5)
    assert row["verdict"] == "contradicted", row["evidence"]
    assert "Tested for a contradiction" in row["evidence"] and s["p"] == pytest.approx(min(1.0, 2 * 2 / 2 ** 12))
    assert s["mean_effect"] < -MARGIN


def test_the_capture_claims_parts_show_numbers_not_verdict_words():
    row, s = decide([0.08] * 12, claim=CAPTURE, pair=("replay", "motion_graph"),
                    extra={"stisomap": 0.1, "floaty": 0.2}, contact={"floaty": 0.0})
    ev = row["evidence"]
    parts = re.findall(r"(\w+): (\d+)/(\d+)/(\d+), mean effect ([-0-9.e]+) \[95 % t interval [^]]+\], p = ([0-9.e-]+)",
                       ev)
    assert {p[0] for p in parts} == {"motion_graph", "stisomap"}
    per = ev[ev.index("per generator"):]
    assert not any(w in per for w in ("reproduced", "contradicted", "partly", "undecided"))
    assert "floaty left out: no clip on which both replay's and floaty's feet touch the floor" in ev
    assert s["p"] == pytest.approx(max(float(p[5]) for p in parts), rel=0.02)  # the intersection-union p
    assert s["b"] == "every generator" and row["verdict"] == "reproduced"


def test_the_capture_claim_is_equivalent_only_when_every_part_is():
    row, s = decide([0.0] * 12, claim=CAPTURE, pair=("replay", "stisomap"), extra={"motion_graph": 0.001},
                    noise=0.003)
    assert row["verdict"] == "no material difference" and -MARGIN < s["ci90_low"] and s["ci90_high"] < MARGIN
    # the weakest part (stisomap, no effect) is equivalent on its own, the other part's interval reaches the margin
    row, s = decide([0.0] * 12, claim=CAPTURE, pair=("replay", "stisomap"), extra={"motion_graph": 0.048},
                    noise=0.01)
    assert s["ci90_high"] > MARGIN and row["verdict"] == "undecided", row["evidence"]


# ------------------------------------------------------------------------------------------- Holm, exploratory
def test_holm_runs_over_the_declared_claims_only():
    metrics, clips = build([0.08] * 12)
    _, alone = CV.decide_claims(metrics, VC, "d", {}, clips, claims=[SKATE])
    more, clips2 = build([0.08] * 12, extra={"isomap": 0.1, "knn": -0.1, "genmm_like": 0.16})
    _, stats = CV.decide_claims(more, VC, "d", {}, clips2, claims=[SKATE])
    assert stats["p_holm"].iloc[0] == alone["p_holm"].iloc[0]
    ex = CV.exploratory_table(more, VC, clips2, claims=[SKATE])
    assert len(ex) >= 6 and (ex["p"] < 0.01).all()  # strong exploratory pairs: counted in Holm they would move it
    pair = (ex["a"] == "motion_graph") & (ex["b"] == "stisomap") & (ex["metric"] == "skate_share")
    assert not pair.any()
    # a claim left out of the declared list: its pair is exploratory, and it is no finding
    ex2 = CV.exploratory_table(more, VC, clips2, claims=[])
    assert ((ex2["a"] == "motion_graph") & (ex2["b"] == "stisomap") & (ex2["metric"] == "skate_share")).sum() == 1
    assert (ex2["margin"][ex2["metric"] == "skate_share"] == MARGIN).all()
    v, _ = CV.decide_claims(more, VC, "d", {}, clips2, claims=[])
    assert v.empty


def test_the_exploratory_table_has_no_verdict_word_the_scoreboard_counts():
    more, clips = build([0.08] * 12, extra={"isomap": 0.1, "knn": -0.1})
    ex = CV.exploratory_table(more, VC, clips, claims=CMP["claims"])
    assert list(ex.columns) == list(CV.EXPLORATORY_COLUMNS) and "verdict" not in ex
    assert set(ex["label"]) == {"exploratory"}
    assert not any(w in set(ex[c].astype(str)) for c in ex.columns for w in VOCABULARY)
    v, _ = CV.decide_claims(more, VC, "d", {}, clips, claims=CMP["claims"])
    claims = v.assign(family="compare", paper="side by side", real=True)
    counts = scoreboard_counts(claims)
    assert int(counts["claims"].iloc[0]) == len(v) == len(CMP["claims"])  # the declared claims, no more
    smk = (REPO / "workflow" / "rules" / "compare.smk").read_text()
    verdict_files = re.search(r"COMPARE_VERDICTS = \[(.*)\]", smk).group(1)
    assert "exploratory" not in verdict_files and "claims_stats" not in verdict_files


def test_every_verdict_word_has_its_own_colour_and_count():
    assert set(VOCABULARY) <= set(VERDICT_COLOURS) and len(set(VERDICT_COLOURS.values())) == len(VERDICT_COLOURS)
    claims = pd.DataFrame({"family": ["compare"] * 3, "paper": ["p"] * 3,
                           "verdict": ["undecided", "reproduced", "no material difference"], "real": [True] * 3})
    counts = scoreboard_counts(claims)
    assert int(counts["undecided"].iloc[0]) == 1 and int(counts["no material difference"].iloc[0]) == 1


# ------------------------------------------------------------------------------------------- the shipped claims
def test_every_declared_claim_of_the_config_has_a_row_and_a_missing_generator_did_not_run():
    metrics, clips = build([0.08] * 12)
    v, stats = CV.decide_claims(metrics, VC, "d", {"fairmotion": "its package is not installed"}, clips,
                                claims=CMP["claims"])
    assert list(v["claim"]) == [c["claim"] for c in CMP["claims"]]
    assert list(stats.columns) == list(CV.STATS_COLUMNS) and list(stats["claim_id"]) == [c["id"] for c in CMP["claims"]]
    ran = {"motion_graph", "stisomap"}
    for c, word, ev in zip(CMP["claims"], v["verdict"], v["evidence"]):
        if c["b"] == "*" or {c["a"], c["b"]} <= ran:
            continue
        assert word == "did not run", c["id"]
        if "fairmotion" in (c["a"], c["b"]):
            assert "its package is not installed" in ev


def test_a_claim_is_a_skating_claim_by_its_metrics_record_unless_it_says():
    """The skating flag is written once, in the metric table: a declared claim on skate_share is a skating claim
    without a ``skating`` key, one on l2p is not, and an explicit key overrides the table."""
    base = {"id": "x", "claim": "x", "a": "a", "b": "b", "direction": "lower"}
    assert CV.skating_claim(dict(base, metric="skate_share"))
    assert CV.skating_claim(dict(base, metric="transition_skate_share"))
    assert not CV.skating_claim(dict(base, metric="l2p"))
    assert not CV.skating_claim(dict(base, metric="skate_share", skating=False))
    assert CV.skating_claim(dict(base, metric="l2p", skating=True))
    assert not any("skating" in c for c in CMP["claims"])


def test_each_claim_id_is_written_in_the_config_and_generated_docs_only():
    """The declared list lives in config/config.yaml alone: no source, test, rule or other config file names a
    claim id (the docs' tables are generated from the config)."""
    files = subprocess.run(["git", "ls-files"], cwd=REPO, capture_output=True, text=True, check=True).stdout.split()
    for c in CMP["claims"]:
        found = [f for f in files if (REPO / f).is_file() and c["id"] in (REPO / f).read_text(errors="ignore")]
        assert set(found) <= {"config/config.yaml"} | {f for f in found if f.startswith("docs/")}, (c["id"], found)
        assert "config/config.yaml" in found
