"""Download/mirror with checksums, and the Table I dataset summary."""

import hashlib
import socket

import pandas as pd
import pytest

from animsynth.data import DownloadError, PAPER_TABLE_I, datasets_table, fetch_file, load_trial, sha256_normalised
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion


def test_sha256_ignores_line_endings():
    assert sha256_normalised(b"a\r\nb\r\n") == sha256_normalised(b"a\nb\n") == hashlib.sha256(b"a\nb\n").hexdigest()
    assert sha256_normalised(b"a\nb\n") != sha256_normalised(b"a\nc\n")


def test_fetch_from_local_mirror_and_checksum_mismatch(tmp_path):
    (tmp_path / "mirror" / "subjects" / "01").mkdir(parents=True)
    src = tmp_path / "mirror" / "subjects" / "01" / "01_01.amc"
    src.write_bytes(b":FULLY-SPECIFIED\r\n:DEGREES\r\n")
    good = sha256_normalised(src.read_bytes())
    dest = tmp_path / "out" / "t.amc"
    assert fetch_file(str(tmp_path / "mirror"), "subjects/01/01_01.amc", dest, good) == good
    assert dest.read_bytes() == src.read_bytes()
    dest2 = tmp_path / "out" / "u.amc"
    with pytest.raises(DownloadError, match="checksum mismatch for subjects/01/01_01.amc"):
        fetch_file(str(tmp_path / "mirror"), "subjects/01/01_01.amc", dest2, "0" * 64)
    assert not dest2.exists()
    assert not list((tmp_path / "out").glob(".tmp-*"))  # no partial file left behind
    with pytest.raises(DownloadError, match="cannot read"):
        fetch_file(str(tmp_path / "mirror"), "subjects/01/missing.amc", dest2, None)


def test_network_failure_is_a_clear_error(tmp_path):
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()  # nothing listens there now
    with pytest.raises(DownloadError, match=rf"cannot download http://127.0.0.1:{port}/subjects/35/35_01.amc.*2 attempts"):
        fetch_file(f"http://127.0.0.1:{port}", "subjects/35/35_01.amc", tmp_path / "x.amc", None, attempts=2, wait=0)
    assert not (tmp_path / "x.amc").exists()


def test_real_mirror_checksums_match_cmu_config(cmu_dir):
    import yaml

    from conftest import REPO

    cfg = yaml.safe_load((REPO / "config" / "cmu.yaml").read_text())
    mirror = cmu_dir.parent
    for t in cfg["trials"]:
        for key, sha in (("amc", "sha256"), ("asf", "asf_sha256")):
            data = (mirror / t[key]).read_bytes()
            assert sha256_normalised(data) == t[sha], t["id"]
    # w1/w2/r1 are the exact Table I trials
    lengths = {}
    for t in cfg["trials"]:
        m = load_trial(amc=mirror / t["amc"], asf=mirror / t["asf"])
        lengths[t["id"]] = m.n_frames
    for name in ("w1", "w2", "r1"):
        assert [lengths[i] for i in cfg["subsets"][name]] == PAPER_TABLE_I[name]


def test_datasets_table_layout():
    sk = cmu_like_skeleton("s", 1)
    motions = {f"t{i}": generate_motion("walk_straight", 50 + i, i, sk) for i in range(4)}
    df = datasets_table({"w1": ["t0", "t1"], "w2": ["t2", "t3"]}, motions, "synthetic")
    assert list(df.columns) == ["dataset", "source", "trials", "dims", "n_sequences", "lengths", "total_nodes"]
    assert df.loc[0, "trials"] == "t0 t1" and df.loc[0, "lengths"] == "50 51" and df.loc[0, "total_nodes"] == 101
    assert (df["dims"] == 56).all()
    # with published lengths: the paper's beside ours and the difference; empty for a subset the paper lacks
    dp = datasets_table({"w1": ["t0", "t1"], "w2": ["t2", "t3"]}, motions, "synthetic", paper={"w1": [50, 60]})
    assert dp.loc[0, "paper_total_nodes"] == 110 and dp.loc[0, "total_nodes_minus_paper"] == 101 - 110
    assert pd.isna(dp.loc[1, "total_nodes_minus_paper"])
    assert "t1 (51) for 60" in dp.loc[0, "length_match"]
