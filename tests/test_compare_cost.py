"""The cost guard of the compare family (compare.cost_guard, animsynth.compare.cost): an estimate before each build,
growing as each generator's method does; a warning line above the warning level, the clip not run (its rows empty,
the key named) above the limit, and nothing at all below."""

from __future__ import annotations

import logging

import pandas as pd
import pytest

from animsynth.compare import cost, jobs, protocol, runner, settings
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

from conftest import default_config


@pytest.fixture(scope="module")
def clips_file(tmp_path_factory):
    """Three short synthetic walks, leave one out (3 databases, windows of 20 frames), 12 generated frames at 30 fps."""
    sk = cmu_like_skeleton("cmp", 3)
    walks = {f"t{s}": protocol.resample(generate_motion("walk_straight", 200, s, sk, name=f"t{s}"), 30.0) for s in range(3)}
    cfg = default_config()["compare"]
    cc = {k: cfg[k] for k in settings.CLIP_KEYS}
    path = tmp_path_factory.mktemp("cost_clips") / "clips.npz"
    protocol.save_clips(path, protocol.prepare_clips(walks, {"w1": ["t0", "t1", "t2"]}, {}, dict(cc, length=12)))
    return path


def _cfg(**guard) -> dict:
    cfg = dict(settings.job_cfg(default_config()), seeds=2)
    cfg["cost_guard"] = dict(cfg["cost_guard"], **guard)
    return cfg


def _run(tmp_path, generator, cfg, clips_file):
    out = {k: str(tmp_path / f"{generator}_{k}{ext}") for k, ext in
           (("metrics", ".csv"), ("timing", "_timing.csv"), ("shown", ".npz"), ("bvh", ".bvh"))}
    jobs.run_job(clips_file, generator, cfg, 7, None, ("w1/t1", 1), out)
    return out


def test_the_estimate_grows_as_each_method_does():
    cfg = settings.job_cfg(default_config())
    e = lambda g, n, **kw: cost.estimate_cpu_s(g, n, cfg, **kw)  # noqa: E731
    for g in ("motion_graph", "isomap", "stisomap"):
        assert e(g, 2000) == pytest.approx(4 * e(g, 1000))  # O(frames^2)
    for g in ("delaunay", "knn", "motion_matching", "motion_matching_pose", "replay", "concat"):
        assert e(g, 2000) == pytest.approx(2 * e(g, 1000))  # O(frames)
    # GenMM: the patch search over the database for every generated frame of every seed
    assert e("genmm", 1000, length=120, seeds=5) - e("genmm", 1000) == pytest.approx(
        2 * (e("genmm", 1000, length=60, seeds=5) - e("genmm", 1000)))
    # fairmotion at its native 60 fps: twice the working frames; its estimate counts its operations
    assert cost.model_frames("fairmotion", 1000, cfg) == 2000 and cost.model_frames("knn", 1000, cfg) == 1000
    ops = cost.fairmotion_ops(1000, cfg, 60, 5)
    c = cost.FAIRMOTION_CPU_S
    assert e("fairmotion", 1000, length=60, seeds=5) == pytest.approx(
        c["load_frame"] * 2000 + c["comparison"] * ops["comparisons"] + c["generated_frame"] * 600)
    assert e("mine", 1000) is None  # a user generator: no model, no guard


def _fm(cfg, **block):
    return dict(cfg, fairmotion=dict(cfg["fairmotion"], **block))


def test_the_fairmotion_estimate_reads_the_peers_settings():
    """Nodes every stride frames (base 15 at 30 fps: 30 native frames), compared pairwise at num_comparison
    frames: a finer stride or more comparisons cost what they cost, and the loading grows with the frames."""
    cfg = settings.job_cfg(default_config())
    ops = cost.fairmotion_ops(2146, cfg)
    # 4292 native frames, a node every 30 leaving 30 + 20 + 1 after it: 142 nodes; 3 compared frames per pair
    assert (ops["load_frames"], ops["nodes"], ops["per_pair"], ops["comparisons"]) == (4292, 142, 3, 142 * 142 * 3)
    finer = cost.fairmotion_ops(2146, _fm(cfg, stride=5))  # a node every 10 native frames: three times the nodes
    assert finer["nodes"] == 425 and finer["comparisons"] == 425 ** 2 * 3
    more = cost.fairmotion_ops(2146, _fm(cfg, num_comparison=6))  # every 3rd of the 21 compared frames: 7
    assert more["per_pair"] == 7
    longer = cost.fairmotion_ops(2146, _fm(cfg, base=30, compare=20))  # nodes of 60 frames, 41 compared frames
    assert (longer["nodes"], longer["per_pair"]) == (70, 4)
    # a stride of 8 native frames does not divide the base's 30: fairmotion lowers it to 6 (a clip's nodes joined)
    assert cost.fairmotion_ops(2146, _fm(cfg, stride=4))["nodes"] == 707  # ceil((4292 - 30 - 20 - 1) / 6)
    # per clip: a clip too short for one node adds none; one number is the clips taken as one (an upper bound)
    assert cost.fairmotion_ops([20, 40, 100], cfg)["nodes"] == 0 + 1 + 5
    assert cost.fairmotion_ops(160, cfg)["nodes"] >= cost.fairmotion_ops([20, 40, 100], cfg)["nodes"]
    est = lambda c: cost.estimate_cpu_s("fairmotion", 2146, c, 60, 5)  # noqa: E731
    assert est(_fm(cfg, stride=5)) > 8 * est(cfg) / 2 and est(_fm(cfg, base=30, compare=20)) < est(cfg)


@pytest.mark.skipif(settings.unavailable("fairmotion") != "", reason="fairmotion is not installed")
@pytest.mark.parametrize("block", [{}, {"stride": 5, "num_comparison": 5}])
def test_the_comparisons_fairmotion_makes_are_the_ones_counted(block):
    """The operation count of the estimate is fairmotion's own: every pose comparison its ``construct`` makes
    on a small database is counted (wrapped), and equals :func:`fairmotion_ops`'s."""
    import fairmotion.tasks.motion_graph.motion_graph as mg

    from animsynth.compare.generators.fairmotion_peer import FairmotionGraph

    cfg = _fm(settings.job_cfg(default_config()), **block)
    sk = cmu_like_skeleton("ops", 4)
    clips = [protocol.resample(generate_motion("walk_straight", 4 * n, 11 + n, sk, name=f"o{n}"), 30.0)
             for n in (40, 50)]
    calls = []
    real = mg.similarity.pose_similarity

    def counted(*a, **k):
        calls.append(1)
        return real(*a, **k)

    mg.similarity.pose_similarity = counted
    try:
        FairmotionGraph(**cfg["fairmotion"], transitions_per_s=cfg["transitions_per_s"]).fit(clips)
    finally:
        mg.similarity.pose_similarity = real
    assert len(calls) == cost.fairmotion_ops([c.n_frames for c in clips], cfg)["comparisons"] > 0


def test_the_paper_run_passes_and_a_large_lafan1_database_is_warned():
    cfg = settings.job_cfg(default_config())
    # the paper run's largest database: 339 frames at 30 fps (60 frames, 5 seeds)
    for g in cost.COST_MODELS:
        assert cost.guard(g, "w1/35_16", 339, cfg, 60, 5) == ("", ""), g
    level, line = cost.guard("fairmotion", "lafan/walk1", 2146, cfg, 60, 5)
    assert level == "warn" and "fairmotion on lafan/walk1: database of 2146 frames (4292 at its native rate)" in line
    assert "compare.cost_guard.warn_cpu_s (60 s)" in line


def test_a_database_over_the_limit_is_not_run_and_names_the_key(tmp_path, clips_file, capsys):
    out = _run(tmp_path, "concat", _cfg(max_cpu_s=1e-9), clips_file)
    err = [x for x in capsys.readouterr().err.splitlines() if x.strip()]
    assert len(err) == 3 and all("above compare.cost_guard.max_cpu_s (1e-09 s): not run" in x for x in err)
    assert "concat on w1/t0: database of" in err[0]
    m = pd.read_csv(out["metrics"])  # one refusal per database (held-out trial), every clip of it empty
    assert len(m) == 2 * m["clip"].nunique() and m["clip"].nunique() >= 3 and m["skate_share"].isna().all()
    assert m["note"].str.startswith("not run: concat on w1/").all()
    assert m["note"].str.contains("compare.cost_guard.max_cpu_s").all()
    shown = runner.load_shown(out["shown"])  # the job completes: the showcase is the start alone
    assert shown.n_frames == shown.meta["context"] and shown.meta["note"].startswith("not run: ")


def test_above_the_warning_level_one_line_per_clip_and_the_clip_runs(tmp_path, clips_file, caplog):
    with caplog.at_level(logging.WARNING, logger="animsynth"):
        out = _run(tmp_path, "concat", _cfg(warn_cpu_s=1e-9), clips_file)
    lines = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(lines) == 3 and all("above compare.cost_guard.warn_cpu_s" in x for x in lines)
    assert pd.read_csv(out["metrics"])["note"].isna().all()


def test_below_the_warning_level_nothing_is_printed(tmp_path, clips_file, capsys, caplog):
    with caplog.at_level(logging.WARNING, logger="animsynth"):
        out = _run(tmp_path, "concat", _cfg(), clips_file)
    assert capsys.readouterr().err.strip() == ""
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]
    assert pd.read_csv(out["metrics"])["note"].isna().all()


def test_every_generator_of_the_family_has_a_cost_model():
    """A row added to the registry without a model would run unguarded (only user generators have none)."""
    from animsynth.compare.generators.names import GENERATORS

    assert set(GENERATORS) <= set(cost.COST_MODELS), sorted(set(GENERATORS) - set(cost.COST_MODELS))


_FIRST_USE = r"""
import json, sys

from animsynth.compare import protocol
from animsynth.compare.generators.registry import make_generator
from animsynth.motion import Motion
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

cfg, name = json.load(sys.stdin), sys.argv[1]
sk = cmu_like_skeleton("cmp", 3)
db = [protocol.resample(generate_motion("walk_straight", 200, s, sk, name=f"t{s}"), 30.0) for s in range(3)]
gen = make_generator(name, cfg)
warm = set(sys.modules)


def compiled():  # each numba kernel of ours and its compiled signatures
    return {f"{m}.{a}": len(f.signatures) for m, mod in list(sys.modules.items()) if m.startswith("animsynth")
            for a, f in vars(mod).items() if hasattr(f, "signatures") and hasattr(f, "py_func")}


gen.warm_up()
before, kernels = set(sys.modules), compiled()
gen.fit(db[:2])
gen.generate(Motion(db[2].values[:8], sk, 30.0, "start"), 12, 0)
heavy = ("animsynth", "sklearn", "scipy", "numba", "networkx", "fairmotion")
new = lambda mods: sorted(m for m in mods if m.split(".")[0] in heavy)
print(json.dumps({"warm_up": new(before - warm), "after": new(set(sys.modules) - before),
                  "kernels": [k for k, n in compiled().items() if n != kernels.get(k, 0)], "loaded": kernels}))
"""


def test_a_build_imports_nothing_after_the_generators_warm_up():
    """Rows of one method share a job's process, so a build is timed after the generator's warm_up: in a fresh
    interpreter, fit and generate of the rows that share method jobs (both field followers, both re-sequencers,
    motion matching) import no module warm_up did not, and compile or load no numba kernel it did not (the field
    follower's warm_up loads its path kernel)."""
    import json
    import subprocess
    import sys

    cfg = json.dumps(settings.job_cfg(default_config()))
    procs = {g: subprocess.Popen([sys.executable, "-c", _FIRST_USE, g], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True)
             for g in ("delaunay", "knn", "isomap", "stisomap", "motion_matching")}
    for g, p in procs.items():
        out, err = p.communicate(cfg, timeout=300)
        assert p.returncode == 0, err[-3000:]
        seen = json.loads(out.strip().splitlines()[-1])
        assert seen["after"] == [] and seen["kernels"] == [], (g, seen)
        assert seen["warm_up"] or g == "motion_matching", g  # its libraries are imported with its module
        if g == "delaunay":
            assert any(n for k, n in seen["loaded"].items() if k.endswith("advance_serial")), seen["loaded"]
