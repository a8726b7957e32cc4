"""Real or synthetic comes from the data layer's record per family, not from words in a verdict's data text;
a run with synthetic data opens its summary with the demo banner and the paper run's command."""

from __future__ import annotations

import pandas as pd
import pytest

from animsynth.families import FAMILIES, paper_families
from animsynth.report import PAPER_RUN_COMMAND, build_summary, claims_table, demo_banner


def _verdicts(tmp_path, family, data):
    d = tmp_path / family
    d.mkdir()
    p = d / "verdicts.csv"
    pd.DataFrame([{"claim": "c", "paper_value": "1", "ours": "2", "data": data, "verdict": "reproduced",
                   "evidence": "e", "source": f"{family}/verdicts.csv"}]).to_csv(p, index=False)
    return p


def test_synthetic_family_without_the_word_synthetic_is_not_real(tmp_path):
    # the default run's re-sequencing rows read like this: trial ids, no word "synthetic"
    reseq = _verdicts(tmp_path, "resequencing", "walk syn35_01 run syn35_20 dance syn05_02")
    mesh = _verdicts(tmp_path, "meshdetail", "mesh sequence samba")
    claims = claims_table([reseq, mesh], family_real={"resequencing": False, "meshdetail": True})
    assert dict(zip(claims["family"], claims["real"])) == {"meshdetail": True, "resequencing": False}
    # a family without a record is an error, never a guess from the text
    with pytest.raises(ValueError, match="no provenance"):
        claims_table([reseq])


def test_summary_lists_synthetic_claims_apart_and_opens_with_the_demo_banner(tmp_path):
    reseq = _verdicts(tmp_path, "resequencing", "walk syn35_01")
    md = build_summary([], [reseq], "note", family_real={"resequencing": False})
    real, synthetic = md.split("### On real data")[1].split("### On synthetic data")
    assert "(none in this run)" in real and "syn35_01" in synthetic
    assert md.index("demo on synthetic data") < md.index("## Claims")
    assert PAPER_RUN_COMMAND in md


def test_no_banner_when_every_family_ran_on_real_data():
    assert demo_banner({"simplicial": True, "meshdetail": True}) == ""
    assert "meshdetail" in demo_banner({"simplicial": True, "meshdetail": False})


def test_paper_run_with_a_synthetic_family_gets_no_demo_banner(tmp_path):
    # the paper run: real mocap and meshes, the facial study on the synthetic CK+-layout database, demo: false
    paper_map = {f.name: f.data != "faces" for f in FAMILIES if f.name in paper_families()}
    assert not paper_map["facegraph"]  # the premise: one family of the paper run on synthetic data
    assert demo_banner(paper_map, demo=False) == ""
    face = _verdicts(tmp_path, "facegraph", "synthetic CK+-layout database")
    md = build_summary([], [face], "note", family_real=paper_map, demo=False)
    assert "demo" not in md.lower()
    assert "### On synthetic data" in md  # its claims still stand apart from the real-data ones
    # the same map in a demo run (e.g. cmu.yaml alone: facial and mesh studies synthetic, at demo size)
    assert "facegraph" in demo_banner(paper_map, demo=True)


def test_configs_say_which_runs_are_demos():
    import yaml
    from pathlib import Path

    root = Path(__file__).resolve().parents[1] / "config"
    assert yaml.safe_load((root / "config.yaml").read_text())["demo"] is True
    assert yaml.safe_load((root / "paper.yaml").read_text())["demo"] is False
