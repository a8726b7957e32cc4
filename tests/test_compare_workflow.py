"""compare outputs of the whole workflow on the tiny config."""
import pandas as pd
import pytest

from animsynth.compare.jobs import KEY_COLUMNS, METRIC_NAMES
from animsynth.verdicts import VOCABULARY


@pytest.mark.workflow
def test_compare_outputs(tiny_workflow):
    from animsynth.io.bvh import read_bvh

    r = tiny_workflow / "results" / "compare"
    clips = pd.read_csv(r / "clips.csv")
    assert set(clips["protocol"]) == {"leave one out", "temporal split"}
    m = pd.read_csv(r / "metrics.csv")
    assert list(m.columns) == KEY_COLUMNS + METRIC_NAMES + ["note"]
    gens = list(dict.fromkeys(m["generator"]))
    assert {"delaunay", "knn", "isomap", "stisomap", "motion_graph", "motion_matching", "motion_matching_pose", "genmm",
            "replay", "concat"} <= set(gens)
    modern = m[m["generator"].isin(["motion_matching", "motion_matching_pose", "genmm"])]
    assert not modern["note"].astype(str).str.startswith("not built").any()  # built on every tiny clip
    mm = modern[modern["generator"] != "genmm"]
    assert (mm["seed_diversity_m"] == 0).all()  # deterministic rows
    assert len(m) == len(clips) * len(gens) * m["seed"].nunique() and m["seed"].nunique() == 2
    rep = m[m["generator"] == "replay"]
    assert (rep["l2p"] == 0).all() and (rep["n_seams"] == 0).all()
    s = pd.read_csv(r / "summary.csv")
    assert {"median", "q25", "q75", "p05", "p95"} <= set(s.columns)
    cost = pd.read_csv(r / "cost_timing.csv")
    assert list(cost["generator"]) == gens and (cost["build_cpu_s_total"] >= 0).all()
    v = pd.read_csv(r / "verdicts.csv")
    assert list(v.columns) == ["claim", "paper_value", "ours", "data", "verdict", "evidence", "source"]
    assert set(v["verdict"]) <= set(VOCABULARY) and len(v) >= 5
    decided = v.set_index("claim")["verdict"]
    for claim in ("motion matching skates less than the motion graph",
                  "GenMM covers more of the database than the motion graph"):
        assert decided[claim] != "not reproduced", claim  # both rows ran: the claim is decided
    for g in gens:
        back = read_bvh(r / "bvh" / f"{g}.bvh")
        assert back.n_frames > 0
    assert {"velocity_jump_p95", "velocity_jump_over_capture", "skating_ratio_gmd", "l2p_m"} <= set(m.columns)
    sanity = pd.read_csv(r / "sanity_checks.csv")
    assert list(sanity.columns) == list(v.columns) and set(sanity["verdict"]) <= set(VOCABULARY)
    assert not set(sanity["claim"]) & set(v["claim"])  # true by construction: not among the findings
    assert (v["evidence"].str.contains("Holm") | (v["verdict"] == "not reproduced")).all()
    sens = pd.read_csv(r / "skating_sensitivity.csv")
    assert set(sens["speed_m_s"]) == {0.15, 0.3, 0.5}
    for png in ("metrics.png", "strips.png"):
        assert (r / png).stat().st_size > 0
    md = (r / "summary.md").read_text()
    assert md.startswith("# The generators side by side") and "## Verdicts" in md
    summary = (tiny_workflow / "results" / "summary.md").read_text()
    assert "## The generators side by side" in summary and "### Which generator wins which metric" in summary
    claims = pd.read_csv(tiny_workflow / "results" / "claims.csv")
    ours = claims[claims["paper"] == "Beyond the papers: generators side by side"]
    assert len(ours) == len(v) + len(sanity)  # the findings, then the sanity checks marked as such
    assert ours["sanity_check"].astype(bool).sum() == len(sanity)
    assert "The generators side by side" in (tiny_workflow / "results" / "claims.rst").read_text()
