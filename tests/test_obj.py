"""OBJ / OBJ.gz mesh and mesh-sequence I/O."""
import gzip

import numpy as np
import pytest

from animsynth.errors import MotionFormatError
from animsynth.io.obj import MeshSequence, list_obj_frames, read_obj, read_obj_sequence, write_obj, write_obj_sequence

QUAD = "# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n"


def test_read_polygon_tokens_and_fan_triangulation(tmp_path):
    p = tmp_path / "q.obj"
    p.write_text(QUAD)
    v, f = read_obj(p)
    assert v.shape == (4, 3)
    np.testing.assert_array_equal(f, [[0, 1, 2], [0, 2, 3]])


def test_negative_indices_and_gz(tmp_path):
    p = tmp_path / "t.obj.gz"
    p.write_bytes(gzip.compress(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"))
    v, f = read_obj(p)
    np.testing.assert_array_equal(f, [[0, 1, 2]])
    np.testing.assert_allclose(v[1], [1, 0, 0])


def test_roundtrip(tmp_path):
    rng = np.random.default_rng(0)
    v = rng.normal(size=(10, 3))
    f = np.array([[0, 1, 2], [2, 3, 4], [5, 6, 9]])
    for name in ("a.obj", "a.obj.gz"):
        write_obj(tmp_path / name, v, f)
        v2, f2 = read_obj(tmp_path / name)
        np.testing.assert_allclose(v2, v, rtol=1e-5, atol=1e-6)
        np.testing.assert_array_equal(f2, f)


@pytest.mark.parametrize("text,line,msg", [
    ("v 0 0 0\nv 1 x 0\n", 2, "non-numeric"),
    ("v 0 0 0\nv 1 0\n", 2, "3 coordinates"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", 4, "not defined"),
    ("v 0 0 0\nv nan 0 0\n", 2, "non-finite"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", 4, "1-based"),
])
def test_malformed_names_line(tmp_path, text, line, msg):
    p = tmp_path / "bad.obj"
    p.write_text(text)
    with pytest.raises(MotionFormatError, match=msg) as e:
        read_obj(p)
    assert e.value.line == line and "bad.obj" in str(e.value)


def test_sequence_natural_order_cache_and_mismatch(tmp_path):
    v = np.random.default_rng(1).normal(size=(5, 3))
    f = np.array([[0, 1, 2], [1, 2, 3], [2, 3, 4]])
    seq = MeshSequence(np.stack([v, v + 1, v + 2]), f)
    d = tmp_path / "seq"
    write_obj_sequence(d, seq, gz=True)
    # natural order: frame_10 after frame_9
    write_obj(d / "mesh_10.obj", v + 10, f)
    write_obj(d / "mesh_9.obj", v + 9, f)
    names = [p.split("/")[-1] for p in list_obj_frames(d)]
    assert names == ["mesh_0000.obj.gz", "mesh_0001.obj.gz", "mesh_0002.obj.gz", "mesh_9.obj", "mesh_10.obj"]
    cache = tmp_path / "c.npz"
    s = read_obj_sequence(d, cache=cache)
    assert s.vertices.shape == (5, 5, 3) and cache.exists()
    np.testing.assert_allclose(s.vertices[4], v + 10, atol=1e-4)  # 6 significant digits
    s2 = read_obj_sequence(d, cache=cache)
    np.testing.assert_array_equal(s2.vertices, s.vertices)
    # topology mismatch names the frame
    write_obj(d / "mesh_11.obj", v + 11, f[:, ::-1])
    with pytest.raises(MotionFormatError, match="mesh_11.obj.*topology mismatch"):
        read_obj_sequence(d)
    write_obj(d / "mesh_11.obj", np.vstack([v, v[:1]]), f)
    with pytest.raises(MotionFormatError, match="mesh_11.obj.*6 vertices"):
        read_obj_sequence(d)


def test_missing_folder(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_obj_sequence(tmp_path / "nope")
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileNotFoundError, match="no .obj"):
        read_obj_sequence(tmp_path / "empty")
