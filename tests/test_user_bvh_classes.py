"""The own-data route on BVH files of every class found in the wild (tests/bvh_classes.py): one config mixes
a centimetre Bandai-style skeleton, a CMU-unit (cgspeed) one, a Bip01 skeleton with 6 channels on every joint
(its roles named on its trials), mixed rotation orders, a rest pose along X and a Z-up file in metres, each
trial with its own unit; simplicial, re-sequencing (a walk, a run and a dance, each of another class) and compare
run on it.

The comparison runs the generators whose code reads the skeleton in its own way (:data:`COMPARE_GENERATORS`): our
motion graph (feet and floor from the joint roles), fairmotion (the skeleton written to BVH and read by fairmotion's
loader), motion matching (foot locking on the roles), GenMM, ST-Isomap (the re-sequencing features: joint
quaternions) and the replay bound. The others read the skeleton only through what these already exercise (isomap:
ST-Isomap's features; Delaunay and k-NN: the DOF values of the simplicial study, which this run fits on every
class; the motion-matching variants: motion matching's code with other weights; concat: clips cut as replay's), and
each job costs its start-up, so they run on the tiny run's synthetic skeleton only. Subsets left null (the shape of
config/user_example.yaml) run through the data layer and Table I, and the whole DAG resolves on them, in
tests/test_user_data.py."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml

from animsynth.synth.mocap import cmu_like_skeleton, generate_motion
from bvh_classes import BIP_ROLES, write_class
from conftest import REPO, copy_workflow, run_snakemake

pytestmark = pytest.mark.workflow

#: the comparison's generators here (module docstring: the ones that read the skeleton in a way of their own)
COMPARE_GENERATORS = ["stisomap", "motion_graph", "fairmotion", "fairmotion_fixed", "motion_matching", "genmm", "replay"]
# (trial id, class, kind, frames, subject seed)
TRIALS = [("ban1", "bandai", "walk_straight", 90), ("ban2", "bandai", "walk_straight", 80),
          ("ban3", "bandai", "walk_straight", 96),
          ("cmu1", "cmu_units", "run_straight", 60), ("cmu2", "cmu_units", "run_straight", 64),
          ("cmu3", "cmu_units", "run_straight", 70),
          ("bip1", "every6", "walk_turn", 84), ("bip2", "every6", "walk_turn", 100), ("bip3", "every6", "walk_turn", 70),
          ("mix1", "mixed", "run_turn", 80), ("mix2", "mixed", "run_turn", 60), ("mix3", "mixed", "run_turn", 70),
          ("lafan", "rest_x", "walk_straight", 120), ("blend", "zup", "run_straight", 100),
          ("dnc", "every6", "dance", 120)]


def _config(data):
    test_cfg = yaml.safe_load((REPO / "config" / "test.yaml").read_text())
    trials = []
    for k, (tid, cls, kind, frames) in enumerate(TRIALS):
        sk = cmu_like_skeleton(cls, 1)
        unit = write_class(generate_motion(kind, frames, k, sk, name=tid), cls, data / f"{tid}.bvh")
        rec = {"id": tid, "subject": cls, "kind": kind, "bvh": f"{tid}.bvh"}
        if cls != "cmu_units":  # the CMU-unit trials take the top-level unit
            rec["bvh_length_to_m"] = unit
        if cls == "every6":
            rec["joint_roles"] = BIP_ROLES
        trials.append(rec)
    return {"mocap_source": "user", "data_dir": str(data), "bvh_length_to_m": 0.05644, "trials": trials,
            "subsets": {"w1": ["ban1", "ban2", "ban3"], "r1": ["cmu1", "cmu2", "cmu3"], "w2": ["bip1", "bip2", "bip3"],
                        "r2": ["mix1", "mix2", "mix3"]},
            "resequencing_trials": {"walk": "lafan", "run": "blend", "dance": "dnc"},
            "simplicial": test_cfg["simplicial"], "resequencing": test_cfg["resequencing"],
            "compare": {**test_cfg["compare"], "subsets": ["w1", "r1"], "resequencing": ["walk", "run"],
                        "generators": COMPARE_GENERATORS}}


def test_every_class_through_simplicial_resequencing_and_compare(tmp_path):
    data = tmp_path / "my_bvh"
    data.mkdir()
    cfg = _config(data)
    wd = copy_workflow(tmp_path / "wf")
    (wd / "config" / "wild.yaml").write_text(yaml.safe_dump(cfg))
    targets = ["results/simplicial/table2.csv", "results/resequencing/smoothness.csv",
               "results/resequencing/table2_min_k.csv", "results/compare/metrics.csv"]
    res = run_snakemake(wd, *targets, "--configfile", "config/wild.yaml")
    assert res.returncode == 0, (res.stdout + res.stderr)[-6000:]
    logs = {p.stem: p.read_text() for p in (wd / "logs" / "data" / "parse_trial").glob("*.log")}
    assert set(logs) == {t[0] for t in TRIALS}
    for tid, text in logs.items():
        assert "WARNING" not in text, (tid, text)  # no false unit (or axis) warning
    assert "up axis +z" in logs["blend"] and "up axis +y" in logs["lafan"]
    assert "Bip01_L_Clavicle" in logs["bip1"] and "merged" in logs["ban1"]
    t2 = pd.read_csv(wd / "results/simplicial/table2.csv")
    assert np.isfinite(t2[["w1", "w2", "r1", "r2", "all"]].to_numpy(float)).all()
    sm = pd.read_csv(wd / "results/resequencing/smoothness.csv")
    assert set(sm["dataset"]) == {"walk", "run", "dance"}
    # the user's own walk, run and dance are not the paper's CMU clips: its min k is not shown beside them
    k = pd.read_csv(wd / "results/resequencing/table2_min_k.csv")
    assert len(k) and k["min_k_paper"].isna().all() and k["min_k"].notna().all()
    assert "not the paper's CMU trial" in (wd / "results/resequencing/table2_min_k.md").read_text()
    m = pd.read_csv(wd / "results/compare/metrics.csv")
    held_out = {c.split("@", 1)[0] for c in m["clip"]}  # a clip is a window <group>/<trial>@<first frame>
    assert {"w1/ban1", "r1/cmu1", "walk/lafan", "run/blend"} <= held_out
    assert set(m["generator"]) == set(COMPARE_GENERATORS)
    ran = m.groupby("generator")["velocity_jump_p95"].apply(lambda v: np.isfinite(v.to_numpy(float)).any())
    assert ran.all(), ran[~ran]  # every generator made motions on these skeletons
    rep = m[m["generator"] == "replay"]
    assert (rep["l2p"] == 0).all()
    assert np.isfinite(m.loc[m["generator"] != "replay", "l2p"].to_numpy(float)).any()


def test_a_bad_file_is_named_by_the_users_path(tmp_path):
    data = tmp_path / "my_bvh"
    data.mkdir()
    cfg = _config(data)
    bad = data / "ban2.bvh"
    bad.write_text(bad.read_text().replace("CHANNELS 3", "CHANNELS 3 Xrotation Xrotation Xrotation", 1))
    wd = copy_workflow(tmp_path / "wf")
    (wd / "config" / "wild.yaml").write_text(yaml.safe_dump(cfg))
    res = run_snakemake(wd, "results/data/trials/ban2.npz", "--configfile", "config/wild.yaml")
    assert res.returncode != 0
    text = (wd / "logs" / "data" / "parse_trial" / "ban2.log").read_text()
    assert f"{bad}:" in text and "resources/mocap" not in text and "Traceback" not in text
