"""Benchmarks are sized by config: demo rows (default and tiny runs) judge no target, full rows do;
`python3 run.py bench` builds the full size in a results folder of its own."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

from animsynth.report import run_benchmarks

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
