"""The SLURM profile end to end: a private single-node SLURM cluster on
localhost (tests/slurm/setup_cluster.sh), the WHOLE tiny configuration
(config/test.yaml) run through snakemake-executor-plugin-slurm with
profiles/slurm, and every table compared with a local run of the same
configuration (the session's ``tiny_workflow`` run, shared with the other
workflow tests, so the local side costs nothing extra in the full suite).

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

import pytest

from conftest import REPO, SAFETY_TIMEOUT, SNAKEMAKE, copy_workflow, place_papers, run_snakemake
from run_outputs import WHOLE_RUN_COMPARED, outputs_that_differ, tables

pytestmark = [pytest.mark.slurm, pytest.mark.workflow]

SCRIPTS = REPO / "tests" / "slurm"
CLUSTER_TOOLS = ("munged", "slurmctld", "slurmd", "sbatch", "squeue", "sinfo", "scontrol", "srun")
# Test-cluster settings on top of the profile: no slurmdbd here, so sacct does
# not work and the plugin must poll squeue (MinJobAge=14400 keeps finished jobs
# visible); poll every 2 s instead of 40 s; keep the SLURM logs to inspect.
SLURM_TEST_ARGS = (
    "--slurm-status-command", "squeue",
    "--slurm-init-seconds-before-status-checks", "2",
    "--seconds-between-status-checks", "2",
    "--slurm-keep-successful-logs",
)
# Safety limits (seconds) of the `timeout -k` wrappers: there only so that a hung
# status check or daemon cannot block CI forever, far above what the calls cost
# on a busy machine (the whole tiny workflow on SLURM: see docs/scale.md).
# ANIMSYNTH_SLURM_TIMEOUT overrides the limit of the whole run.
RUN_TIMEOUT = int(os.environ.get("ANIMSYNTH_SLURM_TIMEOUT", str(SAFETY_TIMEOUT)))
SETUP_TIMEOUT = 3600  # apt-get update + install of slurm-wlm/munge on a fresh machine, daemons started
CALL_TIMEOUT = 600    # one squeue/scontrol call or the teardown


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
        subprocess.run(_timed(CALL_TIMEOUT, "bash", SCRIPTS / "teardown_cluster.sh", state), env=env,
                       capture_output=True, text=True, timeout=CALL_TIMEOUT + 60)

    request.addfinalizer(teardown)  # before the start: a partial start is stopped too
    # apt-get update + install can take minutes on a fresh machine.
    res = subprocess.run(_timed(SETUP_TIMEOUT, "bash", SCRIPTS / "setup_cluster.sh", state), env=env,
                         capture_output=True, text=True, timeout=SETUP_TIMEOUT + 60)
    if res.returncode == 3:  # host already has a SLURM configuration we must not shadow
        pytest.skip("single-node SLURM test not possible here: " + res.stderr.strip().splitlines()[-1])
    assert res.returncode == 0, f"setup_cluster.sh failed ({res.returncode}):\n{res.stdout[-3000:]}\n{res.stderr[-6000:]}"
    conf = res.stdout.strip().splitlines()[-1]
    assert conf.startswith("SLURM_CONF="), res.stdout
    return {"state": state, "env": _clean_env(SLURM_CONF=conf.split("=", 1)[1])}


def _squeue(env) -> dict[str, dict]:
    """Every job slurmctld still knows (MinJobAge=14400): id -> state, comment, limits."""
    res = subprocess.run(_timed(CALL_TIMEOUT, "squeue", "-h", "-t", "all", "-o", "%i|%T|%k|%l|%m|%C"),
                         env=env, capture_output=True, text=True, timeout=CALL_TIMEOUT + 60)
    assert res.returncode == 0, res.stderr
    jobs = {}
    for line in res.stdout.splitlines():
        jid, state, comment, limit, mem, cpus = line.strip().split("|")
        jobs[jid] = {"state": state, "comment": comment, "time_limit": limit, "min_memory": mem, "cpus": cpus}
    return jobs


def _job_counts(wd: Path) -> dict[str, int]:
    """Jobs per rule that a fresh run of ``wd`` will execute (snakemake's dry-run job stats)."""
    res = run_snakemake(wd, "-n", "--quiet", "rules", "--configfile", "config/test.yaml")
    assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]
    counts = {}
    for line in (res.stdout + res.stderr).splitlines():
        m = re.fullmatch(r"\s*([a-z_0-9]+)\s+(\d+)\s*", line)
        if m and m.group(1) != "total":
            counts[m.group(1)] = int(m.group(2))
    assert counts, res.stdout[-3000:]
    return counts


def _assert_same_outputs(local: Path, remote: Path):
    """The SLURM run wrote the files the local run wrote under results/, and every one of them but the timing tables
    holds what the local run's holds (:func:`run_outputs.outputs_that_differ`: tables byte for byte)."""
    assert (local / "results" / "summary.md").is_file(), f"{local} holds no finished local run"
    assert len(tables(local)) > 20, sorted(tables(local))  # the whole workflow, not just the data layer

    def files(root):
        return {str(p.relative_to(root)) for p in (root / "results").rglob("*") if p.is_file()}

    assert files(local) == files(remote), sorted(files(local) ^ files(remote))
    differ = outputs_that_differ(local, remote)
    assert not differ, f"{len(differ)} outputs differ between the local and the SLURM run: {differ[:20]}"


def _declared_sizes() -> dict[str, tuple[str, int, str]]:
    """rule -> (squeue min_memory, minutes, cpus) from the rule's own threads/resources (literal values)."""
    from test_rules import parse_rules

    out = {}
    for smk in sorted((REPO / "workflow" / "rules").glob("*.smk")):
        for name, info in parse_rules(smk).items():
            d = info["directives"]
            res = dict(re.findall(r"(\w+)\s*=\s*(\d+)\s*,?\s*$", "\n".join(d.get("resources", [])), re.M))
            threads = (d.get("threads") or [""])[0]
            if {"mem_mb", "runtime"} <= set(res) and threads.isdigit():
                out[name] = (f"{res['mem_mb']}M", int(res["runtime"]), threads)
    return out


def _minutes(limit: str) -> int:
    """squeue's %l time limit (MM:SS, H:MM:SS or D-HH:MM:SS) in minutes."""
    days, _, hms = limit.rpartition("-")
    parts = [int(x) for x in hms.split(":")]
    while len(parts) < 3:
        parts.insert(0, 0)
    return int(days or 0) * 1440 + parts[0] * 60 + parts[1] + (1 if parts[2] else 0)


@pytest.fixture
def local_reference(request) -> Path:
    """The local run of config/test.yaml to compare with: the session's ``tiny_workflow``, or
    (ANIMSYNTH_SLURM_LOCAL_REFERENCE=DIR) a finished local run made beforehand in DIR, e.g. with
    ``snakemake --cores 2 --configfile config/test.yaml`` in a copy of the workflow, with
    tests/papers copied to DIR/../shared/papers (to compare
    with a run made elsewhere, or to skip the local run when only the SLURM side is of interest)."""
    given = os.environ.get("ANIMSYNTH_SLURM_LOCAL_REFERENCE")
    if given:
        return Path(given)  # checked when compared: it may still be running now
    return request.getfixturevalue("tiny_workflow")


def test_whole_tiny_workflow_through_slurm_matches_local_run(slurm_cluster, local_reference, tmp_path):
    env = slurm_cluster["env"]
    before = set(_squeue(env))

    # The reference is the session's local run of config/test.yaml (tiny_workflow),
    # finished before this starts. (Not concurrently with the SLURM run: on 2
    # cores that slows the SLURM jobs past the plugin's status polls.)
    remote = copy_workflow(tmp_path / "slurm")
    place_papers(remote)  # the published tables beside it, as beside the local run
    expected = _job_counts(remote)
    n_jobs = sum(n for r, n in expected.items() if r != "all")  # `all` is local (localrule)

    # The whole workflow through SLURM with the profile, as docs/cluster.md tells users.
    cmd = _timed(RUN_TIMEOUT, SNAKEMAKE, "--workflow-profile", "profiles/slurm", *SLURM_TEST_ARGS,
                 "--configfile", "config/test.yaml")
    proc = subprocess.run(cmd, cwd=remote, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=RUN_TIMEOUT + 60)
    out = proc.stdout
    if proc.returncode != 0:
        slurm_logs = sorted((remote / ".snakemake" / "slurm_logs").rglob("*.log"))
        logs = "\n".join(f"--- {p}\n{p.read_text()[-3000:]}" for p in slurm_logs)
        pytest.fail(f"snakemake on SLURM failed (rc {proc.returncode}; 124 = timed out):\n{out[-6000:]}\n{logs[-8000:]}")

    # Every job went through sbatch: snakemake reports a SLURM job id for each...
    submitted = dict(re.findall(r"Job (\d+) has been submitted with SLURM jobid (\d+)", out))
    assert len(submitted) == n_jobs, (n_jobs, out[-4000:])
    slurm_ids = set(submitted.values())
    assert len(slurm_ids) == n_jobs
    # ... slurmctld accepted each of them as a batch job ...
    ctld_log = (slurm_cluster["state"] / "log" / "slurmctld.log").read_text()
    accepted = set(re.findall(r"_slurm_rpc_submit_batch_job: JobId=(\d+)", ctld_log))
    assert slurm_ids <= accepted, (slurm_ids - accepted, ctld_log[-3000:])
    # ... and ran it to completion, with the resources its rule declares.
    from test_rules import rule_info

    declared = _declared_sizes()
    jobs = {j: v for j, v in _squeue(env).items() if j not in before}
    assert set(jobs) == slurm_ids, (jobs, slurm_ids)
    rules = {}
    for jid, job in jobs.items():
        assert job["state"] == "COMPLETED", (jid, job)
        rule = re.match(r"rule_([a-z_0-9]+?)(?:_wildcards_|$)", job["comment"]).group(1)
        rules[rule] = rules.get(rule, 0) + 1
        # the threads/mem_mb/runtime that the rule itself declares
        if rule_info(declared, rule) is not None:  # a rule of a loop: its name pattern's entry
            mem, minutes, cpus = rule_info(declared, rule)
            assert (job["min_memory"], _minutes(job["time_limit"]), job["cpus"]) == (mem, minutes, cpus), (jid, rule, job)
    assert rules == {r: n for r, n in expected.items() if r != "all"}, rules
    # the comparison ran as its subjects' jobs side by side: one clips job per subject, one per subject and generator
    # (the rows of one method in one job: compare_run_<method>)
    subjects = {j["comment"].split("_wildcards_", 1)[1] for j in jobs.values()
                if j["comment"].startswith("rule_compare_clips_wildcards_")}
    assert len(subjects) >= 2 and rules.get("compare_run", 0) >= len(subjects), (subjects, rules)
    assert rules["compare_run"] % len(subjects) == 0, (subjects, rules)
    assert all(rules.get(f"compare_run_{m}") == len(subjects) for m in ("simplicial", "motion_matching")), rules
    # Each batch script runs this venv's interpreter (`<venv>/bin/python -m snakemake`
    # ... --executor slurm-jobstep), and each job left its SLURM log.
    venv_bin = str(Path(sys.executable).parent) + os.sep
    for jid in sorted(slurm_ids, key=int)[:10]:  # a sample: scontrol per job is slow
        res = subprocess.run(_timed(CALL_TIMEOUT, "scontrol", "write", "batch_script", jid, "-"),
                             env=env, capture_output=True, text=True, timeout=CALL_TIMEOUT + 60)
        assert res.returncode == 0, res.stderr
        command = [line for line in res.stdout.splitlines() if "-m snakemake" in line]
        assert command and command[0].startswith(venv_bin), (jid, res.stdout[:500])
        assert "--executor slurm-jobstep" in command[0], (jid, command[0][:300])
    slurm_logs = sorted((remote / ".snakemake" / "slurm_logs").rglob("*.log"))
    assert len(slurm_logs) == n_jobs, len(slurm_logs)

    # every output: the SLURM run is a whole second run of the config, so this is the determinism check of every
    # job (tests/test_workflow.py then leaves its partial second run out)
    _assert_same_outputs(local_reference, remote)
    if not os.environ.get("ANIMSYNTH_SLURM_LOCAL_REFERENCE"):  # the session's own tiny run, compared whole
        WHOLE_RUN_COMPARED["tiny"] = True
