"""Benchmarks are sized by config: demo rows (default and tiny runs) judge no target, full rows do;
`python3 run.py bench` builds the full size in a results folder of its own."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

from animsynth.benchmark_tables import run_benchmarks

REPO = Path(__file__).resolve().parents[1]


def _bench(tmp_path):
    f = tmp_path / "bench_fake.py"
    f.write_text(
        "def run(size='full'):\n"
        "    n = 1000 if size == 'full' else 10\n"
        "    return [{'benchmark': f'rate_{n}_paths', 'value': 5.0, 'unit': 'steps/s', 'baseline': 'b',\n"
        "             'baseline_value': 1.0, 'ratio': 5.0, 'target': '>= 2x', 'meets_target': True}]\n")
    return f


def test_demo_rows_keep_values_but_judge_no_target(tmp_path):
    demo = run_benchmarks([_bench(tmp_path)], size="demo").iloc[0]
    full = run_benchmarks([_bench(tmp_path)], size="full").iloc[0]
    assert (demo["benchmark"], demo["size"], demo["value"]) == ("rate_10_paths", "demo", 5.0)
    assert math.isnan(demo["meets_target"]) and "full size only" in demo["target"]
    assert (full["benchmark"], full["size"], bool(full["meets_target"]), full["target"]) == (
        "rate_1000_paths", "full", True, ">= 2x")
    assert demo["family"] == "fake"


def test_unknown_size_is_refused(tmp_path):
    with pytest.raises(ValueError, match="benchmark size"):
        run_benchmarks([_bench(tmp_path)], size="huge")


@pytest.mark.parametrize("config, size", [("config/config.yaml", "demo"), ("config/test.yaml", "demo"),
                                          ("config/paper.yaml", "full")])
def test_configs_choose_their_benchmark_size(config, size):
    import yaml

    base = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    cfg = {**base, **(yaml.safe_load((REPO / config).read_text()) or {})}
    assert cfg["benchmark_size"] == size


def test_every_bench_module_takes_both_sizes():
    import inspect
    import importlib.util

    for f in sorted((REPO / "benchmarks").glob("bench_*.py")):
        spec = importlib.util.spec_from_file_location(f"sizes_{f.stem}", f)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        assert list(inspect.signature(mod.run).parameters) == ["size"], f


def test_run_py_bench_targets_full_size_in_its_own_folder(tmp_path):
    # a dry run of exactly the command run.py builds (prints the job list, runs nothing)
    src = (REPO / "run.py").read_text()
    assert 'BENCH_DIR = "results/bench"' in src and '"benchmark_size=full"' in src
    res = subprocess.run([str(Path(sys.executable).with_name("snakemake")), "-n", "--cores", "1",
                          "results/bench/benchmarks.csv", "--config", "results_dir=results/bench",
                          "benchmark_size=full"], cwd=REPO, capture_output=True, text=True)
    assert res.returncode == 0, res.stderr[-2000:]
    assert "benchmarks" in res.stdout and "results/bench/benchmarks.csv" in res.stdout


def test_run_py_bench_joins_the_users_config_pairs_to_its_own():
    sys.path.insert(0, str(REPO))
    import run

    assert run.bench_args(["--config", "cmu_mirror=/m", "seed=3", "-n"]) == (["-n"], ["cmu_mirror=/m", "seed=3"])
    assert run.bench_args(["-n", "--dry-run"]) == (["-n", "--dry-run"], [])


def test_cost_table_sums_families_and_names_date_and_machine(tmp_path):
    sys.path.insert(0, str(REPO / "benchmarks"))
    import cost_table

    csv = tmp_path / "rule_benchmarks_per_family.csv"
    csv.write_text("family,jobs,wall_s,cpu_s,peak_rss_mb\ndata,3,8.4,2.6,107\nmeshdetail,8,161.2,40.9,419.6\n")
    md = cost_table.cost_table(csv)
    assert "| **total** | 11 | 170 | 44 | 420 |" in md and "| data | 3 | 8 | 3 | 107 |" in md
    line = cost_table.provenance_line(csv)
    assert "cores" in line and str(csv) in line and line.startswith("Measured 20")


def test_benchmark_row_states_the_better_direction_and_one_ratio_convention():
    from animsynth.benchmark_tables import BENCHMARK_COLUMNS, benchmark_row

    t = benchmark_row("f", "build_s", 2.0, "s", better="lower", baseline="theirs", baseline_value=10.0)
    assert list(t) == list(BENCHMARK_COLUMNS) and (t["better"], t["ratio"]) == ("lower", 5.0)  # 5x faster
    r = benchmark_row("f", "rate", 2.0, "steps/s", better="higher", baseline_value=10.0, digits=3)
    assert r["ratio"] == 0.2  # a fifth of the baseline's rate: below 1, ours is worse
    slow = benchmark_row("f", "build_s", 10.0, "s", better="lower", baseline_value=2.0)
    assert slow["ratio"] == 0.2  # the same story for a time: below 1 always means worse
    alone = benchmark_row("f", "only", 1.0, "s", better="lower", extra_column=3)
    assert math.isnan(alone["ratio"]) and math.isnan(alone["baseline_value"]) and alone["extra_column"] == 3
    assert math.isnan(alone["meets_target"]) and alone["target"] == "report only"
    with pytest.raises(ValueError, match="better"):
        benchmark_row("f", "x", 1.0, "s", better="faster")


@pytest.mark.parametrize("name", sorted(p.name for p in (REPO / "benchmarks").glob("bench_*.py")) + ["scale_reseq.py"])
def test_every_benchmark_builds_its_rows_with_the_one_row_builder(name):
    src = (REPO / "benchmarks" / name).read_text()
    assert "benchmark_row(" in src
    assert '"ratio":' not in src and "'ratio':" not in src, f"{name} writes a ratio of its own"


def test_the_benchmark_table_shows_the_direction(tmp_path):
    sys.path.insert(0, str(REPO / "benchmarks"))
    import cost_table

    from animsynth.benchmark_tables import benchmark_row

    csv = tmp_path / "benchmarks.csv"
    import pandas as pd

    pd.DataFrame([benchmark_row("f", "build_s", 2.0, "s", better="lower", baseline_value=10.0, target="t",
                                meets_target=True)]).to_csv(csv, index=False)
    md = cost_table.benchmark_table(csv)
    assert "| f | `build_s` | 2 s | lower | 10 | 5 | t | yes |" in md
    pd.read_csv(csv).drop(columns="better").to_csv(csv, index=False)
    with pytest.raises(ValueError, match="better"):
        cost_table.benchmark_table(csv)
