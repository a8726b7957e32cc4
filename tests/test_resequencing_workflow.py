"""Re-sequencing: workflow outputs on the tiny config, and real CMU data checks."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.sparse.csgraph import connected_components
from sklearn.neighbors import kneighbors_graph

from animsynth.io import read_amc, read_asf
from animsynth.resequencing.jobs import base_distances, method_distances, prepare_motion
from animsynth.resequencing.settings import method_params
from animsynth.resequencing.embedding import min_connected_k
from animsynth.resequencing.features import motion_features
from animsynth.verdicts import VOCABULARY
from conftest import config_block


@pytest.mark.workflow
def test_tiny_workflow_resequencing_outputs(tiny_workflow):
    out = tiny_workflow / "results" / "resequencing"
    t2 = pd.read_csv(out / "table2_min_k.csv")
    assert len(t2) == 3 * 2 * 2 * 2 * 2  # dataset x global x sign mode x method x metric
    assert set(t2["sign_mode"]) == {"continuous", "matrix_naive"}
    assert (t2["components_at_min_k"] == 1).all()
    assert (t2.loc[t2["min_k"] > 1, "components_at_min_k_minus_1"] > 1).all()
    assert (t2.loc[t2["method"] == "stisomap", "min_k"] == 1).all()  # adjacent temporal neighbours: one chain
    # the Lee metric is sign-invariant: same min k in both sign modes
    lee = t2[t2["metric"] == "lee"].pivot_table(index=["dataset", "global_dof", "method"], columns="sign_mode",
                                                values="min_k")
    assert (lee["continuous"] == lee["matrix_naive"]).all()
    grid = pd.read_csv(out / "min_k_explanations.csv")
    assert set(grid["frame_step"]) == {1, 4} and len(grid) == 2 * len(t2)
    flips = pd.read_csv(out / "sign_flips.csv")
    assert (flips["flips_continuous"] == 0).all()
    rv = pd.read_csv(out / "residual_variance.csv")
    assert rv["residual_variance"].between(0, 1).all() and set(rv["k_mode"]) <= {"min_k", "fixed"}
    mk = rv[rv["k_mode"] == "min_k"].merge(t2[t2["sign_mode"] == "continuous"],
                                           on=["dataset", "global_dof", "method", "metric"])
    assert (mk["k"] == mk["min_k"]).all()  # the reproduction uses each configuration's min k
    sm = pd.read_csv(out / "smoothness.csv")
    assert len(sm) == 24 and (sm["paths"] == 3).all()
    paths = pd.read_csv(out / "smoothness_paths.csv")
    assert (paths["end"] < paths["start"]).all()  # pairs chosen so the path must leave the original order
    assert set(paths["path_class"]) <= {"replays", "replays_backwards", "skips", "resequences"}
    tr = pd.read_csv(out / "smoothness_transitions.csv")
    assert len(tr) == paths["transitions"].sum()
    v = pd.read_csv(out / "verdicts.csv")
    assert list(v.columns) == ["claim", "paper_value", "ours", "data", "verdict", "evidence", "source"]
    assert set(v["verdict"]) <= set(VOCABULARY)
    claims = " ".join(v["claim"])
    for text in ("ST-Isomap re-sequences more smoothly", "global DOF", "Lee metric needs far fewer",
                 "which candidate explanation"):
        assert text in claims
    for d in ("walk", "run", "dance"):
        assert (out / "figures" / f"fig3_residual_variance_{d}.png").stat().st_size > 0
        for m in ("isomap", "stisomap"):
            assert (out / "figures" / f"fig2_{d}_{m}.png").stat().st_size > 0
    p = pd.read_csv(out / "paths" / "walk_stisomap_lee_noglobal.csv")
    main = p[p["pair"] == "main"]
    assert main["step"].tolist() == list(range(len(main)))
    assert (out / "paths" / "walk_stisomap_lee_noglobal.bvh").read_text().startswith("HIERARCHY")
    assert (out / "paths" / "walk_stisomap_lee_noglobal.gif").read_bytes()[:3] == b"GIF"


def _brute_min_k(D):
    for k in range(1, D.shape[0]):
        if connected_components(kneighbors_graph(D, k, metric="precomputed"), directed=False)[0] == 1:
            return k


@pytest.mark.realdata
@pytest.mark.parametrize("trial", ["35/35_01", "05/05_02"])
def test_exact_min_k_on_real_cmu_trials(cmu_dir, trial):
    subject, name = trial.split("/")
    m = read_amc(cmu_dir / subject / f"{name}.amc", read_asf(cmu_dir / subject / f"{subject}.asf"))
    m = prepare_motion(m, 400, 2)
    cfg = config_block("resequencing", files=("config.yaml", "cmu.yaml"))
    f = motion_features(m)
    for metric in ("l2", "lee"):
        for g in (False, True):
            D = base_distances(f, metric, g, method_params(cfg))
            Dm, _, _ = method_distances(D, "isomap", method_params(cfg), m.fps)
            assert min_connected_k(Dm) == _brute_min_k(Dm), (metric, g)
    assert np.isfinite(D).all()


@pytest.mark.realdata
def test_matrix_naive_flips_the_humerus_and_raises_l2_min_k_on_cmu_walk(cmu_dir):
    m = read_amc(cmu_dir / "35" / "35_01.amc", read_asf(cmu_dir / "35" / "35.asf"))
    cfg = config_block("resequencing", {"metrics": ["l2"], "explanations": {"frame_steps": [1], "global_dof": [False]}},
                       ("config.yaml", "cmu.yaml"))
    from animsynth.resequencing.jobs import explain

    grid, flips = explain(m, "walk", "35_01", cfg)
    f = flips.set_index("joint")["flips_matrix_naive"]
    assert f["lhumerus"] > 0 and f.drop("lhumerus").sum() == 0
    g = grid[grid["method"] == "isomap"].set_index("sign_mode")["min_k"]
    assert g["continuous"] < 10 <= g["matrix_naive"]


@pytest.mark.workflow
def test_paper_columns_with_and_without_the_published_tables(tiny_workflow, tiny_without_papers):
    """Table 2 and the Lee weights read the published tables as declared inputs: beside the tiny run (made-up
    values in their layout) the paper columns hold numbers; without them they are empty, with a WARNING naming
    the config key, and our columns do not change."""
    rel = "results/resequencing/table2_min_k.csv"
    with_papers, without = pd.read_csv(tiny_workflow / rel), pd.read_csv(tiny_without_papers / rel)
    paper_cols = ["min_k_paper", "paper_frames", "min_k_minus_paper", "frames_minus_paper"]
    assert with_papers["min_k_paper"].notna().any() and with_papers["min_k_minus_paper"].notna().any()
    assert without[paper_cols].isna().all().all()
    ours = [c for c in with_papers.columns if c not in paper_cols]
    pd.testing.assert_frame_equal(with_papers[ours], without[ours])
    lee = "results/resequencing/lee_weights.csv"
    assert pd.read_csv(tiny_workflow / lee)["weight_paper"].notna().all()
    assert pd.read_csv(tiny_without_papers / lee).empty
    log = (tiny_without_papers / "logs" / "resequencing" / "tables.log").read_text()
    for key in ("published.resequencing.table2", "published.resequencing.lee_weights"):
        assert any("WARNING" in line and key in line for line in log.splitlines()), log
