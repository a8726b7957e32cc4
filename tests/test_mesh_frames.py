"""What counts as a mesh frame: one rule (animsynth.io.obj.is_frame_name)
shared by the checksum check, the archive fetch and the reader."""

import hashlib
import io
import tarfile
import zipfile

import numpy as np
import pytest

from animsynth.io.obj import is_frame_name, list_obj_frames, read_obj_sequence
from animsynth.sources import MeshSourceError, fetch_mesh_frames, read_sha256_list, verify_mesh_frames

OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 {z}\nf 1 2 3\n"
MAC_JUNK = b"\x00\x05\x16\x07\x00\x02\x00\x00Mac OS X        "  # an AppleDouble header


def _frames(n=3, upper=()):
    return {(f"mesh_{i:04d}.OBJ" if i in upper else f"mesh_{i:04d}.obj"): OBJ.format(z=i).encode() for i in range(n)}


def _sums(frames, tmp_path):
    p = tmp_path / "sums.txt"
    p.write_text("".join(f"{hashlib.sha256(b).hexdigest()}  {n}\n" for n, b in frames.items()))
    return read_sha256_list(p)


@pytest.mark.parametrize("name,ok", [
    ("mesh_0001.obj", True), ("mesh_0001.OBJ", True), ("mesh_0001.Obj.GZ", True), ("a/b/mesh.obj", True),
    ("._mesh_0001.obj", False), ("__MACOSX/seq/._mesh_0001.obj", False), ("__MACOSX/mesh_0001.obj", False),
    (".hidden/mesh_0001.obj", False), ("mesh_0001.obj.bak", False), ("mesh_0001.mtl", False)])
def test_the_frame_rule(name, ok):
    assert is_frame_name(name) is ok


def test_upper_case_extension_is_a_frame_for_checksum_and_reader(tmp_path):
    frames = _frames(3, upper=(1,))
    for n, b in frames.items():
        (tmp_path / n).write_bytes(b)
    table = verify_mesh_frames(tmp_path, _sums(frames, tmp_path))
    assert len(table) == 3
    seq = read_obj_sequence(tmp_path)
    assert seq.names == ["mesh_0000.obj", "mesh_0001.OBJ", "mesh_0002.obj"]  # no gap
    np.testing.assert_allclose(seq.vertices[:, 2, 2], [0, 1, 2])


def test_hidden_companions_in_a_folder_are_not_frames(tmp_path):
    frames = _frames(3)
    for n, b in frames.items():
        (tmp_path / n).write_bytes(b)
        (tmp_path / f"._{n}").write_bytes(MAC_JUNK)
    assert [p.rsplit("/", 1)[-1] for p in list_obj_frames(tmp_path)] == sorted(frames)
    assert len(verify_mesh_frames(tmp_path, _sums(frames, tmp_path))) == 3
    assert read_obj_sequence(tmp_path).n_frames == 3


def _finder_zip(path, frames):
    """A zip as macOS Finder makes it: the folder, plus __MACOSX/<folder>/._<file> resource forks."""
    with zipfile.ZipFile(path, "w") as z:
        for n, b in frames.items():
            z.writestr(f"seq/{n}", b)
            z.writestr(f"__MACOSX/seq/._{n}", MAC_JUNK)
        z.writestr("__MACOSX/._seq", MAC_JUNK)


def test_finder_zip_gives_the_real_frames(tmp_path):
    frames = _frames(4)
    arch = tmp_path / "seq.zip"
    _finder_zip(arch, frames)
    dest = tmp_path / "out" / "seq"
    got = fetch_mesh_frames(str(arch), dest, sums=_sums(frames, tmp_path))
    assert [p.name for p in got] == sorted(frames)
    assert not [p for p in dest.iterdir() if p.name.startswith(".") or "MACOSX" in p.name]


def test_tar_gz_with_dot_underscore_companions_passes_when_every_frame_matches(tmp_path):
    frames = _frames(3)
    arch = tmp_path / "seq.tar.gz"
    with tarfile.open(arch, "w:gz") as t:
        for n, b in frames.items():
            for name, data in ((f"seq/{n}", b), (f"seq/._{n}", MAC_JUNK)):
                info = tarfile.TarInfo(name)
                info.size = len(data)
                t.addfile(info, io.BytesIO(data))
    dest = tmp_path / "out" / "seq"
    fetch_mesh_frames(str(arch), dest)
    assert len(verify_mesh_frames(dest, _sums(frames, tmp_path))) == 3


def test_frames_in_two_folders_are_refused_naming_both(tmp_path):
    arch = tmp_path / "two.zip"
    with zipfile.ZipFile(arch, "w") as z:
        for n, b in _frames(3).items():
            z.writestr(f"take1/{n}", b)
        for n, b in _frames(2).items():
            z.writestr(f"take2/{n}", b)
    dest = tmp_path / "out" / "two"
    with pytest.raises(MeshSourceError, match="more than one folder.*'take1'.*'take2'"):
        fetch_mesh_frames(str(arch), dest)
    assert not dest.exists() and list((tmp_path / "out").iterdir()) == []


def test_unpacked_size_is_capped(tmp_path):
    arch = tmp_path / "big.zip"
    with zipfile.ZipFile(arch, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("seq/mesh_0000.obj", OBJ.format(z=0) + "#" * 3_000_000)
    dest = tmp_path / "out" / "big"
    with pytest.raises(MeshSourceError, match=r"unpacks to 3\.\d+ MB, over the 1 MB cap.*max_unpacked_mb"):
        fetch_mesh_frames(str(arch), dest, max_unpacked_mb=1)
    assert not dest.exists() and list((tmp_path / "out").iterdir()) == []


def test_a_checksum_failure_in_the_fetch_leaves_nothing(tmp_path):
    frames = _frames(3)
    sums = _sums(frames, tmp_path)
    frames["mesh_0001.obj"] = OBJ.format(z=7).encode()
    arch = tmp_path / "seq.zip"
    _finder_zip(arch, frames)
    dest = tmp_path / "out" / "seq"
    with pytest.raises(MeshSourceError, match=r"mesh_0001\.obj has SHA-256"):
        fetch_mesh_frames(str(arch), dest, sums=sums)
    assert not dest.exists() and list((tmp_path / "out").iterdir()) == []


def test_checksum_list_names_the_frame_the_reader_sees_in_any_case(tmp_path):
    frames = _frames(3)
    sums = _sums(frames, tmp_path)  # lists mesh_0001.obj
    folder = tmp_path / "seq"
    folder.mkdir()
    for n, b in frames.items():
        (folder / (n.replace(".obj", ".OBJ") if n == "mesh_0001.obj" else n)).write_bytes(b)
    table = verify_mesh_frames(folder, sums)
    assert list(table["frame"]) == sorted(frames)
    assert table.set_index("frame").loc["mesh_0001.obj", "file"] == "mesh_0001.OBJ"
    (folder / "mesh_0001.OBJ").write_bytes(OBJ.format(z=9).encode())  # the check still reads it
    with pytest.raises(MeshSourceError, match=r"mesh_0001\.OBJ: frame mesh_0001\.obj has SHA-256"):
        verify_mesh_frames(folder, sums)
    (folder / "mesh_0001.obj").write_bytes(frames["mesh_0001.obj"])
    if len(list(folder.iterdir())) == 4:  # a case-sensitive file system: two files, one frame
        with pytest.raises(MeshSourceError, match="the same frame 'mesh_0001'"):
            verify_mesh_frames(folder, sums)


def _big_zip(path):
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_STORED) as z:
        z.writestr("seq/mesh_0000.obj", OBJ.format(z=0) + "#" * 3_000_000)
    return path


def test_a_download_over_the_cap_is_refused_and_leaves_nothing(tmp_path):
    arch = _big_zip(tmp_path / "big.zip")
    dest = tmp_path / "out" / "big"
    with pytest.raises(MeshSourceError, match=r"big\.zip: download is 3\.\d+ MB, over the 1 MB cap.*max_unpacked_mb"):
        fetch_mesh_frames(arch.as_uri(), dest, max_unpacked_mb=1)
    assert not dest.exists() and list((tmp_path / "out").iterdir()) == []
    assert fetch_mesh_frames(arch.as_uri(), dest, max_unpacked_mb=10)[0].name == "mesh_0000.obj"


def test_a_download_without_a_declared_size_stops_at_the_cap(tmp_path, monkeypatch):
    import urllib.request

    class Response(io.BytesIO):  # a server that sends no Content-Length
        headers = {}
        served = 0

        def read(self, n=-1):
            out = super().read(n)
            Response.served += len(out)
            return out

    body = _big_zip(tmp_path / "big.zip").read_bytes()
    monkeypatch.setattr(urllib.request, "urlopen", lambda url, timeout: Response(body))
    dest = tmp_path / "out" / "big"
    with pytest.raises(MeshSourceError, match=r"download is more than 1 MB, over the 1 MB cap"):
        fetch_mesh_frames("http://mirror.invalid/big.zip", dest, max_unpacked_mb=1)
    assert 1_000_000 < Response.served <= 2 * 2**20 < len(body)  # the copy stopped past the cap
    assert not dest.exists() and list((tmp_path / "out").iterdir()) == []
