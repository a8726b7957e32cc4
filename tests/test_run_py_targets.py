"""run.py: targets may come before or after --configfile / --config (snakemake would read a target after
them as a config file or a KEY=VALUE pair)."""

import importlib.util

from conftest import REPO


def _run_py():
    spec = importlib.util.spec_from_file_location("run_py", REPO / "run.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_targets_after_configfile_are_moved_in_front():
    run = _run_py()
    args = ["--cores", "1", "--configfile", "mine.yaml", "results/x/verdicts.csv", "other.yml",
            "--config", "a=1", "results/y.csv", "-n"]
    out, moved = run.sort_targets(args)
    assert moved == ["results/x/verdicts.csv", "results/y.csv"]
    assert out == ["results/x/verdicts.csv", "results/y.csv", "--cores", "1", "--configfile", "mine.yaml",
                   "other.yml", "--config", "a=1", "-n"]
    assert run.configfiles(out) == ["mine.yaml", "other.yml"]


def test_targets_before_configfile_are_left_alone(capsys):
    run = _run_py()
    args = ["results/x/verdicts.csv", "--configfile", "mine.yaml", "--configfile=b.json", "--config", "k=v"]
    assert run.with_targets_first(args) == args
    assert capsys.readouterr().out == ""
    run.with_targets_first(["--configfile", "mine.yaml", "t.csv"])
    assert "read as target(s), not config: t.csv" in capsys.readouterr().out


def test_every_configfile_option_is_joined_into_one():
    """Snakemake keeps only the last --configfile option: `python3 run.py paper --configfile mine.yaml` must run on
    config/cmu.yaml, samba.yaml, paper.yaml and then mine.yaml, not on mine.yaml alone."""
    run = _run_py()
    args = ["--configfile", "a.yaml", "b.yaml", "--config", "x=1", "--configfile=mine.yaml", "-n"]
    assert run.one_configfile_option(args) == ["--configfile", "a.yaml", "b.yaml", "mine.yaml", "--config", "x=1",
                                               "-n"]
    assert run.one_configfile_option(["t.csv", "-n"]) == ["t.csv", "-n"]
    paper = run.snakemake_args("paper", ["--configfile", "mine.yaml", "results/paper/data/trials/99_01.npz"])
    assert paper == ["results/paper/data/trials/99_01.npz", "--configfile", "config/cmu.yaml", "config/samba.yaml",
                     "config/paper.yaml", "mine.yaml"]
