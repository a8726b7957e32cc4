"""Shared fixtures: paths to the real data in ../shared, and one run of the
whole workflow on the tiny config (config/test.yaml) shared by the workflow tests."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("ANIMSYNTH_SHARED_DATA", REPO.parent / "shared" / "data"))
CMU = SHARED / "cmu_mocap"
VLASIC = SHARED / "vlasic_mesh_animation"
SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))


def need(path: Path):
    """Skip (with the reason) when a real-data folder is absent."""
    if not path.exists():
        pytest.skip(f"real data not available: {path} is absent (it lives in ../shared/data, never in the repo)")
    return path


@pytest.fixture(scope="session")
def cmu_dir():
    return need(CMU / "subjects")


@pytest.fixture(scope="session")
def vlasic_dir():
    return need(VLASIC)


def copy_workflow(dest: Path) -> Path:
    """Copy what a workflow run needs (not results/, resources/, .venv) into ``dest``."""
    dest.mkdir(parents=True, exist_ok=True)
    for name in ("Snakefile", "config", "workflow", "profiles", "benchmarks"):
        src = REPO / name
        if src.is_dir():
            skip = {"rules", ".results"} if name == "benchmarks" else set()
            shutil.copytree(src, dest / name, dirs_exist_ok=True,
                            ignore=lambda d, names, skip=skip, top=str(src): [
                                n for n in names if n == "__pycache__" or (d == top and n in skip)])
        else:
            shutil.copy2(src, dest / name)
    return dest


def run_snakemake(workdir: Path, *args, timeout: int = 1500) -> subprocess.CompletedProcess:
    cmd = [SNAKEMAKE, "--cores", "2", *args]
    return subprocess.run(cmd, cwd=workdir, capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="session")
def tiny_workflow(tmp_path_factory):
    """Run the whole workflow once on config/test.yaml; return the working directory."""
    wd = copy_workflow(tmp_path_factory.mktemp("tiny_workflow"))
    res = run_snakemake(wd, "--configfile", "config/test.yaml")
    if res.returncode != 0:
        pytest.fail("tiny workflow failed:\n" + res.stdout[-4000:] + "\n" + res.stderr[-8000:])
    return wd
