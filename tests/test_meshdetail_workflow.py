"""meshdetail outputs of the whole workflow on the tiny config."""
import pandas as pd
import pytest


@pytest.mark.workflow
def test_meshdetail_outputs(tiny_workflow):
    r = tiny_workflow / "results" / "meshdetail"
    for name in ("fig5a.png", "fig5b.png", "fig5c.png", "frames.png", "rig_fit.md"):
        assert (r / name).stat().st_size > 0
    a = pd.read_csv(r / "fig5a.csv")
    assert list(a.columns) == ["frame", "split", "full_deformation_mm", "detail_only_mm"]
    c = pd.read_csv(r / "fig5c.csv")
    train = c[c["split"] == "train"]
    assert train["hybrid_mm"].mean() < train["lbs_mm"].mean()
    b = pd.read_csv(r / "fig5b.csv")
    assert list(b["level_pct"]) == [100, 10]
    g = pd.read_csv(r / "generalisation.csv")
    assert g["case"].str.startswith("edited motion").any()
    t = pd.read_csv(r / "timing.csv")
    assert {"train_s_per_100_frames", "recon_fps"} <= set(t.columns)
    rep = pd.read_csv(r / "representations.csv")
    assert len(rep) == 6
