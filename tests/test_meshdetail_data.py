"""meshdetail data layer: CMU motion mapping, the synthetic character pipeline, real samba frames."""
from pathlib import Path

import numpy as np
import pytest
import yaml

from animsynth.io.obj import read_obj_sequence
from animsynth.kinematics import forward_kinematics
from animsynth.meshdetail.rigfit import fit_skeleton, rig_from_joints
from animsynth.skinning import JOINTS, cmu_motion_to_rig, forward

REPO = Path(__file__).resolve().parents[1]


def test_cmu_mapping_keeps_spine_and_leg_joints():
    from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

    sk = cmu_like_skeleton("t", 1)
    m = generate_motion("dance", 30, 2, sk)
    rig, rt, A = cmu_motion_to_rig(m)
    _, S = forward(rig, rt, A)
    cmu = forward_kinematics(sk, m.values, ends=False) * sk.length_to_m
    for name, bone in (("l_thigh", "lfemur"), ("l_shin", "ltibia"), ("r_foot", "rfoot"), ("spine1", "upperback")):
        np.testing.assert_allclose(S[:, JOINTS.index(name)], cmu[:, sk.index(bone)], atol=1e-9)


def test_character_pipeline_writes_obj_and_truth(tmp_path):
    from animsynth.meshdetail.jobs import fit_pose, load_prepared, load_sequences, make_character

    cfg = dict(driver="procedural", motion="walk", frames=24, fps=30, asf=None, amc=None, edits=["lean_15deg"],
               resolution=0.4, skirt_rings=5, skirt_around=12, hem_frequency=1.1, damping=2.5, substeps=2)
    make_character(cfg, 3, str(tmp_path / "ch"))
    assert len(list((tmp_path / "ch" / "main").glob("mesh_*.obj.gz"))) == 24
    seq = load_sequences(str(tmp_path / "ch" / "main"), str(tmp_path / "ch" / "truth.npz"),
                         str(tmp_path / "seq.npz"), str(tmp_path / "edits.npz"), 30.0)
    rig_cfg = dict(joints=None, ends={}, refine=True, weight_power=4.0, max_influences=4, fit_iterations=4,
                   skinning="distance", heat_c=1.0, compare_skinning=False)
    table, joints, comparison, method = fit_pose(str(tmp_path / "seq.npz"), str(tmp_path / "ch" / "truth.npz"),
                                                 rig_cfg, 0.75, str(tmp_path / "pose.npz"))
    body = table[(table["part"] == "[body]")].set_index("split")["mean_mm"]
    assert "ground-truth" in method and comparison is None
    assert body["train"] < 3.0 and body["held-out"] < 3.0  # the generator's own skin: the skeleton explains the body
    assert joints["rotation_error_mean_deg"].iloc[1:].mean() < 2.0
    assert set(table["split"]) == {"train", "held-out"} and (table["part"] == "l_shin").sum() == 2
    d = load_prepared(str(tmp_path / "seq.npz"), str(tmp_path / "pose.npz"), str(tmp_path / "edits.npz"), 0.75)
    assert d.frames.shape == (24, seq.n_vertices, 3) and list(d.edits) == ["lean_15deg"]
    assert len(d.train) == 18 and len(d.test) == 6


def test_real_data_needs_an_embedding(tmp_path):
    from animsynth.io.obj import MeshSequence
    from animsynth.meshdetail.jobs import fit_pose

    MeshSequence(np.zeros((20, 3, 3)), np.array([[0, 1, 2]])).save_npz(tmp_path / "s.npz")
    with pytest.raises(ValueError, match="meshdetail.rig.joints"):
        fit_pose(str(tmp_path / "s.npz"), None, dict(joints=None), 0.8, str(tmp_path / "p.npz"))
    with pytest.raises(ValueError, match="misses"):
        rig_from_joints({"hips": [0, 0, 0]})


@pytest.mark.realdata
def test_samba_skeleton_fits_the_whole_sequence(vlasic_dir):
    """Default skinning on the whole samba sequence: joints inside the first-frame mesh, held-out LBS <= 17 mm.

    Every second frame (88 of 175, still the whole dance, the last 20 % held out): about a third of the
    full fit's cost (measured residuals: train 12.9 mm, held-out 14.0 mm, max 18.2 mm)."""
    seq = read_obj_sequence(vlasic_dir / "samba")
    assert seq.vertices.shape == (175, 9971, 3) and seq.faces.shape == (19938, 3)
    cfg = yaml.safe_load((REPO / "config" / "samba.yaml").read_text())["meshdetail"]
    rig = rig_from_joints(cfg["rig"]["joints"], cfg["rig"]["ends"])
    frames = seq.vertices[::2]
    train = np.arange(int(round(0.8 * len(frames))))
    rig, w, fit, joints, _ = fit_skeleton(frames, seq.faces, rig, train, skinning="heat+refit", refine=True)
    assert bool(joints["inside"].all()), joints.to_string()
    assert fit.residual_[train].mean() < 0.016
    assert fit.residual_[len(train):].mean() < 0.017
    assert fit.residual_.max() < 0.03 and np.all(np.isfinite(fit.angles_))


def _validated(**top):
    from animsynth.config import validate_config

    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    cfg.update(top)
    validate_config(cfg, str(REPO / "config" / "schema.yaml"))
    return cfg


def test_config_checks_name_the_key():
    import copy

    from animsynth.config import ConfigError
    from animsynth.meshdetail.settings import check

    base = _validated()
    check(base)

    def with_md(**md):
        cfg = copy.deepcopy(base)
        cfg["meshdetail"].update(md)
        return cfg

    # the synthetic character: frames for training and for the blocked cross-validation, its driver
    with pytest.raises(ConfigError, match="meshdetail.cv_folds"):
        check(with_md(cv_folds=100))
    with pytest.raises(ConfigError, match="meshdetail.train_fraction"):
        check(with_md(train_fraction=0.05))
    with pytest.raises(ConfigError, match="meshdetail.levels"):
        check(with_md(levels=[50, 5, 50]))
    with pytest.raises(ConfigError, match=r"meshdetail.character.fps': must divide 120"):
        check(with_md(character={**base["meshdetail"]["character"], "fps": 25}))
    with pytest.raises(ConfigError, match=r"meshdetail.character.asf' and 'meshdetail.character.amc'"):
        check(with_md(character={**base["meshdetail"]["character"], "driver": "amc"}))
    # real meshes: the 18-joint embedding, checked for every sequence with the sequence's key
    samba = yaml.safe_load((REPO / "config" / "samba.yaml").read_text())["meshdetail"]["rig"]
    joints = dict(samba["joints"])
    real = _validated(mesh_dir="../data/samba")
    real["meshdetail"]["rig"]["joints"] = joints
    check(real)
    short = dict(joints)
    short.pop("l_shin")
    real["meshdetail"]["rig"]["joints"] = short
    with pytest.raises(ConfigError, match=r"meshdetail.rig.joints' misses \['l_shin'\]"):
        check(real)
    real["meshdetail"]["rig"]["joints"] = joints
    real["meshdetail"]["sequences"] = {"crane": {"mesh_dir": "../data/crane", "rig": {"joints": short}}}
    with pytest.raises(ConfigError, match=r"meshdetail.sequences.crane.rig.joints' misses \['l_shin'\]"):
        check(real)
    real["meshdetail"]["sequences"] = {"crane": {"mesh_dir": "../data/crane", "rig": {"joints": joints, "skining": "heat"}}}
    with pytest.raises(ConfigError, match=r"meshdetail.sequences.crane.rig': unknown key\(s\) \['skining'\]"):
        check(real)


def test_fold_rig_fitter_sees_only_the_fold_training_frames(tmp_path):
    import yaml

    from animsynth.meshdetail.evaluation import run_main
    from animsynth.meshdetail.jobs import fit_pose, fold_rig_fitter, load_prepared, load_sequences, make_character
    from animsynth.io.obj import MeshSequence

    cfg = dict(driver="procedural", motion="walk", frames=24, fps=30, asf=None, amc=None, edits=[],
               resolution=0.4, skirt_rings=5, skirt_around=12, hem_frequency=1.1, damping=2.5, substeps=2)
    make_character(cfg, 3, str(tmp_path / "ch"))
    truth = str(tmp_path / "ch" / "truth.npz")
    load_sequences(str(tmp_path / "ch" / "main"), truth, str(tmp_path / "seq.npz"), str(tmp_path / "edits.npz"), 30.0)
    rig_cfg = dict(joints=None, ends={}, refine=True, weight_power=4.0, max_influences=4, fit_iterations=4,
                   skinning="heat+refit", heat_c=1.0, compare_skinning=False)
    fit_pose(str(tmp_path / "seq.npz"), truth, rig_cfg, 0.75, str(tmp_path / "pose.npz"))
    d = load_prepared(str(tmp_path / "seq.npz"), str(tmp_path / "pose.npz"), str(tmp_path / "edits.npz"), 0.75)
    refit = fold_rig_fitter(str(tmp_path / "seq.npz"), truth, rig_cfg)
    _, w, _, ang = refit(d.train)
    # the same training frames give the same skeleton step as the shared fit
    np.testing.assert_allclose(w.toarray(), d.weights.toarray(), atol=1e-10)
    np.testing.assert_allclose(ang, d.angles, atol=1e-8)
    # wreck a frame outside the fold's training frames: that fold's weights do not move, others' do
    seq = MeshSequence.load_npz(str(tmp_path / "seq.npz"))
    seq.vertices[5] += np.random.default_rng(0).normal(0, 0.05, seq.vertices[5].shape)
    seq.save_npz(str(tmp_path / "bad.npz"))
    bad = fold_rig_fitter(str(tmp_path / "bad.npz"), truth, rig_cfg)
    tr = np.setdiff1d(np.arange(24), np.arange(0, 8))
    np.testing.assert_allclose(bad(tr)[1].toarray(), refit(tr)[1].toarray(), atol=1e-10)
    assert np.abs(bad(d.train)[1].toarray() - w.toarray()).max() > 1e-3
    # run_main refits per fold on exactly the other blocks
    seen = []

    def spy(train):
        seen.append(np.asarray(train).copy())
        return refit(train)

    md = yaml.safe_load(open("config/config.yaml"))["meshdetail"]
    mcfg = {k: md[k] for k in ("level", "latent_dim", "dynamics_weight", "ridge_alphas", "joint_param", "detail",
                               "decimation", "rbf_neighbors")}
    mcfg.update(iterations=3, cv_folds=3, level=25)
    _, fig5c, gen, _ = run_main(d, mcfg, refit_rig=spy)
    blocks = np.array_split(np.arange(24), 3)
    assert [list(s) for s in seen] == [list(np.setdiff1d(np.arange(24), b)) for b in blocks]
    assert np.isfinite(fig5c["lbs_mm"]).all() and len(gen) == 2
