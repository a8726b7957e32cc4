"""The declared claims as config: checked at parse time (one line naming compare.claims[i].key), written once (the
config; the schema checks their shape, the docs' table is generated), and a generator with no value anywhere is
"did not run" in every table without stopping the tables job."""

from __future__ import annotations

import copy

import numpy as np
import pandas as pd
import pytest
import yaml

from animsynth.compare import settings, tables
from animsynth.compare.claims import page_parts, track_claims, update_page
from animsynth.compare.measures import metric_table
from animsynth.config import ConfigError

from conftest import REPO, default_config

BASE = default_config()


def _with_claim(**over) -> dict:
    """The default config with one more claim (a valid one, changed by ``over``; ``None`` drops a key)."""
    cfg = copy.deepcopy(BASE)
    claim = {"id": "extra_claim", "claim": "knn skates less than delaunay", "a": "knn", "b": "delaunay",
             "metric": "skate_share", "direction": "lower"}
    claim.update(over)
    cfg["compare"]["claims"].append({k: v for k, v in claim.items() if v is not None})
    return cfg


def test_the_shipped_claims_and_a_valid_extra_claim_pass():
    settings.check(copy.deepcopy(BASE))
    settings.check(_with_claim())
    settings.check(_with_claim(min_effect=0.1))
    cfg = _with_claim(a="mine")
    cfg["compare"]["user_generators"] = {"mine": "mine/toy.py:Toy"}
    settings.check(cfg)  # a user generator may be compared too
    cfg = copy.deepcopy(BASE)
    cfg["compare"]["generators"] = ["delaunay", "knn", "replay", "concat"]
    settings.check(cfg)  # a run of fewer rows keeps the shipped claims: those on rows it leaves out did not run


@pytest.mark.parametrize("over, key, words", [
    ({"metric": "skate_shar"}, "metric", "'skate_shar' is not a metric"),
    ({"metric": "clip"}, "metric", "'clip' is a text column"),
    ({"metric": "seed"}, "metric", "'seed' is a text column"),
    ({"metric": "group"}, "metric", "'group' is a text column"),
    ({"metric": "note"}, "metric", "'note' is a text column"),
    ({"a": "delaunai"}, "a", "'delaunai' is not a generator"),
    ({"b": "knm"}, "b", "'knm' is not a generator"),
    ({"b": "knn"}, "b", "is also a"),
    ({"a": "*", "b": "knn"}, "a", "'*' (every generator) may only be b"),
    ({"id": "<the first claim's id>"}, "id", "is also compare.claims[0].id"),
    ({"metric": "velocity_jump_max"}, "min_effect", "has no margin"),
    ({"metric": "contact_share", "direction": None, "min_effect": 0.1}, "direction", "is descriptive"),
])
def test_a_bad_claim_is_refused_at_config_time_naming_its_key(over, key, words):
    cfg = _with_claim(**over)
    i = len(cfg["compare"]["claims"]) - 1
    if over.get("id") == "<the first claim's id>":  # the same id twice
        cfg["compare"]["claims"][i]["id"] = cfg["compare"]["claims"][0]["id"]
    with pytest.raises(ConfigError) as err:
        settings.check(cfg)
    msg = str(err.value)
    assert f"compare.claims[{i}].{key}'" in msg and words in msg and "\n" not in msg


def test_a_margin_or_direction_given_in_the_claim_makes_it_valid():
    settings.check(_with_claim(metric="velocity_jump_max", min_effect=0.5))
    settings.check(_with_claim(metric="contact_share", direction="higher", min_effect=0.1))
    cfg = _with_claim(metric="velocity_jump_max")
    cfg["compare"]["verdicts"]["min_effect"] = {"velocity_jump_max": 0.5}  # the override gives it a margin
    settings.check(cfg)


def test_the_claims_are_listed_in_the_config_alone():
    schema = yaml.safe_load((REPO / "config" / "schema.yaml").read_text())
    claims = schema["properties"]["compare"]["properties"]["claims"]
    assert "default" not in claims and claims["items"]["required"] == ["id", "claim", "a", "b", "metric"]
    from animsynth.compare import verdicts as CV

    assert not hasattr(CV, "DEFAULT_CLAIMS")
    raw = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    assert [c["id"] for c in raw["compare"]["claims"]] == [c["id"] for c in BASE["compare"]["claims"]]
    assert len(raw["compare"]["claims"]) >= 1


def test_the_verdicts_page_is_generated_from_the_config():
    """docs/compare/verdicts.md: the words, the declared claims and the margins between their markers, as
    ``python -m animsynth.compare.claims`` writes them from config/config.yaml."""
    page = (REPO / "docs" / "compare" / "verdicts.md").read_text()
    assert update_page(page, page_parts(BASE["compare"])) == page, \
        "docs/compare/verdicts.md is stale: run .venv/bin/python -m animsynth.compare.claims"
    for c in BASE["compare"]["claims"]:
        assert f"`{c['id']}`" in page
    with pytest.raises(ValueError, match="no <!-- margins -->"):
        update_page("no markers here", {"margins": "x"})


# ------------------------------------------------------------------------------ a generator with no values
GENS = list(BASE["compare"]["generators"])


def _inputs(tmp_path, empty: str) -> dict:
    """The tables job's input files for every generator of the default config on 2 subjects x 2 clips x 2 seeds,
    ``empty``'s rows all NaN (every build refused by the cost guard)."""
    rng = np.random.default_rng(0)
    clips = pd.DataFrame([{"clip": f"s{s}/{t}", "group": f"s{s}", "protocol": "leave one out", "held_out": t,
                           "database": other} for s, (t, other) in enumerate([("35_01", "35_02"), ("16_01", "16_02")])]
                         + [{"clip": f"s{s}/{t}", "group": f"s{s}", "protocol": "leave one out", "held_out": t,
                             "database": other} for s, (t, other) in enumerate([("35_02", "35_01"), ("16_02", "16_01")])])
    clips.to_csv(tmp_path / "clips.csv", index=False)
    metrics, timing = [], []
    for g in GENS:
        rows, trows = [], []
        for clip in clips["clip"]:
            for seed in range(2):
                row = {"clip": clip, "group": clip.split("/")[0], "protocol": "leave one out", "generator": g,
                       "seed": seed, **{m: float(rng.uniform(0.1, 0.9)) for m in metric_table.METRIC_NAMES},
                       "note": ""}
                if g == empty:
                    row.update({m: np.nan for m in metric_table.METRIC_NAMES}, note="not built: estimated 9999 CPU s "
                               "above compare.cost_guard.max_cpu_s 1800")
                rows.append(row)
            trows.append({"generator": g, "clip": clip, "database_frames": 100, "build_cpu_s": np.nan if g == empty
                          else 1.0, "build_wall_s": 1.0, "generate_cpu_s": 1.0, "generate_wall_s": 1.0,
                          "frames_generated": 0 if g == empty else 60, "peak_rss_mb": 100.0})
        pd.DataFrame(rows).to_csv(tmp_path / f"{g}.csv", index=False)
        pd.DataFrame(trows).to_csv(tmp_path / f"{g}_timing.csv", index=False)
        metrics.append(tmp_path / f"{g}.csv")
        timing.append(tmp_path / f"{g}_timing.csv")
    return {"clips": tmp_path / "clips.csv", "metrics": metrics, "timing": timing}


@pytest.mark.parametrize("empty", GENS)
def test_a_generator_with_no_values_did_not_run_in_every_table(tmp_path, empty):
    cfg = dict(BASE["compare"], verdicts=dict(BASE["compare"]["verdicts"], permutations=2000))
    t = tables.family_tables(_inputs(tmp_path, empty), GENS, {}, cfg, "synthetic")
    stats = t["claims_stats"].set_index("claim_id")
    for c in track_claims(cfg["claims"], "short"):  # the 2-s track's files: its claims (the long ones: their own)
        if empty in (c["a"], c["b"]):
            assert stats.loc[c["id"], "verdict"] == "did not run", c["id"]
            row = t["verdicts"].set_index("claim").loc[c["claim"]]
            assert "above compare.cost_guard.max_cpu_s" in row["evidence"]
        elif c["b"] == "*":
            assert f"{empty} did not run" in t["verdicts"].set_index("claim").loc[c["claim"], "evidence"] or \
                empty in ("replay", "concat")
    assert t["verdicts"]["verdict"].isin(["did not run", "undecided", "no material difference"]).all()
    sanity = t["sanity"]
    if empty in ("isomap", "stisomap", "delaunay", "knn", "motion_graph", "concat"):
        assert not sanity["verdict"].isin(["reproduced", "not reproduced"]).any()
    if empty in ("motion_graph", "concat"):
        assert sanity["verdict"].iloc[-1] == "did not run"
    ex = t["exploratory"]
    assert ex.loc[ex["label"] == "did not run", "a"].tolist() == [empty]
    assert empty not in set(ex.loc[ex["label"] == "exploratory", ["a", "b"]].stack())
    assert empty not in set(t["winners"][["best", "second"]].stack())
    assert (t["summary"].loc[t["summary"]["generator"] == empty, "n"] == 0).all()
    assert "Did not run (no value on any clip" in t["summary_md"] and f"**{empty}**" in t["summary_md"]
