"""Real-data sources: reachability probes, mesh archives and their checksums."""

import gzip
import hashlib
import io
import tarfile
import zipfile

import pytest

from animsynth.sources import (
    MeshSourceError,
    fetch_mesh_frames,
    mesh_source_name,
    probe_source,
    read_sha256_list,
    verify_mesh_frames,
)

OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 {z}\nf 1 2 3\n"


def _frames(n=3):
    return {f"mesh_{i:04d}.obj": OBJ.format(z=i).encode() for i in range(n)}


def _sums(frames, tmp_path):
    p = tmp_path / "sums.txt"
    p.write_text("# hashes of the uncompressed frames\n"
                 + "".join(f"{hashlib.sha256(b).hexdigest()}  {n}\n" for n, b in frames.items()))
    return read_sha256_list(p)


def test_probe_folder_and_unreachable_url(tmp_path):
    assert probe_source(tmp_path) == (True, "")
    ok, why = probe_source(tmp_path, "subjects/35/35_01.amc")
    assert not ok and "35_01.amc does not exist" in why
    ok, why = probe_source(tmp_path / "absent")
    assert not ok and "absent does not exist" in why
    ok, why = probe_source("http://127.0.0.1:9/mirror", "subjects/35/35_01.amc", timeout=2)
    assert not ok and "not reachable" in why and "35_01.amc" in why
    assert probe_source(None) == (False, "no source configured")


def test_tar_gz_archive_with_nested_folder_is_unpacked_and_verified(tmp_path):
    frames = _frames()
    arch = tmp_path / "samba.tar.gz"
    with tarfile.open(arch, "w:gz") as t:
        for name, data in frames.items():
            info = tarfile.TarInfo(f"samba/meshes/{name}.gz")
            gz = gzip.compress(data)
            info.size = len(gz)
            t.addfile(info, io.BytesIO(gz))
    dest = tmp_path / "out" / mesh_source_name(str(arch))
    got = fetch_mesh_frames(str(arch), dest)
    assert [p.name for p in got] == [f"{n}.gz" for n in sorted(frames)]
    table = verify_mesh_frames(dest, _sums(frames, tmp_path))
    assert list(table["frame"]) == sorted(frames)
    assert dest.name == "samba"


def test_checksum_mismatch_names_the_frame(tmp_path):
    frames = _frames()
    folder = tmp_path / "frames"
    folder.mkdir()
    for n, b in frames.items():
        (folder / n).write_bytes(b)
    sums = _sums(frames, tmp_path)
    (folder / "mesh_0001.obj").write_bytes(OBJ.format(z=9).encode())
    with pytest.raises(MeshSourceError, match=r"frame mesh_0001\.obj has SHA-256 [0-9a-f]{64}, expected"):
        verify_mesh_frames(folder, sums)
    (folder / "mesh_0001.obj").unlink()
    with pytest.raises(MeshSourceError, match=r"frame mesh_0001\.obj is missing"):
        verify_mesh_frames(folder, sums)


def test_zip_member_outside_target_is_refused_and_nothing_is_left(tmp_path):
    arch = tmp_path / "evil.zip"
    with zipfile.ZipFile(arch, "w") as z:
        z.writestr("../escape.obj", OBJ.format(z=0))
    dest = tmp_path / "out" / "evil"
    with pytest.raises(MeshSourceError, match="outside the target folder"):
        fetch_mesh_frames(str(arch), dest)
    assert not dest.exists() and not (tmp_path / "escape.obj").exists()
    assert list((tmp_path / "out").iterdir()) == []  # the temporary folder is gone too


def test_bad_checksum_list_names_file_and_line(tmp_path):
    p = tmp_path / "sums.txt"
    p.write_text("# c\nnot-a-hash  mesh_0000.obj\n")
    with pytest.raises(MeshSourceError, match=r"sums\.txt:2: expected"):
        read_sha256_list(p)


def test_shipped_samba_list_matches_the_shared_copy(vlasic_dir):
    from conftest import REPO

    ours = read_sha256_list(REPO / "config" / "checksums" / "samba_obj.sha256")
    shared = read_sha256_list(vlasic_dir / "samba" / "SHA256SUMS_uncompressed_obj.txt")
    assert ours == shared and len(ours) == 175
