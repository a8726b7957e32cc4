"""The public peer: fairmotion's motion graph (``fairmotion.tasks.motion_graph``, BSD licence) on our clips.

What is installed and why
-------------------------
fairmotion's only release on the Python package index is 0.0.4 (August 2020). Its declared requirements
(torch 1.4.0, pyrender, PyOpenGL 3.1.0, human_body_prior, ...) cannot be installed on Python 3.11, but its
motion-graph module needs none of them: it imports numpy, scipy, matplotlib (all in the project's stack),
networkx and tqdm. So it installs reproducibly without its requirements::

    pip install --no-deps fairmotion==0.0.4 networkx==3.6.1 tqdm==4.70.1

(:data:`INSTALL_COMMAND`; networkx 3.6.1 is the newest networkx for Python 3.11).

How it is run
-------------
Our clips are written to BVH with :func:`animsynth.io.bvh.write_bvh` in metres (fairmotion's similarity
constants assume metres), read with fairmotion's own BVH loader, wrapped in its ``MotionWithVelocity`` and
given to its ``MotionGraph`` (``construct``, ``reduce("scc")``, ``create_random_motion``), as its
``tasks/motion_graph/main.py`` does. Three adaptations, none of which changes what fairmotion computes:

* A joint without degrees of freedom (the CMU hip joints) is written with three rotation channels of value
  0 (the identity): fairmotion's loader accepts 1, 3 or 6 channels per joint and refuses ``CHANNELS 0``.
* 0.0.4's ``Skeleton.num_end_effectors`` reads ``joint.child_joint``, an attribute fairmotion's joints do
  not have (it was renamed ``child_joints``; fixed upstream on 2020-10-23, after the release, never
  released), so every graph construction stops with an AttributeError. Every loaded joint gets a
  ``child_joint`` attribute that is the same list object as its ``child_joints`` (data only; no fairmotion
  code is replaced).
* The threshold: ``construct`` is called with an infinite ``diff_threshold`` (every pair of nodes becomes
  an edge with its difference), then the edges above the resolved threshold are removed, which is what
  ``construct(diff_threshold=threshold)`` would have kept. As for our graph, ``threshold=None`` resolves it
  as the ``threshold_quantile`` quantile of the differences (here of the node pairs that are not one clip
  playing on).

The output is observed, not altered: while ``create_random_motion`` runs, fairmotion's
``ops.motion.append_and_blend`` is wrapped by a recorder that calls it unchanged and notes where each
appended piece starts (the seams and source frames of the output). The whole output is then placed at the
start context by the same floor transform as our graph's (a rigid move, which no metric but the distance to
a ground truth sees).

Known defects of 0.0.4 that are left as released (the peer row measures what a user installs): its
``create_random_motion`` builds the output at fairmotion's default 60 fps whatever the data's rate, so the
cut before each appended piece is placed at the wrong frame, and ``append_and_blend`` computes the blend's
source time as ``fps * frame`` instead of ``frame / fps``, so it blends from the last pose of the previous
piece, held still. Together, with the defaults here at 30 fps, every appended piece adds 5 of its 15
frames to the output, all of them blended, and the walk runs through the clips at about 3 times their speed.
Its ``ops.motion.cut`` also shares the Pose objects with the loaded
clips and ``append_and_blend`` moves them in place, so a walk displaces poses that later pieces of the same
walk reuse (a node visited twice, the blend frames shared by consecutive nodes). All of this was changed
upstream after the release. Only between walks do we step in: every :meth:`FairmotionGraph.generate` walks
a fresh copy of the loaded clips, so walks are reproducible and do not depend on each other.

Random choices: fairmotion's walk draws from Python's global ``random`` module; :meth:`FairmotionGraph.generate`
seeds it with ``seed`` and restores its previous state afterwards.
"""

from __future__ import annotations

import contextlib
import copy
import io
import logging
import os
import random
import tempfile

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from ..io.bvh import write_bvh
from ..kinematics import dof_values_from_local
from ..motion import Motion
from ..skeleton import Skeleton
from .motiongraph import _pair_terms, _positions_m, _transform_from_terms, _window_clouds, apply_floor_transform

__all__ = ["FairmotionGraph", "FairmotionUnavailable", "INSTALL_COMMAND", "FAIRMOTION_VERSION"]

#: The fairmotion release this peer is written for (the only one on the package index).
FAIRMOTION_VERSION = "0.0.4"
#: How to install it (and the two small libraries its motion-graph module imports) without its requirements.
INSTALL_COMMAND = "pip install --no-deps fairmotion==0.0.4 networkx==3.6.1 tqdm==4.70.1"

log = logging.getLogger("animsynth.compare")


class FairmotionUnavailable(RuntimeError):
    """fairmotion's motion graph cannot be run here; ``reason`` says why (for the docs and the log)."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


def _fairmotion():
    """Import fairmotion's motion-graph module and what it needs, or raise :class:`FairmotionUnavailable`."""
    root = logging.getLogger()
    handlers, level = list(root.handlers), root.level
    try:
        from importlib.metadata import PackageNotFoundError, version

        try:
            found = version("fairmotion")
        except PackageNotFoundError:
            raise FairmotionUnavailable(f"fairmotion is not installed; install it with: {INSTALL_COMMAND}") from None
        try:
            from fairmotion.core import velocity
            from fairmotion.data import bvh
            from fairmotion.ops import motion as motion_ops
            from fairmotion.tasks.motion_graph import motion_graph
        except ImportError as e:
            raise FairmotionUnavailable(f"fairmotion {found} is installed but its motion graph cannot be imported "
                                        f"({e}); install it with: {INSTALL_COMMAND}") from e
    finally:
        # fairmotion's motion_graph module calls logging.basicConfig at import: undo that on the root logger
        for h in root.handlers[:]:
            if h not in handlers:
                root.removeHandler(h)
        root.setLevel(level)
    if found != FAIRMOTION_VERSION:
        log.warning("fairmotion %s found; this peer was written for %s", found, FAIRMOTION_VERSION)
    return found, bvh, velocity, motion_ops, motion_graph


def _bvh_ready(motion: Motion) -> Motion:
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


class FairmotionGraph:
    """fairmotion 0.0.4's motion graph behind the compare generator interface (see the module docstring).

    Lengths are in frames at the database's rate (converted to fairmotion's seconds). Defaults: nodes of
    ``base`` = 15 frames (0.5 s at 30 fps; fairmotion's own 1.5 s leaves a few nodes on clips of seconds),
    a new node every ``stride`` = ``base`` frames (fairmotion's default), ``blend`` = 10 and ``compare`` =
    10 frames (the span of our graph's windows), the similarity weights of fairmotion's
    ``tasks/motion_graph/main.py``.

    Parameters
    ----------
    base, stride, blend, compare : int
        Frames; fairmotion needs ``base >= stride``, ``base > blend`` and ``compare >= blend``.
    threshold : float or None
        fairmotion's ``diff_threshold`` (its own units); ``None``: the ``threshold_quantile`` quantile of
        the differences between nodes that are not one clip playing on.
    threshold_quantile : float
    w_joint_pos, w_joint_vel, w_root_pos, w_root_vel, w_ee_pos, w_ee_vel, w_trajectory : float
        fairmotion's similarity weights.
    num_comparison : int
        fairmotion's comparisons per node pair.

    Attributes
    ----------
    transitions_ : DataFrame (from_clip, from_frame, to_clip, to_frame, distance): the edges of the reduced
        graph that are not a clip playing on (from = the end frame of a node, to = the start of the next).
    threshold_ : float
    n_nodes_ : int
        Nodes (segments of ``base`` frames) of the reduced graph.
    largest_scc_share_ : float
        ``n_nodes_`` / nodes before the reduction.
    fairmotion_version_ : str
    skeleton_, fps_ : the output skeleton (the first clip's) and frame rate.
    """

    def __init__(self, base: int = 15, stride: int | None = None, blend: int = 10, compare: int = 10,
                 threshold: float | None = None, threshold_quantile: float = 0.5, w_joint_pos: float = 8.0,
                 w_joint_vel: float = 2.0, w_root_pos: float = 0.5, w_root_vel: float = 1.5, w_ee_pos: float = 3.0,
                 w_ee_vel: float = 1.0, w_trajectory: float = 1.0, num_comparison: int = 3):
        self.base = base
        self.stride = stride
        self.blend = blend
        self.compare = compare
        self.threshold = threshold
        self.threshold_quantile = threshold_quantile
        self.w_joint_pos = w_joint_pos
        self.w_joint_vel = w_joint_vel
        self.w_root_pos = w_root_pos
        self.w_root_vel = w_root_vel
        self.w_ee_pos = w_ee_pos
        self.w_ee_vel = w_ee_vel
        self.w_trajectory = w_trajectory
        self.num_comparison = num_comparison

    def _seconds(self, frames: int, fps: float) -> float:
        """``frames / fps`` nudged so that fairmotion's ``int(seconds * fps)`` gives ``frames`` back."""
        s = frames / fps
        while int(s * fps) < frames:
            s = np.nextafter(s, np.inf)
        return float(s)

    def fit(self, database) -> "FairmotionGraph":
        """Write the clips to BVH, load them with fairmotion and build and reduce its graph."""
        found, bvh, velocity, _, motion_graph = _fairmotion()
        stride = self.base if self.stride is None else self.stride
        if not (self.base >= stride >= 1 and self.base > self.blend >= 1 and self.compare >= self.blend):
            raise ValueError(f"fairmotion needs base >= stride >= 1, base > blend >= 1 and compare >= blend "
                             f"(frames), got base={self.base}, stride={stride}, blend={self.blend}, "
                             f"compare={self.compare}")
        if not 0.0 < float(self.threshold_quantile) <= 1.0:
            raise ValueError(f"threshold_quantile must be in (0, 1], got {self.threshold_quantile!r}")
        clips = list(database)
        if not clips:
            raise ValueError("fairmotion graph: the database is empty")
        first = clips[0]
        for c in clips:
            if c.skeleton.columns() != first.skeleton.columns() or not np.isclose(c.fps, first.fps):
                raise ValueError(f"fairmotion graph: clip {c.name!r} differs from {first.name!r} in DOF columns or "
                                 "frame rate")
        fps = float(first.fps)
        with tempfile.TemporaryDirectory(prefix="animsynth_fairmotion_") as tmp:
            files = []
            for i, c in enumerate(clips):
                f = os.path.join(tmp, f"clip{i:03d}.bvh")
                write_bvh(f, _bvh_ready(c), scale=c.skeleton.length_to_m)
                files.append(f)
            loaded = [bvh.load(f) for f in files]
        for c, m in zip(clips, loaded):
            if not np.isclose(m.fps, fps):
                raise ValueError(f"fairmotion read clip {c.name!r} at {m.fps} fps, not {fps:g} (its BVH loader "
                                 "rounds the frame rate to an integer)")
        skel = loaded[0].skel
        for j in skel.joints:
            if not hasattr(j, "child_joint"):
                j.child_joint = j.child_joints  # the attribute 0.0.4's Skeleton.num_end_effectors reads
        motions = []
        for m in loaded:
            m.set_skeleton(skel)
            motions.append(velocity.MotionWithVelocity.from_motion(m))
        graph = motion_graph.MotionGraph(
            motions=motions, motion_files=files, skel=skel, fps=fps, base_length=self._seconds(self.base, fps),
            stride_length=self._seconds(stride, fps), blend_length=self._seconds(self.blend, fps),
            compare_length=self._seconds(self.compare, fps), verbose=False)
        with contextlib.redirect_stderr(io.StringIO()):  # its tqdm progress bars
            graph.construct(w_joints=None, w_joint_pos=self.w_joint_pos, w_joint_vel=self.w_joint_vel,
                            w_root_pos=self.w_root_pos, w_root_vel=self.w_root_vel, w_ee_pos=self.w_ee_pos,
                            w_ee_vel=self.w_ee_vel, w_trajectory=self.w_trajectory, diff_threshold=np.inf,
                            num_comparison=self.num_comparison, num_workers=1)
        nodes = graph.graph.nodes
        n_before = graph.graph.number_of_nodes()
        if n_before == 0:
            raise ValueError(f"fairmotion graph: no clip is longer than base + compare = {self.base + self.compare} "
                             "frames")
        edges = [(u, v, d["weights"]) for u, v, d in graph.graph.edges(data=True)]

        def plays_on(u, v):
            return (nodes[u]["motion_idx"] == nodes[v]["motion_idx"]
                    and nodes[u]["frame_end"] == nodes[v]["frame_start"])

        jumps = np.array([w for u, v, w in edges if not plays_on(u, v)], float)
        if jumps.size == 0:
            raise ValueError("fairmotion graph: no pair of nodes to connect")
        self.threshold_ = (float(self.threshold) if self.threshold is not None
                           else float(np.quantile(jumps, float(self.threshold_quantile))))
        graph.graph.remove_edges_from([(u, v) for u, v, w in edges if w > self.threshold_])
        graph.reduce(method="scc")
        self.n_nodes_ = graph.graph.number_of_nodes()
        if graph.graph.number_of_edges() == 0:
            raise ValueError(f"fairmotion graph: its largest strongly connected component at threshold "
                             f"{self.threshold_:.4g} has no edge: raise the threshold or add clips")
        self.largest_scc_share_ = self.n_nodes_ / n_before
        rows = [(nodes[u]["motion_idx"], nodes[u]["frame_end"], nodes[v]["motion_idx"], nodes[v]["frame_start"],
                 d["weights"]) for u, v, d in graph.graph.edges(data=True) if not plays_on(u, v)]
        self.transitions_ = pd.DataFrame(rows, columns=["from_clip", "from_frame", "to_clip", "to_frame", "distance"])
        self._graph_ = graph
        self._loaded_ = copy.deepcopy(graph.motions)
        self._names_ = [j.name for j in skel.joints]
        self._pos_ = [_positions_m(c) for c in clips]
        self.fairmotion_version_ = found
        self.skeleton_ = first.skeleton
        self.fps_ = fps
        return self

    def _start(self, start: Motion):
        """The reduced graph's node whose preceding frames are nearest the end of ``start``, and its placement."""
        if not hasattr(self, "_graph_"):
            raise RuntimeError("FairmotionGraph is not fitted: call fit(database) first")
        if not isinstance(start, Motion) or start.n_frames < 1:
            raise ValueError("start must be a Motion with at least one frame")
        if not np.isclose(start.fps, self.fps_):
            raise ValueError(f"start {start.name!r} is at {start.fps:g} fps, the database at {self.fps_:g} fps")
        q = _positions_m(start)
        m = min(self.blend, start.n_frames)
        nodes = self._graph_.graph.nodes
        ids = [n for n in nodes if nodes[n]["frame_start"] >= m] or list(nodes)
        clouds = []
        for n in ids:
            c, f = int(nodes[n]["motion_idx"]), int(nodes[n]["frame_start"])
            lo = max(f - m, 0)
            clouds.append(self._pos_[c][lo:lo + m])
        w = np.full(m * q.shape[1], 1.0 / (m * q.shape[1]))
        d2, a, b, cp, cq = _pair_terms(_window_clouds(q[-m:], m), np.stack(clouds).reshape(len(ids), -1, 3), w)
        best = int(np.argmin(d2[0]))
        place = _transform_from_terms(a[0, best], b[0, best], (cp[0][0], cp[1][0]), (cq[0][best], cq[1][best]))
        return ids[best], tuple(float(x) for x in place)

    def generate(self, start: Motion, length: int, seed: int) -> Motion:
        """fairmotion's ``create_random_motion`` from the node nearest the end of ``start``, ``length`` frames.

        Returns
        -------
        Motion (length, n_dof) on ``skeleton_`` at ``fps_``; ``meta``: ``seams`` (output frames where an
        appended piece starts), ``source_frames`` ((length, 2): clip and frame, -1 for blended frames),
        ``start_node`` (clip, frame), ``fairmotion_version``.
        """
        if isinstance(length, bool) or not isinstance(length, (int, np.integer)) or length < 1:
            raise ValueError(f"length must be an integer >= 1 (frames), got {length!r}")
        length = int(length)
        node, place = self._start(start)
        _, _, velocity, motion_ops, _ = _fairmotion()

        def velocity_default_fps() -> float:
            return float(velocity.MotionWithVelocity().fps)

        graph = self._graph_
        nodes = graph.graph.nodes
        pieces = []
        original = motion_ops.append_and_blend

        def recorder(motion1, motion2, blend_length=0):
            out = original(motion1, motion2, blend_length=blend_length)
            pieces.append((out.num_frames() - motion2.num_frames(), motion2.num_frames(), motion1.num_frames() > 0))
            return out

        state = random.getstate()
        motion_ops.append_and_blend = recorder
        try:
            # the walk stops once its output, at the output's frame rate (0.0.4: its default 60 fps whatever
            # the data's), lasts the requested seconds: ask for length frames at that rate, then, if a
            # release builds the output at the data's rate, at the data's rate
            for rate in (velocity_default_fps(), self.fps_):
                graph.motions = copy.deepcopy(self._loaded_)  # 0.0.4's walk moves the poses it appends in place
                pieces.clear()
                random.seed(seed)
                out, visited = graph.create_random_motion(length=length / rate, start_node=node)
                if out.num_frames() >= length:
                    break
        finally:
            motion_ops.append_and_blend = original
            random.setstate(state)
            graph.motions = self._loaded_
        n_out = out.num_frames()
        if n_out < length:
            raise ValueError(f"fairmotion's walk stopped after {n_out} of {length} frames (a dead end)")
        n_blend, t = 0, 0.0  # the frames append_and_blend blends: its running time, summed as it sums it
        while True:
            t += 1 / self.fps_
            if t > graph.blend_length:
                break
            n_blend += 1
        src = np.full((n_out, 2), -1, int)
        seams = []
        for (first, n2, blended), n in zip(pieces, visited):  # one appended piece per visited node, in order
            c, f0 = int(nodes[n]["motion_idx"]), int(nodes[n]["frame_start"])
            stop = min(first + n2, n_out)
            src[first:stop, 0] = c
            src[first:stop, 1] = f0 + np.arange(stop - first)
            if blended:
                src[first:min(first + n_blend, stop)] = -1
                seams.append(first)
        mats = np.array([np.asarray(p.data, float) for p in out.poses[:length]])  # (length, joints, 4, 4), local
        idx = {name: i for i, name in enumerate(self._names_)}
        rots = []
        for j in self.skeleton_.joints:
            rots.append(Rotation.from_matrix(mats[:, idx[j.name], :3, :3]) if j.name in idx
                        else Rotation.identity(length))
        scale = self.skeleton_.length_to_m
        root = mats[:, idx[self.skeleton_.joints[0].name], :3, 3]  # metres (BVH written in metres)
        theta, x0, z0 = place
        rots[0] = Rotation.from_euler("y", theta) * rots[0]
        root = apply_floor_transform(root[:, None, :], theta, x0, z0)[:, 0] / scale
        values = dof_values_from_local(self.skeleton_, rots, root)
        seams = np.asarray([s for s in seams if 0 < s < length], int)
        meta = {"seams": seams, "source_frames": src[:length], "generator": "fairmotion",
                "start_node": (int(nodes[node]["motion_idx"]), int(nodes[node]["frame_start"])),
                "fairmotion_version": self.fairmotion_version_}
        return Motion(values, self.skeleton_, self.fps_, f"fairmotion_walk_seed{seed}", meta)
