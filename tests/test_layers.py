"""The package's import graph: no cycle, no import from a lower layer up to a higher one, families apart.

Every ``import`` statement of every module counts, also those inside functions (a lazy import is still a
dependency). Layers, bottom to top:

0. plain helpers with no animsynth import: atomic writes, file-format errors, limits, the verdict format,
   the published-table reader, joint roles, the skeleton, the family registry;
1. config checks, tables (benchmark rows too), the Motion container, kinematics (pose math) and its springs, the up
   and forward axes of a file, angle continuity and retargeting, the generator interface;
2. io (file formats; knows no method);
3. shared machinery on top of io: synthetic data, skinning, drawing (the scoreboard too), data sources, the data layer,
   the capture check, workflow logging;
4. the four families of the papers, which never import each other;
5. compare, which scores the families' generators side by side (the one package that imports them);
(layers 4 and 5 as the family registry, :mod:`animsynth.families`, gives them: adding a family adds it here)
6. report, scale (the measuring harness) and the command line.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from animsynth import families as registry

SRC = Path(__file__).resolve().parents[1] / "src" / "animsynth"
PKG = "animsynth"
FAMILIES = registry.paper_families()
LAYERS = {
    0: ["_lazy", "atomic", "errors", "limits", "verdicts", "published", "joints", "rig_layout", "skeleton", "families"],
    1: ["config", "tables", "benchmark_tables", "motion", "kinematics", "springs", "axes", "retarget", "generator", "pace"],
    2: ["io"],
    3: ["synth", "skinning", "viz", "scoreboard", "sources", "data", "capture_check", "workflow_utils"],
    4: list(FAMILIES),
    5: [f.name for f in registry.FAMILIES if f.layer == 5],
    6: ["report", "scale", "cli", "cli_inputs"],
}
TOP = {name: layer for layer, names in LAYERS.items() for name in names}


def modules() -> dict[str, Path]:
    out = {}
    for p in sorted(SRC.rglob("*.py")):
        parts = p.relative_to(SRC.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = p
    return out


def import_graph() -> dict[str, set[str]]:
    mods = modules()
    graph = {}
    for name, path in mods.items():
        is_pkg = path.name == "__init__.py"
        deps = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = name.split(".") if is_pkg else name.split(".")[:-1]
                    base = base[: len(base) - (node.level - 1)]
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module or ""
                targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in mods else mod for a in node.names]
            else:
                continue
            for t in targets:
                if t.split(".")[0] != PKG:
                    continue
                while t not in mods and "." in t:
                    t = t.rsplit(".", 1)[0]
                if t in mods and t != name:
                    deps.add(t)
        graph[name] = deps
    return graph


def top_name(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def test_every_module_has_a_layer():
    missing = sorted({top_name(m) for m in modules() if top_name(m) and top_name(m) not in TOP})
    assert not missing, f"modules without a layer in {__file__}: {missing}"


def test_no_import_cycle():
    graph = import_graph()
    names = sorted(graph)
    index = {n: i for i, n in enumerate(names)}
    rows = [index[a] for a in names for b in graph[a]]
    cols = [index[b] for a in names for b in graph[a]]
    adj = csr_matrix(([1] * len(rows), (rows, cols)), shape=(len(names), len(names)))
    _, labels = connected_components(adj, directed=True, connection="strong")
    cycles = [sorted(n for n in names if labels[index[n]] == lab)
              for lab in set(labels) if list(labels).count(lab) > 1]
    assert not cycles, f"import cycles: {cycles}"


def test_no_import_from_a_lower_layer_up():
    bad = []
    for mod, deps in import_graph().items():
        src = top_name(mod)
        if src is None:  # the package's own __init__ exports lazily
            continue
        for d in deps:
            dst = top_name(d)
            if dst is not None and TOP[dst] > TOP[src]:
                bad.append(f"{mod} (layer {TOP[src]}) imports {d} (layer {TOP[dst]})")
    assert not bad, "\n".join(sorted(bad))


@pytest.mark.parametrize("family", FAMILIES)
def test_families_never_import_each_other(family):
    bad = [f"{m} imports {d}" for m, deps in import_graph().items() if top_name(m) == family
           for d in deps if top_name(d) in FAMILIES and top_name(d) != family]
    assert not bad, "\n".join(bad)


def test_the_walk_sees_imports_inside_functions():
    # the resequencing cost steps import the CMU mirror reader inside a function: the walk must count it
    deps = import_graph()
    inside = [m for m in deps if m.startswith("animsynth.resequencing.") and "animsynth.io.cmu_mirror" in deps[m]]
    assert inside, "the walk missed an import made inside a function"


def test_layer_zero_imports_nothing_of_the_package():
    bad = [f"{m} imports {d}" for m, deps in import_graph().items() if top_name(m) in LAYERS[0] for d in deps]
    assert not bad, "\n".join(bad)


def test_lazy_exports_point_down_or_inside_their_own_package():
    """The families' lazy exports (strings, invisible to the import walk) name their own modules or lower
    layers, never another family."""
    import importlib

    bad = []
    for family in registry.names():
        pkg = importlib.import_module(f"animsynth.{family}")
        for name in getattr(pkg, "__all__", []):
            owner = getattr(getattr(pkg, name), "__module__", "") or ""
            top = top_name(owner) if owner.startswith("animsynth.") else None
            if top is not None and top != family and (top in FAMILIES or TOP[top] >= TOP[family]):
                bad.append(f"animsynth.{family}.{name} comes from {owner}")
    assert not bad, "\n".join(bad)


def test_every_family_of_the_registry_is_a_package_with_a_rule_file_and_nothing_else_is_one():
    """The registry is the one list of families: each has its package (with settings.check) and its rule file, and
    every package beside the shared layers is a family of the registry."""
    rules = SRC.parents[1] / "workflow" / "rules"
    for fam in registry.FAMILIES:
        assert (SRC / fam.name / "settings.py").is_file() and (rules / f"{fam.name}.smk").is_file(), fam.name
        assert TOP[fam.name] == fam.layer
        text = (rules / f"{fam.name}.smk").read_text()
        for part in ("TARGETS", "SUMMARY", "VERDICTS", "FIGURES"):  # what the workflow collects of every family
            assert f"\n{fam.name.upper()}_{part} " in text, f"{fam.name}.smk defines no {fam.name.upper()}_{part}"
        assert f"def {fam.name}_benchmarks(" in (rules / "common.smk").read_text(), fam.name
    packages = {p.parent.name for p in SRC.glob("*/__init__.py")}
    assert packages - {"io", "synth"} == set(registry.names())
    shared = {"common", "data", "report", "scale"}
    assert {p.stem for p in rules.glob("*.smk")} - shared == set(registry.names())
