"""GenMM: example-based motion synthesis by generative motion matching (Li et al., SIGGRAPH 2023).

A reimplementation in numpy and scipy, written from the paper and the documented defaults of the
Apache-2.0 reference (github.com/wyysf-98/GenMM, torch); no code copied. The estimator follows the
common interface of :mod:`animsynth.compare.generators.registry` (``fit(database)``, ``generate(start, length,
seed)``).

Representation (one row per frame, :mod:`animsynth.compare.generators.poses`): the 6D rotation (Zhou et al. 2019)
of every joint with rotational DOF, then the root. ``root="local"`` (default, heading-invariant): the
root rotation without its facing yaw (6D), the root height (m), the ground velocity in the previous
frame's facing frame (x, z; m/s) and the turning rate (rad/s). ``root="world"`` (the paper's, an
ablation): the world root rotation (6D), the height and the world ground velocity (x, z).

Synthesis (the paper's, with the reference's defaults):

* patches of ``patch_size`` = 11 consecutive frames; database patches never cross clips;
* distance ``||x - y||^2 / d`` (d: the patch's dimension); with the completeness normalisation each
  database patch's distances are divided by ``alpha + `` its smallest distance to any patch of the
  synthesised motion (``alpha`` = 0.01; ``alpha = inf``: plain nearest neighbours, the ablation);
* each synthesised frame is the mean of the matched patches' frames that overlap it (the vote);
* a pyramid: the coarsest level scales the database by ``coarse_patches * patch_size / longest clip``
  (5 patches, the reference's ``5x_patchsize``), each finer level by 1 / ``pyramid_factor`` (0.75) more,
  the last at full rate; clips and motion are resampled linearly; a clip shorter than a patch at a level
  gives no patch there;
* at least ``min_levels`` (7) levels, the coarsest at least ``min_coarse_patches`` (3) patches of the longest
  clip, on every database whose longest clip is longer than those 3 patches (:func:`level_scales`): when the rule
  gives fewer levels (a longest clip under 232 frames at the defaults, as :func:`level_scales` counts; under 55
  frames the rule alone gives the full rate only, as the reference's own ``_get_pyramid_lengths`` does), the
  coarsest scale is lowered to ``pyramid_factor ** (min_levels - 1)``, and the finer levels follow by the same
  factor; where that would go below the floor (a longest clip under 185 frames), the coarsest level is the floor
  (33 frames) and the 7 levels between it and the full rate are spaced by a larger factor (0.83 on a 100-frame
  clip, 0.96 on a 42-frame one). A database whose longest clip has at most 33 frames would keep one level, the
  full rate (:func:`pyramid_note`; the comparison's clips table says so): with ``min_levels`` above 1, ``fit``
  refuses it (ValueError: the comparison's rows read "not built", GenMM never runs below its level; on the paper
  run the run clip 35_17's temporal blocks, databases of 21 frames). The floor binding is why, before this rule
  spaced the levels, the paper run's clips of short databases (r1, r2, subject 09, the run) had 1 to 3 levels
  despite ``min_levels``: a fixed factor of 0.75 from a 33-frame floor reaches the full rate in fewer steps.
  Why 3 and not 1: with the
  coarsest level one patch long, the synthesised motion's coarsest level is one patch choosing among one
  patch per clip, and the seed no longer matters (measured on three 60-frame synthetic walks, 40 frames from
  an 8-frame start, 12 seeds: 1 distinct motion at a 1-patch floor; 10 (local root) and 8 (world) at 2; 12 and
  11 at 3; 12 with the rule alone; and the compare runner's seed diversity over 5 seeds on three
  leave-one-out clips of 60-frame walks: 0, 0.07, 0 m at 1 patch, 0.006, 0.10, 0.09 at 2, 0.15, 0.15, 0.18
  at 3, 0.09, 0.07, 0.15 with the rule alone). 7 is what the reference's pyramid gives at its defaults
  (``pyr_factor`` 0.75 and ``coarse_ratio`` 0.2, the default of its GenMM class and its ``0.2x_nframes``
  setting, whatever the length; its ``5x_patchsize`` setting gives the same on a 275-frame clip, more
  levels on longer clips, fewer on shorter); ``min_levels=1``: the rule alone (one level under 55 frames);
* ``n_steps`` = 3 match-and-vote steps per level; the motion is resampled up to the next level;
* the initial motion: the coarsest database (clips joined) resampled to the coarsest length, plus
  seeded Gaussian noise of ``noise_sigma`` (10, the reference's config) folded by ``fmod(., 1)`` as in
  the reference (no fold when ``noise_sigma`` is 0);
* keyframe mode, so that every generator starts from the same context: the first ``start`` frames
  (resampled to the level) are written back after every step.

The generated frames are decoded back to the skeleton's Euler DOF (:func:`animsynth.compare.generators.poses.decode`;
1- and 2-DOF joints keep their own axes), the root integrated from the start's last frame.

Departures: the root's velocities are per second (the reference's per frame, in file units); no
contact labels or foot fixing; level lengths come from one scale per level shared by the clips and
the motion (the reference computes each sequence's own list of lengths).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ...kinematics import from_rot6d, rest_forward, root_rotation, rot6d, rotation_heading, wrap_radians, yaw_rotation
from ...motion import Motion
from ...generator import Database, Generator
from .poses import decode, encode, rotating_joints

__all__ = ["GenMM", "make_genmm", "extract_patches", "match_patches", "vote", "resample_rows", "level_scales",
           "pyramid_note"]


def extract_patches(x: np.ndarray, size: int) -> np.ndarray:
    """Every window of ``size`` consecutive rows of ``x (T, D)``, flattened: ``(T - size + 1, size * D)``
    (empty when ``T < size``)."""
    x = np.asarray(x, float)
    T, D = x.shape
    if T < size:
        return np.zeros((0, size * D))
    w = np.lib.stride_tricks.sliding_window_view(x, size, axis=0)  # (T-size+1, D, size)
    return np.ascontiguousarray(w.transpose(0, 2, 1)).reshape(T - size + 1, size * D)


def match_patches(queries: np.ndarray, keys: np.ndarray, alpha: float = 0.01,
                  key_norms: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Nearest key patch of every query patch, GenMM's distance.

    Parameters
    ----------
    queries : (n, d) the synthesised motion's patches
    keys : (m, d) the database's patches
    alpha : completeness normalisation: distances to key ``j`` are divided by ``alpha + min_i D[i, j]``
        (a key already matched well by some query costs more to the others, so unused keys are drawn
        in); ``inf``: plain nearest neighbours
    key_norms : (m,) ``sum(keys ** 2, axis=1)`` when known (the database's patches do not change)

    Returns
    -------
    nn : (n,) int, the chosen key per query
    dist : (n,) float, its unnormalised distance ``||q - k||^2 / d``
    """
    q = np.asarray(queries, float)
    k = np.asarray(keys, float)
    d = q.shape[1]
    kk = np.einsum("ij,ij->i", k, k) if key_norms is None else key_norms
    D = (np.einsum("ij,ij->i", q, q)[:, None] + kk[None, :] - 2.0 * (q @ k.T)) / d
    np.maximum(D, 0.0, out=D)
    S = D if not np.isfinite(alpha) else D / (float(alpha) + D.min(axis=0)[None, :])
    nn = np.argmin(S, axis=1)
    return nn, D[np.arange(q.shape[0]), nn]


def vote(patches: np.ndarray, size: int, T: int) -> np.ndarray:
    """Frames ``(T, D)`` as the mean of the overlapping patches ``(T - size + 1, size * D)`` (patch ``i``
    covers frames ``i .. i + size - 1``)."""
    n = patches.shape[0]
    p = patches.reshape(n, size, -1)
    out = np.zeros((T, p.shape[2]))
    count = np.zeros(T)
    for o in range(size):
        out[o:o + n] += p[:, o]
        count[o:o + n] += 1.0
    return out / count[:, None]


def resample_rows(x: np.ndarray, n: int) -> np.ndarray:
    """``x (T, D)`` linearly resampled to ``n`` rows, first and last rows kept (``n = T``: ``x`` itself)."""
    x = np.asarray(x, float)
    T = x.shape[0]
    if n == T:
        return x.copy()
    pos = np.linspace(0.0, T - 1.0, int(n))
    i0 = np.clip(np.floor(pos).astype(np.int64), 0, max(T - 2, 0))
    f = (pos - i0)[:, None]
    i1 = np.minimum(i0 + 1, T - 1)
    return x[i0] * (1.0 - f) + x[i1] * f


def level_scales(longest: int, patch_size: int, coarse_patches: float, factor: float,
                 min_levels: int = 1, min_coarse_patches: float = 1.0) -> list[float]:
    """Scales of the pyramid levels, coarsest first, the last 1.

    Parameters
    ----------
    longest : int
        Frames of the longest database clip.
    patch_size : int
    coarse_patches : float
        The longest clip's length at the coarsest level, in patches (capped at the full rate).
    factor : float
        ``pyramid_factor``: the scale of a level over the next finer one's, in (0, 1).
    min_levels : int
        When the rule above gives fewer levels, the coarsest scale is lowered to ``factor ** (min_levels - 1)``
        (``min_levels`` levels); where that would go below the floor (``min_coarse_patches``), the coarsest level
        is the floor and the levels between it and the full rate are spaced by the larger factor
        ``floor ** (1 / (min_levels - 1))``, so that ``min_levels`` levels remain.
    min_coarse_patches : float
        The floor: the longest clip's length at the coarsest level, in patches (at least 1, so the longest clip
        keeps a patch at every level). A longest clip not longer than the floor holds no pyramid above it: one
        level, the full rate (:func:`pyramid_note` says so).

    Returns
    -------
    list of float
    """
    s = min(1.0, float(coarse_patches) * patch_size / float(longest))
    n = 1
    while s * float(factor) ** -(n - 1) < 1.0 - 1e-9:
        n += 1  # the rule's level count
    if n < int(min_levels):
        floor = max(1.0, float(min_coarse_patches)) * patch_size / float(longest)
        if floor >= 1.0 - 1e-9:
            return [1.0]
        s = float(factor) ** (int(min_levels) - 1)
        if s < floor:  # the floor binds: min_levels levels from the floor to the full rate, closer together
            return [float(floor ** (1.0 - i / (int(min_levels) - 1))) for i in range(int(min_levels) - 1)] + [1.0]
    out = []
    while s < 1.0 - 1e-9:
        out.append(s)
        s /= float(factor)
    out.append(1.0)
    return out


def pyramid_note(longest: int, patch_size: int, min_coarse_patches: float, min_levels: int = 2) -> str:
    """Why a database gets no pyramid of ``min_levels`` GenMM levels ('' when it does): its longest clip is not
    longer than the floor of ``min_coarse_patches`` patches, so :func:`level_scales` gives the full rate alone."""
    floor = max(1.0, float(min_coarse_patches)) * int(patch_size)
    if int(min_levels) <= 1 or int(longest) > floor + 1e-9:
        return ""
    return (f"GenMM: the longest database clip has {int(longest)} frames, not above the pyramid floor of {floor:g} "
            f"(compare.genmm.min_coarse_patches x patch_size): one level")


class GenMM(Generator):
    """Generative motion matching (Li et al. 2023), a numpy reimplementation in keyframe mode.

    Parameters
    ----------
    patch_size : int (odd), frames per patch (11)
    alpha : float, completeness normalisation (0.01; ``float("inf")``: plain nearest neighbours)
    n_steps : int, match-and-vote steps per level (3)
    pyramid_factor : float, length ratio between a level and the next finer one (0.75)
    coarse_patches : float, the longest clip's length at the coarsest level, in patches (5)
    min_levels : int, levels kept on a short database where its longest clip allows (7; module docstring)
    min_coarse_patches : float, the floor of that: the longest clip's coarsest length in patches (3; >= 1)
    noise_sigma : float, standard deviation of the initial noise (10, folded by fmod 1; 0: none)
    root : {"local", "world"}, the root's representation (module docstring)

    Attributes
    ----------
    db_ : Database
    joints_ : int array, the joints with rotational DOF (root excluded)
    forward_ : ndarray (3,), the skeleton's rest forward direction (facing yaw 0)
    frames_ : list of ndarray (T_i, D), every clip's rows
    scales_ : list of float, the levels' scales, coarsest first
    keys_ : list of ndarray (m_k, patch_size * D), the database patches of each level
    key_norms_ : list of ndarray (m_k,), their squared norms
    """

    name = "genmm"

    def __init__(self, patch_size: int = 11, alpha: float = 0.01, n_steps: int = 3, pyramid_factor: float = 0.75,
                 coarse_patches: float = 5.0, noise_sigma: float = 10.0, root: str = "local", min_levels: int = 7,
                 min_coarse_patches: float = 3.0):
        self.patch_size = patch_size
        self.alpha = alpha
        self.n_steps = n_steps
        self.pyramid_factor = pyramid_factor
        self.coarse_patches = coarse_patches
        self.min_levels = min_levels
        self.min_coarse_patches = min_coarse_patches
        self.noise_sigma = noise_sigma
        self.root = root

    # -- representation -------------------------------------------------------------------------------

    def _rows(self, motion: Motion) -> np.ndarray:
        """``(T, D)`` rows of a motion (>= 2 frames)."""
        tr = encode(motion, self.forward_)
        fps, m = float(motion.fps), float(motion.skeleton.length_to_m)
        T = tr.height.shape[0]
        joints = rot6d(tr.rotations).reshape(T, -1)
        if self.root == "local":
            root = np.column_stack([rot6d(tr.tilt), tr.height * m, tr.step * m * fps, tr.turn * fps])
        else:
            R = yaw_rotation(tr.yaw) * Rotation.from_quat(tr.tilt)
            g = tr.ground * m * fps
            vel = np.diff(g, axis=0)
            vel = np.vstack([vel[:1], vel])
            root = np.column_stack([rot6d(R.as_quat()), tr.height * m, vel])
        return np.hstack([joints, root])

    def _decode(self, rows: np.ndarray, anchor: np.ndarray) -> np.ndarray:
        sk = self.db_.skeleton
        fps, m = self.db_.fps, float(sk.length_to_m)
        T = rows.shape[0]
        nj = self.joints_.size
        q = from_rot6d(rows[:, :6 * nj].reshape(T, nj, 6)) if nj else np.zeros((T, 0, 4))
        r = rows[:, 6 * nj:]
        root_q = from_rot6d(r[:, :6])
        height = r[:, 6] / m
        if self.root == "local":
            return decode(sk, q, root_q, height, r[:, 7:9] / (m * fps), r[:, 9] / fps, anchor, self.forward_)
        R = Rotation.from_quat(root_q)
        yaw0 = rotation_heading(root_rotation(sk, anchor[None, :]), self.forward_, hold_vertical=True)[0]
        yaw = rotation_heading(R, self.forward_, hold_vertical=True)
        prev = np.concatenate([[yaw0], yaw[:-1]])
        turn = wrap_radians(yaw - prev)
        disp = r[:, 7:9] / (m * fps)
        local = yaw_rotation(-prev).apply(np.column_stack([disp[:, 0], np.zeros(T), disp[:, 1]]))[:, [0, 2]]
        tilt = (yaw_rotation(-yaw) * R).as_quat()
        return decode(sk, q, tilt, height, local, turn, anchor, self.forward_)

    # -- estimator ------------------------------------------------------------------------------------

    def fit(self, database, native_clips=None) -> "GenMM":
        """The database's patches at every pyramid level (``native_clips``: ignored, it runs at the working rate)."""
        if self.root not in ("local", "world"):
            raise ValueError(f"genmm: root must be 'local' or 'world', got {self.root!r}")
        P = int(self.patch_size)
        if P < 1 or P % 2 == 0:
            raise ValueError(f"genmm: patch_size must be a positive odd number, got {self.patch_size}")
        if not 0.0 < float(self.pyramid_factor) < 1.0:
            raise ValueError(f"genmm: pyramid_factor must lie in (0, 1), got {self.pyramid_factor}")
        if not float(self.alpha) > 0.0:
            raise ValueError(f"genmm: alpha must be > 0 (inf: no normalisation), got {self.alpha}")
        self.db_ = db = Database(database)
        self.joints_ = rotating_joints(db.skeleton)
        self.forward_ = rest_forward(db.skeleton)
        self.frames_ = [self._rows(c) for c in db.clips]
        longest = max(f.shape[0] for f in self.frames_)
        if longest < P:
            raise ValueError(f"genmm: the longest database clip has {longest} frames, fewer than a patch ({P})")
        if isinstance(self.min_levels, bool) or int(self.min_levels) != self.min_levels or self.min_levels < 1:
            raise ValueError(f"genmm: min_levels must be a whole number >= 1, got {self.min_levels!r}")
        if not float(self.min_coarse_patches) >= 1.0:
            raise ValueError(f"genmm: min_coarse_patches must be >= 1, got {self.min_coarse_patches!r}")
        below = pyramid_note(longest, P, float(self.min_coarse_patches), int(self.min_levels))
        if below:  # GenMM is never run below its level: a database too short for the floor is no GenMM database
            raise ValueError(f"{below}, below min_levels {int(self.min_levels)}: not run below its level (set "
                             "compare.genmm.min_levels: 1 to run it on one level)")
        self.scales_ = level_scales(longest, P, float(self.coarse_patches), float(self.pyramid_factor),
                                    int(self.min_levels), float(self.min_coarse_patches))
        self.level_frames_ = []
        self.keys_ = []
        self.key_norms_ = []
        for s in self.scales_:
            lv = [resample_rows(f, max(2, int(round(f.shape[0] * s)))) for f in self.frames_]
            self.level_frames_.append(lv)
            self.keys_.append(np.vstack([extract_patches(f, P) for f in lv]))
            self.key_norms_.append(np.einsum("ij,ij->i", self.keys_[-1], self.keys_[-1]))
        return self

    def generate(self, start: Motion, length: int, seed: int, initial: Motion | None = None,
                 native_start: Motion | None = None) -> Motion:
        """``length`` frames after ``start`` (``seed`` draws the initial noise).

        Parameters
        ----------
        start : Motion (>= 2 frames), the context (kept as the first frames at every step)
        length : int
        seed : int
        initial : Motion, optional, ``start frames + length`` frames: the initial guess instead of the
            coarsest database (the noise is added to it)
        native_start : ignored (it runs at the working rate)

        ``meta``: ``seams`` empty and ``source_frames`` -1 (every frame is a mean of patches),
        ``match_distance`` (mean distance of the last step's matches), ``levels`` (frames per level).
        """
        self._check_start(start, length)
        length, P = int(length), int(self.patch_size)
        c = start.n_frames
        T = c + length
        if T < P:
            raise ValueError(f"genmm: start ({c}) + length ({length}) frames is shorter than a patch ({P})")
        ctx = self._rows(start)
        lengths = [max(P, int(round(T * s))) for s in self.scales_]
        lengths[-1] = T
        rng = np.random.default_rng(seed)
        if initial is None:
            x = resample_rows(np.vstack(self.level_frames_[0]), lengths[0])
        else:
            if initial.n_frames != T or initial.columns != start.columns:
                raise ValueError(f"genmm: the initial motion needs {T} frames on the start's skeleton, has "
                                 f"{initial.n_frames}")
            x = resample_rows(self._rows(initial), lengths[0])
        if float(self.noise_sigma) > 0:
            x = np.fmod(x + rng.standard_normal(x.shape) * float(self.noise_sigma), 1.0)
        dist = np.zeros(0)
        for k, L in enumerate(lengths):
            if k:
                x = resample_rows(x, L)
            keys = self.keys_[k]
            if keys.shape[0] == 0:  # pragma: no cover - the longest clip always has patches
                raise ValueError(f"genmm: no database patch at level {k}")
            # the context at this level: frames whose full-rate position lies within the start
            pos = np.linspace(0.0, T - 1.0, L)
            fixed = pos <= c - 1 + 1e-9
            ctx_rows = self._context_rows(ctx, pos[fixed])
            x[fixed] = ctx_rows
            for _ in range(int(self.n_steps)):
                nn, dist = match_patches(extract_patches(x, P), keys, float(self.alpha), self.key_norms_[k])
                x = vote(keys[nn], P, L)
                x[fixed] = ctx_rows
        values = self._decode(x[c:], np.asarray(start.values, float)[-1])
        return self._motion(values, length, [], np.full((length, 2), -1),
                            match_distance=float(dist.mean()) if dist.size else float("nan"),
                            levels=np.asarray(lengths, np.int64))

    @staticmethod
    def _context_rows(ctx: np.ndarray, pos: np.ndarray) -> np.ndarray:
        i0 = np.clip(np.floor(pos).astype(np.int64), 0, ctx.shape[0] - 1)
        i1 = np.minimum(i0 + 1, ctx.shape[0] - 1)
        f = (pos - i0)[:, None]
        return ctx[i0] * (1.0 - f) + ctx[i1] * f


def make_genmm(cfg: dict | None = None, name: str | None = None, **override) -> GenMM:
    """An unfitted :class:`GenMM` from a config block (its keys are the parameters; ``None``: the paper's
    defaults); keyword arguments override the block (e.g. ``alpha=float("inf")``, ``root="world"``) and ``name``
    sets the generator's name (the row)."""
    kw = dict(cfg or {})
    kw.update(override)
    gen = GenMM(**kw)
    if name is not None:
        gen.name = name
    return gen
