"""A researcher's own generator in the comparison (config key ``compare.user_generators``).

``compare.user_generators`` maps a row name to ``"path/to/file.py:ClassName"`` (the path absolute or relative
to the working directory of the run: the project folder under ``python3 run.py``). The class is built with no
arguments and has the interface of the family's generators (docs/compare/own_generator.md)::

    gen = ClassName()
    gen.fit(database)                       # database.clips: list of Motion; .skeleton, .fps
    motion = gen.generate(start, length, seed)

``generate`` returns a :class:`~animsynth.motion.Motion` of ``length`` frames on the start's skeleton (its DOF
columns) at the database's frame rate; ``meta["seams"]`` (frame indices ``t >= 1`` where frame ``t`` does not follow
frame ``t - 1``) is optional. :class:`UserGenerator` wraps the class so that the family's job runs it exactly as
it runs its own generators (the same clips, seeds, metrics and files); every way the class can fail (the file or
the class missing, no ``fit`` / ``generate``, an exception inside it, a motion of the wrong shape) becomes one
:class:`UserGeneratorError` whose message is one line naming the file, the class and the generator.

The file is imported once per job with its own folder first on ``sys.path`` (so it may import modules beside
it); the workflow reruns a user generator's job when the file's content changes (:func:`file_sha256`), not when
a module it imports does.
"""

from __future__ import annotations

import hashlib
import importlib.util
import inspect
import os
import sys
import logging
import traceback
from pathlib import Path

import numpy as np

from ...motion import Motion
from ...generator import Database, Generator, check_generated
from .user_guard import STOP, inside, install_guard

__all__ = ["UserGeneratorError", "UserGenerator", "UserProcess", "user_process", "close_processes", "parse_spec",
           "resolve_path", "file_sha256", "load_class"]

log = logging.getLogger("animsynth.compare.generators.user")


class UserGeneratorError(RuntimeError):
    """A user generator cannot run or returned an unusable motion (the message: one line naming the file, the
    class and the generator). Not a ValueError: the family's "not built on this clip" handling never takes it."""


def parse_spec(spec: str) -> tuple[str, str]:
    """``"path/to/file.py:ClassName"`` -> ``(path, class name)`` (split at the last colon, so a Windows drive
    letter stays in the path)."""
    path, sep, cls = str(spec).rpartition(":")
    if not sep or not path or not cls.isidentifier():
        raise ValueError(f"expected 'path/to/file.py:ClassName', got {spec!r}")
    return path, cls


def resolve_path(path: str, base: str | None = None) -> Path:
    """The file of a spec: absolute, or relative to ``base`` (default: the current working directory)."""
    p = Path(os.path.expanduser(path))
    return p if p.is_absolute() else Path(base or os.getcwd()) / p


def file_sha256(spec: str) -> str:
    """SHA-256 of the spec's file (the rerun trigger of its job); ``"missing"`` when there is no such file (the
    job then reports it)."""
    try:
        p = resolve_path(parse_spec(spec)[0])
        return hashlib.sha256(p.read_bytes()).hexdigest()
    except (OSError, ValueError):
        return "missing"


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _raised(exc: BaseException, where: str, path: Path) -> str:
    """``"raised ValueError at file.py:12: message"`` (the deepest frame in the user's file, else the deepest)."""
    if isinstance(exc, SyntaxError):  # raised while compiling: the place is on the exception
        return (f"{where} raised {type(exc).__name__} at {Path(str(exc.filename)).name}:{exc.lineno}: "
                f"{_one_line(exc.msg)}")
    frames = traceback.extract_tb(exc.__traceback__)
    own = [f for f in frames if Path(f.filename).resolve() == path.resolve()] if path.exists() else []
    f = (own or frames or [None])[-1]
    at = f" at {Path(f.filename).name}:{f.lineno}" if f is not None else ""
    msg = _one_line(exc) or "(no message)"
    return f"{where} raised {type(exc).__name__}{at}: {msg}"


_CLASSES: dict = {}


def load_class(name: str, spec: str, base: str | None = None):
    """The class of ``spec`` (imported once per process), checked for ``fit`` and ``generate``.

    ``base``: the folder a relative path is read from (default: the current working directory).

    Raises
    ------
    UserGeneratorError
        the spec malformed, the file missing or failing to import, no such class, or a class without
        ``fit(database)`` / ``generate(start, length, seed)``.
    """
    try:
        path_text, cls_name = parse_spec(spec)
    except ValueError as exc:
        raise UserGeneratorError(f"user generator {name!r}: config key 'compare.user_generators.{name}': "
                                 f"{exc}") from None
    path = resolve_path(path_text, base)
    head = f"user generator {name!r} ({path_text}:{cls_name})"
    key = (str(path), cls_name)
    if key in _CLASSES:
        return _CLASSES[key]
    if not path.is_file():
        raise UserGeneratorError(f"{head}: no such file {str(path)!r} (a path relative to the working directory "
                                 f"{base or os.getcwd()!r} or absolute)")
    mod_name = "animsynth_user_" + hashlib.sha256(str(path).encode()).hexdigest()[:16]
    module = sys.modules.get(mod_name)
    if module is None:
        ispec = importlib.util.spec_from_file_location(mod_name, path)
        if ispec is None or ispec.loader is None:
            raise UserGeneratorError(f"{head}: {str(path)!r} cannot be imported as a Python file")
        module = importlib.util.module_from_spec(ispec)
        folder = str(path.parent)
        sys.path.insert(0, folder)
        try:
            ispec.loader.exec_module(module)
        except (Exception, SystemExit) as exc:  # noqa: BLE001 - the user's code: any failure is reported as one line
            raise UserGeneratorError(f"{head}: importing the file {_raised(exc, 'it', path).removeprefix('it ')}") \
                from None
        finally:
            if folder in sys.path:
                sys.path.remove(folder)
        sys.modules[mod_name] = module
    cls = getattr(module, cls_name, None)
    if cls is None:
        raise UserGeneratorError(f"{head}: the file has no class {cls_name!r}")
    if not inspect.isclass(cls):
        raise UserGeneratorError(f"{head}: {cls_name!r} is a {type(cls).__name__}, not a class")
    for meth, args in (("fit", ("database",)), ("generate", ("start", "length", "seed"))):
        fn = getattr(cls, meth, None)
        if not callable(fn):
            raise UserGeneratorError(f"{head}: the class has no method {meth}({', '.join(args)})")
        try:
            inspect.signature(fn).bind(None, *args)  # self + the arguments
        except TypeError:
            raise UserGeneratorError(f"{head}: {meth}{inspect.signature(fn)} cannot be called as "
                                     f"{meth}({', '.join(args)})") from None
        except ValueError:  # no signature to inspect (a builtin): found out when it is called
            pass
    _CLASSES[key] = cls
    return cls


def _copy(m: Motion) -> Motion:
    return Motion(np.array(m.values, float), m.skeleton, m.fps, m.name)


def _head(name: str, spec: str) -> str:
    try:
        path, cls = parse_spec(spec)
    except ValueError:
        return f"user generator {name!r} ({spec})"
    return f"user generator {name!r} ({path}:{cls})"


def _spec_path(spec: str, base: str | None = None) -> Path:
    try:
        return resolve_path(parse_spec(spec)[0], base)
    except ValueError:
        return Path(spec)


def _fit_model(name: str, spec: str, clips: list, base: str | None = None):
    """A fresh instance of the user's class fitted on ``clips`` (every failure: :class:`UserGeneratorError`)."""
    cls = load_class(name, spec, base)
    head, path = _head(name, spec), _spec_path(spec, base)
    try:
        model = cls()
    except (Exception, SystemExit) as exc:  # noqa: BLE001 - the user's code: any failure is reported as one line
        raise UserGeneratorError(f"{head}: {_raised(exc, cls.__name__ + '()', path)}") from None
    # the user's class sees its own copy of the clips (Database: .clips, .skeleton, .fps)
    try:
        model.fit(Database([_copy(c) for c in clips]))
    except (Exception, SystemExit) as exc:  # noqa: BLE001
        raise UserGeneratorError(f"{head}: {_raised(exc, 'fit(database)', path)}") from None
    return model


def _generate_raw(model, name: str, spec: str, start: Motion, length: int, seed: int, base: str | None = None):
    """What the user's ``generate`` returns (unchecked; every exception: :class:`UserGeneratorError`)."""
    try:
        return model.generate(_copy(start), int(length), int(seed))
    except (Exception, SystemExit) as exc:  # noqa: BLE001
        raise UserGeneratorError(f"{_head(name, spec)}: "
                                 f"{_raised(exc, 'generate(start, length, seed)', _spec_path(spec, base))}") from None


# ----------------------------------------------------------------------------- the child process

def _child_main(fd: int, job_pid: int, name: str, spec: str, base: str, guard: list, allow: list) -> None:
    """The child process of one job's user generator: answers ``("fit", clips)`` and ``("generate", start, length,
    seed)`` requests on the connection ``fd`` until ``("stop",)`` or the end of the connection. Started by
    :class:`UserProcess` after :func:`.user_guard.watch_parent` has tied it to the job ``job_pid``.

    Each reply is ``(status, result, cpu_s, peak_rss_mb, refused writes)``: ``status`` ``"ok"`` (the fit's result
    is None, the generation's the user's returned object) or ``"error"`` (``result``: the one-line message)."""
    import resource
    import time
    from multiprocessing.connection import Connection

    conn = Connection(fd)
    refused: list = []
    install_guard(guard, allow, refused, job_pid)
    model = None
    while True:
        try:
            msg = conn.recv()
        except (EOFError, OSError):
            return
        if msg[0] == "stop":
            return
        c0 = time.process_time()
        del refused[:]
        try:
            if msg[0] == "fit":
                model = None
                model = _fit_model(name, spec, msg[1], base)
                reply = ("ok", None)
            else:
                reply = ("ok", _generate_raw(model, name, spec, msg[1], msg[2], msg[3], base))
        except UserGeneratorError as exc:
            reply = ("error", str(exc))
        except BaseException as exc:  # noqa: BLE001 - anything else the class let out (KeyboardInterrupt, ...)
            reply = ("error", f"{_head(name, spec)}: {msg[0]} raised {type(exc).__name__}: {_one_line(exc)}")
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
        try:
            conn.send(reply + (time.process_time() - c0, rss, list(refused)))
        except Exception as exc:  # noqa: BLE001 - the returned object cannot be pickled
            conn.send(("error", f"{_head(name, spec)}: {msg[0]} returned a {type(reply[1]).__name__} that cannot be "
                                f"sent back to the job ({type(exc).__name__}: {_one_line(exc)})",
                       time.process_time() - c0, rss, list(refused)))


class UserProcess:
    """The child process that runs one user generator for one job (fit once per clip, generate per seed).

    Parameters
    ----------
    name, spec : the row name and ``"path/to/file.py:ClassName"``
    guard : folders the class may not change files in (the project folder and the job's results folder)

    Attributes
    ----------
    workdir : str, the child's working directory: a fresh temporary folder (relative writes land here); removed
        when the job ends if empty, else kept and named in the log
    """

    def __init__(self, name: str, spec: str, guard=()):
        import socket
        import subprocess
        import tempfile

        self.name, self.spec = name, spec
        self.base = os.getcwd()
        self.workdir = tempfile.mkdtemp(prefix=f"animsynth-user-{name}-")
        user_dir = str(_spec_path(spec, self.base).resolve().parent)
        guard = [os.path.realpath(g) for g in guard]
        # the file's own folder may be written (a cache beside the module) unless a guarded folder lies in it
        allow = [os.path.realpath(self.workdir)] + ([user_dir] if not any(inside(g, user_dir) for g in guard)
                                                    else [])
        mine, theirs = socket.socketpair()
        # the lifeline: the job alone holds its write end, so the class's watchdog sees it end with the job
        life_r, self.lifeline = os.pipe()
        head = _head(name, spec)
        code = ("import sys; sys.path[:0] = {path!r}; from animsynth.compare.generators.user_guard import "
                "watch_parent; watch_parent({life}, {job}, {head!r}); from animsynth.compare.generators.user "
                "import _child_main; _child_main({fd}, {job}, {name!r}, {spec!r}, {base!r}, {guard!r}, "
                "{allow!r})").format(path=[p for p in sys.path if p], life=life_r, job=os.getpid(), head=head,
                                     fd=theirs.fileno(), name=name, spec=spec, base=self.base, guard=guard,
                                     allow=allow)
        env = dict(os.environ)
        for var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):  # one thread, as the job
            env.setdefault(var, "1")
        try:
            self.proc = subprocess.Popen([sys.executable, "-c", code], cwd=self.workdir,
                                         pass_fds=[theirs.fileno(), life_r], env=env, start_new_session=True)
        finally:
            theirs.close()
            os.close(life_r)
        from multiprocessing.connection import Connection

        self.conn = Connection(mine.detach())
        log.info("user generator %s: runs in process %d, working directory %s", name, self.proc.pid, self.workdir)

    def _ended(self) -> str:
        import signal

        code = self.proc.wait()
        if code < 0:
            try:
                return f"was killed by signal {signal.Signals(-code).name}"
            except ValueError:
                return f"was killed by signal {-code}"
        return f"ended its process with exit code {code}"

    def call(self, request: tuple, timeout_s: float | None, what: str):
        """Send ``request``, wait at most ``timeout_s`` seconds for the reply; returns ``(result, cpu_s,
        peak_rss_mb)``.

        Raises
        ------
        UserGeneratorError
            the class raised (its one line), the process ended (exit code or signal named) or the time limit passed
            (the process and everything it started are stopped)
        """
        head = f"{_head(self.name, self.spec)}: {what}"
        try:
            self.conn.send(request)
            ready = self.conn.poll(timeout_s)
        except (BrokenPipeError, ConnectionError, EOFError, OSError):
            raise UserGeneratorError(f"{head} {self._ended()} (os._exit, a crash or a signal inside the class)") \
                from None
        if not ready:
            self.kill()
            raise UserGeneratorError(f"{head} passed the time limit of {timeout_s:g} s (config key "
                                     "'compare.user_timeout_s'): its process was stopped")
        try:
            status, result, cpu, rss, refused = self.conn.recv()
        except (EOFError, OSError):
            raise UserGeneratorError(f"{head} {self._ended()} (os._exit, a crash or a signal inside the class)") \
                from None
        if refused:
            log.warning("%s: refused %d write(s) inside the project or results folder: %s", head, len(refused),
                        ", ".join(dict.fromkeys(refused)))
        if status != "ok":
            raise UserGeneratorError(result)
        return result, cpu, rss

    def kill(self) -> None:
        """Stop the child and every process in its process group (what the class started, its watchdog), whether
        the child is still running or not."""
        import signal

        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):  # the group is gone
            if self.proc.poll() is None:
                self.proc.kill()
        self.proc.wait()

    def close(self) -> None:
        """Ask the child to stop (killed after 5 s), end its whole process group (the watchdog, and any background
        process the class started there, also when the child has ended already), and remove its working directory
        if the class left nothing there (else keep it and say where)."""
        import shutil
        import subprocess

        try:
            self.conn.send(("stop",))
            self.proc.wait(timeout=5)
        except (OSError, ValueError, subprocess.TimeoutExpired):
            pass
        try:  # the watchdog ends the group quietly (the job ended normally) ...
            os.write(self.lifeline, STOP)
        except OSError:
            pass
        self.kill()  # ... and so does the job, in case the watchdog is gone
        os.close(self.lifeline)
        self.conn.close()
        try:
            left = sorted(os.listdir(self.workdir))
        except OSError:
            return
        if left:
            log.info("user generator %s: left %d file(s) in its working directory %s (kept): %s", self.name,
                     len(left), self.workdir, ", ".join(left[:10]))
        else:
            shutil.rmtree(self.workdir, ignore_errors=True)


_PROCESSES: dict = {}


def user_process(name: str, spec: str, guard=()) -> UserProcess:
    """The job's child process of user generator ``name`` (started on the first call, then reused)."""
    key = (name, spec)
    proc = _PROCESSES.get(key)
    if proc is not None and proc.proc.poll() is not None:  # it ended (an exit inside the class): its group too
        _PROCESSES.pop(key).close()
        proc = None
    if proc is None:
        proc = _PROCESSES[key] = UserProcess(name, spec, guard)
    return proc


def close_processes() -> None:
    """Stop every child process of this job (the end of a generator job)."""
    while _PROCESSES:
        _PROCESSES.popitem()[1].close()


class UserGenerator(Generator):
    """A user's class behind the family's interface.

    Parameters
    ----------
    name : str, the row name (a key of ``compare.user_generators``)
    spec : str, ``"path/to/file.py:ClassName"``
    timeout_s : float or None, the time limit of one ``fit`` or ``generate`` call (``compare.user_timeout_s``;
        with ``process`` only)
    process : bool, run the class in the job's child process (:class:`UserProcess`: a time limit, its own working
        directory, writes into ``guard`` refused, an exit or crash blamed on it); False: in the job's own process
        (``compare.user_process: false``, e.g. to debug the class)
    guard : folders the class may not change files in (``process`` only)

    Attributes
    ----------
    clip : str, what the job is fitting or generating for (:meth:`set_label`; named in the log lines)
    db_ : Database, the clips the class was fitted on (copies: the class cannot change the family's data)
    model_ : the user's fitted instance (in-process route only)
    child_cpu_s_, child_rss_mb_ : the CPU seconds of the last call in the child process and its peak resident
        memory (0 in-process: the job's own counters hold them); read through :meth:`outside_cost`
    """

    def __init__(self, name: str, spec: str, timeout_s: float | None = None, process: bool = False, guard=()):
        self.name = name
        self.spec = spec
        self.timeout_s = timeout_s
        self.process = process
        self.guard = tuple(guard)
        self.clip = ""
        self.child_cpu_s_ = 0.0
        self.child_rss_mb_ = 0.0

    def _head(self) -> str:
        return _head(self.name, self.spec)

    def set_label(self, label: str) -> None:
        """The clip (or database) the next calls are for, named in the log lines."""
        self.clip = str(label)

    def outside_cost(self) -> dict:
        """The last call's CPU seconds in the child process and its peak resident memory (0 in-process)."""
        return {"cpu_s": float(self.child_cpu_s_), "rss_mb": float(self.child_rss_mb_)}

    def fit(self, database, native_clips=None) -> "UserGenerator":
        """Fit the user's class on copies of ``database`` (``native_clips``: ignored; a user's class runs at the
        working rate)."""
        import time

        clips = [_copy(c) for c in database]
        self.db_ = Database(clips)
        frames = int(sum(c.n_frames for c in clips))
        log.info("user generator %s: fit on clip %s (%d frames) ...", self.name, self.clip or "?", frames)
        t0 = time.perf_counter()
        if self.process:
            proc = user_process(self.name, self.spec, self.guard)
            _, self.child_cpu_s_, self.child_rss_mb_ = proc.call(("fit", clips), self.timeout_s,
                                                                 f"fit(database) on clip {self.clip or '?'}")
            self.model_ = None
        else:
            self.model_ = _fit_model(self.name, self.spec, clips)
        log.info("user generator %s: fit on clip %s done in %.2f s", self.name, self.clip or "?",
                 time.perf_counter() - t0)
        return self

    def generate(self, start: Motion, length: int, seed: int, native_start: Motion | None = None) -> Motion:
        import time

        self._check_start(start, length)
        length = int(length)
        log.info("user generator %s: generate on clip %s (%d frames, seed %d) ...", self.name, self.clip or "?",
                 length, int(seed))
        t0 = time.perf_counter()
        if self.process:
            out, self.child_cpu_s_, self.child_rss_mb_ = user_process(self.name, self.spec, self.guard).call(
                ("generate", _copy(start), length, int(seed)), self.timeout_s,
                f"generate(start, {length}, {int(seed)}) on clip {self.clip or '?'}")
        else:
            out = _generate_raw(self.model_, self.name, self.spec, start, length, seed)
        log.info("user generator %s: generate on clip %s done in %.2f s", self.name, self.clip or "?",
                 time.perf_counter() - t0)
        return self._checked(out, start, length, seed)

    def _checked(self, out, start: Motion, length: int, seed: int) -> Motion:
        """The user's returned motion checked against the interface (one :class:`UserGeneratorError` if not)."""
        head = f"{self._head()}: generate(start, {length}, {int(seed)})"
        if not isinstance(out, Motion):
            raise UserGeneratorError(f"{head} returned a {type(out).__name__}, not an animsynth.motion.Motion")
        try:
            values = np.asarray(out.values, float)
        except (TypeError, ValueError) as exc:
            raise UserGeneratorError(f"{head} returned values that are not numbers ({_one_line(exc)})") from None
        want = (length, start.skeleton.n_dof)
        if values.shape != want:
            raise UserGeneratorError(f"{head} returned values of shape {values.shape}, expected {want} ({length} "
                                     f"frames x the start's {start.skeleton.n_dof} DOF)")
        try:
            columns = out.skeleton.columns()
        except (AttributeError, TypeError, ValueError):
            columns = None
        if columns != start.skeleton.columns():
            raise UserGeneratorError(f"{head} returned a motion on another skeleton (its DOF columns differ from "
                                     "the start's)")
        try:
            fps = float(out.fps)
        except (TypeError, ValueError):
            fps = float("nan")
        if not np.isclose(fps, float(start.fps)):
            raise UserGeneratorError(f"{head} returned {fps:g} fps, the database runs at {float(start.fps):g} fps")
        meta = out.meta if isinstance(out.meta, dict) else {}
        m = Motion(values.copy(), self.db_.skeleton, self.db_.fps, self.name,
                   {"seams": meta.get("seams", []), "source_frames": None})
        m.meta.pop("source_frames")
        try:
            return check_generated(m, length, self.db_.skeleton, head)
        except (ValueError, TypeError) as exc:
            raise UserGeneratorError(_one_line(exc)) from None
