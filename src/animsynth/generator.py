"""The one interface of every motion generator, and what they share.

A generator is a scikit-learn-style estimator (:class:`Generator`): parameters in ``__init__``,
``fit(database)`` returns it, fitted attributes end in ``_``, ``generate(start, length, seed)`` returns a
:class:`~animsynth.motion.Motion` of ``length`` frames continuing ``start`` with ``meta["seams"]``. The
:class:`Database` is the clips it is fitted on; :func:`align_root` places a generated motion where the start
stands (on :func:`animsynth.kinematics.heading` and :func:`animsynth.kinematics.set_root`); :func:`play_path`
plays a path of frames with the root integrated along it.

Each method family holds its own generator (:mod:`animsynth.simplicial.generator`,
:mod:`animsynth.resequencing.generator`), which its paper steps, the command line and the side-by-side
comparison (:mod:`animsynth.compare`) all call; this module knows no family.
"""

from __future__ import annotations

import numpy as np

from .kinematics import (heading, local_rotations, root_rotation, root_translation, rotation_heading, set_root,
                         wrap_radians, yaw_rotation)
from .motion import Motion

__all__ = ["Database", "Generator", "align_root", "check_generated", "play_path", "QUERY_START",
           "QUERY_FUTURE_TRAJECTORY"]


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
    Ry = yaw_rotation(turn)[0]
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
        (:func:`play_path`: a step within a clip moves the root as the capture
        did, a jump takes the destination frame's own step) and the whole placed so that the path's
        first frame has the root ground position and heading of ``anchor`` (n_dof,).
        Returns ``(len(path), n_dof)``."""
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


#: ``Generator.query``: the generator is given the start alone (every generator's protocol by default)
QUERY_START = "start"
#: ``Generator.query``: the generator is also given the held-out future (``generate(..., trajectory=future)``)
QUERY_FUTURE_TRAJECTORY = "future_trajectory"


class Generator:
    """Base class: ``fit(database)`` then ``generate(start, length, seed)``.

    A subclass takes its parameters in ``__init__`` (stored as given), ``fit(database)`` (a list of
    :class:`~animsynth.motion.Motion`, one skeleton and frame rate) sets ``db_`` (:class:`Database`) and its other
    fitted attributes (names ending in ``_``) and returns ``self``; ``generate(start, length, seed)`` returns
    ``length`` frames continuing ``start`` (>= 2 frames), checked by :func:`check_generated`, with
    ``meta["seams"]`` and ``meta["source_frames"]``.

    What a caller (the compare family's runner) reads of a generator is declared here, with its default:

    ``query``
        what it is given besides the database: :data:`QUERY_START` (``"start"``, the default: the start alone) or
        :data:`QUERY_FUTURE_TRAJECTORY` (``"future_trajectory"``: its ``generate`` takes ``trajectory=``, the
        held-out frames after the start, information the other generators do not see).
    ``native_fps``
        the rate of the native-rate clips it reads (fps), or ``None`` (the default): it runs on the working-rate
        clips alone. Every ``fit`` takes ``native_clips=`` (the database at ``native_fps``, taken from the
        source) and every ``generate`` ``native_start=`` (the start at that rate); a generator whose
        ``native_fps`` is ``None`` is given ``None`` for both and ignores them.
    ``entry_seam``
        whether the step from the start into its first generated frame is a seam (``True``, the default: a
        generator starts from the start's pose, not from the capture's next frame; ``False`` only for a replay of
        the held-out capture).
    :meth:`run_notes`
        the values of a fitted generator that a run records besides its motion (empty by default; the graph
        generators: the transitions they kept).
    :meth:`outside_cost`
        the CPU seconds and peak memory of its last ``fit`` or ``generate`` call spent outside the caller's
        process (a child process that has not ended; zero by default: the caller's own counters hold the cost).
    :meth:`set_label`
        what the caller is fitting or generating for (e.g. a clip id), for the generator's own log lines (the
        default ignores it).
    """

    name = "generator"
    query = QUERY_START
    native_fps: float | None = None
    entry_seam = True

    def fit(self, database, native_clips=None) -> "Generator":  # pragma: no cover - every generator overrides it
        raise NotImplementedError

    def generate(self, start: Motion, length: int, seed: int,
                 native_start: Motion | None = None) -> Motion:  # pragma: no cover
        raise NotImplementedError

    #: the modules :meth:`fit` and :meth:`generate` import on first use (:meth:`warm_up` imports them): here the
    #: joint roles, which playing a path on the skeleton reads
    lazy_imports: tuple[str, ...] = ("animsynth.joints",)

    def warm_up(self) -> None:
        """Import :attr:`lazy_imports`, what :meth:`fit` and :meth:`generate` import on first use (a library such
        as scikit-learn, the method's own modules), so that a timed build or generation is that work, not one
        process's imports: the comparison calls it before it times a build, and the rows of one method share a
        process (its first row would otherwise pay the imports for the others)."""
        import importlib

        for name in self.lazy_imports:
            importlib.import_module(name)

    def run_notes(self) -> dict:
        """Values of the fitted generator that a run records with its metrics, ``{name: number}``; a name a
        generator does not give is recorded as NaN (:meth:`Generator.run_notes` itself gives none).

        ``transitions_kept``: the candidate transitions a graph generator keeps before pruning.
        """
        return {}

    def outside_cost(self) -> dict:
        """``{"cpu_s": ..., "rss_mb": ...}``: the CPU seconds of the last ``fit`` or ``generate`` call spent outside
        this process and the peak resident memory (MB) of the process that spent them (both 0: none)."""
        return {"cpu_s": 0.0, "rss_mb": 0.0}

    def set_label(self, label: str) -> None:
        """Name what the next calls are for (``label``, e.g. a clip id) in the generator's own log lines (the
        default keeps no label)."""

    def _check_start(self, start: Motion, length: int, database: Database | None = None) -> None:
        """Refuse a generator that is not fitted, a start of fewer than 2 frames or of other DOF columns than
        ``database`` (``db_`` unless given: the clips a generator that runs on other clips than ``db_`` really
        receives), and a ``length`` below 1."""
        if not hasattr(self, "db_"):
            raise RuntimeError(f"{self.name}: call fit(database) before generate")
        if start.n_frames < 2:
            raise ValueError(f"{self.name}: the start needs >= 2 frames, has {start.n_frames}")
        if start.columns != (self.db_ if database is None else database).skeleton.columns():
            raise ValueError(f"{self.name}: the start's DOF columns differ from the database's")
        if int(length) < 1:
            raise ValueError(f"{self.name}: length must be >= 1, got {length}")

    def _motion(self, values, length: int, seams, sources, **meta) -> Motion:
        m = Motion(np.asarray(values, float), self.db_.skeleton, self.db_.fps, self.name,
                   dict(seams=np.asarray(seams, np.int64), source_frames=np.asarray(sources, np.int64), **meta))
        return check_generated(m, length, self.db_.skeleton, self.name)


# ----------------------------------------------------------------------------- playing a path


def play_path(motion: Motion, path, root: str = "integrate", name: str | None = None, same_pass: int = 1) -> Motion:
    """The motion a frame-index path plays.

    Joint angles are those of the path's frames. The root:

    * ``"absolute"``: the frames' own root position and orientation (the
      character teleports when the path jumps between distant frames).
    * ``"integrate"``: root motion is re-integrated. Each step ``a -> b`` moves
      the root by the original displacement ``p[b] - p[a]`` and turns it by the
      original heading change when ``1 <= |b - a| <= same_pass`` (a step within
      the same pass of the capture, forward *or backward*, possibly skipping
      frames); after a jump to another pass it uses frame ``b``'s own step
      ``b-1 -> b``.
      Displacements are expressed in the heading frame (rotation about Y), so
      they follow the accumulated heading; the height is frame ``b``'s own.

    Returns a :class:`Motion` on the same skeleton and frame rate.
    """
    path = np.asarray(path, dtype=np.int64)
    sk = motion.skeleton
    vals = np.asarray(motion.values, float)
    n = vals.shape[0]
    if path.size == 0 or path.min() < 0 or path.max() >= n:
        raise ValueError(f"path indices must lie in 0..{n - 1}")
    out = vals[path].copy()
    if root not in ("absolute", "integrate"):
        raise ValueError(f"root must be 'absolute' or 'integrate', got {root!r}")
    if root == "integrate" and path.size > 1:
        R0 = local_rotations(sk, vals)[0]
        p = root_translation(sk, vals)
        yaw = rotation_heading(R0)
        m = path.size
        new_yaw = np.empty(m)
        new_p = np.empty((m, 3))
        new_yaw[0] = yaw[path[0]]
        new_p[0] = p[path[0]]
        for t in range(1, m):
            a, b = int(path[t - 1]), int(path[t])
            if 1 <= abs(b - a) <= max(1, int(same_pass)):
                src, dst = a, b
            elif b > 0:
                src, dst = b - 1, b
            else:
                src, dst = b, b  # first frame reached by a jump: no step information
            dyaw = wrap_radians(yaw[dst] - yaw[src])
            d = p[dst] - p[src]
            c, s = np.cos(-yaw[src]), np.sin(-yaw[src])
            local = np.array([c * d[0] + s * d[2], -s * d[0] + c * d[2]])  # R_y(-yaw) on (x, z)
            c2, s2 = np.cos(new_yaw[t - 1]), np.sin(new_yaw[t - 1])
            new_p[t, 0] = new_p[t - 1, 0] + c2 * local[0] + s2 * local[1]
            new_p[t, 2] = new_p[t - 1, 2] - s2 * local[0] + c2 * local[1]
            new_p[t, 1] = p[b, 1]
            new_yaw[t] = new_yaw[t - 1] + dyaw
        # new root rotation = R_y(new_yaw - yaw[b]) * R[b]
        Ry = yaw_rotation(new_yaw - yaw[path])
        out = set_root(sk, out, Ry * R0[path], new_p)
    return Motion(out, sk, motion.fps, name or f"{motion.name}_reseq", dict(motion.meta))
