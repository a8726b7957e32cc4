"""What two runs of one config must share, read by the determinism test (tests/test_workflow.py) and the SLURM
test (tests/test_slurm.py): every output under ``results/`` but the timing tables, compared as :func:`comparable`
says."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

#: timing tables (compared nowhere: they differ between any two runs); facegraph/table1.md is the rendered view that
#: joins Table 1 with its timing table (as the paper's Table 1 does), table1.csv itself is compared
NOT_COMPARED = re.compile(r"((^|_)timing\.(csv|md)|^benchmarks\.(csv|md)|^rule_benchmarks.*\.(csv|md)|^table1\.md)$")
#: timing fields inside otherwise deterministic JSON outputs (e.g. a facegraph configuration's run record)
JSON_TIMING = re.compile(r"_(cpu|wall)_s$|_ms(_sd)?$")
#: every rule's benchmark file (timing) and Snakemake's marker of a finished folder output (its write time)
NOT_OUTPUTS = ("results/benchmarks/",)
MARKER = ".snakemake_timestamp"

#: set by the SLURM test once it found every output of its whole run equal to the local run's (the determinism
#: test then has nothing left to check: that run repeated every job of the local one)
WHOLE_RUN_COMPARED: dict[str, bool] = {}


def tables(root: Path) -> dict[str, bytes]:
    """Every table under results/ (CSV, and its Markdown rendering), as bytes."""
    out = {}
    for p in sorted((root / "results").rglob("*")):
        if p.suffix not in (".csv", ".md") or NOT_COMPARED.search(p.name):
            continue
        out[str(p.relative_to(root))] = p.read_bytes()
    return out


def comparable(path: Path, root: Path):
    """What must be equal in an output of the run in ``root``: its bytes with ``root`` written as ``<wd>``
    (a few outputs record where their inputs were); JSON without timing fields; ``.npz`` array by array
    (the zip container stores write times); a folder, file by file (Snakemake's marker aside)."""
    if path.is_dir():
        return {str(p.relative_to(path)): comparable(p, root) for p in sorted(path.rglob("*"))
                if p.is_file() and p.name != MARKER}
    if path.suffix == ".npz":
        with np.load(path) as z:
            return {k: ("U", z[k].shape, str(z[k].tolist()).replace(str(root), "<wd>")) if z[k].dtype.kind == "U"
                    else (z[k].dtype.str, z[k].shape, z[k].tobytes()) for k in z.files}
    data = path.read_bytes().replace(str(root).encode(), b"<wd>")
    if path.suffix == ".json":
        def drop(x):
            if isinstance(x, dict):
                return {k: drop(v) for k, v in x.items() if not JSON_TIMING.search(str(k))}
            return [drop(v) for v in x] if isinstance(x, list) else x
        return drop(json.loads(data))
    return data


def same_content(a: Path, root_a: Path, b: Path, root_b: Path) -> bool:
    """``a`` (of the run in ``root_a``) and ``b`` (of the run in ``root_b``) hold the same :func:`comparable`."""
    return comparable(a, root_a.resolve()) == comparable(b, root_b.resolve())


def compared_outputs(root: Path) -> list[str]:
    """Every file under ``root``/results that two runs must share: all but the timing tables, the benchmark
    files and Snakemake's folder markers (relative paths, sorted)."""
    out = []
    for p in sorted((root / "results").rglob("*")):
        rel = p.relative_to(root).as_posix()
        if p.is_file() and p.name != MARKER and not NOT_COMPARED.search(p.name) and not rel.startswith(NOT_OUTPUTS):
            out.append(rel)
    return out


def outputs_that_differ(local: Path, other: Path) -> list[str]:
    """The files of :func:`compared_outputs` (of either run) that the two runs do not share: a table (CSV or its
    Markdown) byte for byte, as :func:`tables` holds it (a table naming the working directory differs), any other
    file as :func:`comparable` says."""
    def same(n: str) -> bool:
        a, b = local / n, other / n
        if not (a.is_file() and b.is_file()):
            return False
        if a.suffix in (".csv", ".md"):
            return a.read_bytes() == b.read_bytes()
        return same_content(a, local, b, other)

    return [n for n in sorted(set(compared_outputs(local)) | set(compared_outputs(other))) if not same(n)]
