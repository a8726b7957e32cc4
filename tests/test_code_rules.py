"""Rules about names in the library, checked: no dead public names, one quaternion logarithm, one meaning per name.

* Every public module-level name of ``src/animsynth`` (function, class, constant) is used somewhere besides its
  definition: in code (``src/``, ``tests/``, ``benchmarks/``, ``workflow/``; strings count, as the registries name
  functions by string, docstrings and ``__all__`` do not) or in the documentation a user reads (``docs/``,
  ``README.md``, ``config/``). :data:`UNUSED_FOR_NOW` lists the exceptions with their reason.
* The quaternion logarithm is written once, :func:`animsynth.kinematics.qlog`; every other function named as a
  log of quaternions (first parameter ``q...``) calls it, except the documented reproduction of an artefact
  (:data:`OTHER_LOGS`).
* A name clash that hid two meanings stays gone: ``leg_chains`` is defined once (the axis detection's leg-like
  chains; foot locking's hip-knee-ankle triples are ``hip_knee_ankle``).
"""

from __future__ import annotations

import ast
import re
from collections import Counter
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SRC = REPO / "src" / "animsynth"
CODE_DIRS = ("src", "tests", "benchmarks", "workflow")
DOC_FILES = ("README.md", "Snakefile")
DOC_DIRS = ("docs", "config", "workflow")

#: public names no code or page uses yet, each with its reason (remove an entry once the name is used or gone)
UNUSED_FOR_NOW: dict[str, str] = {}
#: functions named as a quaternion log that do not call kinematics.qlog, with the reason
OTHER_LOGS = {
    "resequencing/features.py:naive_quat_log": "the matrix_naive reproduction of a probable artefact: acos(w) "
                                               "without |w|, the long way round, on purpose",
}


def _docstrings(tree) -> set[int]:
    """ids of the string constants that stand alone as statements (docstrings, attribute docstrings)."""
    return {id(n.value) for n in ast.walk(tree)
            if isinstance(n, ast.Expr) and isinstance(n.value, ast.Constant) and isinstance(n.value.value, str)}


def _code_uses(path: Path) -> Counter:
    """Identifiers a Python file uses: names, attributes, imported names and the words of its strings, leaving
    out docstrings and ``__all__``."""
    tree = ast.parse(path.read_text(), str(path))
    skip = {id(x) for n in tree.body if isinstance(n, ast.Assign)
            and any(isinstance(t, ast.Name) and t.id == "__all__" for t in n.targets) for x in ast.walk(n)}
    skip |= _docstrings(tree)
    uses = Counter()
    for n in ast.walk(tree):
        if id(n) in skip:
            continue
        if isinstance(n, ast.Name):
            uses[n.id] += 1
        elif isinstance(n, ast.Attribute):
            uses[n.attr] += 1
        elif isinstance(n, ast.alias):
            uses[n.name.rsplit(".", 1)[-1]] += 1
        elif isinstance(n, ast.Constant) and isinstance(n.value, str):
            uses.update(re.findall(r"\w+", n.value))
    return uses


def _public_definitions() -> dict[str, list[str]]:
    """``{name: [file, ...]}`` of the public module-level functions, classes and constants of the package, and
    the number of times each definition itself counts as a use (an assignment's target)."""
    defs: dict[str, list[str]] = {}
    for path in sorted(SRC.rglob("*.py")):
        for n in ast.parse(path.read_text(), str(path)).body:
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names = [n.name]
            elif isinstance(n, ast.Assign):
                names = [t.id for t in n.targets if isinstance(t, ast.Name)]
            elif isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name):
                names = [n.target.id]
            else:
                continue
            for name in names:
                if not name.startswith("_"):
                    defs.setdefault(name, []).append(path.relative_to(SRC).as_posix())
    return defs


def test_every_public_name_is_used_somewhere():
    defs = _public_definitions()
    assert len(defs) > 500, "the walk found too few public names"
    uses = Counter()
    for d in CODE_DIRS:
        for path in (REPO / d).rglob("*.py"):
            if path != Path(__file__).resolve():  # this file names the exceptions: not a use
                uses += _code_uses(path)
    pages = [REPO / f for f in DOC_FILES] + [p for d in DOC_DIRS for p in (REPO / d).rglob("*")
                                              if p.suffix in (".md", ".yaml", ".smk", ".rst")]
    for path in pages:
        uses.update(re.findall(r"\w+", path.read_text(errors="replace")))
    assigned = Counter()  # an assignment's own target is a Name the walk counted: not a use
    for path in SRC.rglob("*.py"):
        for n in ast.parse(path.read_text()).body:
            targets = n.targets if isinstance(n, ast.Assign) else [n.target] if isinstance(n, ast.AnnAssign) else []
            assigned.update(t.id for t in targets if isinstance(t, ast.Name))
    unused = {name: files for name, files in defs.items()
              if uses[name] - assigned[name] <= 0 and name not in UNUSED_FOR_NOW}
    assert not unused, f"public names nothing uses (remove them, or use them): {unused}"
    stale = [name for name in UNUSED_FOR_NOW if name not in defs or uses[name] - assigned[name] > 0]
    assert not stale, f"remove from UNUSED_FOR_NOW (used or gone now): {stale}"


def _functions(pattern: str):
    """``(path:name, function node)`` of every module-level function or method whose name matches ``pattern``."""
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        for n in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and re.fullmatch(pattern, n.name):
                yield f"{rel}:{n.name}", n


def test_the_quaternion_log_is_written_once():
    # a quaternion log: a function named ...log whose first parameter is a quaternion array (q, qa, ...)
    logs = {key: node for key, node in _functions(r"\w*log") if node.args.args and node.args.args[0].arg[0] == "q"}
    assert "kinematics.py:qlog" in logs
    calls = {key: {c.func.id if isinstance(c.func, ast.Name) else getattr(c.func, "attr", "")
                   for c in ast.walk(node) if isinstance(c, ast.Call)}
             for key, node in logs.items()}
    own = [key for key, called in calls.items()
           if key != "kinematics.py:qlog" and key not in OTHER_LOGS and "qlog" not in called]
    assert not own, f"functions named as a log that do not call kinematics.qlog (a second quaternion log?): {own}"
    assert set(OTHER_LOGS) <= set(logs), f"stale OTHER_LOGS entries: {set(OTHER_LOGS) - set(logs)}"


def test_leg_chains_has_one_meaning():
    found = [key for key, _ in _functions("leg_chains")]
    assert found == ["axes.py:leg_chains"], found
