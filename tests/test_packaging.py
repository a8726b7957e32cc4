"""pyproject.toml and environment.yml pin the same versions; README commands are what CI runs."""

import re
import tomllib

import yaml

from conftest import REPO


def _norm(name):
    return re.sub(r"[-_.]+", "-", name).lower()


def _pins(reqs):
    out = {}
    for r in reqs:
        m = re.fullmatch(r"\s*([A-Za-z0-9_.\-]+)\s*==\s*([^\s;]+)\s*", r)
        if m:
            out[_norm(m.group(1))] = m.group(2)
    return out


def test_pyproject_and_environment_agree():
    py = tomllib.loads((REPO / "pyproject.toml").read_text())
    pins = _pins(py["project"]["dependencies"]) | _pins(py["project"]["optional-dependencies"]["test"])
    assert len(pins) == len(py["project"]["dependencies"]) + len(py["project"]["optional-dependencies"]["test"]), \
        "every runtime and test dependency must be pinned with =="
    env = yaml.safe_load((REPO / "environment.yml").read_text())
    pip = [d for dep in env["dependencies"] if isinstance(dep, dict) for d in dep.get("pip", [])]
    conda = _pins([d for d in env["dependencies"] + pip if isinstance(d, str) and "==" in d])
    assert conda == pins, f"environment.yml {conda} != pyproject.toml {pins}"
    rule_env = yaml.safe_load((REPO / "workflow" / "envs" / "animsynth.yaml").read_text())
    rule_pip = [d for dep in rule_env["dependencies"] if isinstance(dep, dict) for d in dep.get("pip", [])]
    rule_pins = _pins([d for d in rule_env["dependencies"] + rule_pip if isinstance(d, str) and "==" in d])
    for name, version in rule_pins.items():
        assert pins.get(name) == version, f"workflow/envs/animsynth.yaml pins {name}=={version}, pyproject.toml {pins.get(name)}"


def test_ci_runs_the_readme_test_command():
    readme = (REPO / "README.md").read_text()
    ci = (REPO / ".ci" / "run").read_text()
    m = re.search(r"<!-- test-command -->\s*```(?:bash|sh)?\n(.+?)\n```", readme, re.S)
    assert m, "README must show the test command after a <!-- test-command --> marker"
    assert m.group(1).strip() in ci
    m = re.search(r"<!-- run-command -->\s*```(?:bash|sh)?\n(.+?)\n```", readme, re.S)
    assert m, "README must show the run command after a <!-- run-command --> marker"
