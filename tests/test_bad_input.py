"""Bad input, fed to the readers and the command line as a careful user would.

Every case asserts the error type, that the message names the file and line
(or the argument / config key), and that nothing was written.
"""

import gzip
import re

import numpy as np
import pytest

from animsynth.io import MotionFormatError, read_amc, read_asf, write_amc, write_asf
from animsynth.io.bvh import read_bvh, write_bvh
from animsynth.io.obj import read_obj, read_obj_sequence, write_obj
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("bad_input")
    sk = cmu_like_skeleton("s1", 3)
    m = generate_motion("walk_straight", 40, 5, sk)
    write_asf(d / "s1.asf", sk, length_unit=0.45)
    write_amc(d / "s1_01.amc", m)
    write_bvh(d / "s1_01.bvh", m)
    return d, sk, m


def _line_of(err: MotionFormatError, path) -> int:
    """The line number in the message, checking that the message names the file."""
    msg = str(err)
    m = re.match(re.escape(str(path)) + r":(\d+): ", msg)
    assert m, f"message does not start with 'file:line:': {msg}"
    assert err.line == int(m.group(1))
    return err.line


def _replace_line(text: str, startswith: str, new: str) -> tuple[str, int]:
    lines = text.split("\n")
    k = next(i for i, ln in enumerate(lines) if ln.strip().startswith(startswith))
    lines[k] = new
    return "\n".join(lines), k + 1


# --- OBJ ---------------------------------------------------------------

SIX = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"


@pytest.mark.parametrize("faces,line,msg", [
    # a quad then a two-vertex face: 6 tokens, once read as two triangles
    ("f 1 2 3 4\nf 5 6\n", 8, "at least 3 vertices"),
    # a face naming a vertex defined only after it
    ("f 1 2 3\nf 4 5 7\nv 3 3 0\n", 8, "not defined before it"),
    ("f 1 2 3\nf 1 2 3.5\n", 8, "non-integer face index"),
])
def test_obj_irregular_records_are_refused_and_not_cached(tmp_path, faces, line, msg):
    d = tmp_path / "seq"
    d.mkdir()
    (d / "mesh_0000.obj").write_text(SIX + faces)
    with pytest.raises(MotionFormatError, match=msg) as ei:
        read_obj(d / "mesh_0000.obj")
    assert _line_of(ei.value, d / "mesh_0000.obj") == line
    cache = tmp_path / "cache.npz"
    with pytest.raises(MotionFormatError, match=msg):
        read_obj_sequence(d, cache=cache)
    assert not cache.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["seq"]


def test_obj_fast_and_careful_parsers_agree(tmp_path):
    """Regular files take the fast path; the result equals the careful parser's."""
    from animsynth.io.obj import _fast_parse, _slow_parse

    rng = np.random.default_rng(0)
    v = rng.normal(size=(30, 3))
    f = rng.integers(0, 30, size=(40, 3))
    write_obj(tmp_path / "a.obj", v, f)
    lines = (tmp_path / "a.obj").read_text().splitlines()
    fv, ff = _fast_parse(lines)
    sv, sf = _slow_parse(tmp_path / "a.obj", lines)
    np.testing.assert_array_equal(fv, np.array(sv))
    np.testing.assert_array_equal(ff, np.array(sf))
    # a polygon or i/t/n tokens leave the fast path (the careful one fans them)
    assert _fast_parse(lines + ["f 1 2 3 4"]) is None
    assert _fast_parse(lines + ["f 1/1 2/2 3/3"]) is None


@pytest.mark.parametrize("damage", ["truncated", "corrupt", "not_gzip"])
def test_obj_gz_damage_names_the_file(tmp_path, damage):
    good = gzip.compress((SIX + "f 1 2 3\n").encode() * 50, mtime=0)
    if damage == "truncated":
        data = good[: len(good) // 2]
    elif damage == "corrupt":
        data = good[:12] + bytes(b ^ 0xFF for b in good[12:40]) + good[40:]
    else:
        data = b"this is not gzip data at all\n"
    d = tmp_path / "seq"
    d.mkdir()
    p = d / "mesh_0000.obj.gz"
    p.write_bytes(data)
    with pytest.raises(MotionFormatError, match="gzip") as ei:
        read_obj(p)
    assert str(ei.value).startswith(f"{p}: ")
    with pytest.raises(MotionFormatError):
        read_obj_sequence(d, cache=tmp_path / "c.npz")
    assert not (tmp_path / "c.npz").exists()


# --- AMC ---------------------------------------------------------------

def test_amc_non_utf8_names_line(tmp_path, files):
    d, sk, _ = files
    text = (d / "s1_01.amc").read_text()
    body, line = _replace_line(text, "head ", "head 0.0 \xe9 0.0")
    p = tmp_path / "latin1.amc"
    p.write_bytes(body.encode("latin-1"))
    with pytest.raises(MotionFormatError, match="not UTF-8") as ei:
        read_amc(p, sk)
    assert _line_of(ei.value, p) == line


def test_amc_unicode_digit_frame_number(tmp_path, files):
    d, sk, _ = files
    text = (d / "s1_01.amc").read_text()
    body, line = _replace_line(text, "2", "\u00b2")  # superscript two: isdigit() but not int()
    p = tmp_path / "sup.amc"
    p.write_text(body, encoding="utf-8")
    with pytest.raises(MotionFormatError, match="unknown bone '²'") as ei:
        read_amc(p, sk)
    assert _line_of(ei.value, p) == line


def test_amc_byte_order_mark_is_an_encoding_signature(tmp_path, files):
    """A UTF-8 BOM (Windows editors) is dropped: same values as without it, with CRLF too."""
    d, sk, m = files
    text = (d / "s1_01.amc").read_text()
    p = tmp_path / "bom.amc"
    p.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    np.testing.assert_array_equal(read_amc(p, sk).values, read_amc(d / "s1_01.amc", sk).values)
    # a BOM anywhere else is content, and refused with the line
    p.write_bytes(text.replace("\nroot", "\n\ufeffroot", 1).encode())
    with pytest.raises(MotionFormatError, match="unknown bone") as ei:
        read_amc(p, sk)
    assert _line_of(ei.value, p) > 1


# --- ASF ---------------------------------------------------------------

@pytest.mark.parametrize("case,msg", [
    ("length0", "length unit must be positive"),
    ("length_neg", "length unit must be positive"),
    ("no_root", "no :root section"),
    ("latin1", "not UTF-8"),
])
def test_asf_bad_units_root_encoding(tmp_path, files, case, msg):
    d, _, _ = files
    text = (d / "s1.asf").read_text()
    p = tmp_path / f"{case}.asf"
    line = None
    if case == "length0":
        text, line = _replace_line(text, "length 0.45", "  length 0")
    elif case == "length_neg":
        text, line = _replace_line(text, "length 0.45", "  length -1")
    elif case == "no_root":
        start = text.index(":root")
        text = text[:start] + text[text.index(":bonedata"):]
    elif case == "latin1":
        text, line = _replace_line(text, "written by animsynth", "   \xe9crit par animsynth")
    p.write_bytes(text.encode("latin-1"))
    with pytest.raises(MotionFormatError, match=msg) as ei:
        read_asf(p)
    if line is None:
        assert str(ei.value).startswith(f"{p}: ")
    else:
        assert _line_of(ei.value, p) == line


# --- BVH ---------------------------------------------------------------

@pytest.mark.parametrize("case,msg", [
    ("time0", "frame time must be positive"),
    ("time_neg", "frame time must be positive"),
    ("frames0", "frame count must be at least 1"),
    ("latin1", "not UTF-8"),
    ("extra_row", "more frame rows"),
])
def test_bvh_bad_header_and_encoding(tmp_path, files, case, msg):
    d, _, _ = files
    text = (d / "s1_01.bvh").read_text()
    p = tmp_path / f"{case}.bvh"
    if case == "time0":
        text, line = _replace_line(text, "Frame Time:", "Frame Time: 0")
    elif case == "time_neg":
        text, line = _replace_line(text, "Frame Time:", "Frame Time: -0.008333")
    elif case == "frames0":
        text, line = _replace_line(text, "Frames:", "Frames: 0")
    elif case == "latin1":
        text, line = _replace_line(text, "ROOT", "ROOT r\xf6\xf6t")
    else:
        rows = text.rstrip("\n").split("\n")
        text = "\n".join(rows + [rows[-1]]) + "\n"
        line = len(rows) + 1
    p.write_bytes(text.encode("latin-1"))
    with pytest.raises(MotionFormatError, match=msg) as ei:
        read_bvh(p)
    assert _line_of(ei.value, p) == line


# --- the command line -----------------------------------------------------

def _cli_cases():
    g = ["generate", "{amc}", "--asf", "{asf}", "--steps", "5"]
    r = ["resequence", "{asf}", "{amc}", "--start", "0", "--end", "30"]
    a = ["amc2bvh", "{asf}", "{amc}", "{out}.bvh"]
    return [
        ("start_frame", g + ["--start-frame", "9999", "--out", "{out}.bvh"], "--start-frame", "40 frames"),
        ("start_trial", g + ["--start-trial", "7", "--out", "{out}.bvh"], "--start-trial", "1 training file"),
        ("fps0", a + ["--fps", "0"], "--fps", "must be > 0"),
        ("fps_neg", a + ["--fps", "-30"], "--fps", "must be > 0"),
        ("fps_nan", a + ["--fps", "nan"], "--fps", "finite"),
        ("fps_inf", g + ["--fps", "inf", "--out", "{out}.amc"], "--fps", "finite"),
        ("start_neg", r + ["--start", "-5", "--out", "{out}.bvh"], "--start", "must be >= 0"),
        ("end_past", ["resequence", "{asf}", "{amc}", "--start", "0", "--end", "9999", "--out", "{out}.bvh"],
         "--end", "40 frames"),
        ("k_reseq", r + ["--k", "40", "--out", "{out}.bvh"], "--k", "only 40 frames"),
        ("k_generate", g + ["--method", "knn", "--k", "41", "--out", "{out}.bvh"], "--k", "only 40 frames"),
        ("k_zero", g + ["--k", "0", "--out", "{out}.bvh"], "--k", "must be >= 1"),
        ("steps0", ["generate", "{amc}", "--asf", "{asf}", "--steps", "0", "--out", "{out}.bvh"], "--steps", ">= 1"),
        ("length0", r + ["--length", "0", "--out", "{out}.bvh"], "--length", ">= 1"),
        ("seed_neg", g + ["--seed", "-1", "--out", "{out}.bvh"], "--seed", "2**32"),
        ("out_ext", g + ["--out", "{out}.txt"], "--out", "use a .bvh, .amc or .gif"),
        ("bvh_ext", ["amc2bvh", "{asf}", "{amc}", "{out}.amc"], "out", "use a .bvh file name"),
        ("missing_amc", ["amc2bvh", "{asf}", "{dir}/nope.amc", "{out}.bvh"], "amc", "no such file"),
        ("labels_empty", ["face", "--labels", ",", "{out}.gif"], "--labels", "comma-separated"),
        ("labels_unknown", ["face", "--labels", "fear,bored", "{out}.gif"], "--labels", "unknown CK+ emotion 'bored'"),
        ("ckplus_missing", ["face", "--labels", "fear", "--ckplus", "{dir}/nope", "{out}.gif"], "--ckplus", "no such folder"),
    ]


@pytest.mark.parametrize("name,argv,option,fragment", _cli_cases(), ids=[c[0] for c in _cli_cases()])
def test_cli_bad_argument_one_line_exit_2_nothing_written(tmp_path, files, capsys, name, argv, option, fragment):
    from animsynth.cli import main

    d, _, _ = files
    out = tmp_path / "out"
    out.mkdir()
    fill = {"asf": str(d / "s1.asf"), "amc": str(d / "s1_01.amc"), "out": str(out / "o"), "dir": str(tmp_path)}
    rc = main([a.format(**fill) for a in argv])
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert len(err.splitlines()) == 1, err
    assert f"argument {option}" in err or f"argument {option.lstrip('-')}" in err, err
    assert fragment in err, err
    assert list(out.iterdir()) == []


def test_cli_malformed_input_names_file_and_line(tmp_path, files, capsys):
    from animsynth.cli import main

    d, _, _ = files
    text = (d / "s1_01.amc").read_text()
    body, line = _replace_line(text, "head ", "head 0.0 x 0.0")
    (tmp_path / "bad.amc").write_text(body)
    rc = main(["amc2bvh", str(d / "s1.asf"), str(tmp_path / "bad.amc"), str(tmp_path / "o.bvh")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1
    assert f"{tmp_path / 'bad.amc'}:{line}: non-numeric" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.amc"]


# --- where data may come from ----------------------------------------------

def _user_config(data_dir, **trial):
    import yaml

    from conftest import REPO

    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    cfg.update(mocap_source="user", data_dir=str(data_dir))
    t = {"id": "t1", "subject": "me", "kind": "walk_straight", "amc": "me/t1.amc", "asf": "me/me.asf"}
    t.update(trial)
    t2 = {"id": "t2", "subject": "me", "kind": "walk_straight", "amc": "me/t1.amc", "asf": "me/me.asf"}
    cfg["trials"] = [t, t2]
    cfg["subsets"] = {"w1": ["t1", "t2"], "w2": None, "r1": None, "r2": None}
    cfg["resequencing_trials"] = {"walk": "t1", "run": "t1", "dance": "t1"}
    return cfg


@pytest.mark.parametrize("field,value,fragment", [
    ("amc", "../../../../etc/hostname", "leaves"),
    ("amc", "me/../../outside.amc", "leaves"),
    ("asf", "/etc/hostname", "absolute path"),
    ("asf", "~/me.asf", "absolute path"),
    ("bvh", "C:\\mocap\\t1.bvh", "absolute path"),
    ("amc", "..", "leaves"),
])
def test_config_paths_must_stay_inside_data_dir(tmp_path, field, value, fragment):
    from animsynth.config import ConfigError, check_config

    cfg = _user_config(tmp_path, **{field: value})
    with pytest.raises(ConfigError, match=fragment) as ei:
        check_config(cfg)
    assert f"config key 'trials[0].{field}'" in str(ei.value)


def test_a_folder_of_links_to_readable_files_is_a_mirror(tmp_path):
    """Inputs are only read: a link below data_dir (or a mirror) may point anywhere, as in a merged mirror built
    from links; a path text leaving the folder is still refused."""
    from animsynth.config import check_config
    from animsynth.data import DownloadError, fetch_file

    (tmp_path / "outside.amc").write_text("motion\n")
    data = tmp_path / "data"
    (data / "me").mkdir(parents=True)
    (data / "me" / "t1.amc").symlink_to(tmp_path / "outside.amc")
    check_config(_user_config(data))
    dest = tmp_path / "res" / "t1.amc"
    fetch_file(str(data), "me/t1.amc", dest, None)
    assert dest.read_text() == "motion\n" and not dest.is_symlink()  # a copy of the file the link names
    with pytest.raises(DownloadError, match="refusing to fetch"):
        fetch_file(str(data), "../outside.amc", tmp_path / "res2" / "x.amc", None)
    assert not (tmp_path / "res2").exists()


# --- honest, quiet failures ---------------------------------------------------

def test_atomic_write_names_the_target_on_permission_error(tmp_path):
    import os

    from animsynth.atomic import atomic_write_text

    ro = tmp_path / "ro"
    ro.mkdir()
    os.chmod(ro, 0o555)
    try:
        if os.access(ro, os.W_OK):
            pytest.skip("running as a user who can write a read-only folder (root)")
        with pytest.raises(PermissionError) as ei:
            atomic_write_text(ro / "table.csv", "a\n")
        assert str(ro / "table.csv") in str(ei.value) and ".tmp-" not in str(ei.value)
    finally:
        os.chmod(ro, 0o755)


def test_atomic_replace_failure_names_the_target(tmp_path):
    from animsynth.atomic import atomic_write_text

    (tmp_path / "table.csv").mkdir()  # a folder where the file should go: rename fails
    with pytest.raises(OSError) as ei:
        atomic_write_text(tmp_path / "table.csv", "a\n")
    assert str(tmp_path / "table.csv") in str(ei.value) and ".tmp-" not in str(ei.value)
    assert [p.name for p in tmp_path.iterdir()] == ["table.csv"]


def test_stale_temporaries_of_a_jobs_outputs_are_removed(tmp_path):
    """SIGKILL leaves .tmp-<name>-* behind; the next job for that output removes them, no others."""
    import os
    import signal
    import subprocess
    import sys

    from animsynth.atomic import clean_stale_temporaries

    out = tmp_path / "big.csv"
    code = ("import sys, time\nfrom animsynth.atomic import atomic_path\n"
            "with atomic_path(sys.argv[1]) as tmp:\n"
            "    open(tmp, 'w').write('partial')\n    print('ready', flush=True)\n    time.sleep(60)\n")
    proc = subprocess.Popen([sys.executable, "-c", code, str(out)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "ready"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()  # SIGKILL cannot be ignored
    left = sorted(p.name for p in tmp_path.glob(".tmp-*"))
    assert len(left) == 1 and left[0].startswith(".tmp-big.csv-") and not out.exists()
    other = tmp_path / ".tmp-other.csv-abc123.csv"  # another job's live temporary
    other.write_text("busy")
    removed = clean_stale_temporaries([out, tmp_path / "never_written.csv"])
    assert [os.path.basename(r) for r in removed] == left
    assert sorted(p.name for p in tmp_path.iterdir()) == [other.name]


@pytest.fixture
def user_workflow(tmp_path, files):
    """A copy of the workflow and a user data folder with one ASF/AMC trial."""
    import shutil

    import yaml

    from conftest import copy_workflow

    d, _, _ = files
    data = tmp_path / "data"
    (data / "me").mkdir(parents=True)
    shutil.copyfile(d / "s1.asf", data / "me" / "me.asf")
    shutil.copyfile(d / "s1_01.amc", data / "me" / "t1.amc")
    wd = copy_workflow(tmp_path / "wf")

    def write(**trial):
        cfg = _user_config(data, **trial)
        keep = {k: cfg[k] for k in ("mocap_source", "data_dir", "trials", "subsets", "resequencing_trials")}
        (wd / "config" / "bad.yaml").write_text(yaml.safe_dump(keep))
        return wd

    return write


@pytest.mark.workflow
def test_workflow_checksum_mismatch_is_one_line_not_retried(user_workflow):
    from conftest import run_snakemake

    wd = user_workflow(sha256="0" * 64)
    res = run_snakemake(wd, "results/resources/mocap/t1.amc", "--configfile", "config/bad.yaml")
    out = res.stdout + res.stderr
    assert res.returncode != 0
    log = (wd / "logs" / "data" / "download_trial" / "t1.log").read_text()
    assert "checksum mismatch for me/t1.amc" in log and "expected " + "0" * 64 + ", got " in log
    assert "Traceback" not in log and "Traceback" not in out
    assert out.count("Error in rule download_trial") == 1  # no retries
    assert not (wd / "results" / "resources" / "mocap" / "t1.amc").exists()
    assert not list((wd / "results" / "resources").rglob(".tmp-*"))


@pytest.mark.workflow
def test_workflow_refuses_a_path_leaving_data_dir(user_workflow):
    from conftest import run_snakemake

    wd = user_workflow(amc="../../../../../../etc/hostname")
    res = run_snakemake(wd, "results/resources/mocap/t1.amc", "--configfile", "config/bad.yaml")
    out = res.stdout + res.stderr
    assert res.returncode != 0
    assert "config key 'trials[0].amc'" in out and "leaves" in out
    assert len(out.strip().splitlines()) < 15, out
    assert not (wd / "results" / "resources").exists()
