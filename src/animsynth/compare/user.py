"""A researcher's own generator in the comparison (config key ``compare.user_generators``).

``compare.user_generators`` maps a row name to ``"path/to/file.py:ClassName"`` (the path absolute or relative
to the working directory of the run: the project folder under ``python3 run.py``). The class is built with no
arguments and has the interface of the family's generators (docs/compare.md, "Your own generator")::

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
import traceback
from pathlib import Path

import numpy as np

from ..motion import Motion
from ..generator import Database, Generator, check_generated

__all__ = ["UserGeneratorError", "UserGenerator", "parse_spec", "resolve_path", "file_sha256", "load_class"]


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


def resolve_path(path: str) -> Path:
    """The file of a spec: absolute, or relative to the current working directory."""
    p = Path(os.path.expanduser(path))
    return p if p.is_absolute() else Path.cwd() / p


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


def load_class(name: str, spec: str):
    """The class of ``spec`` (imported once per process), checked for ``fit`` and ``generate``.

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
    path = resolve_path(path_text)
    head = f"user generator {name!r} ({path_text}:{cls_name})"
    key = (str(path), cls_name)
    if key in _CLASSES:
        return _CLASSES[key]
    if not path.is_file():
        raise UserGeneratorError(f"{head}: no such file {str(path)!r} (a path relative to the working directory "
                                 f"{os.getcwd()!r} or absolute)")
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


class UserGenerator(Generator):
    """A user's class behind the family's interface.

    Parameters
    ----------
    name : str, the row name (a key of ``compare.user_generators``)
    spec : str, ``"path/to/file.py:ClassName"``

    Attributes
    ----------
    db_ : Database, the clips the class was fitted on (copies: the class cannot change the family's data)
    model_ : the user's fitted instance
    """

    def __init__(self, name: str, spec: str):
        self.name = name
        self.spec = spec

    def _head(self) -> str:
        try:
            path, cls = parse_spec(self.spec)
        except ValueError:
            return f"user generator {self.name!r} ({self.spec})"
        return f"user generator {self.name!r} ({path}:{cls})"

    def _path(self) -> Path:
        try:
            return resolve_path(parse_spec(self.spec)[0])
        except ValueError:
            return Path(self.spec)

    def fit(self, database) -> "UserGenerator":
        cls = load_class(self.name, self.spec)
        clips = [Motion(np.array(c.values, float), c.skeleton, c.fps, c.name) for c in database]
        self.db_ = Database(clips)
        try:
            model = cls()
        except (Exception, SystemExit) as exc:  # noqa: BLE001 - the user's code
            raise UserGeneratorError(f"{self._head()}: {_raised(exc, cls.__name__ + '()', self._path())}") from None
        # the user's class sees its own copy of the clips (Database: .clips, .skeleton, .fps)
        try:
            model.fit(Database([Motion(np.array(c.values, float), c.skeleton, c.fps, c.name) for c in clips]))
        except (Exception, SystemExit) as exc:  # noqa: BLE001
            raise UserGeneratorError(f"{self._head()}: {_raised(exc, 'fit(database)', self._path())}") from None
        self.model_ = model
        return self

    def generate(self, start: Motion, length: int, seed: int) -> Motion:
        self._check_start(start, length)
        length = int(length)
        given = Motion(np.array(start.values, float), start.skeleton, start.fps, start.name)
        try:
            out = self.model_.generate(given, length, int(seed))
        except (Exception, SystemExit) as exc:  # noqa: BLE001
            raise UserGeneratorError(f"{self._head()}: {_raised(exc, 'generate(start, length, seed)', self._path())}") \
                from None
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
