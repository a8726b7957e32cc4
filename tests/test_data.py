"""Download/mirror with checksums, and the real CMU trials behind Gauch & Peters Table I."""

import hashlib
import socket

import numpy as np
import pytest

from animsynth.data import DownloadError, fetch_file, load_trial, sha256_normalised


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


def test_real_mirror_checksums_match_cmu_config(cmu_dir, cmu_many_dir):
    """Every trial of config/cmu.yaml, read from its own mirror (mirror: many = the shared cmu_mocap_many folder),
    has the LF-normalised SHA-256 of its record (the motion file's and the ASF's)."""
    import yaml

    from conftest import REPO

    cfg = yaml.safe_load((REPO / "config" / "cmu.yaml").read_text())
    mirrors = {"main": cmu_dir.parent, "many": cmu_many_dir.parent}
    for t in cfg["trials"]:
        mirror = mirrors[t.get("mirror", "main")]
        pairs = (("bvh", "sha256"),) if "bvh" in t else (("amc", "sha256"), ("asf", "asf_sha256"))
        for key, sha in pairs:
            data = (mirror / t[key]).read_bytes()
            assert sha256_normalised(data) == t[sha], t["id"]


def test_real_w1_w2_r1_are_the_exact_table1_trials(cmu_dir):
    """w1/w2/r1 of config/cmu.yaml have the frame counts of the published Table I (../shared/papers)."""
    import yaml

    from animsynth.simplicial.settings import read_paper_table1
    from conftest import REPO

    published = REPO.parent / "shared" / "papers" / "s1_table1.csv"
    if not published.is_file():
        pytest.skip(f"{published} is absent (it lives in ../shared, never in the repo)")
    paper = read_paper_table1(published)
    cfg = yaml.safe_load((REPO / "config" / "cmu.yaml").read_text())
    mirror = cmu_dir.parent
    table1 = {i for name in ("w1", "w2", "r1") for i in cfg["subsets"][name]}
    lengths = {t["id"]: load_trial(amc=mirror / t["amc"], asf=mirror / t["asf"]).n_frames for t in cfg["trials"]
               if t["id"] in table1}
    for name in ("w1", "w2", "r1"):
        assert [lengths[i] for i in cfg["subsets"][name]] == paper[name]


def test_cmu_yaml_bvh_trials_parse_with_their_records_settings(cmu_many_dir):
    """The cgspeed ROOT hip BVH trials (06_01, 10_04) of config/cmu.yaml, read as the parse job reads them: the
    T-pose frame 0 dropped (first_frame: 1) leaves the AMC's frame count, the figure stands a plausible height in
    metres, and the compare family's foot roles resolve (ankles found by name, the toes named on the record). The
    other BVH trials (subjects 26, 27, 32, 131): tests/test_cmu_many_subjects.py."""
    import yaml

    from animsynth.compare.measures import foot_indices, positions
    from conftest import REPO

    cfg = yaml.safe_load((REPO / "config" / "cmu.yaml").read_text())
    amc_frames = {"06_01": 494, "10_04": 549}  # cmu_mocap_many/SOURCE.md: BVH = AMC + 1 (the T-pose)
    bvh = [t for t in cfg["trials"] if "bvh" in t and t["subject"] in ("06", "10")]
    assert sorted(t["id"] for t in bvh) == sorted(amc_frames)
    for t in bvh:
        whole = load_trial(bvh=cmu_many_dir.parent / t["bvh"], bvh_length_to_m=t["bvh_length_to_m"])
        m = load_trial(bvh=cmu_many_dir.parent / t["bvh"], bvh_length_to_m=t["bvh_length_to_m"],
                       joint_roles=t["joint_roles"], first_frame=t["first_frame"])
        assert whole.n_frames == amc_frames[t["id"]] + 1 and m.n_frames == amc_frames[t["id"]]
        assert np.allclose(whole.values[1:], m.values)
        names = [m.skeleton.names[i] for i in foot_indices(m.skeleton)]
        assert names[0] == "lFoot" and names[2] == "rFoot", names
        pos = positions(m)
        head = pos[:, m.skeleton.names.index("head"), 1]
        assert 1.3 < float(np.median(head)) < 2.0  # metres, with bvh_length_to_m 0.01


def test_first_frame_past_the_end_is_refused(cmu_many_dir):
    from animsynth.config import ConfigError

    with pytest.raises(ConfigError, match="first_frame"):
        load_trial(bvh=cmu_many_dir / "06" / "06_01.bvh", bvh_length_to_m=0.01, first_frame=495)
