"""A user generator's child process ends with its job, whatever ends the job (a normal end, the time limit, a
SIGKILL of the job), and so does every process the class started; the write guard sees dir_fd calls and links, and
a class cannot signal its job."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from animsynth.compare.generators.user import UserGeneratorError, UserProcess, close_processes, user_process
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

from conftest import SAFETY_TIMEOUT

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="process groups and /proc: Linux")


def _alive(pid: int) -> bool:
    """A process that exists and is not a zombie (a killed process not yet reaped by whoever adopted it)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _wait_gone(pids, what: str) -> None:
    deadline = time.monotonic() + 60  # a guard against a hang only: a SIGKILL takes effect at once
    while any(_alive(p) for p in pids):
        if time.monotonic() > deadline:
            left = [p for p in pids if _alive(p)]
            for p in left:  # this test started them: stop them before failing
                os.kill(p, signal.SIGKILL)
            pytest.fail(f"{what}: still running: {left}")
        time.sleep(0.05)


def _wait_file(path, proc=None):
    deadline = time.monotonic() + SAFETY_TIMEOUT
    while not (path.exists() and path.read_text().strip()):
        assert proc is None or proc.poll() is None, f"the job ended with {proc.returncode}"
        assert time.monotonic() < deadline, f"{path} never written"
        time.sleep(0.05)
    return [int(x) for x in path.read_text().split()]


def _clips():
    return [generate_motion("walk_straight", 30, 0, cmu_like_skeleton("u", 1), name="t0")]


#: a class whose fit starts a background process, records both process ids, then either returns or spins forever
CLASS = """
import os, subprocess


class Starts:
    spin = False

    def fit(self, database):
        bg = subprocess.Popen(["sleep", "600"])
        with open({pids!r} + ".tmp", "w") as fh:
            fh.write(f"{{os.getpid()}} {{bg.pid}}")
        os.replace({pids!r} + ".tmp", {pids!r})
        while self.spin:
            pass
        return self

    def generate(self, start, length, seed):
        return start


class Spins(Starts):
    spin = True


class Sleeps(Starts):
    def fit(self, database):
        import time

        super().fit(database)
        time.sleep(600)
"""


def _write_class(tmp_path):
    pids = tmp_path / "pids.txt"
    (tmp_path / "mine.py").write_text(CLASS.format(pids=str(pids)))
    return pids


def test_a_background_process_of_the_class_ends_with_a_normal_end_of_the_job(tmp_path):
    pids = _write_class(tmp_path)
    proc = user_process("mine", f"{tmp_path / 'mine.py'}:Starts")
    proc.call(("fit", _clips()), 120, "fit(database)")
    child, background = _wait_file(pids)
    assert _alive(background)
    close_processes()  # the end of the job
    _wait_gone([child, background], "after a normal end")


def test_a_background_process_ends_also_when_the_class_ended_first(tmp_path):
    pids = _write_class(tmp_path)
    proc = UserProcess("mine", f"{tmp_path / 'mine.py'}:Starts")
    proc.call(("fit", _clips()), 120, "fit(database)")
    child, background = _wait_file(pids)
    proc.conn.send(("stop",))
    proc.proc.wait(timeout=SAFETY_TIMEOUT)  # the class's process is gone, what it started is not
    assert _alive(background)
    proc.close()
    _wait_gone([background], "after the class's process ended")


def test_a_hung_class_and_its_background_process_end_at_the_time_limit(tmp_path):
    pids = _write_class(tmp_path)
    proc = UserProcess("mine", f"{tmp_path / 'mine.py'}:Sleeps")
    with pytest.raises(UserGeneratorError, match="passed the time limit of 10 s"):
        proc.call(("fit", _clips()), 10, "fit(database)")  # it sleeps 600 s: always past the limit
    assert pids.exists(), "the class did not start within the time limit"
    child, background = _wait_file(pids)
    _wait_gone([child, background], "after the time limit")
    proc.close()


def test_a_spinning_class_and_its_background_process_end_when_the_job_is_killed(tmp_path):
    pids = _write_class(tmp_path)
    job = textwrap.dedent(f"""
        from animsynth.compare.generators.user import UserProcess
        from animsynth.synth.mocap import cmu_like_skeleton, generate_motion
        clips = [generate_motion("walk_straight", 30, 0, cmu_like_skeleton("u", 1), name="t0")]
        UserProcess("mine", {str(tmp_path / 'mine.py') + ':Spins'!r}).call(("fit", clips), None, "fit(database)")
    """)
    log = tmp_path / "job.log"  # a file, not a pipe: a process left behind would hold a pipe open forever
    with open(log, "w") as fh:
        proc = subprocess.Popen([sys.executable, "-c", job], stderr=fh, start_new_session=True)
    child, background = _wait_file(pids, proc)
    os.kill(proc.pid, signal.SIGKILL)  # as a scheduler or `timeout -k` ends a job: no cleanup code runs in it
    proc.wait(timeout=SAFETY_TIMEOUT)
    _wait_gone([child, background], "after SIGKILL of the job")
    err = log.read_text()
    # the watchdog names the class (the job itself could say nothing)
    assert f"user generator 'mine' ({tmp_path / 'mine.py'}:Spins): the job's process {proc.pid} ended" in err, err


GUARDED = """
import os, signal


class Spoils:
    def fit(self, database):
        {body}

    def generate(self, start, length, seed):
        return start
"""


@pytest.mark.parametrize("body, says", [
    ('fd = os.open({guarded!r}, os.O_RDONLY)\n        os.open("knn.csv", os.O_WRONLY | os.O_APPEND, dir_fd=fd)',
     "(open {guarded}/knn.csv)"),
    ('fd = os.open({guarded!r}, os.O_RDONLY)\n        os.unlink("knn.csv", dir_fd=fd)', "(os.remove {guarded}/knn.csv)"),
    ('os.link({guarded!r} + "/knn.csv", "mine.csv")', "(os.link {guarded}/knn.csv)"),
    ('fd = os.open({guarded!r}, os.O_RDONLY)\n        os.symlink("/etc/hostname", "x.csv", dir_fd=fd)',
     "(os.symlink {guarded}/x.csv)"),
    ("os.kill(os.getppid(), signal.SIGWINCH)", "may not signal its job's process (os.kill"),
    ("os.killpg(os.getpgid(os.getppid()), signal.SIGWINCH)", "may not signal its job's process (os.killpg"),
])
def test_dir_fd_calls_links_and_signals_to_the_job_are_refused(tmp_path, body, says):
    guarded = tmp_path / "results" / "compare"
    guarded.mkdir(parents=True)
    (guarded / "knn.csv").write_text("ours\n")
    (tmp_path / "mine.py").write_text(GUARDED.format(body=body.format(guarded=str(guarded))))
    proc = UserProcess("mine", f"{tmp_path / 'mine.py'}:Spoils", guard=[str(guarded)])
    try:
        with pytest.raises(UserGeneratorError) as exc:
            proc.call(("fit", _clips()), 120, "fit(database)")
    finally:
        proc.close()
    assert "fit(database) raised PermissionError at mine.py:" in str(exc.value)
    assert says.format(guarded=str(guarded)) in str(exc.value)
    assert (guarded / "knn.csv").read_text() == "ours\n" and sorted(os.listdir(guarded)) == ["knn.csv"]
