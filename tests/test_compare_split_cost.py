"""benchmarks/compare_split_cost.py: the copy it makes plans the comparison as one job per generator over every
subject (the design the paired cost measurement of docs/compare/long_track.md starts from), with the long track
off and only the short track's claims."""

from __future__ import annotations

import sys

import pytest
import yaml

from animsynth.compare.generators.names import FAIRMOTION_ROWS
from conftest import REPO, copy_workflow, run_snakemake

pytestmark = pytest.mark.workflow
sys.path.insert(0, str(REPO / "benchmarks"))


def test_the_copy_runs_one_comparison_job_per_generator_over_every_subject(tmp_path):
    from compare_split_cost import before_split

    wd = copy_workflow(tmp_path / "before")
    before_split(wd)
    extra = yaml.safe_load((wd / "config" / "before_split.yaml").read_text())["compare"]
    assert extra["long_track"] == {"enabled": False}
    assert extra["claims"] and all(c.get("track", "short") != "long" for c in extra["claims"])
    res = run_snakemake(wd, "-n", "--configfile", "config/test.yaml", "config/before_split.yaml")
    assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]
    counts = {}
    for line in res.stdout.splitlines():
        parts = line.split()
        if len(parts) == 2 and parts[1].isdigit():
            counts[parts[0]] = int(parts[1])
    test_cfg = yaml.safe_load((REPO / "config" / "test.yaml").read_text())["compare"]
    default = yaml.safe_load((REPO / "config" / "config.yaml").read_text())["compare"]
    gens = test_cfg.get("generators", default["generators"])
    expected = {f"compare_all_{g}" for g in gens if g not in FAIRMOTION_ROWS} | {"compare_all_fairmotion"}
    assert {k for k in counts if k.startswith("compare_all_")} == expected
    assert all(counts[k] == 1 for k in expected)
    assert not any(k.startswith("compare_run") for k in counts)  # the per-subject jobs are gone
    assert counts["compare_clips"] == 2 and counts["compare_tables"] == 1  # the rest of the comparison as before


def test_it_refuses_the_repository_itself():
    from compare_split_cost import before_split

    with pytest.raises(SystemExit, match="not the repository itself"):
        before_split(REPO)
