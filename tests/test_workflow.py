"""The workflow itself: lint, a dry run of every config, the tiny run, determinism."""

import re
import shutil
from pathlib import Path

import pandas as pd
import pytest

from conftest import REPO, copy_finished_run, copy_workflow, place_papers, run_snakemake
from run_outputs import NOT_COMPARED, WHOLE_RUN_COMPARED, same_content, tables

CONFIGS = sorted(p.name for p in (REPO / "config").glob("*.yaml") if p.name != "schema.yaml")

pytestmark = pytest.mark.workflow


def test_lint_is_clean(tmp_path):
    wd = copy_workflow(tmp_path)
    res = run_snakemake(wd, "--lint")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-4000:]
    assert "Lints for" not in out, out[-6000:]


@pytest.mark.parametrize("cfg", CONFIGS)
def test_dry_run_of_every_config(tmp_path, cfg):
    wd = copy_workflow(tmp_path)
    extra = []
    shared = REPO.parent / "shared" / "data"
    if cfg == "cmu.yaml":
        extra = ["--config", f"cmu_mirror={shared / 'cmu_mocap'}"]
    elif cfg == "samba.yaml":  # mesh_dir is relative to the repo; the copy lives elsewhere
        if not (shared / "vlasic_mesh_animation" / "samba").exists():
            pytest.skip("real data not available: ../shared/data/vlasic_mesh_animation/samba is absent")
        extra = ["--config", f"mesh_dir={shared / 'vlasic_mesh_animation' / 'samba'}"]
    args = ["-n", "--quiet", "rules"] if cfg == "config.yaml" else ["-n", "--quiet", "rules", "--configfile", f"config/{cfg}"]
    res = run_snakemake(wd, *args, *extra)
    assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]


def test_tiny_run_data_outputs(tiny_workflow):
    df = pd.read_csv(tiny_workflow / "results" / "data" / "datasets.csv")
    assert list(df["dataset"]) == ["w1", "w2", "r1", "r2"]
    assert (df["dims"] == 56).all() and (df["n_sequences"] == 3).all()
    assert df.loc[0, "lengths"] == "90 80 96"
    assert (tiny_workflow / "results" / "data" / "datasets.md").read_text().startswith("### Table I")


def _run_jobs(wd: Path) -> list[dict]:
    """The jobs a snakemake run in ``wd`` printed (``rule NAME:`` blocks of .snakemake/log/), each as
    {"rule": NAME, key: value} with the block's ``output``, ``log``, ``benchmark`` ... lines."""
    jobs = []
    for log in sorted((wd / ".snakemake" / "log").glob("*.snakemake.log")):
        job = None
        for line in log.read_text().splitlines():
            m = re.fullmatch(r"(?:local)?rule (\w+):", line)
            if m:
                job = {"rule": m.group(1)}
                jobs.append(job)
            elif job is not None and line.startswith("    ") and ": " in line:
                k, v = line.strip().split(": ", 1)
                job.setdefault(k, v)
            else:
                job = None
    return jobs


@pytest.fixture(scope="module")
def tiny_summary(tiny_workflow) -> str:
    """``snakemake --detailed-summary`` of the finished tiny run (one call, read by the two tests below that need
    every output with its rule and log)."""
    res = run_snakemake(tiny_workflow, "--configfile", "config/test.yaml", "--detailed-summary")
    assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]
    return res.stdout


def test_every_job_of_the_tiny_run_kept_a_log_and_a_benchmark_file(tiny_workflow):
    jobs = [j for j in _run_jobs(tiny_workflow) if "output" in j]  # the target rule `all` makes nothing
    rules = {j["rule"] for j in jobs}
    assert len(rules) > 20, sorted(rules)
    problems = []
    for j in jobs:
        where = f"rule {j['rule']} ({j['output'][:60]})"
        logs = [s.strip() for s in j.get("log", "").split(",") if s.strip()]
        if not logs:
            problems.append(f"{where}: no log")
        for lg in logs:
            if not (tiny_workflow / lg).is_file() or (tiny_workflow / lg).stat().st_size == 0:
                problems.append(f"{where}: log {lg} missing or empty")
        bench = j.get("benchmark")
        if not bench or not (tiny_workflow / bench).is_file() or (tiny_workflow / bench).stat().st_size == 0:
            problems.append(f"{where}: no benchmark file ({bench})")
    assert not problems, "\n".join(problems[:40])


def test_every_file_the_tiny_run_wrote_is_a_declared_output(tiny_workflow, tiny_summary):
    """No rule writes a file it does not declare (snakemake --list-untracked lists none under results/).

    The one exception is the benchmark file of the job that aggregates the benchmark files (it is written
    by Snakemake after that job, so no rule can take it as an input). --list-untracked compares file paths
    only, so it also lists the files inside a declared ``directory()`` output (the synthetic mesh
    character's OBJ clips); those belong to that output and are left out here."""
    res = run_snakemake(tiny_workflow, "--configfile", "config/test.yaml", "--list-untracked")
    assert res.returncode == 0, res.stderr[-2000:]
    listed = [ln.strip() for ln in (res.stdout + res.stderr).splitlines() if ln.strip().startswith("results")]
    outputs = [ln.split("\t")[0] for ln in tiny_summary.splitlines()[1:] if ln.strip()]
    folders = [o.rstrip("/") + "/" for o in outputs if (tiny_workflow / o).is_dir()]
    assert any("meshdetail/character/main" in f for f in folders), folders  # the directory outputs are seen
    own = "results/benchmarks/rules/report/rule_benchmarks.tsv"
    untracked = [p for p in listed if p != own and "/logs/" not in p and not any(p.startswith(f) for f in folders)]
    assert not untracked, "written but not declared:\n" + "\n".join(untracked[:40])


def test_not_compared_is_only_timing_tables():
    names = ["meshdetail/timing.csv", "facegraph/table1_timing.csv", "benchmarks.csv", "rule_benchmarks.csv",
             "rule_benchmarks_per_rule.md", "facegraph/table1.csv", "summary.md", "simplicial/benchmarks_paper.csv"]
    skipped = [n for n in names if NOT_COMPARED.search(n.rsplit("/", 1)[-1])]
    assert skipped == ["meshdetail/timing.csv", "facegraph/table1_timing.csv", "benchmarks.csv",
                       "rule_benchmarks.csv", "rule_benchmarks_per_rule.md"]


def _jobs_by_rule(summary: str) -> dict[str, list[tuple[str, ...]]]:
    """Every job of a finished run, as its output files, per rule, from the run's ``--detailed-summary``
    (outputs of one job share its log)."""
    lines = summary.splitlines()
    assert lines and lines[0].startswith("output_file\tdate\trule\tlog-file(s)"), summary[:2000]
    jobs: dict[tuple[str, str], list[str]] = {}
    for line in lines[1:]:
        out, date, rule, log = line.split("\t")[:4]
        if date == "-":  # not made by this run (no such output)
            continue
        jobs.setdefault((rule, log if log != "-" else out), []).append(out)
    by_rule: dict[str, list[tuple[str, ...]]] = {}
    for (rule, _), outs in sorted(jobs.items()):
        by_rule.setdefault(rule, []).append(tuple(sorted(outs)))
    return by_rule


def test_same_config_gives_identical_outputs(tiny_workflow, tiny_summary, tmp_path):
    """Determinism without a second whole run: in a copy of the finished tiny run, one job of every rule
    loses its outputs, and one snakemake call rebuilds exactly those (plus whatever lies between them);
    every rule's computation thus runs a second time (except rules that write only timing tables). Each
    rebuilt output must equal the first run's (:func:`run_outputs.comparable`: bytes, up to the working directory's
    path, timing fields of JSON records aside), and so must every table under results/ except the timing
    ones, byte for byte. When the SLURM test of this session (tests/test_slurm.py, which runs first) has run the
    whole tiny config again and found every output equal to this run's, every job has already run twice and been
    compared: this test would repeat a part of that run, and says so instead."""
    if WHOLE_RUN_COMPARED.get("tiny"):
        pytest.skip("the SLURM test ran every job of the tiny config a second time and found every output under "
                    "results/ equal to this run's (run_outputs.outputs_that_differ): nothing left to rebuild here")
    wd = copy_finished_run(tiny_workflow, tmp_path / "again" / "run")
    place_papers(wd)
    by_rule = _jobs_by_rule(tiny_summary)  # the copy holds the tiny run's outputs, under the same relative paths
    assert len(by_rule) > 20, sorted(by_rule)
    # one job per rule; a rule that writes only timing tables (compared nowhere) is not re-run
    chosen = {rule: jobs[0] for rule, jobs in by_rule.items()
              if not all(NOT_COMPARED.search(Path(o).name) for o in jobs[0])}
    targets = sorted(o for outs in chosen.values() for o in outs)
    for rel in targets:
        p = wd / rel
        shutil.rmtree(p) if p.is_dir() else p.unlink()
    res = run_snakemake(wd, *targets, "--configfile", "config/test.yaml", "--rerun-triggers", "mtime")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-4000:]
    ran = set(re.findall(r"^(?:local)?rule (\w+):$", out, re.M))
    assert set(chosen) <= ran, f"rules not re-executed: {sorted(set(chosen) - ran)}"
    timing = [t for t in targets if NOT_COMPARED.search(Path(t).name)]
    differ = [t for t in targets if t not in timing and not same_content(tiny_workflow / t, tiny_workflow, wd / t, wd)]
    assert not differ, f"{len(differ)} of {len(targets)} rebuilt outputs differ from the first run: {differ}"
    a, b = tables(tiny_workflow), tables(wd)
    assert a.keys() == b.keys() and len(a) > 20
    differ = sorted(k for k in a if a[k] != b[k])
    assert not differ, f"{len(differ)} of {len(a)} tables differ between two runs of one config: {differ}"
