"""The `animsynth` command line: help, conversions, generation, errors."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from animsynth.cli import main
from animsynth.io import read_asf, write_amc, write_asf
from animsynth.io.bvh import read_bvh
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

EXE = str(Path(sys.executable).with_name("animsynth"))


@pytest.fixture(scope="module")
def trial_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("cli")
    sk = cmu_like_skeleton("c", 1)
    write_asf(d / "c.asf", sk, length_unit=0.45)
    for i in range(3):
        write_amc(d / f"c_{i}.amc", generate_motion("walk_straight", 150, i, sk))
    return d


@pytest.mark.parametrize("cmd", ["", "amc2bvh", "preview", "generate", "resequence", "face"])
def test_help(cmd):
    res = subprocess.run([EXE, *([cmd] if cmd else []), "--help"], capture_output=True, text=True)
    assert res.returncode == 0 and "usage: animsynth" in res.stdout


def test_amc2bvh(trial_files, tmp_path, capsys):
    assert main(["amc2bvh", str(trial_files / "c.asf"), str(trial_files / "c_0.amc"), str(tmp_path / "o.bvh")]) == 0
    b = read_bvh(tmp_path / "o.bvh")
    assert b.n_frames == 150 and "wrote" in capsys.readouterr().out


def test_generate_both_methods(trial_files, tmp_path):
    for method in ("delaunay", "knn"):
        out = tmp_path / f"{method}.amc"
        rc = main(["generate", str(trial_files / "c_0.amc"), str(trial_files / "c_1.amc"), str(trial_files / "c_2.amc"),
                   "--asf", str(trial_files / "c.asf"), "--method", method, "--steps", "60", "--out", str(out)])
        assert rc == 0
        from animsynth.io import read_amc
        m = read_amc(out, read_asf(trial_files / "c.asf"))
        assert m.n_frames == 61 and np.all(np.isfinite(m.values))
        assert np.ptp(m.values[:, 6:], axis=0).max() > 5  # it moves


def test_resequence(trial_files, tmp_path, capsys):
    rc = main(["resequence", str(trial_files / "c.asf"), str(trial_files / "c_0.amc"), "--start", "5", "--end", "140",
               "--method", "isomap", "--out", str(tmp_path / "r.bvh"), "--length", "200"])
    assert rc == 0
    assert read_bvh(tmp_path / "r.bvh").n_frames == 200
    assert "path 5 " in capsys.readouterr().out


def test_errors_are_clear(trial_files, tmp_path, capsys):
    assert main(["amc2bvh", str(tmp_path / "missing.asf"), str(trial_files / "c_0.amc"), str(tmp_path / "x.bvh")]) == 2
    assert f"argument asf: no such file '{tmp_path / 'missing.asf'}'" in capsys.readouterr().err
    assert main(["resequence", str(trial_files / "c.asf"), str(trial_files / "c_0.amc"), "--start", "0",
                 "--end", "999", "--out", str(tmp_path / "r.bvh")]) == 2
    assert "argument --end: 999 is outside" in capsys.readouterr().err
    assert main(["face", "--labels", "fear,bored", str(tmp_path / "f.gif")]) == 2
    assert "unknown CK+ emotion 'bored'" in capsys.readouterr().err
    assert main(["generate", str(trial_files / "c_0.amc"), "--asf", str(trial_files / "c.asf"),
                 "--out", str(tmp_path / "g.txt")]) == 2
    assert "use a .bvh, .amc or .gif" in capsys.readouterr().err
    assert not (tmp_path / "x.bvh").exists() and not (tmp_path / "f.gif").exists()


def test_face_from_labels(tmp_path, monkeypatch):
    # the default route (a fresh synthetic CK+-layout database, written, read back, fitted), on a database
    # of 14 sequences with every CK+ label instead of the paper-sized 70
    from animsynth.synth import faces

    full = faces.generate_database
    monkeypatch.setattr(faces, "generate_database", lambda root, seed=0: full(
        root, seed=seed, n_subjects=6, n_sequences=14, total_frames=280, n_unlabelled=1, min_frames=10,
        max_frames=40))
    rc = main(["face", "--labels", "fear,surprise,happy", "--seed", "3", str(tmp_path / "f.csv")])
    assert rc == 0
    import pandas as pd
    df = pd.read_csv(tmp_path / "f.csv")
    assert set(df["landmark"]) == set(range(68)) and df["frame"].nunique() > 20
