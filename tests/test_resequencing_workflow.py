"""Re-sequencing (issue 4): workflow outputs on the tiny config, and real CMU data checks."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.sparse.csgraph import connected_components
from sklearn.neighbors import kneighbors_graph

from animsynth.io import read_amc, read_asf
from animsynth.resequencing.study import base_distances, method_distances, prepare_motion, with_defaults
from animsynth.resequencing.embedding import min_connected_k
from animsynth.resequencing.features import motion_features


@pytest.mark.workflow
def test_tiny_workflow_resequencing_outputs(tiny_workflow):
    out = tiny_workflow / "results" / "resequencing"
    t2 = pd.read_csv(out / "table2_min_k.csv")
    assert len(t2) == 3 * 2 * 2 * 2
    assert (t2["components_at_min_k"] == 1).all()
    assert (t2.loc[t2["min_k"] > 1, "components_at_min_k_minus_1"] > 1).all()
    assert (t2["min_k"] >= 1).all() and (t2["k_used"] >= t2["min_k"]).all()
    assert (out / "table2_min_k.md").read_text().count("\n|") >= 25
    rv = pd.read_csv(out / "residual_variance.csv")
    assert rv["residual_variance"].between(0, 1).all()
    sm = pd.read_csv(out / "smoothness.csv")
    assert len(sm) == 24 and (sm["paths"] >= 1).all()
    v = pd.read_csv(out / "verdicts.csv")
    claims = set(v["claim"])
    assert "ST-Isomap gives fewer jerks than Isomap" in claims
    assert "global DOF hurt cyclic locomotion but not dance" in claims
    for d in ("walk", "run", "dance"):
        assert (out / "figures" / f"fig3_residual_variance_{d}.png").stat().st_size > 0
        for m in ("isomap", "stisomap"):
            assert (out / "figures" / f"fig2_{d}_{m}.png").stat().st_size > 0
    p = pd.read_csv(out / "paths" / "walk_stisomap_lee_noglobal.csv")
    main = p[p["pair"] == 0]
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
    cfg = with_defaults({})
    f = motion_features(m)
    for metric in ("l2", "lee"):
        for g in (False, True):
            D = base_distances(f, metric, g, cfg["lee"])
            for method in ("isomap", "stisomap"):
                Dm, _ = method_distances(D, method, cfg, m.fps)
                assert min_connected_k(Dm) == _brute_min_k(Dm), (metric, g, method)
    assert np.isfinite(D).all()
