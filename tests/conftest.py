"""Shared fixtures: paths to the real data in ../shared, and one run of the
whole workflow on the tiny config (config/test.yaml) shared by the workflow tests.

The tiny run sees made-up tables in the layout of the published ones (tests/papers/,
the file names and columns of ../shared/papers/, none of its values) at
``../shared/papers`` relative to its working directory,
where the default configuration looks for them, so its "ours minus paper"
columns hold numbers; :func:`tiny_without_papers` rebuilds only the tables that
read them in a copy of the finished run where that folder is absent.

No test depends on how long a run takes: every subprocess gets the same
generous safety limit (:data:`SAFETY_TIMEOUT`), there only so that a hung
process cannot block a CI job forever."""

from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from threadpoolctl import threadpool_limits

# One BLAS thread in the test process, as the workflow's jobs run their heavy loops: on a busy 2-core
# machine OpenBLAS's threads turned scipy's first Delaunay.find_simplex (a thousand small LAPACK calls)
# from 1 ms into 9 s. Subprocesses (snakemake runs) are not affected.
_BLAS_LIMIT = threadpool_limits(1, user_api="blas")

REPO = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("ANIMSYNTH_SHARED_DATA", REPO.parent / "shared" / "data"))
CMU = SHARED / "cmu_mocap"
#: the comparison's extra subjects (config/cmu.yaml trials with mirror: many; config/paper.yaml's cmu_many_mirror)
CMU_MANY = SHARED / "cmu_mocap_many"
VLASIC = SHARED / "vlasic_mesh_animation"
SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))
PAPERS = REPO / "tests" / "papers"
#: Seconds any one subprocess of a test may run before it is killed: a guard against a hang, far above
#: what a run costs even on a busy machine (never a measure of speed).
SAFETY_TIMEOUT = 3 * 3600


def merged_config(*names: str, validate: bool = True) -> dict:
    """The config files ``names`` of config/ merged as Snakemake merges ``--configfile`` files (each over the ones
    before), then validated against the schema (defaults filled in) unless ``validate`` is false."""
    import yaml
    from snakemake.utils import update_config

    from animsynth.config import validate_config

    cfg: dict = {}
    for name in names:
        update_config(cfg, yaml.safe_load((REPO / "config" / name).read_text()))
    if validate:
        validate_config(cfg, str(REPO / "config" / "schema.yaml"))
    return cfg


_DEFAULT_CONFIG: dict = {}


def default_config() -> dict:
    """The embedded default config (config/config.yaml), validated against the schema (defaults filled in): parsed
    and validated once per test process (the key: both files' modification times and sizes), a deep copy per call,
    so a test may change what it gets."""
    import copy

    import yaml

    from animsynth.config import validate_config

    files = (REPO / "config" / "config.yaml", REPO / "config" / "schema.yaml")
    key = tuple((f.stat().st_mtime_ns, f.stat().st_size) for f in files)
    if key not in _DEFAULT_CONFIG:
        cfg = yaml.safe_load(files[0].read_text())
        validate_config(cfg, str(files[1]))
        _DEFAULT_CONFIG.clear()
        _DEFAULT_CONFIG[key] = cfg
    return copy.deepcopy(_DEFAULT_CONFIG[key])


def need(path: Path):
    """Skip (with the reason) when a real-data folder is absent."""
    if not path.exists():
        pytest.skip(f"real data not available: {path} is absent (it lives in ../shared/data, never in the repo)")
    return path


@pytest.fixture(scope="session")
def cmu_dir():
    return need(CMU / "subjects")


@pytest.fixture(scope="session")
def cmu_many_dir():
    return need(CMU_MANY / "subjects")


@pytest.fixture(scope="session")
def vlasic_dir():
    return need(VLASIC)


@pytest.fixture(scope="module")
def cfg():
    """The comparison's generator-job config from the default config (config/config.yaml): every generator's
    block at once (the workflow's ``job_cfg``), the clips job's keys, and ``seeds=2``."""
    from animsynth.compare import settings

    config = default_config()
    return dict(settings.job_cfg(config), **settings.clips_cfg(config), seeds=2)


def _walks_30fps(subject: str, seed: int) -> list:
    """Four synthetic ``walk_straight`` trials (seeds 0-3, named w0-w3) of the CMU-like skeleton ``(subject, seed)``,
    240 frames at 120 fps resampled to 30 fps (every 4th frame: 60 frames each)."""
    from animsynth.compare import protocol
    from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

    sk = cmu_like_skeleton(subject, seed)
    return [protocol.resample(generate_motion("walk_straight", 240, s, sk, name=f"w{s}"), 30.0) for s in range(4)]


@pytest.fixture(scope="module")
def walks():
    """The comparison tests' database: four short synthetic walks of one subject (skeleton ``("cmp", 3)``) at
    30 fps, 60 frames each (:func:`_walks_30fps`)."""
    return _walks_30fps("cmp", 3)


@pytest.fixture(scope="module")
def est_walks():
    """The estimator tests' walks: built as :func:`walks` but on another subject (skeleton ``("est", 2)``). The
    golden values of tests/test_estimators.py were recorded on exactly these, so they must not change."""
    return _walks_30fps("est", 2)


def copy_workflow(dest: Path) -> Path:
    """Copy what a workflow run needs (not results/, resources/, .venv) into ``dest``."""
    dest.mkdir(parents=True, exist_ok=True)
    for name in ("Snakefile", "config", "workflow", "profiles", "benchmarks"):
        src = REPO / name
        if src.is_dir():
            skip = set()
            shutil.copytree(src, dest / name, dirs_exist_ok=True,
                            ignore=lambda d, names, skip=skip, top=str(src): [
                                n for n in names if n == "__pycache__" or (d == top and n in skip)])
        else:
            shutil.copy2(src, dest / name)
    return dest


def run_snakemake(workdir: Path, *args, timeout: int = SAFETY_TIMEOUT) -> subprocess.CompletedProcess:
    cmd = [SNAKEMAKE, "--cores", "2", *args]
    return subprocess.run(cmd, cwd=workdir, capture_output=True, text=True, timeout=timeout)


def place_papers(workdir: Path) -> Path:
    """Put the published tables where the default config looks for them: ``<workdir>/../shared/papers``."""
    dest = workdir.parent / "shared" / "papers"
    shutil.copytree(PAPERS, dest, dirs_exist_ok=True)
    return dest


@pytest.fixture(scope="session")
def tiny_workflow(tmp_path_factory):
    """Run the whole workflow once on config/test.yaml (published tables beside it); return the working
    directory. The session's only full run: every other workflow test reads it or copies it."""
    root = tmp_path_factory.mktemp("tiny_workflow")  # holds run/ and shared/papers/, nothing else
    wd = copy_workflow(root / "run")
    place_papers(wd)
    res = run_snakemake(wd, "--configfile", "config/test.yaml")
    if res.returncode != 0:
        pytest.fail("tiny workflow failed:\n" + res.stdout[-4000:] + "\n" + res.stderr[-8000:])
    return wd


def copy_finished_run(src: Path, dest: Path) -> Path:
    """A copy of a finished run (workflow, resources, results, logs, snakemake metadata), times kept."""
    shutil.copytree(src, dest, symlinks=True)
    return dest


#: The tables that read the published values (each with its rule's other outputs).
PAPER_TABLES = ("results/data/datasets.csv", "results/simplicial/table2.csv", "results/facegraph/table1.csv",
                "results/resequencing/table2_min_k.csv")


@pytest.fixture(scope="session")
def tiny_without_papers(tiny_workflow, tmp_path_factory):
    """The finished tiny run copied where no ``../shared/papers`` exists, with the tables that read the
    published values (:data:`PAPER_TABLES`) rebuilt there (those jobs only); return its directory."""
    root = tmp_path_factory.mktemp("tiny_without_papers")
    wd = copy_finished_run(tiny_workflow, root / "run")
    assert not (wd / "../shared/papers").exists()
    for rel in PAPER_TABLES:
        (wd / rel).unlink()
    res = run_snakemake(wd, *PAPER_TABLES, "--configfile", "config/test.yaml", "--rerun-triggers", "mtime")
    if res.returncode != 0:
        pytest.fail("rebuilding the paper tables failed:\n" + res.stdout[-4000:] + "\n" + res.stderr[-8000:])
    return wd


def pytest_addoption(parser):
    parser.addoption("--cpu-report", metavar="CSV", default=None,
                     help="write each test phase's CPU seconds (user + system of the test process and of every "
                          "subprocess it waited for, e.g. snakemake runs) and wall seconds to CSV, slowest first; "
                          "a fixture's setup is charged to the first test that asks for it")


def _cpu_seconds() -> float:
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


@pytest.hookimpl(wrapper=True)
def pytest_runtest_setup(item):
    return (yield from _timed(item, "setup"))


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item):
    return (yield from _timed(item, "call"))


@pytest.hookimpl(wrapper=True)
def pytest_runtest_teardown(item, nextitem):
    return (yield from _timed(item, "teardown"))


def _timed(item, phase: str):
    """Run one phase of a test (the generator-style hook wrapper's ``yield``) and, with ``--cpu-report``, keep its
    CPU and wall seconds."""
    import time

    if item.config.getoption("--cpu-report") is None:
        return (yield)
    c0, t0 = _cpu_seconds(), time.perf_counter()
    try:
        return (yield)
    finally:
        item.config.stash.setdefault(_CPU_ROWS, []).append(
            (item.nodeid, phase, _cpu_seconds() - c0, time.perf_counter() - t0))


_CPU_ROWS = pytest.StashKey[list]()


def pytest_sessionfinish(session):
    path = session.config.getoption("--cpu-report")
    rows = session.config.stash.get(_CPU_ROWS, [])
    if path and rows:
        import csv

        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["test", "phase", "cpu_s", "wall_s"])
            w.writerows((t, ph, f"{c:.2f}", f"{s:.2f}") for t, ph, c, s in sorted(rows, key=lambda r: -r[2]))


def pytest_collection_modifyitems(config, items):
    """A test that reads the tiny run must be marked ``workflow``, so ``-m "not workflow"`` never starts it."""
    bad = [i.nodeid for i in items if {"tiny_workflow", "tiny_without_papers"} & set(getattr(i, "fixturenames", ()))
           and i.get_closest_marker("workflow") is None]
    if bad:
        raise pytest.UsageError("tests using the tiny workflow run must be marked workflow: " + ", ".join(bad))


def write_small_trial(folder: Path, frames: int) -> Path:
    """A synthetic CMU-layout trial ``c.asf`` + ``c.amc`` (a walk of ``frames`` frames) in ``folder``."""
    from animsynth.io import write_amc, write_asf
    from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

    sk = cmu_like_skeleton("c", 1)
    write_asf(folder / "c.asf", sk, length_unit=0.45)
    write_amc(folder / "c.amc", generate_motion("walk_straight", frames, 0, sk))
    return folder


def config_block(family: str, overrides: dict | None = None, files=("config.yaml",)) -> dict:
    """The ``family`` block of ``config/<files>`` merged in order (as snakemake merges ``--configfile``s), with
    ``overrides`` merged over it, validated by config/schema.yaml (which fills every default, as in a run)."""
    import copy

    import yaml
    from snakemake.utils import update_config

    from animsynth.config import validate_config

    cfg = {}
    for name in files:
        update_config(cfg, yaml.safe_load((REPO / "config" / name).read_text()))
    update_config(cfg, {family: copy.deepcopy(overrides or {})})
    validate_config(cfg, str(REPO / "config" / "schema.yaml"))
    return cfg[family]
