"""Inputs and requests that used to end in a traceback or an error naming no
file: deep BVH nesting, huge AMC frame numbers and OBJ face indices, a full
disk, a checksum list naming one frame twice, memory running out under a raised
budget, and the command line's smaller slips (the stated --fps end, --latent-dim,
an upper-case output suffix, an output that is an input). Each is one line
naming the file and line, the output, or the option."""

import errno
import hashlib
import logging
import os

import pytest

from animsynth.cli import main
from animsynth.io import MotionFormatError, read_amc, read_asf
from animsynth.io.bvh import read_bvh
from animsynth.io.obj import read_obj


@pytest.fixture(scope="module")
def trial(tmp_path_factory):
    from conftest import write_small_trial

    return write_small_trial(tmp_path_factory.mktemp("input_limits"), 40)


def _one_line(capsys, rc, *needles, status=2):
    err = capsys.readouterr().err
    assert rc == status, err
    assert len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err
    for n in needles:
        assert n in err, err
    return err


# ---- readers -------------------------------------------------------------------

def _deep_bvh(depth: int) -> str:
    lines = ["HIERARCHY", "ROOT j0", "{", "OFFSET 0 0 0", "CHANNELS 6 Xposition Yposition Zposition "
             "Zrotation Xrotation Yrotation"]
    for k in range(1, depth):
        lines += [f"JOINT j{k}", "{", "OFFSET 0 1 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
    lines += ["End Site", "{", "OFFSET 0 1 0", "}"] + ["}"] * depth
    n = 6 + 3 * (depth - 1)
    lines += ["MOTION", "Frames: 1", "Frame Time: 0.008333", " ".join(["0"] * n)]
    return "\n".join(lines) + "\n"


def test_bvh_nested_1200_deep_names_file_and_line(tmp_path):
    from animsynth.io.bvh import MAX_JOINT_DEPTH

    p = tmp_path / "deep.bvh"
    p.write_text(_deep_bvh(1200))
    with pytest.raises(MotionFormatError) as ei:
        read_bvh(p)
    assert str(ei.value).startswith(f"{p}:") and f"nested more than {MAX_JOINT_DEPTH} deep" in str(ei.value)
    # the line named is the first joint past the limit
    assert ei.value.line == p.read_text().splitlines().index(f"JOINT j{MAX_JOINT_DEPTH}") + 1


def test_bvh_at_the_depth_limit_is_read(tmp_path):
    p = tmp_path / "deep_ok.bvh"
    p.write_text(_deep_bvh(60))
    assert len(read_bvh(p).skeleton.joints) == 60


def test_amc_huge_frame_number_names_file_and_line(tmp_path, trial):
    sk = read_asf(trial / "c.asf")
    lines = (trial / "c.amc").read_text().splitlines()
    first = next(i for i, ln in enumerate(lines) if ln.strip().isdigit())
    lines[first] = "9" * 5001
    p = tmp_path / "huge.amc"
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(MotionFormatError) as ei:
        read_amc(p, sk)
    assert str(ei.value).startswith(f"{p}:{first + 1}: frame number of 5001 digits")


@pytest.mark.parametrize("index", ["1" * 30, "9" * 19, "1" * 5001], ids=["30_digits", "past_int64", "5001_digits"])
def test_obj_huge_face_index_names_file_and_line(tmp_path, index):
    p = tmp_path / "mesh_0000.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n" + f"f 1 2 {index}\n")
    with pytest.raises(MotionFormatError) as ei:
        read_obj(p)
    assert str(ei.value).startswith(f"{p}:4: ") and len(str(ei.value)) < 300


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (a device that is always full)")
def test_a_full_disk_names_the_output(tmp_path):
    from animsynth.atomic import atomic_path

    out = tmp_path / "table.csv"
    with pytest.raises(OSError) as ei:
        with atomic_path(out):
            with open("/dev/full", "w") as fh:  # what a write to a full disk raises: ENOSPC, no file named
                fh.write("x" * 100_000)
                fh.flush()
    assert ei.value.errno == errno.ENOSPC
    assert str(out) in str(ei.value) and "No space left on device" in str(ei.value)
    assert not out.exists() and not list(tmp_path.iterdir())


def test_a_full_disk_in_the_cli_is_one_line_naming_the_output(trial, tmp_path, capsys, monkeypatch):
    import animsynth.atomic as atomic

    real_open = open

    def full_open(path, mode="r", *a, **k):
        if "w" in mode and os.path.basename(str(path)).startswith(atomic.TMP_PREFIX):
            return real_open("/dev/full", mode, *a, **k)
        return real_open(path, mode, *a, **k)

    if not os.path.exists("/dev/full"):
        pytest.skip("needs /dev/full")
    monkeypatch.setattr("builtins.open", full_open)
    out = tmp_path / "o.bvh"
    rc = main(["amc2bvh", str(trial / "c.asf"), str(trial / "c.amc"), str(out)])
    _one_line(capsys, rc, str(out), "No space left on device")
    assert not out.exists()


# ---- checksum lists --------------------------------------------------------------

@pytest.mark.parametrize("second", ["mesh_0001.obj", "mesh_0001.obj.gz", "*mesh_0001.OBJ"])
def test_checksum_list_naming_a_frame_twice_is_refused_naming_both_lines(tmp_path, second):
    from animsynth.sources import MeshSourceError, read_sha256_list

    p = tmp_path / "sums.txt"
    p.write_text(f"{'a' * 64}  mesh_0001.obj\n{'c' * 64}  mesh_0002.obj\n# note\n{'b' * 64}  {second}\n")
    with pytest.raises(MeshSourceError) as ei:
        read_sha256_list(p)
    msg = str(ei.value)
    assert msg.startswith(f"{p}:4: ") and "line 1" in msg and "line 4" in msg and "mesh_0001" in msg


def test_a_wrong_first_hash_no_longer_verifies(tmp_path):
    from animsynth.sources import MeshSourceError, read_sha256_list, verify_mesh_frames

    frames = tmp_path / "frames"
    frames.mkdir()
    (frames / "mesh_0001.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    good = hashlib.sha256((frames / "mesh_0001.obj").read_bytes()).hexdigest()
    p = tmp_path / "sums.txt"
    p.write_text(f"{'0' * 64}  mesh_0001.obj\n{good}  mesh_0001.obj\n")
    with pytest.raises(MeshSourceError, match="listed twice"):
        verify_mesh_frames(frames, read_sha256_list(p))


# ---- the command line --------------------------------------------------------------

def test_memory_error_under_a_raised_budget_is_one_line_naming_the_option(trial, tmp_path, capsys, monkeypatch):
    import animsynth.simplicial as simplicial

    def out_of_memory(*a, **k):
        # what numpy raises (its _ArrayMemoryError is a MemoryError) on a machine smaller than the budget
        raise MemoryError("Unable to allocate 146. TiB for an array with shape (1000000000001, 10, 2)")

    monkeypatch.setattr(simplicial, "generate_from_trials", out_of_memory)
    out = tmp_path / "g.bvh"
    rc = main(["generate", str(trial / "c.amc"), "--asf", str(trial / "c.asf"), "--steps", "200000",
               "--memory-budget-gib", "1000", "--out", str(out)])
    _one_line(capsys, rc, "--steps 200000", "out of memory", "--memory-budget-gib 1000")
    assert not out.exists()


def test_recursion_error_is_one_line_naming_the_input(trial, tmp_path, capsys, monkeypatch):
    import animsynth.io as io

    def too_deep(*a, **k):
        raise RecursionError("maximum recursion depth exceeded")

    monkeypatch.setattr(io, "read_amc", too_deep)
    rc = main(["amc2bvh", str(trial / "c.asf"), str(trial / "c.amc"), str(tmp_path / "o.bvh")])
    _one_line(capsys, rc, str(trial / "c.amc"), "nested too deeply")


def test_the_stated_upper_fps_is_accepted(trial, tmp_path, capsys):
    out = tmp_path / "fast.bvh"
    assert main(["amc2bvh", str(trial / "c.asf"), str(trial / "c.amc"), str(out), "--fps", "100000"]) == 0
    assert read_bvh(out).fps == pytest.approx(100000)
    rc = main(["amc2bvh", str(trial / "c.asf"), str(trial / "c.amc"), str(tmp_path / "o.bvh"), "--fps", "100001"])
    _one_line(capsys, rc, "--fps")


def test_huge_latent_dim_blames_latent_dim(trial, tmp_path, capsys):
    rc = main(["generate", str(trial / "c.amc"), "--asf", str(trial / "c.asf"), "--latent-dim", "1000000000",
               "--out", str(tmp_path / "g.bvh")])
    err = _one_line(capsys, rc, "--latent-dim", "joint angles")
    assert "--steps" not in err


@pytest.mark.parametrize("suffix", [".BVH", ".Amc"])
def test_upper_case_output_suffix_is_written(trial, tmp_path, capsys, suffix):
    out = tmp_path / f"OUT{suffix}"
    rc = main(["generate", str(trial / "c.amc"), "--asf", str(trial / "c.asf"), "--steps", "5", "--out", str(out)])
    assert rc == 0, capsys.readouterr().err
    if suffix == ".BVH":
        assert read_bvh(out).n_frames == 6
    else:
        assert read_amc(out, read_asf(trial / "c.asf")).n_frames == 6


@pytest.mark.parametrize("cmd", ["generate", "resequence"])
def test_an_output_that_is_an_input_is_refused(trial, tmp_path, capsys, cmd):
    import shutil

    amc, asf = tmp_path / "in.amc", tmp_path / "in.asf"
    shutil.copy(trial / "c.amc", amc)
    shutil.copy(trial / "c.asf", asf)
    before = amc.read_bytes(), asf.read_bytes()
    args = {"generate": ["generate", str(amc), "--asf", str(asf), "--steps", "5", "--out", str(amc)],
            "resequence": ["resequence", str(asf), str(amc), "--start", "0", "--end", "30", "--out",
                           str(tmp_path / "." / "in.amc")]}[cmd]
    rc = main(args)
    _one_line(capsys, rc, "--out", "would replace the input")
    assert (amc.read_bytes(), asf.read_bytes()) == before


# ---- warnings of a workflow job reach the console --------------------------------------

def test_job_warnings_reach_the_console_as_well_as_the_log(tmp_path, capfd):
    from animsynth.workflow_utils import setup_logging

    log_path = tmp_path / "job.log"
    log = setup_logging(log_path=str(log_path), name="animsynth.data")
    try:
        log.info("parsed 40 frames")
        log.warning("the skeleton is 172 m tall at rest with bvh_length_to_m=1")
        err = capfd.readouterr().err
    finally:
        root = logging.getLogger("animsynth")
        for h in list(root.handlers):
            root.removeHandler(h)
            h.close()
    assert "172 m tall" in err and "parsed 40 frames" not in err
    text = log_path.read_text()
    assert "172 m tall" in text and "parsed 40 frames" in text
