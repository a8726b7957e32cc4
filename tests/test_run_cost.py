"""run.py's CPU breakdown of a run (run_cost.csv)."""
import csv
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def _run_py():
    spec = importlib.util.spec_from_file_location("run_py_cost", REPO / "run.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_snakemake_wrapper_records_its_own_and_its_childrens_cpu(tmp_path):
    run_py = _run_py()
    log = tmp_path / "cost.jsonl"
    env = dict(os.environ, ANIMSYNTH_RUN_COST=str(log), ANIMSYNTH_RUN_COST_LABEL="run")
    out = subprocess.run([sys.executable, "-c", run_py.MEASURED_SNAKEMAKE, "--version"], env=env,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0 and out.stdout.strip()[:1].isdigit()
    (rec,) = [json.loads(line) for line in log.read_text().splitlines()]
    assert rec["label"] == "run" and rec["self_user_s"] > 0 and rec["wall_s"] > 0
    assert {"children_user_s", "children_system_s", "self_system_s"} <= set(rec)


def test_run_cost_splits_the_jobs_from_what_their_benchmark_files_missed_and_from_snakemake(tmp_path,
                                                                                          monkeypatch):
    run_py = _run_py()
    monkeypatch.setattr(run_py, "ROOT", tmp_path)
    res = tmp_path / "results" / "paper"
    res.mkdir(parents=True)
    with open(res / "rule_benchmarks.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["family", "rule", "job", "seconds", "max_rss_mb", "max_vms_mb", "cpu_time_s"])
        w.writerow(["meshdetail", "meshdetail_main", "a", 100, 1, 1, 80.0])
        w.writerow(["data", "parse_trial", "b", 3, 1, 1, ""])
        w.writerow(["report", "summary", "c", 5, 1, 1, 20.0])
    cost = run_py.RunCost()
    with open(cost.path, "w") as f:
        f.write(json.dumps({"label": "run", "wall_s": 60, "self_user_s": 30.0, "self_system_s": 6.0,
                            "children_user_s": 110.0, "children_system_s": 20.0}) + "\n")
        f.write(json.dumps({"label": "report", "wall_s": 9, "self_user_s": 5.0, "self_system_s": 1.0,
                            "children_user_s": 0.0, "children_system_s": 0.0}) + "\n")
    cost.write(run_py.results_dir_of(["--config", "results_dir=results/paper"], "results"))
    rows = {r["part"]: r for r in csv.DictReader(open(res / "run_cost.csv"))}
    assert float(rows["jobs: CPU in their benchmark files (rule_benchmarks.csv)"]["cpu_s"]) == 100.0
    assert float(rows["jobs: CPU their benchmark files missed"]["cpu_s"]) == 30.0  # 130 counted by the OS
    assert float(rows["run: Snakemake's own process"]["cpu_s"]) == 36.0
    assert float(rows["report: Snakemake's own process"]["cpu_s"]) == 6.0
    assert float(rows["total"]["cpu_s"]) >= 0 and "run.py (venv check, config prescan)" in rows
    assert not Path(cost.path).exists()
