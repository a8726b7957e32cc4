#!/usr/bin/env python3
"""One entry point for newcomers (needs only Python >= 3.11 and pip):

    python3 run.py            # full default reproduction + report (results/)
    python3 run.py paper [--config cmu_mirror=... mesh_dir=...]
                              # all four papers on real data -> results/paper/
    python3 run.py test       # the test suite (what CI runs); add -m "not workflow" for the fast unit subset
    python3 run.py bench      # the performance benchmarks at full size -> results/bench/benchmarks.csv
    python3 run.py snakemake ARGS...   # any snakemake call inside the project's venv

Every --configfile given (and the config/*.yaml files run.py passes itself) is
checked first for YAML aliases that expand past a size limit ("billion
laughs"), before Snakemake loads and merges it: a plain `snakemake
--configfile` merges the file before any project code runs.

Targets may come before or after --configfile / --config: a value of
--configfile that is not a .yaml/.yml/.json file, or of --config without
"=", is read as a target (run.py says so) and passed first.

It creates ./.venv on first use (or when pyproject.toml changes) and installs
the pinned stack from pyproject.toml into it. Set ANIMSYNTH_VENV to use
another location.
"""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import tomllib
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parent
VENV = Path(os.environ.get("ANIMSYNTH_VENV", ROOT / ".venv"))
BIN = VENV / ("Scripts" if os.name == "nt" else "bin")
PY = BIN / ("python.exe" if os.name == "nt" else "python")


# The real-data reproduction: CMU trials, the samba meshes, then the paper run's
# own settings (results/paper/, skip a family whose data are unavailable).
PAPER_CONFIG = ("--configfile", "config/cmu.yaml", "config/samba.yaml", "config/paper.yaml")
DEMO_NOTE = """
[run.py] Done: results/summary.md and results/report.html.
[run.py] This was a DEMO on synthetic data (every study of the four papers, at demo size). The real-data
[run.py] reproduction at full size (CMU mocap, the samba meshes):
[run.py]   python3 run.py paper --config cmu_mirror=../shared/data/cmu_mocap mesh_dir=../shared/data/vlasic_mesh_animation/samba
"""
# The performance benchmarks at the sizes their targets are stated for, in a results folder of their own.
BENCH_DIR = "results/bench"


def ensure_venv() -> None:
    if sys.version_info < (3, 11):
        sys.exit(f"animsynth needs Python >= 3.11 (this is {sys.version.split()[0]})")
    stamp = VENV / ".animsynth-installed"
    want = hashlib.sha256((ROOT / "pyproject.toml").read_bytes()).hexdigest()
    if stamp.exists() and stamp.read_text().strip() == want and PY.exists():
        return
    if not PY.exists():
        print(f"[run.py] creating virtual environment {VENV}", flush=True)
        venv.EnvBuilder(with_pip=True).create(VENV)
    print("[run.py] installing the pinned stack (pyproject.toml) ...", flush=True)
    subprocess.check_call([str(PY), "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                           "-e", f"{ROOT}[test]"])
    no_deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["animsynth"]["no_deps"]
    if no_deps:  # packages whose declared requirements cannot be installed (see pyproject.toml)
        subprocess.check_call([str(PY), "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                               "--no-deps", *no_deps])
    stamp.write_text(want + "\n")


def split_option(args: list[str], names: tuple[str, ...]) -> tuple[list[str], list[str]]:
    """(``args`` without the options ``names``, the values given to them): ``--opt v1 v2 ...`` (values up to
    the next argument starting with ``-``) and ``--opt=v`` both count."""
    rest, values, taking = [], [], False
    for a in args:
        opt, eq, val = a.partition("=")
        if opt in names:
            taking = not eq
            if eq:
                values.append(val)
        elif a.startswith("-"):
            taking = False
            rest.append(a)
        elif taking:
            values.append(a)
        else:
            rest.append(a)
    return rest, values


#: What a config file's name ends with; any other value after --configfile is a target.
CONFIG_SUFFIXES = (".yaml", ".yml", ".json")


def sort_targets(args: list[str]) -> tuple[list[str], list[str]]:
    """``(args with the targets first, the targets moved)``.

    Snakemake's ``--configfile`` (and ``--config``) take every value up to the next option, so a target
    written after them (``--configfile mine.yaml results/x/verdicts.csv``) would be read as a config file
    (or a KEY=VALUE pair). A value of ``--configfile`` / ``--configfiles`` whose name does not end with
    :data:`CONFIG_SUFFIXES`, and a value of ``--config`` without ``=``, is a target: it is moved in front.
    """
    out, moved, mode = [], [], None
    for a in args:
        opt, eq, _ = a.partition("=")
        if a.startswith("-"):
            mode = opt if opt in ("--configfile", "--configfiles", "--config") and not eq else None
            out.append(a)
        elif mode in ("--configfile", "--configfiles") and not a.lower().endswith(CONFIG_SUFFIXES):
            moved.append(a)
        elif mode == "--config" and "=" not in a:
            moved.append(a)
        else:
            out.append(a)
    return moved + out, moved


def with_targets_first(args: list[str]) -> list[str]:
    """:func:`sort_targets`, saying which values it read as targets."""
    args, moved = sort_targets(args)
    if moved:
        print(f"[run.py] read as target(s), not config: {' '.join(moved)} (config files end with "
              f"{', '.join(CONFIG_SUFFIXES)}; --config takes KEY=VALUE)", flush=True)
    return args


def one_configfile_option(args: list[str]) -> list[str]:
    """``args`` with every ``--configfile`` / ``--configfiles`` option joined into one, at the place of the first,
    its files in the order given.

    Snakemake keeps only the last ``--configfile`` option, so ``python3 run.py paper --configfile mine.yaml``
    would otherwise run on ``mine.yaml`` alone, without config/cmu.yaml, samba.yaml and paper.yaml that run.py
    passes first: a user's config over the paper run is meant (its trials mapping adds to cmu.yaml's).
    """
    names = ("--configfile", "--configfiles")
    rest, files = split_option(args, names)
    if not files:
        return list(args)
    first = next(i for i, a in enumerate(args) if a.partition("=")[0] in names)
    before = split_option(args[:first], names)[0]
    return [*before, "--configfile", *files, *rest[len(before):]]


def snakemake_args(command: str, argv: list[str]) -> list[str]:
    """The Snakemake arguments of ``python3 run.py COMMAND ARGV...`` (paper, bench, snakemake): targets first
    (:func:`with_targets_first`), for ``paper`` the paper run's config files before the user's, and every config
    file in one ``--configfile`` option (:func:`one_configfile_option`)."""
    args = with_targets_first(argv)
    if command == "paper":
        args = sort_targets([*PAPER_CONFIG, *args])[0]
    return one_configfile_option(args)


def bench_args(argv: list[str]) -> tuple[list[str], list[str]]:
    """Split snakemake arguments into (the others, the KEY=VALUE pairs of a --config option)."""
    return split_option(argv, ("--config",))


def configfiles(args: list[str]) -> list[str]:
    """The files given to snakemake's ``--configfile`` / ``--configfiles`` in ``args``."""
    return split_option(args, ("--configfile", "--configfiles"))[1]


def check_configfiles(files: list[str]) -> str | None:
    """The first refusal of ``animsynth.config.check_config_file`` among
    ``files`` (relative to the project, where snakemake runs), as one line
    naming the file, or None. Needs the project's packages (runs in the venv)."""
    from animsynth.config import ConfigError, check_config_file

    for f in files:
        path = Path(f) if Path(f).is_absolute() else ROOT / f
        try:
            check_config_file(path)
        except ConfigError as exc:
            return str(exc)
    return None


def prescan(args: list[str]) -> int:
    """Check the config files among snakemake ``args`` in the venv; 0 if fine, 2 (and one line) if not."""
    files = configfiles(args)
    if not files:
        return 0
    return call([str(PY), str(Path(__file__).resolve()), "_check-configfiles", *files], "the config check", cwd=ROOT)


#: Snakemake's dry-run options.
DRY_RUN = {"-n", "--dry-run", "--dryrun"}

#: The exit code of a command stopped by Ctrl-C (128 + SIGINT, as a shell reports it).
INTERRUPTED = 130


def call(cmd: list[str], what: str = "", **kwargs) -> int:
    """Run ``cmd`` and return its exit code; :data:`INTERRUPTED` (and one line) when Ctrl-C stopped it.

    ``subprocess.call`` kills its child 0.25 s after a Ctrl-C, which leaves Snakemake's lock (every rerun is
    then refused) and half-written outputs behind. Here a Ctrl-C (SIGINT, which the terminal sends to run.py
    and Snakemake together, as one process group) only marks the run as interrupted: Snakemake cancels its
    jobs, removes their incomplete outputs and its lock, and exits in its own time; run.py waits for it. A
    SIGTERM sent to run.py alone (a scheduler stopping the run) is passed on to Snakemake, which then lets
    its running jobs finish and stops. The same command afterwards resumes where the run stopped.

    ``what``: how the one line names the command ("snakemake": it also says how to resume).
    """
    stopped, procs = [], []

    def on_signal(signum, _frame):
        stopped.append(signum)
        if signum == signal.SIGTERM and procs and procs[0].poll() is None:
            procs[0].send_signal(signal.SIGTERM)

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        procs.append(subprocess.Popen(cmd, **kwargs))
        rc = procs[0].wait()
    finally:
        for s, h in old.items():
            signal.signal(s, h)
    if stopped or rc in (-signal.SIGINT, INTERRUPTED):
        what = what or Path(cmd[0]).name
        tail = (" after removing its lock and incomplete outputs; the same command resumes the run"
                if what == "snakemake" else "")
        print(f"[run.py] interrupted: {what} stopped{tail}", file=sys.stderr, flush=True)
        return INTERRUPTED
    return rc


def sh(*args: str) -> int:
    print("[run.py] " + " ".join(args), flush=True)
    return call(list(args), "snakemake" if Path(args[0]).name == "snakemake" else "", cwd=ROOT)


# ----------------------------------------------------------------------------- the run's CPU breakdown
# Snakemake runs inside a small wrapper that records, when it exits, the CPU time of its own process
# (DAG, job selection, benchmark sampling, status checks) apart from that of the processes it started
# and waited for (the jobs, from interpreter start-up to exit). run.py writes them, beside the jobs' CPU
# as their benchmark files measured it, to <results_dir>/run_cost.csv.
MEASURED_SNAKEMAKE = """
import atexit, json, os, resource, sys, time
_pid, _t0 = os.getpid(), time.perf_counter()
def _record():
    if os.getpid() != _pid:
        return
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    with open(os.environ["ANIMSYNTH_RUN_COST"], "a") as f:
        f.write(json.dumps({"label": os.environ.get("ANIMSYNTH_RUN_COST_LABEL", ""), "wall_s": time.perf_counter() - _t0,
                            "self_user_s": me.ru_utime, "self_system_s": me.ru_stime,
                            "children_user_s": kids.ru_utime, "children_system_s": kids.ru_stime}) + "\\n")
atexit.register(_record)
sys.argv[0] = "snakemake"
from snakemake.cli import main
sys.exit(main())
"""


class RunCost:
    """CPU accounting of one ``run.py`` call: every Snakemake call it makes, and run.py itself."""

    def __init__(self) -> None:
        import tempfile
        import time

        fd, self.path = tempfile.mkstemp(prefix="animsynth-run-cost-", suffix=".jsonl")
        os.close(fd)
        self.t0 = time.perf_counter()

    def snakemake(self, label: str, *args: str) -> int:
        """Run ``snakemake ARGS`` (as :func:`sh` does) and record its CPU under ``label``."""
        print("[run.py] " + " ".join([str(BIN / "snakemake"), *args]), flush=True)
        env = dict(os.environ, ANIMSYNTH_RUN_COST=self.path, ANIMSYNTH_RUN_COST_LABEL=label)
        return call([str(PY), "-c", MEASURED_SNAKEMAKE, *args], "snakemake", cwd=ROOT, env=env)

    def write(self, results_dir: str) -> None:
        """``results_dir``/run_cost.csv: where the CPU time of this run.py call went."""
        import csv
        import json
        import resource
        import time

        with open(self.path) as f:
            calls = [json.loads(line) for line in f if line.strip()]
        os.unlink(self.path)
        me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        total_user, total_sys = me.ru_utime + kids.ru_utime, me.ru_stime + kids.ru_stime
        rows = []

        def row(part, user, system, note, wall=""):
            rows.append({"part": part, "cpu_s": round(user + system, 1), "user_s": round(user, 1),
                         "system_s": round(system, 1), "wall_s": wall if wall == "" else round(wall, 1),
                         "note": note})

        bench = Path(ROOT, results_dir, "rule_benchmarks.csv")
        job_cpu = None
        if bench.exists():
            with open(bench, newline="") as f:
                job_cpu = sum(float(r["cpu_time_s"] or 0) for r in csv.DictReader(f) if r["cpu_time_s"] not in ("", "nan"))
        used_user = used_sys = 0.0
        for c in calls:
            used_user += c["self_user_s"] + c["children_user_s"]
            used_sys += c["self_system_s"] + c["children_system_s"]
            kid = c["children_user_s"] + c["children_system_s"]
            if c["label"] == "run" and job_cpu is not None:
                row("jobs: CPU in their benchmark files (rule_benchmarks.csv)", job_cpu, 0.0,
                    "sum of cpu_time_s over this run's jobs (per family: rule_benchmarks_per_family.csv); "
                    "user and system time together")
                row("jobs: CPU their benchmark files missed", max(kid - job_cpu, 0.0), 0.0,
                    "job processes as the OS counted them minus the benchmark files: Snakemake samples a job's "
                    "CPU every 0.5 s, then every 30 s, so the time after a job's last sample is not in its file; "
                    "negative differences (files of jobs that did not run in this call) count as 0")
            else:
                row(f"{c['label']}: processes Snakemake started", c["children_user_s"], c["children_system_s"],
                    "every process the Snakemake call started and waited for")
            row(f"{c['label']}: Snakemake's own process", c["self_user_s"], c["self_system_s"],
                "parsing and DAG, job selection, benchmark sampling, status checks", c["wall_s"])
        row("run.py (venv check, config prescan)", total_user - used_user, total_sys - used_sys,
            "run.py and the processes it started other than Snakemake")
        row("total", total_user, total_sys, "everything this run.py call used", time.perf_counter() - self.t0)
        out = Path(ROOT, results_dir, "run_cost.csv")
        out.parent.mkdir(parents=True, exist_ok=True)
        with open(out, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        print(f"[run.py] CPU time of this run: {(total_user + total_sys) / 60:.1f} min; breakdown in {out}",
              flush=True)


def results_dir_of(args: list[str], default: str) -> str:
    """The results_dir a ``--config results_dir=DIR`` among ``args`` sets (else ``default``)."""
    found = default
    for a in args:
        if a.startswith("results_dir="):
            found = a.split("=", 1)[1]
    return found


def main(argv: list[str]) -> int:
    if argv[:1] == ["_check-configfiles"]:  # run by prescan() inside the venv
        msg = check_configfiles(argv[1:])
        if msg:
            print(f"[run.py] {msg}", file=sys.stderr, flush=True)
            return 2
        return 0
    ensure_venv()
    snakemake = str(BIN / "snakemake")
    if not argv:
        cost = RunCost()
        rc = cost.snakemake("run", "--cores", str(os.cpu_count() or 2))
        if rc == 0:
            rc = cost.snakemake("report", "--report", "results/report.html")
        if rc == 0:
            cost.write("results")
            print(DEMO_NOTE, flush=True)
        return rc
    if argv[0] in ("paper", "bench", "snakemake"):
        args = snakemake_args(argv[0], argv[1:])
        rc = prescan(args)
        if rc:  # 2: a config file refused (one line printed); 130: interrupted
            return rc
    if argv[0] == "paper":
        # Extra arguments (e.g. --config cmu_mirror=DIR mesh_dir=DIR) go to both calls; a dry run (-n) or a run of
        # named targets makes no report and no CPU breakdown (they describe the whole run).
        cost = RunCost()
        rc = cost.snakemake("run", "--cores", str(os.cpu_count() or 2), *args)
        whole = not (DRY_RUN & set(args) or args[:1] and not args[0].startswith("-"))
        if rc == 0 and whole:
            rc = cost.snakemake("report", *args, "--report", "results/paper/report.html")
        if rc == 0 and whole:
            cost.write(results_dir_of(args, "results/paper"))
        else:
            os.unlink(cost.path)
        return rc
    if argv[0] == "bench":
        # Extra arguments go to snakemake; KEY=VALUE pairs after --config join the bench run's own (snakemake
        # keeps only the last --config option).
        args, extra = bench_args(args)
        return sh(snakemake, "--cores", str(os.cpu_count() or 2), f"{BENCH_DIR}/benchmarks.csv", *args,
                  "--config", *extra, f"results_dir={BENCH_DIR}", "benchmark_size=full")
    if argv[0] == "test":
        return sh(str(PY), "-m", "pytest", *argv[1:])
    if argv[0] == "snakemake":
        return sh(snakemake, *args)
    print(__doc__)
    return 2


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except KeyboardInterrupt:  # Ctrl-C outside a Snakemake call (the venv set-up, the config prescan)
        if sys.argv[1:2] != ["_check-configfiles"]:  # the prescan's parent says it
            print("[run.py] interrupted", file=sys.stderr, flush=True)
        sys.exit(INTERRUPTED)
