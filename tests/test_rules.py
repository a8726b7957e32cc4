"""The workflow's rules are ready for a cluster, and its scripts follow one style.

* every rule (except local ones) declares ``threads`` and ``resources`` with
  ``mem_mb`` and ``runtime`` (minutes), so a SLURM profile needs no per-rule
  blocks;
* ``ruff check`` is clean on the whole project (the ``snakemake`` object that
  Snakemake's ``script:`` directive injects is a declared builtin);
* no tracker references (issue numbers) in code, config or docs.
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from conftest import REPO, SAFETY_TIMEOUT, SNAKEMAKE

RULE_FILES = [REPO / "Snakefile", *sorted((REPO / "workflow" / "rules").glob("*.smk"))]
SCRIPTS = sorted((REPO / "workflow" / "scripts").glob("*.py"))


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip(" "))


def parse_rules(path: Path) -> dict[str, dict]:
    """Each ``rule NAME:`` block of a Snakefile: its directives and resource names.

    A block is every line indented deeper than its ``rule`` line (rules may sit
    inside ``if``/``else``). A rule written in a loop (``rule:`` with a ``name:``
    directive such as ``f"compare_run_{_method}"``) is keyed by its name's
    pattern, each ``{...}`` a ``*`` (``compare_run_*``; :func:`rule_info` finds a
    name's rule). Returns name -> {"file", "line", "directives": {directive:
    [body lines]}}.
    """
    lines = path.read_text().splitlines()
    rules = {}
    for i, line in enumerate(lines):
        m = re.match(r"^(\s*)rule(?:\s+(\w+))?\s*:", line)
        if not m:
            continue
        base = len(m.group(1))
        body = []
        for nxt in lines[i + 1:]:
            if nxt.strip() and _indent(nxt) <= base:
                break
            body.append(nxt)
        body_indent = min((_indent(b) for b in body if b.strip()), default=base + 4)
        directives: dict[str, list[str]] = {}
        current = None
        for b in body:
            if not b.strip() or b.strip().startswith("#"):
                continue
            if _indent(b) == body_indent:
                dm = re.match(r"\s*(\w+)\s*:(.*)$", b)
                current = dm.group(1) if dm else None
                if current:
                    directives[current] = [dm.group(2).strip()] if dm.group(2).strip() else []
            elif current:
                directives[current].append(b.strip())
        name = m.group(2)
        if name is None:  # a rule written in a loop: its name directive, an f-string or a string
            expr = " ".join(directives.get("name", []))
            nm = re.fullmatch(r"f?([\"'])(\w*(?:\{\w+\}\w*)*)\1,?", expr)
            assert nm, f"{path}:{i + 1}: a rule without a name needs a name: directive (a string), got {expr!r}"
            name = re.sub(r"\{\w+\}", "*", nm.group(2))
        assert name not in rules, f"rule {name} defined twice in {path}"
        where = path.relative_to(REPO) if path.is_relative_to(REPO) else path
        rules[name] = {"file": where, "line": i + 1, "directives": directives}
    return rules


def rule_info(rules: dict, name: str):
    """The entry of ``rules`` (:func:`parse_rules`) of the rule Snakemake calls ``name``: its own block, else the
    loop's block whose name pattern it matches; None if neither."""
    from fnmatch import fnmatchcase

    if name in rules:
        return rules[name]
    return next((info for pattern, info in rules.items() if "*" in pattern and fnmatchcase(name, pattern)), None)


def loop_names() -> dict[str, set[str]]:
    """The names each loop of the rule files gives its rules: {name pattern of :func:`parse_rules`: names}."""
    from animsynth.compare.generators.names import METHOD_ROWS

    return {"compare_run_*": {f"compare_run_{m}" for m in METHOD_ROWS}}


def all_rules() -> dict[str, dict]:
    out = {}
    for f in RULE_FILES:
        for name, info in parse_rules(f).items():
            assert name not in out, f"rule {name} defined in {out[name]['file']} and {f}"
            out[name] = info
    return out


def _is_local(info) -> bool:
    return info["directives"].get("localrule", [""])[0] == "True"


def test_parser_reads_directives(tmp_path):
    text = ("if X:\n\n    rule a:\n        input:\n            'x',\n        threads: 2\n        resources:\n"
            "            mem_mb=100,\n            runtime=5,\n        script:\n            's.py'\n\nelse:\n\n"
            "    rule b:\n        output:\n            'y',\n\n\nrule c:\n    output:\n        'z',\n    localrule: True\n")
    text += ("\nfor _m in M:\n\n    rule:\n        name:\n            f\"run_{_m}\"\n        threads: 1\n\n"
             "    rule:\n        name: \"fixed\"\n        threads: 3\n")
    p = tmp_path / "rules.smk"
    p.write_text(text)
    rules = parse_rules(p)
    assert set(rules) == {"a", "b", "c", "run_*", "fixed"}
    assert rule_info(rules, "run_simplicial")["directives"]["threads"] == ["1"] and rule_info(rules, "run") is None
    assert rules["fixed"]["directives"]["threads"] == ["3"]
    assert rules["a"]["directives"]["threads"] == ["2"]
    assert rules["a"]["directives"]["resources"] == ["mem_mb=100,", "runtime=5,"]
    assert "threads" not in rules["b"]["directives"] and _is_local(rules["c"])


@pytest.mark.parametrize("cfg", ["config.yaml", "cmu.yaml"])
def test_parser_sees_every_rule_snakemake_sees(cfg, tmp_path):
    """The text parse cannot miss a rule: compare with ``snakemake --list-rules``."""
    from conftest import copy_workflow

    wd = copy_workflow(tmp_path)
    args = [SNAKEMAKE, "--list-rules"] + ([] if cfg == "config.yaml" else ["--configfile", f"config/{cfg}"])
    res = subprocess.run(args, cwd=wd, capture_output=True, text=True, timeout=SAFETY_TIMEOUT)
    assert res.returncode == 0, res.stderr[-3000:]
    listed = {ln.strip() for ln in res.stdout.splitlines() if re.fullmatch(r"\s*\w+\s*", ln)}
    rules, loops = all_rules(), loop_names()
    assert {p for p in rules if "*" in p} == set(loops)  # every loop of the rule files is known to loop_names
    missed = {r for r in listed if r not in rules and not any(r in names for names in loops.values())}
    assert listed and not missed, missed


def test_every_rule_has_threads_and_resources():
    """threads, and resources with mem_mb and runtime, on every rule that runs a job."""
    missing = []
    for name, info in sorted(all_rules().items()):
        if _is_local(info):
            continue
        d = info["directives"]
        where = f"{info['file']}:{info['line']} rule {name}"
        if "threads" not in d:
            missing.append(f"{where}: no threads")
        res = " ".join(d.get("resources", []))
        for key in ("mem_mb", "runtime"):
            if not re.search(rf"\b{key}\s*=", res):
                missing.append(f"{where}: no resources {key}")
    assert not missing, "rules not ready for a cluster:\n" + "\n".join(missing)


def test_scripts_read_config_only_through_params():
    """A script that read ``snakemake.config`` would not rerun when that key changes (Snakemake's rerun trigger
    is the job's params): every config value reaches a script through ``params:``."""
    readers = [p.name for p in SCRIPTS if re.search(r"snakemake\.config\b", p.read_text())]
    assert not readers, f"workflow scripts reading snakemake.config instead of params: {readers}"


def test_local_rules_run_nothing():
    for name, info in all_rules().items():
        if _is_local(info):
            assert not {"script", "shell", "run", "notebook", "wrapper"} & set(info["directives"]), name


def test_slurm_profile_has_no_per_rule_blocks():
    import yaml

    text = (REPO / "profiles" / "slurm" / "config.yaml").read_text()
    prof = yaml.safe_load(text)
    assert "set-resources" not in prof and "set-threads" not in prof
    assert {"mem_mb", "runtime"} <= set(prof["default-resources"])
    assert "lead adds" not in text and "placeholder" not in text.lower()


# --- one linter for the code -------------------------------------------------

def test_ruff_finds_nothing():
    """``ruff check`` (configured in pyproject.toml: pyflakes and pycodestyle rules, 130 columns) is clean on
    the whole project: the library, the workflow's scripts, the tests, the benchmarks and run.py."""
    import sys

    res = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", "--output-format", "concise", "."],
                         cwd=REPO, capture_output=True, text=True, timeout=SAFETY_TIMEOUT)
    assert res.returncode == 0, res.stdout[-6000:] + res.stderr[-2000:]


# --- no tracker references ---------------------------------------------------

# "issue 3", "issues 3-4", "(issue 5)", "Target (issue)"; not upstream bugs such as "scipy issue 21279"
TRACKER = re.compile(r"\bissues?\s*#?\s*\d{1,3}\b|\(issues?\b|\bthe issue's\b|\bmethod issues\b", re.I)
TEXT_SUFFIXES = {".py", ".smk", ".yaml", ".yml", ".md", ".rst", ".toml", ".cfg", ".txt", ".sh", ""}


def _tracked_text_files():
    res = subprocess.run(["git", "ls-files"], cwd=REPO, capture_output=True, text=True)
    if res.returncode != 0:
        pytest.skip("not a git checkout")
    for rel in res.stdout.splitlines():
        p = REPO / rel
        if p.suffix in TEXT_SUFFIXES and p.is_file() and p.name != "test_rules.py" and "tests/data" not in rel:
            yield rel, p


def test_no_tracker_references():
    hits = []
    for rel, p in _tracked_text_files():
        try:
            text = p.read_text()
        except UnicodeDecodeError:
            continue
        for k, line in enumerate(text.splitlines(), start=1):
            if TRACKER.search(line):
                hits.append(f"{rel}:{k}: {line.strip()[:100]}")
    assert not hits, "tracker references (name things by what they are):\n" + "\n".join(hits)


def test_jobs_cap_numba_threads_at_the_rule_threads(monkeypatch):
    numba = pytest.importorskip("numba")
    from animsynth.workflow_utils import limit_compiled_threads

    monkeypatch.setenv("NUMBA_NUM_THREADS", "2")  # restored after the test (the call sets it for later imports)
    before = numba.get_num_threads()
    try:
        limit_compiled_threads(1)
        assert numba.get_num_threads() == 1
        assert os.environ["NUMBA_NUM_THREADS"] == "2"  # numba already imported: the pool is masked, env untouched

        # and a function compiled afterwards still runs (a changed env variable made numba refuse to compile)
        @numba.njit(parallel=True)
        def total(a):
            s = 0.0
            for i in numba.prange(a.size):
                s += a[i]
            return s

        assert total(np.arange(10.0)) == 45.0
    finally:
        numba.set_num_threads(before)
