"""Two runs never make each other stale: the inputs a run generates or copies
(synthetic trials, copied or downloaded trials, the synthetic CK+-layout
database, unpacked mesh archives) live below its own results_dir, so a run with
another config (the paper run, python3 run.py bench, a user's) never rewrites
them."""

import re

import pytest

from conftest import REPO, copy_finished_run, place_papers, run_snakemake


def _code_lines(path):
    for n, line in enumerate(path.read_text().splitlines(), start=1):
        code = line.split("#", 1)[0]
        if code.strip():
            yield n, code


def test_no_rule_writes_a_shared_resources_folder():
    # every path a rule makes goes through R() (results_dir), L() (logs) or B() (benchmarks); a fixed
    # "resources/..." path would be shared by every config run in the project
    hits = [f"{p.name}:{n}: {code.strip()}" for p in sorted((REPO / "workflow" / "rules").glob("*.smk"))
            for n, code in _code_lines(p) if re.search(r"""(?<!R\()(?<!R\(f)["'](\./)?resources/""", code)]
    assert hits == []


def test_generated_inputs_are_below_results_dir():
    text = {p.name: p.read_text() for p in (REPO / "workflow" / "rules").glob("*.smk")}
    assert 'R(f"resources/mocap/{trial}.amc")' in text["common.smk"]
    assert 'directory(R("resources/mesh/{meshsrc}"))' in text["data.smk"]
    assert 'FG_DB_DIR = R("resources/facegraph/ckplus_synthetic")' in text["facegraph.smk"]


OTHER = """# another run in the same project: its own results_dir, other synthetic trials and faces
results_dir: results/other
synthetic_mocap: {seed: 8}
facegraph:
  synthetic: {n_subjects: 5, n_sequences: 12, total_frames: 240, n_unlabelled: 1, min_frames: 10, max_frames: 40}
"""


#: What makes a job rerun, but for the set of input files: the copy of the finished run moves the published
#: tables' absolute path (they are read from ../shared/papers), which alone would replan the jobs reading them.
TRIGGERS = ["--rerun-triggers", "mtime", "params", "code", "software-env"]


@pytest.mark.workflow
def test_a_second_config_leaves_the_first_run_up_to_date(tiny_workflow, tmp_path):
    wd = copy_finished_run(tiny_workflow, tmp_path / "run")
    place_papers(wd)
    first = ["--configfile", "config/test.yaml", *TRIGGERS]
    res = run_snakemake(wd, "-n", *first)
    assert res.returncode == 0 and "Nothing to be done" in res.stdout + res.stderr, res.stdout[-3000:]
    (wd / "config" / "other.yaml").write_text(OTHER)
    # the second run makes its own trial and face database (one job of each rule that generates an input: every
    # synth_trial job writes through the same R() path, so one trial stands for the twelve)
    res = run_snakemake(wd, "results/other/resources/mocap/syn35_16.amc", "results/other/resources/facegraph/ckplus_synthetic",
                        "--configfile", "config/test.yaml", "config/other.yaml")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-4000:]
    assert "facegraph_synth_db" in out and "synth_trial" in out
    assert (wd / "results/other/resources/facegraph/ckplus_synthetic/Landmarks").is_dir()
    assert (wd / "results/other/resources/mocap/syn35_16.amc").read_bytes() != \
        (wd / "results/resources/mocap/syn35_16.amc").read_bytes()
    # ... and the first run's dry run still plans nothing
    res = run_snakemake(wd, "-n", *first)
    out = res.stdout + res.stderr
    assert res.returncode == 0 and "Nothing to be done" in out, out[-4000:]
