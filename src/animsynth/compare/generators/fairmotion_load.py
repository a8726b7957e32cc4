"""Feeding clips to fairmotion 0.0.4 (:mod:`.fairmotion_peer`): BVH files its loader reads, the upsampling to its
native rate, the loading and graph-construction memos shared by the peer's rows, budgets and leave-one-out
databases within one process, and the copy-on-read clip list its walk needs."""

from __future__ import annotations

import copy
import os
import tempfile

import numpy as np
from scipy.spatial.transform import Rotation

from ...io.bvh import write_bvh
from ...kinematics import dof_values_from_local, local_rotations, root_translation
from ...motion import Motion
from ...skeleton import Skeleton

__all__ = ["upsample"]


def bvh_ready(motion: Motion) -> Motion:
    """The motion on a copy of its skeleton where every joint without DOF has three zero rotation DOF."""
    sk = copy.deepcopy(motion.skeleton)
    sl = motion.skeleton.dof_slices()
    blocks = []
    for i, j in enumerate(sk.joints):
        if not j.dofs and i > 0:
            j.dofs = ["rx", "ry", "rz"]
            blocks.append(np.zeros((motion.n_frames, 3)))
        else:
            blocks.append(np.asarray(motion.values, float)[:, sl[j.name]])
    sk = Skeleton(sk.joints, sk.length_to_m, sk.angle_unit, sk.name, sk.file_angle_unit, dict(sk.roles))
    return Motion(np.hstack(blocks), sk, motion.fps, motion.name)


def upsample(motion: Motion, factor: int) -> Motion:
    """``motion`` at ``factor`` times its frame rate: ``(T - 1) * factor + 1`` frames, every joint's local rotation
    slerped and the root translation interpolated linearly between neighbouring frames (no frame is made
    after the last one). Written here because our Motion stores DOF values, not poses; fairmotion's own
    ``ops.motion.resample`` in 0.0.4 runs ``fps * frames`` seconds (the same rate-for-period slip as its blend)."""
    k = int(factor)
    if k < 1:
        raise ValueError(f"upsampling factor must be a whole number >= 1, got {factor!r}")
    if k == 1 or motion.n_frames < 2:
        return motion
    sk = motion.skeleton
    T = motion.n_frames
    frac = np.arange(k) / k
    rots = []
    for r in local_rotations(sk, motion.values):
        q = r.as_quat()
        r0, r1 = Rotation.from_quat(q[:-1]), Rotation.from_quat(q[1:])
        step = (r0.inv() * r1).as_rotvec()  # the shortest turn from frame t to t + 1
        parts = [r0 * Rotation.from_rotvec(step * f) for f in frac]
        mats = np.stack([p.as_quat() for p in parts], axis=1).reshape(-1, 4)
        rots.append(Rotation.from_quat(np.vstack([mats, q[-1:]])))
    root = np.asarray(root_translation(sk, motion.values), float)
    t_new = np.arange((T - 1) * k + 1) / k
    root_new = np.stack([np.interp(t_new, np.arange(T), root[:, c]) for c in range(3)], axis=1)
    return Motion(dof_values_from_local(sk, rots, root_new), sk, float(motion.fps) * k, motion.name)


#: fairmotion's loading of a clip (:func:`load_native`), kept for the rest of the process: ``{key: motion}``.
LOADED: dict = {}
LOADED_MAX = 64


def native_key(clip: Motion, up: int, on=None) -> str:
    """The key of :func:`load_native`'s memo: the clip's values, rate and skeleton, ``up`` and the skeleton
    it is put on."""
    import hashlib

    h = hashlib.sha256()
    parts = [np.ascontiguousarray(clip.values, np.float64).tobytes(), repr(float(clip.fps)).encode(),
             str(int(up)).encode(), clip.skeleton.to_json().encode(), repr(clip.skeleton.length_to_m).encode()]
    put_on = clip if on is None else on[0]  # the skeleton the velocities are computed on (a first clip: its own)
    parts += [put_on.skeleton.to_json().encode(), repr(put_on.skeleton.length_to_m).encode()]
    for part in parts:
        h.update(part)
        h.update(b"\0")
    return h.hexdigest()


#: fairmotion's constructed graph of a database (:meth:`FairmotionGraph.fit`), kept for the rest of the
#: process: ``{key: (nodes, edges)}``, the nodes' attributes and the ``(u, v, weights)`` edges in the order
#: ``construct`` added them.
CONSTRUCTED: dict = {}
CONSTRUCTED_MAX = 64


def load_native(clip: Motion, up: int, bvh, velocity, on=None, key: str | None = None):
    """fairmotion's ``MotionWithVelocity`` of ``clip`` at ``up`` times its rate: the clip upsampled
    (:func:`upsample`), written to BVH, read by fairmotion's loader, put on the skeleton ``on`` and given
    fairmotion's velocities (``MotionWithVelocity.from_motion``), as :meth:`FairmotionGraph.fit` needs it.

    ``on``: ``(first clip, its fairmotion Skeleton)`` of the database, whose skeleton every clip is put on
    before its velocities (fairmotion's ``set_skeleton``); ``None`` for the first clip itself.

    Remembered for the rest of the process, keyed on the clip's values, rate and skeleton and the skeleton
    it is put on (the first clip's, equal in a database of one subject), and handed out as a deep copy: the
    leave-one-out databases of a subset share their trials (each trial is in three of the four databases), so
    fairmotion's loading and velocities (most of a graph's build) run once per trial and job, not once per
    database. The copy is what fairmotion would have computed again: the same file, read and differentiated by
    the same code (a test checks the graph and the walks equal those of a fresh load)."""
    key = native_key(clip, up, on) if key is None else key  # the caller's, when it has hashed the clip already
    if key not in LOADED:
        with tempfile.TemporaryDirectory(prefix="animsynth_fairmotion_") as tmp:
            f = os.path.join(tmp, "clip.bvh")
            write_bvh(f, bvh_ready(upsample(clip, up)), scale=clip.skeleton.length_to_m)
            m = bvh.load(f)
        skel = m.skel if on is None else on[1]
        for j in skel.joints:
            if not hasattr(j, "child_joint"):
                j.child_joint = j.child_joints  # the attribute 0.0.4's Skeleton.num_end_effectors reads
        m.set_skeleton(skel)
        if len(LOADED) >= LOADED_MAX:
            LOADED.pop(next(iter(LOADED)))
        LOADED[key] = velocity.MotionWithVelocity.from_motion(m)
    return copy.deepcopy(LOADED[key])


class CopyOnRead:
    """The loaded clips as one walk sees them (``MotionGraph.motions`` during :meth:`FairmotionGraph.generate`):
    clip ``i`` is deep-copied from ``motions`` the first time the walk reads it, every copy with one shared memo,
    so the clips a walk reads are exactly what ``copy.deepcopy(motions)`` makes of them (objects the clips share,
    their skeleton, copied once and shared). 0.0.4's walk moves the poses it appends in place, hence a copy per
    walk; a walk reads a few of the database's clips, hence copies on first read (a whole deep copy was a tenth
    of a walk's CPU)."""

    def __init__(self, motions):
        self._src = list(motions)
        self._copies: dict = {}
        self._memo: dict = {}

    def __len__(self) -> int:
        return len(self._src)

    def _index(self, i) -> int:
        i = int(i)
        if not -len(self._src) <= i < len(self._src):
            raise IndexError(f"clip index {i} out of range for {len(self._src)} clips")
        return i % len(self._src)

    def __getitem__(self, i):
        i = self._index(i)
        if i not in self._copies:
            self._copies[i] = copy.deepcopy(self._src[i], self._memo)
        return self._copies[i]

    def __setitem__(self, i, motion) -> None:
        self._copies[self._index(i)] = motion

    def __iter__(self):
        return (self[i] for i in range(len(self._src)))


def run_serially(func, iterable, num_cpus=1, **kwargs):
    """fairmotion's ``utils.run_parallel`` for one worker, in this process: ``[func(x, **kwargs) for x in
    iterable]``. Its own runs ``Pool(1).map``, which pickles the clips to a worker process once per chunk; the
    functions it maps (``create_nodes``, ``compare_and_connect_edge``) only read the clips, so the results are
    the same (a test compares the graphs)."""
    return [func(x, **kwargs) for x in iterable]


def fairmotion_input(clips: list, native_clips, native: float, up: int) -> tuple[list, int]:
    """``(src, k)``: what is written for fairmotion and the factor it is upsampled by: the native-rate clips from
    the source as they are (``k = 1``) when given and the rates differ, else the working clips (``k = up``)."""
    if native_clips is None or up <= 1:
        return clips, up
    src = list(native_clips)
    if len(src) != len(clips):
        raise ValueError(f"fairmotion graph: {len(src)} native-rate clips for {len(clips)} database clips")
    first = clips[0]
    for c, n in zip(clips, src):
        if (not np.isclose(n.fps, native) or n.skeleton.columns() != first.skeleton.columns()
                or n.n_frames < (c.n_frames - 1) * up + 1):
            raise ValueError(f"fairmotion graph: native clip {n.name!r} is not clip {c.name!r} at {native:g} fps "
                             f"(its rate {n.fps:g}, {n.n_frames} frames, need >= {(c.n_frames - 1) * up + 1})")
    return src, 1


def load_clips(clips: list, src: list, load_up: int, native: float, bvh, velocity) -> tuple[list, list]:
    """``(keys, motions)``: each clip's memo key (hashed once: the loading memo's and, together, the construction
    memo's) and the clips ``src`` loaded by fairmotion (upsampled by ``load_up``) on the first one's skeleton."""
    keys = [native_key(c, load_up, None if i == 0 else (src[0], None)) for i, c in enumerate(src)]
    loaded = [load_native(src[0], load_up, bvh, velocity, key=keys[0])]
    loaded += [load_native(c, load_up, bvh, velocity, on=(src[0], loaded[0].skel), key=k)
               for c, k in zip(src[1:], keys[1:])]
    for c, m in zip(clips, loaded):
        if not np.isclose(m.fps, native):
            raise ValueError(f"fairmotion read clip {c.name!r} at {m.fps} fps, not {native:g} (its BVH loader "
                             "rounds the frame rate to an integer)")
    for m in loaded:
        m.set_skeleton(loaded[0].skel)
    return keys, loaded
