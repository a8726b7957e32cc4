"""The two reference rows of the comparison, bounds rather than methods: :class:`Replay` (the held-out capture
itself, the upper bound for realism) and :class:`Concat` (random database segments appended without blending,
the lower bound). The registry (:mod:`animsynth.compare.generators.registry`) names them ``replay`` and ``concat``."""

from __future__ import annotations

import numpy as np

from ...generator import QUERY_FUTURE_TRAJECTORY, Database, Generator
from ...kinematics import root_rotation, root_translation, set_root
from ...motion import Motion

__all__ = ["Concat", "Replay"]


class Replay(Generator):
    """The held-out capture itself: the frames that follow the start (the same for every seed).

    Its query is the held-out future (``query = "future_trajectory"``: the caller passes the held-out frames after
    the start as ``trajectory``) and it plays their first ``length``; the step into them is the capture's own, so
    the entry is no seam (``entry_seam = False``). Fitted once per database like every generator, it serves every
    held-out window of that database.
    """

    name = "replay"
    query = QUERY_FUTURE_TRAJECTORY
    entry_seam = False

    def __init__(self):
        """No parameters: what it plays is the held-out future it is given."""

    def fit(self, database, native_clips=None) -> "Replay":
        """Keep the database (``native_clips``: ignored): the replay reads only the held-out frames it is given."""
        self.db_ = Database(database)
        return self

    def generate(self, start: Motion, length: int, seed: int, trajectory: Motion | None = None,
                 native_start: Motion | None = None) -> Motion:
        """The first ``length`` frames of ``trajectory`` (the held-out frames after ``start``)."""
        self._check_start(start, length)
        length = int(length)
        if trajectory is None:
            raise ValueError("replay: its query is the held-out future: pass trajectory= (the held-out frames "
                             "after the start)")
        if trajectory.columns != start.columns:
            raise ValueError("replay: the held-out frames are on other DOF columns than the start")
        if trajectory.n_frames < length:
            raise ValueError(f"replay: {trajectory.n_frames} held-out frames after the start, {length} asked for")
        return self._motion(np.asarray(trajectory.values[:length], float), length, [], np.full((length, 2), -1))


class Concat(Generator):
    """Random database segments appended without blending (the lower bound).

    Each segment (a random clip, weighted by its frames, a random first frame, a length drawn
    uniformly between ``min_segment_s`` and ``max_segment_s``) keeps its own poses and heading;
    only its root is shifted on the ground so that its first frame stands where the previous frame
    stood (the first segment: where the start's last frame stands).

    Attributes
    ----------
    db_ : Database
    """

    def __init__(self, min_segment_s: float = 0.5, max_segment_s: float = 1.5):
        self.min_segment_s = min_segment_s
        self.max_segment_s = max_segment_s
        self.name = "concat"

    def fit(self, database, native_clips=None) -> "Concat":
        if not 0 < float(self.min_segment_s) <= float(self.max_segment_s):
            raise ValueError(f"concat segments: need 0 < min_segment_s <= max_segment_s, got "
                             f"{self.min_segment_s}, {self.max_segment_s}")
        self.db_ = Database(database)
        return self

    def generate(self, start: Motion, length: int, seed: int, native_start: Motion | None = None) -> Motion:
        self._check_start(start, length)
        db, length = self.db_, int(length)
        sk = db.skeleton
        rng = np.random.default_rng(seed)
        lo = max(1, int(round(float(self.min_segment_s) * db.fps)))
        hi = max(lo, int(round(float(self.max_segment_s) * db.fps)))
        sizes = np.array([c.n_frames for c in db.clips], float)
        last = np.asarray(start.values, float)[-1]
        parts, seams, sources, t = [], [], [], 0
        while t < length:
            c = int(rng.choice(len(db.clips), p=sizes / sizes.sum()))
            n_c = db.clips[c].n_frames
            size = int(min(rng.integers(lo, hi + 1), n_c, length - t))
            f0 = int(rng.integers(0, n_c - size + 1))
            seg = np.asarray(db.clips[c].values[f0:f0 + size], float)
            p = root_translation(sk, seg)
            target = root_translation(sk, last[None, :])[0]
            shift = np.array([target[0] - p[0, 0], 0.0, target[2] - p[0, 2]])
            seg = set_root(sk, seg, root_rotation(sk, seg), p + shift)
            parts.append(seg)
            seams.append(t)
            sources.append(np.stack([np.full(size, c), np.arange(f0, f0 + size)], 1))
            last = seg[-1]
            t += size
        seams = [s for s in seams if s > 0]
        return self._motion(np.vstack(parts), length, seams, np.vstack(sources))
