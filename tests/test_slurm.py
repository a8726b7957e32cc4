"""The SLURM profile end to end: a private single-node SLURM cluster on
localhost (tests/slurm/setup_cluster.sh), the data layer of the tiny config
run through snakemake-executor-plugin-slurm with profiles/slurm, and the
outputs compared with a local run of the same target.

Opt-in (it installs Debian packages and starts daemons as root):
    ANIMSYNTH_SLURM_TEST=1 .venv/bin/pytest tests/test_slurm.py
.ci/run sets ANIMSYNTH_SLURM_TEST=1. Skips with the reason when not opted in,
not root, or when slurm-wlm/munge are missing and apt-get is unavailable.
Every SLURM / snakemake-on-SLURM call is wrapped in `timeout -k` so a broken
status check cannot hang CI; the daemons are always stopped (by PID) in the
fixture finalizer.
"""

from __future__ import annotations

import os
import re
import shutil
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from conftest import REPO, SNAKEMAKE, copy_workflow, run_snakemake

pytestmark = pytest.mark.slurm

SCRIPTS = REPO / "tests" / "slurm"
CLUSTER_TOOLS = ("munged", "slurmctld", "slurmd", "sbatch", "squeue", "sinfo", "scontrol", "srun")
TARGET = "results/data/datasets.csv"
# Shrink the tiny config's data layer (12 trials, 25 jobs) to 4 trials, 9 jobs
# (4 synth_trial, 4 parse_trial, 1 datasets_table): each SLURM job pays two
# snakemake start-ups plus the plugin's status polling. (A YAML file, not
# --config, because null - "drop this subset" - only survives a YAML file.)
OVERRIDES = {
    "subsets": {
        "w1": ["syn35_16", "syn35_07"],
        "w2": None,
        "r1": ["syn35_17", "syn35_22"],
        "r2": None,
    }
}
TRIALS = ["syn35_16", "syn35_07", "syn35_17", "syn35_22"]
N_JOBS = 2 * len(TRIALS) + 1
# Test-cluster settings on top of the profile: no slurmdbd here, so sacct does
# not work and the plugin must poll squeue (MinJobAge=600 keeps finished jobs
# visible); poll every 2 s instead of 40 s; keep the SLURM logs to inspect.
SLURM_TEST_ARGS = (
    "--slurm-status-command", "squeue",
    "--slurm-init-seconds-before-status-checks", "2",
    "--seconds-between-status-checks", "2",
    "--slurm-keep-successful-logs",
)
RUN_TIMEOUT = 420  # seconds for the snakemake-on-SLURM run (measured: ~75 s on 2 cores)


def _skip_reason() -> str | None:
    if os.environ.get("ANIMSYNTH_SLURM_TEST") != "1":
        return ("opt-in: set ANIMSYNTH_SLURM_TEST=1 to start a single-node SLURM cluster "
                "on localhost (.ci/run does); it installs slurm-wlm + munge and needs root")
    if sys.platform != "linux":
        return "the single-node SLURM test needs Linux"
    if os.geteuid() != 0:
        return "the single-node SLURM test must run as root (it installs packages and runs slurmctld/slurmd/munged)"
    if shutil.which("timeout") is None:
        return "coreutils 'timeout' is unavailable"
    missing = [t for t in CLUSTER_TOOLS if shutil.which(t) is None]
    if missing and shutil.which("apt-get") is None:
        return f"SLURM tools missing ({', '.join(missing)}) and apt-get is unavailable to install slurm-wlm/munge"
    return None


def _free_ports(n: int) -> list[int]:
    socks = []
    try:
        for _ in range(n):
            s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            s.bind(("127.0.0.1", 0))
            socks.append(s)
        return [s.getsockname()[1] for s in socks]
    finally:
        for s in socks:
            s.close()


def _clean_env(**extra) -> dict:
    """Environment for cluster calls: no inherited SLURM job context; the
    venv's bin/ first on PATH (jobs inherit it through sbatch --export=ALL)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("SLURM_", "SBATCH_", "SRUN_", "SQUEUE_", "SINFO_"))}
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "/usr/bin:/bin")])
    env.update(extra)
    return env


def _timed(seconds: int, *cmd) -> list[str]:
    """`timeout -k 10 SECONDS cmd...`: a hung call is killed, never waited on."""
    return ["timeout", "-k", "10", str(seconds), *map(str, cmd)]


@pytest.fixture(scope="module")
def slurm_cluster(tmp_path_factory, request):
    """Start the private cluster once for this module; always stop it."""
    reason = _skip_reason()
    if reason:
        pytest.skip(reason)
    state = tmp_path_factory.mktemp("slurm_cluster")
    env = _clean_env()
    env["SLURMCTLD_PORT"], env["SLURMD_PORT"] = map(str, _free_ports(2))

    def teardown():
        subprocess.run(_timed(90, "bash", SCRIPTS / "teardown_cluster.sh", state), env=env,
                       capture_output=True, text=True, timeout=120)

    request.addfinalizer(teardown)  # before the start: a partial start is stopped too
    # apt-get update + install can take minutes on a fresh machine.
    res = subprocess.run(_timed(1500, "bash", SCRIPTS / "setup_cluster.sh", state), env=env,
                         capture_output=True, text=True, timeout=1600)
    if res.returncode == 3:  # host already has a SLURM configuration we must not shadow
        pytest.skip("single-node SLURM test not possible here: " + res.stderr.strip().splitlines()[-1])
    assert res.returncode == 0, f"setup_cluster.sh failed ({res.returncode}):\n{res.stdout[-3000:]}\n{res.stderr[-6000:]}"
    conf = res.stdout.strip().splitlines()[-1]
    assert conf.startswith("SLURM_CONF="), res.stdout
    return {"state": state, "env": _clean_env(SLURM_CONF=conf.split("=", 1)[1])}


def _prepare(wd: Path) -> list[str]:
    copy_workflow(wd)
    (wd / "config" / "slurm_test_overrides.yaml").write_text(yaml.safe_dump(OVERRIDES, sort_keys=False))
    return ["--configfile", "config/test.yaml", "config/slurm_test_overrides.yaml"]


def _squeue(env) -> dict[str, dict]:
    """Every job slurmctld still knows (MinJobAge=600): id -> state, comment, limits."""
    res = subprocess.run(_timed(30, "squeue", "-h", "-t", "all", "-o", "%i|%T|%k|%l|%m|%C"),
                         env=env, capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr
    jobs = {}
    for line in res.stdout.splitlines():
        jid, state, comment, limit, mem, cpus = line.strip().split("|")
        jobs[jid] = {"state": state, "comment": comment, "time_limit": limit, "min_memory": mem, "cpus": cpus}
    return jobs


def _declared_sizes() -> dict[str, tuple[str, str, str]]:
    """rule -> (squeue min_memory, time_limit, cpus) from the rule's own threads/resources."""
    from test_rules import parse_rules

    out = {}
    for name, info in parse_rules(REPO / "workflow" / "rules" / "data.smk").items():
        d = info["directives"]
        res = dict(re.findall(r"(\w+)\s*=\s*(\d+)", " ".join(d["resources"])))
        minutes = int(res["runtime"])
        out[name] = (f"{res['mem_mb']}M", f"{minutes // 60}:{minutes % 60:02d}:00" if minutes >= 60
                     else f"{minutes}:00", d["threads"][0])
    return out


def _assert_same_outputs(local: Path, remote: Path):
    for rel in ("results/data/datasets.csv", "results/data/datasets.md"):
        assert (remote / rel).read_bytes() == (local / rel).read_bytes(), rel
    for t in TRIALS:
        for ext in ("amc", "asf"):
            rel = f"resources/mocap/{t}.{ext}"
            assert (remote / rel).read_bytes() == (local / rel).read_bytes(), rel
        rel = f"results/data/trials/{t}.npz"
        with np.load(local / rel, allow_pickle=False) as a, np.load(remote / rel, allow_pickle=False) as b:
            assert sorted(a.files) == sorted(b.files), rel
            for key in a.files:
                assert a[key].dtype == b[key].dtype and a[key].shape == b[key].shape, (rel, key)
                assert np.array_equal(a[key], b[key]), (rel, key)


def test_data_layer_through_slurm_matches_local_run(slurm_cluster, tmp_path):
    env = slurm_cluster["env"]
    before = set(_squeue(env))

    # Reference: the same target and overrides, run locally. (Not concurrently
    # with the SLURM run: on 2 cores that slows the SLURM jobs past the
    # plugin's status polls, whose interval then backs off by 10 s each.)
    local = tmp_path / "local"
    res = run_snakemake(local, *_prepare(local), "--", TARGET, timeout=600)
    assert res.returncode == 0, "local reference run failed:\n" + (res.stdout + res.stderr)[-6000:]

    # The data layer through SLURM with the profile, as docs/cluster.md tells users.
    remote = tmp_path / "slurm"
    cmd = _timed(RUN_TIMEOUT, SNAKEMAKE, "--workflow-profile", "profiles/slurm", *SLURM_TEST_ARGS,
                 *_prepare(remote), "--", TARGET)
    proc = subprocess.run(cmd, cwd=remote, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=RUN_TIMEOUT + 60)
    out = proc.stdout
    if proc.returncode != 0:
        logs = "\n".join(f"--- {p}\n{p.read_text()[-3000:]}" for p in sorted((remote / ".snakemake" / "slurm_logs").rglob("*.log")))
        pytest.fail(f"snakemake on SLURM failed (rc {proc.returncode}; 124 = timed out):\n{out[-6000:]}\n{logs[-8000:]}")

    # Every job went through sbatch: snakemake reports a SLURM job id for each...
    submitted = dict(re.findall(r"Job (\d+) has been submitted with SLURM jobid (\d+)", out))
    assert len(submitted) == N_JOBS, out[-4000:]
    slurm_ids = set(submitted.values())
    assert len(slurm_ids) == N_JOBS
    # ... slurmctld accepted each of them as a batch job ...
    ctld_log = (slurm_cluster["state"] / "log" / "slurmctld.log").read_text()
    accepted = set(re.findall(r"_slurm_rpc_submit_batch_job: JobId=(\d+)", ctld_log))
    assert slurm_ids <= accepted, (slurm_ids - accepted, ctld_log[-3000:])
    # ... and ran it to completion, with the profile's per-rule resources.
    jobs = {j: v for j, v in _squeue(env).items() if j not in before}
    assert set(jobs) == slurm_ids, (jobs, slurm_ids)
    rules = {}
    declared = _declared_sizes()
    for jid, job in jobs.items():
        assert job["state"] == "COMPLETED", (jid, job)
        rule = re.match(r"rule_([a-z_]+?)(?:_wildcards_|$)", job["comment"]).group(1)
        rules[rule] = rules.get(rule, 0) + 1
        # the threads/mem_mb/runtime that the rule itself declares in data.smk
        assert (job["min_memory"], job["time_limit"], job["cpus"]) == declared[rule], (jid, job)
    assert rules == {"synth_trial": len(TRIALS), "parse_trial": len(TRIALS), "datasets_table": 1}, rules
    # Each batch script runs this venv's interpreter (`<venv>/bin/python -m snakemake`
    # ... --executor slurm-jobstep), and each job left its SLURM log.
    venv_bin = str(Path(sys.executable).parent) + os.sep
    for jid in sorted(slurm_ids, key=int):
        res = subprocess.run(_timed(30, "scontrol", "write", "batch_script", jid, "-"),
                             env=env, capture_output=True, text=True, timeout=60)
        assert res.returncode == 0, res.stderr
        command = [line for line in res.stdout.splitlines() if "-m snakemake" in line]
        assert command and command[0].startswith(venv_bin), (jid, res.stdout[:500])
        assert "--executor slurm-jobstep" in command[0], (jid, command[0][:300])
    slurm_logs = sorted((remote / ".snakemake" / "slurm_logs").rglob("*.log"))
    assert len(slurm_logs) == N_JOBS, slurm_logs

    _assert_same_outputs(local, remote)
