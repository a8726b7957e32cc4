"""Ctrl-C of ``python3 run.py``: Snakemake finishes its own shutdown (its lock and incomplete outputs removed),
run.py says so in one line and exits 130, and the same command resumes to the tables of an uninterrupted run."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import REPO, SAFETY_TIMEOUT, copy_finished_run, place_papers

pytestmark = pytest.mark.workflow

#: a small part of the tiny run: Table I's lengths, rebuilt in a copy of the finished tiny run whose 12 parsed trials
#: and Table I are removed (13 jobs; the synthetic trials the parse jobs read are kept, so none of the 12
#: synth_trial jobs runs again)
TARGET = "results/data/datasets.csv"
REMOVED = ("results/data/trials/*.npz", TARGET, "results/data/datasets.md")


def _run_py(wd: Path, **kw) -> subprocess.Popen:
    """``python3 run.py snakemake --cores 1 TARGET --configfile config/test.yaml`` in ``wd``, in a process group of
    its own (as a terminal starts a command), with this test's virtual environment."""
    env = dict(os.environ, ANIMSYNTH_VENV=str(Path(sys.executable).parents[1]))
    cmd = [sys.executable, "run.py", "snakemake", "--cores", "1", TARGET, "--configfile", "config/test.yaml"]
    return subprocess.Popen(cmd, cwd=wd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, **kw)


def test_ctrl_c_leaves_no_lock_and_the_same_command_resumes(tiny_workflow, tmp_path):
    wd = copy_finished_run(tiny_workflow, tmp_path / "run")
    for pattern in REMOVED:
        for p in wd.glob(pattern):
            p.unlink()
    assert not list((wd / "results/data/trials").glob("*.npz"))
    for name in ("run.py", "pyproject.toml"):  # run.py checks the venv against pyproject.toml
        shutil.copy2(REPO / name, wd / name)
    place_papers(wd)
    proc = _run_py(wd)
    # Ctrl-C once a job has finished (the first parsed trial) while the next one runs: SIGINT to the process
    # group, as a terminal sends it to run.py and Snakemake together
    deadline = time.monotonic() + SAFETY_TIMEOUT
    while not list((wd / "results/data/trials").glob("*.npz")) and proc.poll() is None:
        assert time.monotonic() < deadline, "no job finished"
        time.sleep(0.1)
    assert proc.poll() is None, "the run ended before it could be interrupted:\n" + proc.communicate()[1][-3000:]
    os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=SAFETY_TIMEOUT)
    assert proc.returncode == 130, err[-3000:]
    said = [ln for ln in err.splitlines() if ln.startswith("[run.py] interrupted")]
    assert len(said) == 1 and "the same command resumes" in said[0], err[-3000:]
    assert "Terminating processes on user request" in err  # Snakemake's own shutdown ran
    assert 'run.py", line' not in err  # no traceback of run.py's (a job's own KeyboardInterrupt is in its log)
    assert not list((wd / ".snakemake/locks").glob("*")), "Snakemake's lock is left behind"
    assert not (wd / TARGET).exists()
    # the same command resumes (no LockException), and the table equals the uninterrupted tiny run's
    again = _run_py(wd)
    out2, err2 = again.communicate(timeout=SAFETY_TIMEOUT)
    assert again.returncode == 0, err2[-3000:]
    assert "LockException" not in err2
    for rel in (TARGET, "results/data/datasets.md"):
        assert (wd / rel).read_bytes() == (tiny_workflow / rel).read_bytes(), rel
