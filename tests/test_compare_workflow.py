"""compare outputs of the whole workflow on the tiny config."""
import pandas as pd
import pytest

from animsynth.compare.measures.metric_table import KEY_COLUMNS, METRIC_NAMES
from animsynth.verdicts import VOCABULARY

from conftest import default_config


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
    claims = {(c["a"], c["b"]): c["claim"] for c in default_config()["compare"]["claims"]}
    for pair in (("motion_matching", "motion_graph"), ("genmm", "motion_graph")):
        assert decided[claims[pair]] != "did not run", pair  # both rows ran: the claim is tested
    for g in gens:
        back = read_bvh(r / "bvh" / f"{g}.bvh")
        assert back.n_frames > 0
    assert {"velocity_jump_p95", "velocity_jump_over_capture", "skating_ratio_gmd", "l2p_m"} <= set(m.columns)
    sanity = pd.read_csv(r / "sanity_checks.csv")
    assert list(sanity.columns) == list(v.columns) and set(sanity["verdict"]) <= set(VOCABULARY)
    assert not set(sanity["claim"]) & set(v["claim"])  # true by construction: not among the findings
    assert (v["evidence"].str.contains("Holm") | v["verdict"].isin(["did not run", "undecided"])).all()
    # the declared claims' numbers, one row per verdict row; the exploratory pairs apart, without a verdict
    from animsynth.compare.verdicts import EXPLORATORY_COLUMNS, STATS_COLUMNS

    stats = pd.read_csv(r / "claims_stats.csv")
    assert list(stats.columns) == list(STATS_COLUMNS) and len(stats) == len(v)
    assert list(stats["verdict"]) == list(v["verdict"])
    ex = pd.read_csv(r / "exploratory.csv")
    assert list(ex.columns) == list(EXPLORATORY_COLUMNS) and len(ex) > 0 and set(ex["label"]) == {"exploratory"}
    assert (r / "exploratory.md").stat().st_size > 0
    sens = pd.read_csv(r / "skating_sensitivity.csv")
    assert set(sens["speed_m_s"]) == {0.15, 0.3, 0.5}
    for png in ("metrics.png", "strips.png"):
        assert (r / png).stat().st_size > 0
    md = (r / "summary.md").read_text()
    assert md.startswith("# The generators side by side") and "## Verdicts" in md
    summary = (tiny_workflow / "results" / "summary.md").read_text()
    assert "## The generators side by side" in summary and "### Which generator wins which metric" in summary
    claims = pd.read_csv(tiny_workflow / "results" / "claims.csv")
    ours = claims[claims["family"] == "compare"]  # the 2-s and the long track's rows (two scoreboard rows)
    assert len(ours) == len(v) + len(sanity)  # the findings, then the sanity checks marked as such
    assert ours["sanity_check"].astype(bool).sum() == len(sanity)
    assert "The generators side by side" in (tiny_workflow / "results" / "claims.rst").read_text()
    _long_track_outputs(r, clips, gens, v, stats)


def _long_track_outputs(r, clips, gens, v, stats):
    """The long track of the tiny run (compare.long_track of config/test.yaml): every generator's rows on each
    subject's long context, replay's "did not run", its claims after the 2-s ones, its preview."""
    from animsynth.compare.long_track import LONG_COLUMNS

    lm = pd.read_csv(r / "metrics_long.csv")
    lm["note"] = lm["note"].fillna("")
    assert list(lm.columns) == LONG_COLUMNS
    per = lm.merge(clips[["clip", "subject"]], on="clip").groupby("subject")["generator"].agg(set)
    assert len(per) == clips["subject"].nunique() and all(set(gens) == g for g in per)  # every row, every subject
    assert (lm["generator"] != "replay").sum() and (lm.loc[lm["generator"] == "replay", "note"].str.startswith(
        "did not run: its query is the held-out future")).all()
    assert lm.groupby("generator")["seed"].nunique().to_dict()["fairmotion"] == 1  # compare.long_track.seeds_by_generator
    ran = lm[lm["note"] == ""]
    assert ran["repetition_share"].between(0, 1).all() and ran["coverage_after_5s"].notna().any()
    long_claims = [c for c in default_config()["compare"]["claims"] if c.get("track") == "long"]
    assert list(v["claim"].tail(len(long_claims))) == [c["claim"] for c in long_claims]
    assert set(v["source"].tail(len(long_claims))) == {"compare/metrics_long.csv"}
    assert set(v["source"].head(len(v) - len(long_claims))) == {"compare/metrics.csv"}
    assert list(stats["claim_id"].tail(len(long_claims))) == [c["id"] for c in long_claims]
    t = pd.read_csv(r / "metrics_long_timing.csv")
    assert set(t["generator"]) == set(gens) and (t.loc[t["generator"].isin(ran["generator"]), "frames_generated"]
                                                 .groupby(t["generator"]).sum() > 0).all()
    assert "## The 5-second track" in (r / "summary.md").read_text()
    assert (r / "long_strips.png").stat().st_size > 0 and (r / "metrics_long.md").stat().st_size > 0
    # the results page (docs/compare/results.md) carries the long track's medians as its tables job wrote them
    from animsynth.compare.tables import results_markdown

    page = results_markdown(r)
    assert "**The long track**" in page and "repetition_share" in page and "freezing_share" in page


def _docs_toy() -> str:
    """The toy generator shown in docs/compare/own_generator.md (run here as a user would copy it)."""
    from conftest import REPO

    text = (REPO / "docs" / "compare" / "own_generator.md").read_text()
    start = text.index("```python\n# mine/toy.py") + len("```python\n")
    return text[start:text.index("```", start)]


@pytest.mark.workflow
def test_a_user_generator_and_animsynth_score_on_the_tiny_run(tiny_workflow, tmp_path_factory):
    """The docs' toy generator and a broken one added to a copy of the finished tiny run: only their jobs run (one
    per subject), the broken one is one error line per job and empty rows, the toy is in every table, figure and the
    BVH folder, the family's rows and claims are byte for byte the same; then animsynth score reads the toy's BVH
    file back."""
    import numpy as np

    from animsynth import cli
    from animsynth.compare import protocol
    from animsynth.compare.scoring import DATABASE_METRICS
    from animsynth.io.bvh import read_bvh
    from conftest import copy_finished_run, run_snakemake

    wd = copy_finished_run(tiny_workflow, tmp_path_factory.mktemp("tiny_user") / "run")
    r = wd / "results" / "compare"
    before = {f: (r / f).read_text() for f in ("metrics.csv", "verdicts.csv", "sanity_checks.csv")}
    (wd / "mine").mkdir()
    (wd / "mine" / "toy.py").write_text(_docs_toy())
    (wd / "config" / "mine.yaml").write_text("compare:\n  user_generators:\n    toy: mine/toy.py:RandomSegments\n"
                                             "    broken: mine/toy.py:NoSuchClass\n")
    summary_before = (wd / "results" / "summary.md").stat().st_mtime_ns
    res = run_snakemake(wd, "results/compare/summary.md", "results/compare/metrics.png", "results/compare/strips.png",
                        "results/compare/bvh/toy.bvh", "results/compare/bvh/broken.bvh", "results/summary.md",
                        "--configfile", "config/test.yaml", "config/mine.yaml")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-6000:]
    broken = [line for line in out.splitlines() if "user generator 'broken'" in line]
    # one error line per job: one job per subject (syn35, syn05)
    assert len(broken) == 2 and all("(mine/toy.py:NoSuchClass): the file has no class 'NoSuchClass'" in b
                                    for b in broken), broken
    assert "Traceback" not in out
    ran = {line.split("cmpgen=")[1].split(",")[0].strip() for line in out.splitlines() if "cmpgen=" in line}
    assert ran == {"toy", "broken"}  # the family's generator jobs did not run again
    m = pd.read_csv(r / "metrics.csv")
    assert list(dict.fromkeys(m["generator"]))[-2:] == ["toy", "broken"]
    ours = [row for row in (r / "metrics.csv").read_text().splitlines() if ",toy," not in row and ",broken," not in row]
    assert ours == before["metrics.csv"].splitlines()  # the family's rows byte for byte
    for f in ("verdicts.csv", "sanity_checks.csv"):
        assert (r / f).read_text() == before[f], f  # the claims are the family's alone
    toy = m[m["generator"] == "toy"]
    assert len(toy) == len(m[m["generator"] == "replay"]) and toy[["skate_share", "l2p", "coverage"]].notna().all().all()
    assert (toy["n_seams"] >= 1).all() and toy["note"].isna().all()
    bad = m[m["generator"] == "broken"]
    assert bad[METRIC_NAMES].isna().all().all() and bad["note"].str.startswith("failed: user generator 'broken'").all()
    for f in ("summary.csv", "cost_timing.csv", "skating_sensitivity.csv"):
        assert {"toy", "broken"} <= set(pd.read_csv(r / f)["generator"]), f
    page = (r / "summary.md").read_text()
    assert "Your own generators (compare.user_generators): **toy**, **broken**" in page and "**broken**: user generator" in page
    assert (wd / "results" / "summary.md").stat().st_mtime_ns > summary_before  # the report is rebuilt with them
    clips = protocol.load_clips(r / "clips" / "syn35.npz")  # the showcase: the first subject's first clip
    show = clips[0]
    assert read_bvh(r / "bvh" / "toy.bvh").n_frames == show.context + show.length
    assert read_bvh(r / "bvh" / "broken.bvh").n_frames == show.context  # the start alone

    # animsynth score on the run's own files: the toy's motion against the held-out start and continuation
    unit = str(show.held_out.skeleton.length_to_m)
    assert cli.main(["score", str(r / "bvh" / "toy.bvh"), "--reference", str(r / "bvh" / "replay.bvh"), "--config",
                     str(wd / "config" / "test.yaml"), "--length-to-m", unit, "--out", str(wd / "scores.csv")]) == 0
    s = pd.read_csv(wd / "scores.csv").iloc[0]
    row = toy[(toy["clip"] == show.clip) & (toy["seed"] == 0)].iloc[0]
    for c in ("l2p_m", "l2q", "npss", "ldlj", "sparc", "velocity_jump_p95", "velocity_jump_max", "accel_jump_p95",
              "accel_jump_max"):
        assert np.isclose(s[c], row[c], rtol=1e-4, atol=1e-6), (c, s[c], row[c])
    assert all(np.isnan(s[c]) for c in DATABASE_METRICS)  # no --database


def _planned(res) -> list[tuple[str, dict]]:
    """(rule, wildcards) of every compare job a dry run plans."""
    import re

    out = []
    for rule, block in re.findall(r"^(?:local)?rule (compare_\w+):\n((?:    .*\n)+)", res.stdout, flags=re.M):
        w = re.search(r"^    wildcards: (.*)$", block, flags=re.M)
        out.append((rule, dict(kv.split("=", 1) for kv in w.group(1).split(", ")) if w else {}))
    return out


def _planned_rows(res) -> list[tuple[str, str]]:
    """(subject, row) of every generator row the compare jobs of a dry run write: the metrics files
    (``compare/runs/<subject>/<row>.csv``) among the outputs of each planned ``compare_run*`` job."""
    import re

    out = []
    for _rule, block in re.findall(r"^rule (compare_run\w*):\n((?:    .*\n)+)", res.stdout, flags=re.M):
        files = re.search(r"^    output: (.*)$", block, flags=re.M).group(1).split(", ")
        out += [m.groups() for f in files if (m := re.search(r"compare/runs/(\w+)/(\w+)\.csv$", f))
                and not m.group(2).endswith(("_timing", "_long"))]
    return out


@pytest.mark.workflow
def test_fairmotion_rows_and_sweep_are_one_job_per_subject_and_our_graph_keeps_its_own(tmp_path):
    """With a budget sweep, fairmotion's two rows and the fixed row's further budgets are planned as one job per
    subject (compare_run_fairmotion, which builds each graph once per database); our motion graph and its budgets are
    one compare_run_graph job per subject; the rows of one method (names.METHOD_ROWS) one compare_run_<method> job
    per subject, and the other generator (GenMM) its compare_run job per subject: every row once per subject."""
    from animsynth.compare.generators.names import GENERATORS, METHOD_ROWS
    import re

    from conftest import copy_workflow, run_snakemake

    from animsynth.compare.settings import unavailable

    if unavailable("fairmotion"):
        pytest.skip(f"needs fairmotion: {unavailable('fairmotion')}")
    wd = copy_workflow(tmp_path / "wf")
    (wd / "config" / "sweep.yaml").write_text("compare:\n  budget_sweep: [2, 8]\n")
    res = run_snakemake(wd, "-n", "--configfile", "config/test.yaml", "config/sweep.yaml", "--",
                        "results/compare/budget_sweep.csv", "results/compare/verdicts.csv")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    jobs = _planned(res)
    by_rule = {}
    for rule, w in jobs:
        by_rule.setdefault(rule, []).append(w)
    assert sorted(w["cmpsubj"] for w in by_rule["compare_run_fairmotion"]) == ["syn05", "syn35"]
    assert sorted(w["cmpsubj"] for w in by_rule["compare_clips"]) == ["syn05", "syn35"]
    blocks = dict(re.findall(r"^rule (compare_run_fairmotion):\n((?:    .*\n)+)", res.stdout, flags=re.M))
    for f in ("runs/syn\\d+/fairmotion.csv", "runs/syn\\d+/fairmotion_fixed.csv", "sweep/syn\\d+/fairmotion_fixed_2.csv",
              "sweep/syn\\d+/fairmotion_fixed_8.csv"):
        assert re.search(f"results/compare/{f}", blocks["compare_run_fairmotion"]), f
    assert [w["cmpgen"] for w in by_rule["compare_run_graph"]] == ["motion_graph", "motion_graph"]
    assert sorted(w["cmpgen"] for w in by_rule["compare_run"]) == ["genmm", "genmm"]
    for method, rows in METHOD_ROWS.items():  # one job per subject, writing each of its rows' files
        assert sorted(w["cmpsubj"] for w in by_rule[f"compare_run_{method}"]) == ["syn05", "syn35"], method
        block = "".join(re.findall(rf"^rule compare_run_{method}:\n((?:    .*\n)+)", res.stdout, flags=re.M))
        for g in rows:
            assert re.search(f"results/compare/runs/syn05/{g}_long.csv", block), (method, g)
    planned = _planned_rows(res)
    assert sorted(planned) == sorted((s, g) for s in ("syn05", "syn35") for g in GENERATORS)  # each row once
    assert "compare_sweep_run" not in by_rule
    # without our motion graph the sweep is fairmotion's alone: no compare_run_graph job, and the run still plans
    (wd / "config" / "fm_only.yaml").write_text(
        "compare:\n  budget_sweep: [2, 8]\n  generators: [delaunay, fairmotion, fairmotion_fixed, replay, concat]\n")
    res = run_snakemake(wd, "-n", "--configfile", "config/test.yaml", "config/fm_only.yaml")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    assert "rule compare_run_fairmotion:" in res.stdout and "rule compare_run_graph:" not in res.stdout
    # a method with some of its rows runs those only (Delaunay without k-NN), and a method with none has no job
    assert sorted(_planned_rows(res)) == sorted((s, g) for s in ("syn05", "syn35")
                                                for g in ("delaunay", "fairmotion", "fairmotion_fixed", "replay", "concat"))
    assert "rule compare_run_isomap:" not in res.stdout and "rule compare_run_simplicial:" in res.stdout


@pytest.mark.workflow
def test_rerunning_one_subjects_clips_reruns_only_that_subjects_jobs(tiny_workflow, tmp_path_factory):
    """The finished tiny run (two subjects, syn35 and syn05): a changed clips file of syn05 plans syn05's generator
    jobs and the gathering, none of syn35's; a changed trial list of syn35 (one more set of compare.subjects) plans
    syn35's clips job and its generator jobs, none of syn05's."""
    import shutil

    from animsynth.compare import protocol
    from conftest import copy_finished_run, run_snakemake

    wd = copy_finished_run(tiny_workflow, tmp_path_factory.mktemp("tiny_rerun") / "run")
    res = run_snakemake(wd, "-n", "--configfile", "config/test.yaml")
    assert res.returncode == 0 and not _planned(res), (res.stdout + res.stderr)[-3000:]  # nothing of compare to do
    clips = wd / "results" / "compare" / "clips" / "syn05.npz"
    kept = wd / "syn05.npz"
    shutil.copy2(clips, kept)
    protocol.save_clips(clips, protocol.load_clips(clips)[:-1])  # as if its clips job had cut one clip fewer
    res = run_snakemake(wd, "-n", "--configfile", "config/test.yaml")
    assert res.returncode == 0, (res.stdout + res.stderr)[-3000:]
    jobs = _planned(res)
    subjects = {w.get("cmpsubj") for _r, w in jobs if "cmpsubj" in w}
    assert subjects == {"syn05"}, jobs
    rules = [r for r, _w in jobs]
    assert "compare_clips" not in rules and {"compare_tables", "compare_figures"} <= set(rules)
    from animsynth.compare.settings import unavailable

    ran = [g for g in default_config()["compare"]["generators"] if not unavailable(g)]
    assert sorted(g for _s, g in _planned_rows(res)) == sorted(ran)  # every row of syn05 once
    shutil.copy2(kept, clips)  # back as it was
    (wd / "config" / "more.yaml").write_text("compare:\n  subjects: {s35: [syn35_20]}\n")
    res = run_snakemake(wd, "-n", "--configfile", "config/test.yaml", "config/more.yaml")
    assert res.returncode == 0, (res.stdout + res.stderr)[-3000:]
    jobs = _planned(res)
    assert {w.get("cmpsubj") for _r, w in jobs if "cmpsubj" in w} == {"syn35"}, jobs
    assert ("compare_clips", {"cmpsubj": "syn35"}) in jobs
