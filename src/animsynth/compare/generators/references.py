"""The two reference rows of the comparison, bounds rather than methods: :class:`Replay` (the held-out capture
itself, the upper bound for realism) and :class:`Concat` (random database segments appended without blending,
the lower bound). The registry (:mod:`animsynth.compare.generators.registry`) names them ``replay`` and ``concat``."""

from __future__ import annotations

import numpy as np

from ...generator import Database, Generator
from ...kinematics import root_rotation, root_translation, set_root
from ...motion import Motion

__all__ = ["Concat", "Replay"]


class Replay(Generator):
    """The held-out capture itself: the frames that follow the start (the same for every seed).

    Parameters
    ----------
    held_out : Motion, the held-out clip whose first frames are the start
    """

    def __init__(self, held_out: Motion | None = None):
        self.held_out = held_out
        self.name = "replay"

    def fit(self, database) -> "Replay":
        if self.held_out is None:
            raise ValueError("replay needs the held-out clip (Replay(held_out=...))")
        self.db_ = Database(database)
        return self

    def generate(self, start: Motion, length: int, seed: int) -> Motion:
        self._check_start(start, length)
        h = np.asarray(self.held_out.values, float)
        c, length = start.n_frames, int(length)
        if not np.array_equal(h[:c], np.asarray(start.values, float)):
            raise ValueError("replay: the start is not the held-out clip's first frames")
        if c + length > h.shape[0]:
            raise ValueError(f"replay: the held-out clip has {h.shape[0]} frames, {c} + {length} asked for")
        return self._motion(h[c:c + length], length, [], np.full((length, 2), -1))


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

    def fit(self, database) -> "Concat":
        if not 0 < float(self.min_segment_s) <= float(self.max_segment_s):
            raise ValueError(f"concat segments: need 0 < min_segment_s <= max_segment_s, got "
                             f"{self.min_segment_s}, {self.max_segment_s}")
        self.db_ = Database(database)
        return self

    def generate(self, start: Motion, length: int, seed: int) -> Motion:
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
