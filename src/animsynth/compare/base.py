"""The common interface of the compare family's generators: :class:`Generator` (``fit`` / ``generate``), the
:class:`Database` of clips they are fitted on, and the root helper that places a generated motion where the start
stands (on :func:`animsynth.kinematics.heading` and :func:`animsynth.kinematics.set_root`). The generators
themselves and the factory are in :mod:`animsynth.compare.generators` (which re-exports these names); the modern
generators (:mod:`.motionmatching`, :mod:`.genmm`) build on this module alone, so the factory can import them
without an import cycle.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ..kinematics import heading, root_rotation, root_translation, set_root
from ..motion import Motion

__all__ = ["Database", "Generator", "align_root", "check_generated"]


# ----------------------------------------------------------------------------- root helpers


def align_root(skeleton, values, anchor, index: int = 0) -> np.ndarray:
    """Move ``values`` rigidly on the ground (a turn about +Y and a horizontal shift) so that frame
    ``index`` has the root ground position and heading of the pose ``anchor`` (n_dof,).

    Heights and the root's tilt are each frame's own. Returns a new ``(frames, n_dof)`` array.
    """
    values = np.asarray(values, float)
    anchor = np.asarray(anchor, float)[None, :]
    R = root_rotation(skeleton, values)
    p = root_translation(skeleton, values)
    turn = float(heading(skeleton, anchor)[0] - heading(skeleton, values[index:index + 1])[0])
    Ry = Rotation.from_euler("y", turn)
    pa = root_translation(skeleton, anchor)[0]
    q = Ry.apply(p - p[index])
    q[:, 0] += pa[0]
    q[:, 2] += pa[2]
    q[:, 1] = p[:, 1]
    return set_root(skeleton, values, Ry * R, q)


def check_generated(motion: Motion, length: int, skeleton, name: str = "generator") -> Motion:
    """Check a generator's output (``length`` frames, the skeleton's DOF, finite); fill missing meta."""
    v = np.asarray(motion.values)
    if v.shape != (int(length), skeleton.n_dof):
        raise ValueError(f"{name}: generated {v.shape}, expected ({int(length)}, {skeleton.n_dof})")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{name}: generated motion has non-finite values")
    seams = np.asarray(motion.meta.get("seams", []), np.int64).ravel()
    if seams.size and (seams.min() < 0 or seams.max() >= length):
        raise ValueError(f"{name}: seam indices outside 0..{length - 1}")
    motion.meta["seams"] = np.unique(seams)
    src = motion.meta.get("source_frames")
    if src is None:
        motion.meta["source_frames"] = np.full((int(length), 2), -1, np.int64)
    return motion


# ----------------------------------------------------------------------------- the database


class Database:
    """Clips of one skeleton and frame rate, their frames numbered one after the other.

    Parameters
    ----------
    clips : list of Motion (>= 2 frames each, equal columns and fps)

    Attributes
    ----------
    values : ndarray (N, n_dof), the clips' frames concatenated
    clip, frame : int arrays (N,), each frame's clip index and frame within its clip
    skeleton, fps
    """

    def __init__(self, clips):
        clips = list(clips)
        if not clips:
            raise ValueError("empty database: no clips")
        sk, fps = clips[0].skeleton, float(clips[0].fps)
        for c in clips:
            if c.columns != sk.columns():
                raise ValueError(f"database clip {c.name!r} has other DOF columns than {clips[0].name!r}")
            if abs(float(c.fps) - fps) > 1e-9 * fps:
                raise ValueError(f"database clip {c.name!r} runs at {c.fps} fps, {clips[0].name!r} at {fps}")
            if c.n_frames < 2:
                raise ValueError(f"database clip {c.name!r} has {c.n_frames} frame(s); need >= 2")
        self.clips, self.skeleton, self.fps = clips, sk, fps
        self.values = np.vstack([np.asarray(c.values, float) for c in clips])
        self.clip = np.concatenate([np.full(c.n_frames, i, np.int64) for i, c in enumerate(clips)])
        self.frame = np.concatenate([np.arange(c.n_frames, dtype=np.int64) for c in clips])
        self.n_root = len(sk.joints[0].dofs)
        # play_path reads a step a -> a+1 as motion within one capture: a copy of every clip's first frame
        # is put before it (never on a path), so no step of the played motion runs from one clip into the next
        rows, index, k = [], np.empty(self.clip.size, np.int64), 0
        off = 0
        for i, c in enumerate(clips):
            if i:
                rows.append(np.asarray(c.values[:1], float))
                k += 1
            index[off:off + c.n_frames] = k + np.arange(c.n_frames)
            rows.append(np.asarray(c.values, float))
            k += c.n_frames
            off += c.n_frames
        self._playable = Motion(np.vstack(rows), sk, fps, "database")
        self._index = index

    @property
    def n_frames(self) -> int:
        return int(self.values.shape[0])

    def play(self, path, anchor) -> np.ndarray:
        """The frames of ``path`` (database frame indices) with the root integrated along the path
        (:func:`animsynth.resequencing.play_path`: a step within a clip moves the root as the capture
        did, a jump takes the destination frame's own step) and the whole placed so that the path's
        first frame has the root ground position and heading of ``anchor`` (n_dof,).
        Returns ``(len(path), n_dof)``."""
        from ..resequencing.paths import play_path

        path = np.asarray(path, np.int64)
        played = play_path(self._playable, self._index[path], root="integrate", same_pass=1)
        return align_root(self.skeleton, played.values, anchor)

    def seams(self, path) -> np.ndarray:
        """Positions ``t >= 1`` of ``path`` where frame ``t`` is not the frame after ``t - 1`` in one clip."""
        path = np.asarray(path, np.int64)
        if path.size < 2:
            return np.zeros(0, np.int64)
        follows = (self.clip[path[1:]] == self.clip[path[:-1]]) & (self.frame[path[1:]] == self.frame[path[:-1]] + 1)
        return np.flatnonzero(~follows) + 1

    def sources(self, path) -> np.ndarray:
        """``(len(path), 2)`` int array: (clip, frame) of every path frame."""
        path = np.asarray(path, np.int64)
        return np.stack([self.clip[path], self.frame[path]], axis=1)


class Generator:
    """Base class: ``fit(database)`` then ``generate(start, length, seed)``."""

    name = "generator"

    def fit(self, database) -> "Generator":  # pragma: no cover - every generator overrides it
        raise NotImplementedError

    def generate(self, start: Motion, length: int, seed: int) -> Motion:  # pragma: no cover
        raise NotImplementedError

    def _check_start(self, start: Motion, length: int) -> None:
        if not hasattr(self, "db_"):
            raise RuntimeError(f"{self.name}: call fit(database) before generate")
        if start.n_frames < 2:
            raise ValueError(f"{self.name}: the start needs >= 2 frames, has {start.n_frames}")
        if start.columns != self.db_.skeleton.columns():
            raise ValueError(f"{self.name}: the start's DOF columns differ from the database's")
        if int(length) < 1:
            raise ValueError(f"{self.name}: length must be >= 1, got {length}")

    def _motion(self, values, length: int, seams, sources, **meta) -> Motion:
        m = Motion(np.asarray(values, float), self.db_.skeleton, self.db_.fps, self.name,
                   dict(seams=np.asarray(seams, np.int64), source_frames=np.asarray(sources, np.int64), **meta))
        return check_generated(m, length, self.db_.skeleton, self.name)
