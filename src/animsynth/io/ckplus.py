"""CK+ (Extended Cohn-Kanade) landmark sequences and emotion labels.

The official layout (Lucey et al. 2010), which :func:`read_ckplus` reads as is::

    <root>/Landmarks/S005/001/S005_001_00000001_landmarks.txt   68 rows "x y" (image pixels)
    <root>/Landmarks/S005/001/S005_001_00000002_landmarks.txt
    ...
    <root>/Emotion/S005/001/S005_001_00000011_emotion.txt        one number: the emotion code

* Subject folders are ``S`` + 3 digits, sequence folders 3 digits, and every
  landmark file is named ``<subject>_<sequence>_<8-digit frame>_landmarks.txt``
  with the subject and sequence of its folders. Frames are numbered 1, 2, ...
  without gaps. A landmark file holds exactly 68 non-empty lines of two finite
  numbers (CK+ writes them as ``   2.1944181e+02   2.5828398e+02``); blank
  lines are ignored.
* Only some sequences are labelled: their ``Emotion/<subject>/<sequence>/``
  folder holds exactly one ``..._emotion.txt`` file whose single number is an
  integral code 1-7 (:data:`EMOTIONS`; 0 = neutral is not a label and is
  refused) for the frame in its name, which is the
  peak (in CK+ the last) frame. If the emotion frame is not the last landmark
  frame, the sequence is cut at the emotion frame and a warning is logged; an
  emotion frame without a landmark file is an error.
* Hidden files (``.DS_Store`` ...) are skipped; any other unexpected file or
  folder inside ``Landmarks/`` or ``Emotion/`` is an error naming it, so a
  damaged copy never yields silently wrong data. Other top-level folders
  (``cohn-kanade-images``, ``FACS``) are not read.

* Landmark coordinates must lie in the image (0-720 x 0-576 px) give or take
  a margin of 150 px; a UTF-8 byte-order mark is stripped; undecodable bytes
  are reported with their line.

Every problem raises :class:`~animsynth.errors.MotionFormatError` with the
file (and the 1-based line for content errors).
"""

from __future__ import annotations

import logging
import os
import re
from dataclasses import dataclass

import numpy as np

from ..atomic import atomic_write_text
from ..errors import MotionFormatError, parse_float

log = logging.getLogger("animsynth.io.ckplus")

#: CK+ emotion codes (index = code).
EMOTIONS = ("neutral", "anger", "contempt", "disgust", "fear", "happy", "sadness", "surprise")
N_LANDMARKS = 68

_SUBJECT_RE = re.compile(r"^S\d{3}$")
_SEQ_RE = re.compile(r"^\d{3}$")
_LM_RE = re.compile(r"^(S\d{3})_(\d{3})_(\d{8})_landmarks\.txt$")
_EMO_RE = re.compile(r"^(S\d{3})_(\d{3})_(\d{8})_emotion\.txt$")

__all__ = [
    "EMOTIONS",
    "CKSequence",
    "emotion_code",
    "read_ckplus",
    "read_emotion",
    "read_landmarks",
    "read_sequence",
    "write_emotion",
    "write_landmarks",
    "write_sequence",
]


def emotion_code(label) -> int:
    """Code 0-7 of an emotion name (``"happy"``) or code; ``ValueError`` otherwise."""
    if isinstance(label, (int, np.integer)) and 0 <= int(label) < len(EMOTIONS):
        return int(label)
    if isinstance(label, str) and label.lower() in EMOTIONS:
        return EMOTIONS.index(label.lower())
    raise ValueError(f"unknown CK+ emotion {label!r}; expected one of {list(EMOTIONS)} or a code 0-7")


@dataclass
class CKSequence:
    """One CK+ sequence.

    Attributes
    ----------
    subject, sequence : str
        ``"S005"``, ``"001"``.
    landmarks : ndarray, shape (frames, 68, 2)
        Image coordinates in pixels (x right, y down), neutral first.
    emotion : int or None
        Emotion code of the peak frame (None: unlabelled).
    frames : ndarray of int
        CK+ frame numbers (1 ... frames).
    """

    subject: str
    sequence: str
    landmarks: np.ndarray
    emotion: int | None = None
    frames: np.ndarray | None = None

    @property
    def name(self) -> str:
        return f"{self.subject}_{self.sequence}"

    @property
    def label(self) -> str | None:
        return None if self.emotion is None else EMOTIONS[self.emotion]

    @property
    def n_frames(self) -> int:
        return int(self.landmarks.shape[0])


def _read_lines(path) -> list[str]:
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        raise MotionFormatError(path, None, f"cannot read: {exc}") from None
    try:
        text = data.decode("utf-8-sig")  # a UTF-8 byte-order mark is stripped
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise MotionFormatError(path, line, f"undecodable bytes (not UTF-8 text) at byte {exc.start}") from None
    return text.splitlines()


#: CK+ images are at most 720 x 576 pixels; coordinates may lie this far outside (landmark fits at the border).
IMAGE_MAX_PX = (720.0, 576.0)
IMAGE_MARGIN_PX = 150.0


def read_landmarks(path) -> np.ndarray:
    """One CK+ landmark file -> (68, 2) float array; strict (see module docs).

    Coordinates outside the image (0-720 x 0-576 px) by more than
    :data:`IMAGE_MARGIN_PX` are refused with the file and line.
    """
    pts = []
    lo = -IMAGE_MARGIN_PX
    for ln, raw in enumerate(_read_lines(path), start=1):
        tok = raw.split()
        if not tok:
            continue
        if len(tok) != 2:
            raise MotionFormatError(path, ln, f"expected 2 numbers 'x y', got {len(tok)} field(s): {raw.strip()!r}")
        xy = [parse_float(t, path, ln, "landmark coordinate") for t in tok]
        for v, hi, axis in ((xy[0], IMAGE_MAX_PX[0], "x"), (xy[1], IMAGE_MAX_PX[1], "y")):
            if not lo <= v <= hi + IMAGE_MARGIN_PX:
                raise MotionFormatError(path, ln, f"landmark {axis} = {v:g} px lies outside the image "
                                                  f"(0-{hi:g} px, margin {IMAGE_MARGIN_PX:g} px)")
        pts.append(xy)
        if len(pts) > N_LANDMARKS:
            raise MotionFormatError(path, ln, f"more than {N_LANDMARKS} landmark rows")
    if len(pts) != N_LANDMARKS:
        raise MotionFormatError(path, None, f"expected {N_LANDMARKS} landmark rows, found {len(pts)}")
    return np.asarray(pts, dtype=float)


def read_emotion(path) -> int:
    """One CK+ emotion file -> code 0-7; strict (one integral number)."""
    values = []
    for ln, raw in enumerate(_read_lines(path), start=1):
        for t in raw.split():
            values.append((ln, parse_float(t, path, ln, "emotion code")))
    if len(values) != 1:
        raise MotionFormatError(path, values[1][0] if len(values) > 1 else None,
                                f"expected exactly one emotion code, found {len(values)}")
    ln, v = values[0]
    if v != round(v) or not 0 <= v < len(EMOTIONS):
        raise MotionFormatError(path, ln, f"emotion code must be an integer 1-{len(EMOTIONS) - 1}, got {v:g}")
    if v == 0:
        raise MotionFormatError(path, ln, "emotion code 0 (neutral) is not an expression label; CK+ labels are 1-7")
    return int(round(v))


def _visible(folder) -> list[str]:
    try:
        return sorted(n for n in os.listdir(folder) if not n.startswith("."))
    except OSError as exc:
        raise MotionFormatError(folder, None, f"cannot list folder: {exc}") from None


def _check_dir_name(path, regex, what):
    name = os.path.basename(path)
    if not regex.match(name):
        raise MotionFormatError(path, None, f"unexpected {what} name {name!r} in the CK+ layout")
    if not os.path.isdir(path):
        raise MotionFormatError(path, None, f"expected a {what} folder, found a file")


def read_sequence(root, subject: str, sequence: str) -> CKSequence:
    """Read ``Landmarks/<subject>/<sequence>`` and its emotion label (if any)."""
    lm_dir = os.path.join(root, "Landmarks", subject, sequence)
    names = _visible(lm_dir)
    by_frame: dict[int, str] = {}
    for n in names:
        p = os.path.join(lm_dir, n)
        m = _LM_RE.match(n)
        if not m:
            raise MotionFormatError(p, None, "unexpected file in a CK+ landmark folder "
                                             "(expected Sxxx_yyy_########_landmarks.txt)")
        if (m.group(1), m.group(2)) != (subject, sequence):
            raise MotionFormatError(p, None, f"file name says {m.group(1)}/{m.group(2)} but it lies in {subject}/{sequence}")
        by_frame[int(m.group(3))] = p
    if not by_frame:
        raise MotionFormatError(lm_dir, None, "sequence folder holds no landmark files")
    frames = sorted(by_frame)
    expected = list(range(1, len(frames) + 1))
    if frames[0] < 1:
        raise MotionFormatError(by_frame[frames[0]], None, "CK+ frame numbers start at 1")
    if frames != expected:
        missing = sorted(set(range(1, frames[-1] + 1)) - set(frames))
        raise MotionFormatError(lm_dir, None, "landmark frames must be numbered 1..N without gaps; "
                                              f"missing frame(s) {missing[:10]}")
    lms = np.stack([read_landmarks(by_frame[f]) for f in frames])
    emotion = None
    emo_dir = os.path.join(root, "Emotion", subject, sequence)
    if os.path.isdir(emo_dir):
        enames = _visible(emo_dir)
        if len(enames) > 1:
            raise MotionFormatError(emo_dir, None, f"expected at most one emotion file, found {len(enames)}")
        if enames:
            p = os.path.join(emo_dir, enames[0])
            m = _EMO_RE.match(enames[0])
            if not m:
                raise MotionFormatError(p, None, "unexpected file in a CK+ emotion folder "
                                                 "(expected Sxxx_yyy_########_emotion.txt)")
            if (m.group(1), m.group(2)) != (subject, sequence):
                raise MotionFormatError(p, None, f"file name says {m.group(1)}/{m.group(2)} but it lies in {subject}/{sequence}")
            ef = int(m.group(3))
            if ef not in by_frame:
                raise MotionFormatError(p, None, f"emotion frame {ef} has no landmark file (sequence has {len(frames)} frames)")
            emotion = read_emotion(p)
            if ef != frames[-1]:
                log.warning("%s: emotion frame %d is not the last frame %d; sequence cut at the emotion (peak) frame",
                            p, ef, frames[-1])
                lms = lms[:ef]
                frames = frames[:ef]
    elif os.path.exists(emo_dir):
        raise MotionFormatError(emo_dir, None, "expected a sequence folder, found a file")
    return CKSequence(subject, sequence, lms, emotion, np.asarray(frames, dtype=int))


def read_ckplus(root, labelled_only: bool = False, require_emotion_dir: bool = True) -> list[CKSequence]:
    """Read a CK+ database (official layout) -> sequences sorted by subject, sequence.

    Parameters
    ----------
    root : path
        Folder holding ``Landmarks/`` and ``Emotion/``.
    labelled_only : bool
        Return only the sequences that have an emotion label.
    require_emotion_dir : bool
        Raise if ``Emotion/`` is missing (the labels are needed for synthesis).
    """
    root = os.fspath(root)
    lm_root = os.path.join(root, "Landmarks")
    emo_root = os.path.join(root, "Emotion")
    if not os.path.isdir(root):
        raise MotionFormatError(root, None, "CK+ folder does not exist")
    if not os.path.isdir(lm_root):
        raise MotionFormatError(root, None, "not a CK+ folder: no Landmarks/ subfolder")
    if require_emotion_dir and not os.path.isdir(emo_root):
        raise MotionFormatError(root, None, "no Emotion/ subfolder (the CK+ emotion labels are needed)")
    pairs = []
    for subj in _visible(lm_root):
        sp = os.path.join(lm_root, subj)
        _check_dir_name(sp, _SUBJECT_RE, "subject folder")
        for seq in _visible(sp):
            qp = os.path.join(sp, seq)
            _check_dir_name(qp, _SEQ_RE, "sequence folder")
            pairs.append((subj, seq))
    if not pairs:
        raise MotionFormatError(lm_root, None, "no subject/sequence folders found")
    if os.path.isdir(emo_root):
        known = set(pairs)
        for subj in _visible(emo_root):
            sp = os.path.join(emo_root, subj)
            _check_dir_name(sp, _SUBJECT_RE, "subject folder")
            for seq in _visible(sp):
                qp = os.path.join(sp, seq)
                _check_dir_name(qp, _SEQ_RE, "sequence folder")
                if (subj, seq) not in known and _visible(qp):
                    raise MotionFormatError(qp, None, "emotion label for a sequence that has no Landmarks/ folder")
    out = [read_sequence(root, s, q) for s, q in pairs]
    if labelled_only:
        out = [s for s in out if s.emotion is not None]
    return out


# -- writing (used by the synthetic CK+-layout generator) --------------------
def write_landmarks(path, points) -> None:
    """Write a (68, 2) array in the CK+ landmark format."""
    pts = np.asarray(points, float)
    if pts.shape != (N_LANDMARKS, 2) or not np.all(np.isfinite(pts)):
        raise ValueError(f"landmarks must be a finite ({N_LANDMARKS}, 2) array, got shape {pts.shape}")
    atomic_write_text(path, "".join(f"   {x:.7e}   {y:.7e}\n" for x, y in pts))


def write_emotion(path, code: int) -> None:
    atomic_write_text(path, f"   {float(emotion_code(code)):.7e}\n")


def write_sequence(root, seq: CKSequence) -> list[str]:
    """Write one sequence in the CK+ layout under ``root``; returns the files written."""
    lm_dir = os.path.join(root, "Landmarks", seq.subject, seq.sequence)
    os.makedirs(lm_dir, exist_ok=True)
    written = []
    for i, pts in enumerate(seq.landmarks, start=1):
        p = os.path.join(lm_dir, f"{seq.subject}_{seq.sequence}_{i:08d}_landmarks.txt")
        write_landmarks(p, pts)
        written.append(p)
    emo_dir = os.path.join(root, "Emotion", seq.subject, seq.sequence)
    os.makedirs(emo_dir, exist_ok=True)  # CK+ has (empty) folders for unlabelled sequences too
    if seq.emotion is not None:
        p = os.path.join(emo_dir, f"{seq.subject}_{seq.sequence}_{seq.n_frames:08d}_emotion.txt")
        write_emotion(p, seq.emotion)
        written.append(p)
    return written
