"""Command-line requests that used to end in a traceback, a huge allocation or
an option without effect: one line on stderr, exit 2, nothing written."""

import hashlib
import os

import pytest

from animsynth.cli import main


@pytest.fixture(scope="module")
def trial(tmp_path_factory):
    from conftest import write_small_trial

    return write_small_trial(tmp_path_factory.mktemp("cli_limits"), 40)


def _one_line_exit_2(capsys, rc, *needles):
    err = capsys.readouterr().err
    assert rc == 2, err
    assert len(err.strip().splitlines()) == 1, err
    for n in needles:
        assert n in err, err
    return err


def test_generate_steps_over_the_memory_budget(trial, tmp_path, capsys):
    out = tmp_path / "g.bvh"
    rc = main(["generate", str(trial / "c.amc"), "--asf", str(trial / "c.asf"), "--steps", "1000000000",
               "--out", str(out)])
    _one_line_exit_2(capsys, rc, "--steps", "GiB", "memory budget")
    assert not out.exists()


def test_resequence_length_over_the_memory_budget(trial, tmp_path, capsys):
    out = tmp_path / "r.bvh"
    rc = main(["resequence", str(trial / "c.asf"), str(trial / "c.amc"), "--start", "0", "--end", "30",
               "--length", "1000000000", "--out", str(out)])
    _one_line_exit_2(capsys, rc, "--length", "GiB")
    assert not out.exists()


def test_memory_budget_is_configurable(trial, tmp_path, capsys):
    out = tmp_path / "r.bvh"
    rc = main(["resequence", str(trial / "c.asf"), str(trial / "c.amc"), "--start", "0", "--end", "30",
               "--length", "100000", "--out", str(out), "--memory-budget-gib", "0.01"])
    _one_line_exit_2(capsys, rc, "--length", "0.01 GiB")


@pytest.mark.parametrize("cmd", ["resequence", "amc2bvh", "preview", "generate"])
def test_fps_out_of_range(trial, tmp_path, capsys, cmd):
    asf, amc = str(trial / "c.asf"), str(trial / "c.amc")
    args = {"resequence": ["resequence", asf, amc, "--start", "0", "--end", "30", "--out", str(tmp_path / "o.bvh")],
            "amc2bvh": ["amc2bvh", asf, amc, str(tmp_path / "o.bvh")],
            "preview": ["preview", asf, amc, str(tmp_path / "o.gif")],
            "generate": ["generate", amc, "--asf", asf, "--steps", "5", "--out", str(tmp_path / "o.bvh")]}[cmd]
    rc = main(args + ["--fps", "1e308"])
    _one_line_exit_2(capsys, rc, "--fps")
    assert not any(tmp_path.iterdir())


def test_preview_fps_changes_the_gif(trial, tmp_path):
    digests = {}
    for fps in ("30", "120"):
        out = tmp_path / f"p{fps}.gif"
        assert main(["preview", str(trial / "c.asf"), str(trial / "c.amc"), str(out), "--fps", fps]) == 0
        digests[fps] = hashlib.sha256(out.read_bytes()).hexdigest()
    assert digests["30"] != digests["120"]
    from PIL import Image

    def duration_s(p):
        im = Image.open(p)
        total = 0
        for k in range(im.n_frames):
            im.seek(k)
            total += im.info["duration"]
        return total / 1000.0

    # 40 frames: 1.33 s at 30 fps, 0.33 s at 120 fps (real time, within the GIF's 10 ms resolution)
    assert duration_s(tmp_path / "p30.gif") == pytest.approx(40 / 30, abs=0.15)  # 33.3 ms is stored as 30
    assert duration_s(tmp_path / "p120.gif") == pytest.approx(40 / 120, abs=0.1)


def test_face_label_missing_from_the_ckplus_copy(tmp_path, capsys):
    from animsynth.io.ckplus import EMOTIONS
    from animsynth.synth.faces import generate_database

    root = tmp_path / "ck"
    generate_database(root, seed=0, total_frames=800)
    for f in list((root / "Emotion").rglob("*_emotion.txt")):
        if EMOTIONS[int(float(f.read_text().strip()))] == "fear":
            for g in f.parent.iterdir():
                g.unlink()
            f.parent.rmdir()
    out = tmp_path / "f.gif"
    rc = main(["face", "--labels", "fear,happy", "--ckplus", str(root), str(out)])
    _one_line_exit_2(capsys, rc, "'fear'", str(root))
    assert not out.exists()
    assert not [p for p in os.listdir(tmp_path) if p.startswith(".tmp")]
