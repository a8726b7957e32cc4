"""What keeps a user generator's child process (:mod:`.user`) inside its job: the write and signal guard, and the
lifeline that ends the class's processes with the job.

Standard library only: the child imports this module first, before numpy, so that it can start its watchdog
process (:func:`watch_parent`) while it is still a single thread.

The write guard (:func:`install_guard`) refuses, with a ``PermissionError`` inside the class, a file change inside
the guarded folders (the project and the job's results folder) made through Python's audited calls (``open`` for
writing, ``os.open`` also with ``dir_fd``, rename / replace, remove / unlink, rmdir, mkdir, mkfifo, mknod, hard and
symbolic links, chmod, chown, utime, truncate, ``shutil`` copy / move / rmtree; a path relative to a ``dir_fd`` is
read through ``/proc/self/fd``). A hard link whose source lies in a guarded folder is refused too (it would give a
writable name to a guarded file). Not guarded, and said so in docs/compare/own_generator.md: writes by code that Python does not
audit (a C extension's own ``fopen``, ``ctypes``), by programs the class starts, and through a file descriptor the
class holds already (a descriptor is only obtained by a checked ``open``, except those the job passed on: the
standard streams).

The signal guard refuses ``os.kill`` / ``os.killpg`` of the job's process or process group and ``os.kill(-1, ...)``
(every process of the user), so a class cannot end its own job from Python; one that does it another way (a
``kill`` command) is named by the watchdog's line.
"""

from __future__ import annotations

import os
import signal
import sys

__all__ = ["install_guard", "watch_parent", "inside", "STOP"]

#: the byte the job writes on the lifeline when it ends normally (the end of the pipe alone: the job died)
STOP = b"q"

#: audit events that change a file: ``(position of a path, position of its dir_fd or None)`` for each path
_WRITE_EVENTS = {
    "os.rename": ((0, 2), (1, 3)), "os.replace": ((0, 2), (1, 3)), "os.remove": ((0, 1),), "os.unlink": ((0, 1),),
    "os.rmdir": ((0, 1),), "os.mkdir": ((0, 2),), "os.mkfifo": ((0, 2),), "os.mknod": ((0, 3),),
    "shutil.rmtree": ((0, 1),), "os.truncate": ((0, None),), "os.symlink": ((1, 2),), "os.link": ((0, 2), (1, 3)),
    "os.chmod": ((0, 2),), "os.chown": ((0, 3),), "os.utime": ((0, 3),), "shutil.copyfile": ((1, None),),
    "shutil.move": ((0, None), (1, None)),
}
_WRITE_FLAGS = os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_TRUNC | os.O_APPEND


def inside(path: str, root: str) -> bool:
    """``path`` is ``root`` or below it (both absolute)."""
    try:
        return os.path.commonpath([path, root]) == root
    except ValueError:  # different drives
        return False


def _resolve(path, dir_fd) -> str | None:
    """The absolute, symbolic-link-free path ``path`` names (relative to the folder open as ``dir_fd`` when that is
    a descriptor); None for a descriptor used as the path itself (not checked: see the module docstring).

    Raises PermissionError when ``dir_fd`` names a folder that cannot be told (no ``/proc``): refused, not guessed.
    """
    if path is None or isinstance(path, int):
        return None
    try:
        text = os.fsdecode(path)
    except (TypeError, ValueError):
        return None
    if isinstance(dir_fd, int) and dir_fd >= 0 and not os.path.isabs(text):
        try:
            base = os.readlink(f"/proc/self/fd/{dir_fd}")
        except OSError:
            raise PermissionError(f"a user generator may not change a file relative to dir_fd {dir_fd} where the "
                                  "folder it names cannot be told") from None
        text = os.path.join(base, text)
    return os.path.realpath(text)


def _guarded(path: str | None, guard: list[str], allow: list[str]) -> str | None:
    """``path`` if it lies inside a guarded folder and no allowed one (else None); compiled-bytecode caches
    (``__pycache__``) are never guarded (Python's import writes them)."""
    if path is None or "__pycache__" in path.split(os.sep):
        return None
    if any(inside(path, a) for a in allow):
        return None
    return next((path for g in guard if inside(path, g)), None)


def _refuse(event: str, hit: str, refused: list) -> None:
    refused.append(hit)
    raise PermissionError(f"a user generator may not change files inside the run's project or results folder "
                          f"({event} {hit}); write below its working directory or use an absolute path elsewhere")


def install_guard(guard: list[str], allow: list[str], refused: list, job_pid: int) -> None:
    """Refuse (PermissionError) and record in ``refused`` every file change inside ``guard`` and outside ``allow``
    made through Python's audited calls, and every signal to the job (``job_pid``, its process group, or every
    process), in this process. ``os.open`` is wrapped so that its ``dir_fd`` is seen (its audit event leaves it
    out)."""
    try:
        job_group = os.getpgid(job_pid)
    except OSError:
        job_group = None
    busy = []

    def check(event: str, pairs) -> None:
        busy.append(1)
        try:
            hit = next((h for h in (_guarded(_resolve(p, d), guard, allow) for p, d in pairs) if h), None)
        finally:
            busy.pop()
        if hit:
            _refuse(event, hit, refused)

    def hook(event, args):
        if busy:
            return
        if event in ("os.kill", "os.killpg"):
            target = args[0]
            if (event == "os.kill" and target in (job_pid, -1) or job_group is not None
                    and target == (job_group if event == "os.killpg" else -job_group)):
                raise PermissionError(f"a user generator may not signal its job's process ({event} {target}): the "
                                      "job would end without its files")
        elif event == "open":
            path, mode, flags = (tuple(args) + (None, None, None))[:3]
            writes = (any(c in mode for c in "wax+") if isinstance(mode, str)
                      else isinstance(flags, int) and bool(flags & _WRITE_FLAGS))
            if writes:
                check(event, [(path, None)])
        elif event in _WRITE_EVENTS:
            check(event, [(args[i], args[d] if d is not None and d < len(args) else None)
                          for i, d in _WRITE_EVENTS[event] if i < len(args)])

    real_open = os.open

    def open_checked(path, flags, mode=0o777, *, dir_fd=None):
        if dir_fd is not None and flags & _WRITE_FLAGS and not busy:
            check("open", [(path, dir_fd)])
        return real_open(path, flags, mode, dir_fd=dir_fd)

    open_checked.__doc__ = real_open.__doc__
    os.open = open_checked
    if "posix" in sys.modules:
        sys.modules["posix"].open = open_checked
    sys.addaudithook(hook)


def _parent_death_signal(sig: int) -> None:
    """Ask Linux to send ``sig`` to this process when the thread that started it ends (``prctl(PR_SET_PDEATHSIG)``);
    nothing elsewhere (the watchdog covers every system)."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, int(sig), 0, 0, 0)  # 1 = PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def watch_parent(lifeline: int, job_pid: int, head: str) -> None:
    """Tie this process (the class's, leader of its own process group) and its group to the job ``job_pid``.

    * the parent-death signal: SIGKILL to this process the moment the job's process ends (Linux);
    * a watchdog process in the same group, holding only ``lifeline`` (the read end of a pipe whose write end the
      job alone holds): when the job ends normally it writes :data:`STOP`; when it dies (SIGKILL, a crash, the
      class killing it) the pipe ends. Either way the watchdog kills the whole group (the class's process,
      everything it started there, itself); after a death it first prints one line naming the class (``head``).

    A program the class starts that leaves the group (``setsid``) is not covered.
    """
    _parent_death_signal(signal.SIGKILL)
    if os.getppid() != job_pid:  # the job ended before the signal was asked for
        os._exit(1)
    if os.fork() == 0:  # the watchdog: keeps only the standard streams and the lifeline (the job must see the
        os.closerange(3, lifeline)  # class's connection end when the class's process does)
        os.closerange(lifeline + 1, os.sysconf("SC_OPEN_MAX") if hasattr(os, "sysconf") else 65536)
        try:
            got = os.read(lifeline, 1)
        except OSError:
            got = b""
        if got != STOP:
            print(f"animsynth: {head}: the job's process {job_pid} ended while the class's process ran (killed by "
                  "a signal, a crash, or the class itself); the class's processes were stopped", file=sys.stderr,
                  flush=True)
        os.killpg(0, signal.SIGKILL)
        os._exit(0)
    os.close(lifeline)
