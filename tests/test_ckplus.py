"""CK+ loader (strict official layout) and the synthetic CK+-layout generator."""

from __future__ import annotations

import logging
import os

import numpy as np
import pytest

from animsynth.io.ckplus import (EMOTIONS, CKSequence, emotion_code, read_ckplus, read_emotion, read_landmarks,
                                 write_sequence)
from animsynth.errors import MotionFormatError
from animsynth.synth.faces import CKPLUS_COUNTS, au_field, generate_sequences, write_database


def _seq(subject="S005", sequence="001", frames=4, emotion=3, seed=0):
    rng = np.random.default_rng(seed)
    return CKSequence(subject, sequence, 200 + 50 * rng.random((frames, 68, 2)), emotion)


@pytest.fixture
def db(tmp_path):
    root = tmp_path / "ck"
    write_sequence(root, _seq("S005", "001", 4, 3, 0))
    write_sequence(root, _seq("S005", "002", 5, None, 1))
    write_sequence(root, _seq("S010", "001", 3, 7, 2))
    return root


def lm_file(root, subj="S005", seq="001", frame=1):
    return root / "Landmarks" / subj / seq / f"{subj}_{seq}_{frame:08d}_landmarks.txt"


def test_roundtrip_layout_and_values(db):
    seqs = read_ckplus(db)
    assert [s.name for s in seqs] == ["S005_001", "S005_002", "S010_001"]
    assert [s.emotion for s in seqs] == [3, None, 7]
    assert [s.label for s in seqs] == ["disgust", None, "surprise"]
    assert seqs[0].landmarks.shape == (4, 68, 2) and list(seqs[0].frames) == [1, 2, 3, 4]
    np.testing.assert_allclose(seqs[0].landmarks, _seq("S005", "001", 4, 3, 0).landmarks, rtol=1e-7)
    assert [s.name for s in read_ckplus(db, labelled_only=True)] == ["S005_001", "S010_001"]
    # CK+ formatting: scientific notation, leading spaces; emotion as a float
    assert lm_file(db).read_text().splitlines()[0].startswith("   ")
    emo = db / "Emotion" / "S005" / "001" / "S005_001_00000004_emotion.txt"
    assert float(emo.read_text()) == 3.0


def test_hidden_files_and_blank_lines_are_ignored(db):
    (db / "Landmarks" / "S005" / "001" / ".DS_Store").write_bytes(b"\x00\x01")
    (db / "Landmarks" / ".DS_Store").write_text("x")
    p = lm_file(db)
    p.write_text(p.read_text() + "\n\n")
    assert len(read_ckplus(db)) == 3


@pytest.mark.parametrize("mutate, line, fragment", [
    (lambda t: "\n".join(t.splitlines()[:67]) + "\n", None, "expected 68 landmark rows, found 67"),
    (lambda t: t + "   1.0e+00   2.0e+00\n", 69, "more than 68"),
    (lambda t: t.replace(t.splitlines()[4], "   1.0   2.0   3.0", 1), 5, "expected 2 numbers"),
    (lambda t: t.replace(t.splitlines()[9], "   1.0   abc", 1), 10, "non-numeric"),
    (lambda t: t.replace(t.splitlines()[0], "   nan   2.0", 1), 1, "non-finite"),
    (lambda t: t.replace(t.splitlines()[6], "   1e300   2.0", 1), 7, "outside the image"),
    (lambda t: t.replace(t.splitlines()[7], "   100.0   -400.0", 1), 8, "outside the image"),
])
def test_malformed_landmark_file(db, mutate, line, fragment):
    p = lm_file(db, frame=2)
    p.write_text(mutate(p.read_text()))
    with pytest.raises(MotionFormatError) as e:
        read_ckplus(db)
    assert fragment in str(e.value) and str(p) in str(e.value)
    assert e.value.line == line


def test_missing_frame(db):
    os.remove(lm_file(db, frame=2))
    with pytest.raises(MotionFormatError, match=r"missing frame\(s\) \[2\]"):
        read_ckplus(db)


def test_frames_must_start_at_one(db):
    p = lm_file(db, frame=1)
    p.rename(p.with_name("S005_001_00000000_landmarks.txt"))
    with pytest.raises(MotionFormatError, match="start at 1"):
        read_ckplus(db)


def test_bad_and_mismatched_file_names(db):
    bad = db / "Landmarks" / "S005" / "001" / "notes.txt"
    bad.write_text("x")
    with pytest.raises(MotionFormatError, match="unexpected file") as e:
        read_ckplus(db)
    assert str(bad) in str(e.value)
    bad.unlink()
    p = lm_file(db, frame=2)
    p.rename(p.with_name("S006_001_00000002_landmarks.txt"))
    with pytest.raises(MotionFormatError, match="lies in S005/001"):
        read_ckplus(db)


def test_bad_folder_names(db):
    (db / "Landmarks" / "Subject5").mkdir()
    with pytest.raises(MotionFormatError, match="unexpected subject folder name 'Subject5'"):
        read_ckplus(db)


def test_empty_sequence_folder(db):
    (db / "Landmarks" / "S010" / "002").mkdir()
    with pytest.raises(MotionFormatError, match="no landmark files"):
        read_ckplus(db)


def test_byte_order_mark_stripped_and_undecodable_line(db):
    p = lm_file(db, frame=3)
    p.write_bytes(b"\xef\xbb\xbf" + p.read_bytes())
    seqs = read_ckplus(db)
    np.testing.assert_allclose(seqs[0].landmarks[2], _seq("S005", "001", 4, 3, 0).landmarks[2], rtol=1e-7)
    lines = p.read_bytes().split(b"\n")
    lines[4] = b"   1.0\xff\xfe   2.0"
    p.write_bytes(b"\n".join(lines))
    with pytest.raises(MotionFormatError, match="undecodable") as e:
        read_ckplus(db)
    assert e.value.line == 5 and str(p) in str(e.value)


def emo_file(db, subj="S005", seq="001", frame=4):
    return db / "Emotion" / subj / seq / f"{subj}_{seq}_{frame:08d}_emotion.txt"


@pytest.mark.parametrize("text, fragment", [
    ("   9.0000000e+00\n", "integer 1-7, got 9"),
    ("   2.5000000e+00\n", "integer 1-7, got 2.5"),
    ("   0.0000000e+00\n", "code 0 \\(neutral\\) is not an expression label"),
    ("   3.0000000e+00\n   4.0000000e+00\n", "exactly one emotion code, found 2"),
    ("\n", "exactly one emotion code, found 0"),
    ("   happy\n", "non-numeric emotion code"),
])
def test_malformed_emotion_file(db, text, fragment):
    emo_file(db).write_text(text)
    with pytest.raises(MotionFormatError, match=fragment) as e:
        read_ckplus(db)
    assert str(emo_file(db)) in str(e.value)


def test_emotion_frame_checks(db, caplog):
    p = emo_file(db)
    p.rename(emo_file(db, frame=9))
    with pytest.raises(MotionFormatError, match="emotion frame 9 has no landmark file"):
        read_ckplus(db)
    emo_file(db, frame=9).rename(emo_file(db, frame=3))
    with caplog.at_level(logging.WARNING, logger="animsynth.io.ckplus"):
        seqs = read_ckplus(db)
    assert seqs[0].n_frames == 3 and seqs[0].emotion == 3  # cut at the labelled (peak) frame
    assert "not the last frame" in caplog.text
    (db / "Emotion" / "S005" / "001" / "S005_001_00000004_emotion.txt").write_text("   3.0e+00\n")
    with pytest.raises(MotionFormatError, match="at most one emotion file"):
        read_ckplus(db)


def test_label_without_landmarks_and_missing_folders(db, tmp_path):
    d = db / "Emotion" / "S099" / "001"
    d.mkdir(parents=True)
    (d / "S099_001_00000003_emotion.txt").write_text("   1.0e+00\n")
    with pytest.raises(MotionFormatError, match="no Landmarks/ folder"):
        read_ckplus(db)
    with pytest.raises(MotionFormatError, match="does not exist"):
        read_ckplus(tmp_path / "nowhere")
    (tmp_path / "empty").mkdir()
    with pytest.raises(MotionFormatError, match="no Landmarks/"):
        read_ckplus(tmp_path / "empty")
    only = tmp_path / "only"
    write_sequence(only, _seq())
    import shutil

    shutil.rmtree(only / "Emotion")
    with pytest.raises(MotionFormatError, match="no Emotion/"):
        read_ckplus(only)
    assert len(read_ckplus(only, require_emotion_dir=False)) == 1


def test_single_file_readers(tmp_path):
    p = tmp_path / "x_landmarks.txt"
    p.write_text("".join(f"{i} {2 * i}\n" for i in range(68)))
    pts = read_landmarks(p)
    assert pts.shape == (68, 2) and pts[5, 1] == 10.0
    e = tmp_path / "e.txt"
    e.write_text("   5.0000000e+00")
    assert read_emotion(e) == 5


def test_emotion_codes():
    assert EMOTIONS[4] == "fear" and emotion_code("Happy") == 5 and emotion_code(7) == 7
    with pytest.raises(ValueError):
        emotion_code("joy")
    with pytest.raises(ValueError):
        emotion_code(8)


# -- synthetic generator ----------------------------------------------------
def test_synthetic_database_matches_spec(tmp_path):
    seqs = generate_sequences(n_subjects=20, n_sequences=70, total_frames=1800, n_unlabelled=4, seed=5)
    lab = [s for s in seqs if s.emotion is not None]
    assert len(lab) == 70 and sum(s.n_frames for s in lab) == 1800
    assert len({s.subject for s in seqs}) == 20 and len(seqs) == 74
    assert all(10 <= s.n_frames <= 60 for s in seqs)
    counts = {e: sum(s.label == e for s in lab) for e in CKPLUS_COUNTS}
    assert counts == {"anger": 10, "contempt": 4, "disgust": 12, "fear": 5, "happy": 15, "sadness": 6, "surprise": 18}
    # image scale: ~270 px wide faces inside a 640 x 490 image
    widths = [np.ptp(s.landmarks[0, :17, 0]) for s in lab]
    assert 230 < np.mean(widths) < 310
    allp = np.concatenate([s.landmarks.reshape(-1, 2) for s in seqs])
    assert allp.min() > 0 and allp[:, 0].max() < 640 and allp[:, 1].max() < 490
    # neutral first, label-specific peak: surprise opens the jaw, happy pulls the mouth corners wider
    # (per-sequence intensity varies: compare label means)
    sur = [s for s in lab if s.label == "surprise"]
    assert np.mean([s.landmarks[-1, 8, 1] - s.landmarks[0, 8, 1] for s in sur]) > 10
    hap = [s for s in lab if s.label == "happy"]
    w = lambda p: p[54, 0] - p[48, 0]  # noqa: E731
    assert np.mean([w(s.landmarks[-1]) - w(s.landmarks[0]) for s in hap]) > 10
    # written in the CK+ layout and read back like real CK+
    write_database(tmp_path / "syn", seqs[:6])
    back = read_ckplus(tmp_path / "syn")
    assert (tmp_path / "syn" / "README.txt").exists()
    by = {s.name: s for s in seqs[:6]}
    for s in back:
        np.testing.assert_allclose(s.landmarks, by[s.name].landmarks, rtol=1e-7, atol=1e-4)
        assert s.emotion == by[s.name].emotion


def test_synthetic_paths_are_curved_and_onsets_not_all_sigmoid():
    from animsynth.synth.faces import ONSET_SHAPES, onset_profile

    tau = np.linspace(0, 1, 30)
    for shape in ONSET_SHAPES:
        w = onset_profile(shape, tau, 0.45, 10.0)
        assert w[0] == pytest.approx(0, abs=1e-9) and w[-1] == pytest.approx(1)
    assert onset_profile("overshoot", tau, 0.45, 10.0).max() > 1.05       # overshoots the peak
    seqs = generate_sequences(n_subjects=4, n_sequences=12, total_frames=360, n_unlabelled=0, seed=3,
                              jitter_px=0.0, head_rotation_deg=0.0, head_translation_px=0.0, blink_probability=0.0)
    # a moving landmark leaves the straight neutral-to-peak line by more than a pixel somewhere
    dev = []
    for s in seqs:
        d = s.landmarks - s.landmarks[0]
        end = d[-1]
        n = np.linalg.norm(end, axis=-1)
        mv = n > 5
        u = end[mv] / n[mv, None]
        off = np.abs(d[:, mv, 0] * u[:, 1] - d[:, mv, 1] * u[:, 0])
        dev.append(off.max())
    assert max(dev) > 1.0


def test_generator_is_seeded():
    a = generate_sequences(n_subjects=3, n_sequences=6, total_frames=120, n_unlabelled=1, seed=1)
    b = generate_sequences(n_subjects=3, n_sequences=6, total_frames=120, n_unlabelled=1, seed=1)
    c = generate_sequences(n_subjects=3, n_sequences=6, total_frames=120, n_unlabelled=1, seed=2)
    assert all(np.array_equal(x.landmarks, y.landmarks) for x, y in zip(a, b))
    assert not np.array_equal(a[0].landmarks, c[0].landmarks)


def test_action_unit_fields():
    f = au_field(12)  # lip corner puller: corners move outwards and up, mirror-symmetric
    assert f[48, 0] < 0 < f[54, 0] and f[48, 1] < 0 and f[48, 1] == f[54, 1]
    one = au_field("12R")  # one-sided (contempt): the other corner stays
    assert one[48, 0] < 0 and one[54, 0] == 0
