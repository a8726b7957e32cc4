"""meshdetail outputs of the whole workflow on the tiny config."""
import pandas as pd
import pytest

from animsynth.verdicts import VOCABULARY


@pytest.mark.workflow
def test_meshdetail_outputs(tiny_workflow):
    r = tiny_workflow / "results" / "meshdetail" / "character"  # one folder per sequence
    for name in ("fig5a.png", "fig5b.png", "fig5c.png", "frames.png", "error_map.png", "rig_fit.md"):
        assert (r / name).stat().st_size > 0
    a = pd.read_csv(r / "fig5a.csv")
    assert list(a.columns) == ["frame", "split", "full_deformation_mm", "detail_only_mm"]
    c = pd.read_csv(r / "fig5c.csv")
    assert {"lbs_mm", "hybrid_mm", "gp_regression_mm", "ridge_cv_mm", "block"} <= set(c.columns)
    assert c["block"].nunique() == 5
    b = pd.read_csv(r / "fig5b.csv")
    assert list(b["level_pct"]) == [100, 10, 10]
    assert list(b["decimation"]) == ["full mesh", "edge collapse (replayed)", "farthest-point subset"]
    g = pd.read_csv(r / "generalisation.csv").set_index("case")
    assert g.index.str.startswith("edited motion").any()
    tr = g.loc["training frames (in-fold fit)"]
    assert tr["hybrid_mm"] < tr["lbs_mm"]
    assert {"hybrid_fold_sd_mm", "ridge_cv_fold_sd_mm", "gp_regression_fold_sd_mm"} <= set(g.columns)
    t = pd.read_csv(r / "fig5b_timing.csv")
    assert {"train_wall_s_per_100_frames", "train_cpu_s_per_100_frames", "recon_fps"} <= set(t.columns)
    assert not any(col.startswith("meets_") for col in t.columns)
    v = pd.read_csv(r / "verdicts.csv")
    assert list(v.columns) == ["claim", "paper_value", "ours", "data", "verdict", "evidence", "source"]
    assert set(v["verdict"]) <= set(VOCABULARY)
    j = pd.read_csv(r / "joints.csv")
    assert len(j) == 18
    rep = pd.read_csv(r / "representations.csv")
    assert len(rep) == 6
    d = pd.read_csv(r / "dembones.csv")
    assert set(d["fold"]) == set(range(5)) and (d["heldout_mm"] > 0).all()
    side = pd.read_csv(r.parent / "sequences.csv").set_index("method")
    assert {"character_mm", "character_fold_sd_mm"} <= set(side.columns)
    assert side.index.str.startswith("Dem Bones LBS floor").any()
    top = pd.read_csv(r.parent / "verdicts.csv")
    assert top["claim"].str.startswith("[all sequences]").sum() == len(v)
