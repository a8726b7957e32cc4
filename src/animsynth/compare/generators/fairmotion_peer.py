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
  playing on). With a transition budget (``transitions_per_s``, :func:`animsynth.compare.generators.motiongraph.budget_count`)
  the threshold is the difference of the budget's last kept pair instead: the same rule as our motion graph's.
  Since that graph does not depend on the threshold, it is built once per database and process and reused
  (the nodes and weighted edges in ``construct``'s order): both rows and every budget of the sweep run in one
  workflow job (``compare_run_fairmotion``) and pay fairmotion's loading and construction once.

The output is observed, not altered, apart from the named fixes: while ``create_random_motion`` runs, fairmotion's
``ops.motion.append_and_blend`` is wrapped by a recorder that calls it unchanged and notes where each
appended piece starts (the seams and source frames of the output). The whole output is then placed at the
start context by the same floor transform as our graph's (a rigid move, which no metric but the distance to
a ground truth sees).

Its native rate
---------------
fairmotion's walk assumes 60 fps (its output motion is built at its default 60 fps whatever the data's rate).
The peer is therefore fed its native rate, ``native_fps`` = 60 (default; a whole multiple ``k`` of the working
rate). In the comparison the clips carry the database and the start at that rate taken by frame step from the
source trials (CMU's 120 fps: every second frame; :class:`animsynth.compare.protocol.NativeRate`), and the runner
passes them (``fit(database, native_clips=...)``, ``generate(..., native_start=...)``; its ``native_fps``, the
interface's declared native rate, says at which rate it reads them): fairmotion builds its graph and walks on the captured 60 fps
frames, and the start node is chosen by the 60 fps start. Without them (a source rate that is not a whole multiple
of 60, or a caller that has only the working-rate clips) every database clip is upsampled from the working rate by
``k`` before it is written to BVH (:func:`.fairmotion_load.upsample`: joint rotations slerped, the root translation interpolated
linearly between neighbouring frames). Either way lengths stay in seconds and the walk's output is taken back to
the working rate by keeping every ``k``-th frame (native frame ``i * k`` is working frame ``i``).
``native_fps=None`` feeds the working rate unchanged.

Defects of the release, and the fixes (``fixes``)
-------------------------------------------------
Four defects of 0.0.4's walk were changed upstream after the release (never released). The peer runs as
released (``fixes=()``, the row ``fairmotion``) and with each fix applied as a small patch of the walk
(``fixes=FIXES``, the row ``fairmotion_fixed``; :mod:`animsynth.compare.generators.fairmotion_fixes` names and describes them).

Released (the row ``fairmotion``), ``cut`` shares the poses and a walk displaces poses that later pieces of the
same walk reuse. Between walks we step in for both rows: every :meth:`FairmotionGraph.generate` walks a fresh
copy of the loaded clips, so walks are reproducible and do not depend on each other.

Random choices: fairmotion's walk draws from Python's global ``random`` module; :meth:`FairmotionGraph.generate`
seeds it with ``seed`` and restores its previous state afterwards.
"""

from __future__ import annotations

import contextlib
import copy
import io
import logging
import random

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from ...generator import Database, Generator, check_generated
from ...kinematics import dof_values_from_local
from ...motion import Motion
from ...kinematics import yaw_rotation
from .fairmotion_fixes import check_fixes, walk_patches
from .fairmotion_load import CONSTRUCTED, CONSTRUCTED_MAX, CopyOnRead, fairmotion_input, load_clips, run_serially
from .motiongraph import budget_keep
from .point_clouds import apply_floor_transform, pair_terms, positions_m, transform_from_terms, window_clouds

__all__ = ["FairmotionGraph", "FairmotionUnavailable", "INSTALL_COMMAND", "FAIRMOTION_VERSION", "NATIVE_FPS"]

#: The fairmotion release this peer is written for (the only one on the package index).
FAIRMOTION_VERSION = "0.0.4"
#: How to install it (and the two small libraries its motion-graph module imports) without its requirements.
INSTALL_COMMAND = "pip install --no-deps fairmotion==0.0.4 networkx==3.6.1 tqdm==4.70.1"

#: The frame rate fairmotion's walk assumes (its Motion's default).
NATIVE_FPS = 60.0

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


class FairmotionGraph(Generator):
    """fairmotion 0.0.4's motion graph behind the compare generator interface (see the module docstring).

    ``native_fps`` (the interface's declared native rate, :class:`animsynth.generator.Generator`): :meth:`fit` and
    :meth:`generate` read the database and the start at that rate (``native_clips``, ``native_start``), which the
    compare runner passes when the clips carry them (``None``: the working-rate clips upsampled).

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
    transitions_per_s : float or None
        The transition budget (:func:`animsynth.compare.generators.motiongraph.budget_count`): keep the node pairs of
        smallest difference, ``transitions_per_s`` per second of database; overrides both thresholds.
    native_fps : float or None
        The rate the walk runs at (fairmotion's native 60 fps; an integer multiple of the database's rate);
        ``None``: the database's rate.
    fixes : sequence of str
        Which of :data:`animsynth.compare.generators.fairmotion_fixes.FIXES` to apply to the walk (``()``: as released).
        They change the walk, not the graph: read at every :meth:`generate`.
    w_joint_pos, w_joint_vel, w_root_pos, w_root_vel, w_ee_pos, w_ee_vel, w_trajectory : float
        fairmotion's similarity weights.
    num_comparison : int
        fairmotion's comparisons per node pair.
    pool : bool
        Run ``construct`` as released: its node comparisons in a ``multiprocessing`` pool of one worker process,
        to which the clips are pickled once per chunk (what a user of fairmotion runs; the build benchmark).
        ``False`` (default): the same functions mapped in this process (:func:`run_serially`); the graph is
        the same (tested), without the pickling and the worker.

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
    skeleton_, fps_ : the output skeleton (the first clip's) and frame rate (the database's).
    native_fps_ : float
        The rate fairmotion ran at; ``upsample_`` = native_fps_ / fps_.
    fixes_ : tuple of str
    n_below_threshold_ : int
        Node pairs that are not a clip playing on kept at the threshold (before the reduction).
    db_ : Database, the clips at the working rate (:class:`animsynth.generator.Database`)
    native_db_ : Database or None, the native-rate clips fairmotion was given (``native_clips``); ``None`` when it
        was given the working clips upsampled
    construct_reused_ : bool
        Whether ``construct`` ran in this fit or its graph came from the process's memo (an earlier fit on the
        same clips with the same lengths, weights and comparison count: the other row, another budget).
    native_input_ : str
        ``"source"`` (fitted on the native-rate clips given) or ``"upsampled"`` (the working-rate clips upsampled;
        also when native_fps_ equals the database's rate).
    last_walk_ : dict
        Of the last :meth:`generate`: ``out_fps`` (the rate of fairmotion's output motion), ``pieces``
        (first output frame, frames of each appended piece, at that rate), ``blend_sources`` (root position of
        every source pose a blend drew, in order).
    """

    name = "fairmotion"

    def __init__(self, base: int = 15, stride: int | None = None, blend: int = 10, compare: int = 10,
                 threshold: float | None = None, threshold_quantile: float = 0.5, w_joint_pos: float = 8.0,
                 w_joint_vel: float = 2.0, w_root_pos: float = 0.5, w_root_vel: float = 1.5, w_ee_pos: float = 3.0,
                 w_ee_vel: float = 1.0, w_trajectory: float = 1.0, num_comparison: int = 3,
                 transitions_per_s: float | None = None, native_fps: float | None = NATIVE_FPS, fixes=(),
                 pool: bool = False):
        self.transitions_per_s = transitions_per_s
        self.pool = pool
        self.native_fps = native_fps
        self.fixes = fixes
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

    def warm_up(self) -> None:
        """Import fairmotion's motion-graph module and what it imports (:func:`_fairmotion`) before a timed build
        (:meth:`animsynth.generator.Generator.warm_up`): the package's import is not its build."""
        _fairmotion()

    def _seconds(self, frames: int, fps: float) -> float:
        """``frames / fps`` nudged so that fairmotion's ``int(seconds * fps)`` gives ``frames`` back."""
        s = frames / fps
        while int(s * fps) < frames:
            s = np.nextafter(s, np.inf)
        return float(s)

    def fit(self, database, native_clips=None) -> "FairmotionGraph":
        """Write the clips to BVH, load them with fairmotion and build and reduce its graph.

        Parameters
        ----------
        database : list of Motion, the clips at the working rate (one skeleton and rate)
        native_clips : list of Motion, optional
            The same clips at ``native_fps`` from the source (frame ``i * k`` of each the working clip's frame
            ``i``, ``k = native_fps / rate``), fed to fairmotion instead of the working clips upsampled.
        """
        found, bvh, velocity, _, motion_graph = _fairmotion()
        stride = self._check_lengths()
        clips = list(database)
        if not clips:
            raise ValueError("fairmotion graph: the database is empty")
        first = clips[0]
        for c in clips:
            if c.skeleton.columns() != first.skeleton.columns() or not np.isclose(c.fps, first.fps):
                raise ValueError(f"fairmotion graph: clip {c.name!r} differs from {first.name!r} in DOF columns or "
                                 "frame rate")
        db = Database(clips)
        fixes = self._fixes()
        fps = float(first.fps)
        native, up = self._native_rate(fps)
        src, load_up = fairmotion_input(clips, native_clips, native, up)
        native_db = Database(src) if src is not clips else None  # the clips fairmotion is given, when not upsampled
        keys, motions = load_clips(clips, src, load_up, native, bvh, velocity)
        skel = motions[0].skel
        files = [f"clip{i:03d}.bvh" for i in range(len(clips))]  # names only: fairmotion keeps them, never reads them
        graph = motion_graph.MotionGraph(
            motions=motions, motion_files=files, skel=skel, fps=native,
            base_length=self._seconds(self.base * up, native), stride_length=self._seconds(stride * up, native),
            blend_length=self._seconds(self.blend * up, native), compare_length=self._seconds(self.compare * up, native),
            verbose=False)
        self._construct(graph, motion_graph, skel, keys, native)
        self._reduce(graph, sum(c.n_frames for c in clips) / fps, up)
        self._graph_ = graph
        self._loaded_ = copy.deepcopy(graph.motions)
        self._names_ = [j.name for j in skel.joints]
        self._pos_ = [positions_m(c) for c in clips]
        self._native_pos_ = [positions_m(c) for c in src] if src is not clips else None
        self.native_input_ = "source" if src is not clips else "upsampled"
        self.fairmotion_version_ = found
        self.skeleton_ = first.skeleton
        self.fps_ = fps
        self.native_fps_ = native
        self.upsample_ = up
        self.fixes_ = fixes
        self.db_, self.native_db_ = db, native_db
        return self

    def _check_lengths(self) -> int:
        """The stride in frames, once the node, stride, blend and comparison lengths and the threshold quantile
        are checked."""
        stride = self.base if self.stride is None else self.stride
        if not (self.base >= stride >= 1 and self.base > self.blend >= 1 and self.compare >= self.blend):
            raise ValueError(f"fairmotion needs base >= stride >= 1, base > blend >= 1 and compare >= blend "
                             f"(frames), got base={self.base}, stride={stride}, blend={self.blend}, "
                             f"compare={self.compare}")
        if not 0.0 < float(self.threshold_quantile) <= 1.0:
            raise ValueError(f"threshold_quantile must be in (0, 1], got {self.threshold_quantile!r}")
        return stride

    def _native_rate(self, fps: float) -> tuple[float, int]:
        """``(native, k)``: the rate fairmotion runs at and its whole multiple ``k`` of the database's ``fps``."""
        native = fps if self.native_fps is None else float(self.native_fps)
        up = native / fps
        if abs(up - round(up)) > 1e-9 or round(up) < 1:
            raise ValueError(f"fairmotion native_fps {native:g} must be a whole multiple of the database's "
                             f"{fps:g} fps")
        return native, int(round(up))

    def _construct(self, graph, motion_graph, skel, keys: list, native: float) -> None:
        """fairmotion's graph construction at an infinite threshold (every node pair's distance), or the one this
        process built already for the same clips, lengths, weights and comparison count (``construct_reused_``)."""
        weights = dict(w_joint_pos=self.w_joint_pos, w_joint_vel=self.w_joint_vel, w_root_pos=self.w_root_pos,
                       w_root_vel=self.w_root_vel, w_ee_pos=self.w_ee_pos, w_ee_vel=self.w_ee_vel,
                       w_trajectory=self.w_trajectory)
        # the graph at an infinite threshold depends on the loaded clips, the lengths, the weights and the comparison
        # count, not on the threshold, the budget or the walk's fixes: both rows and every budget of the sweep build
        # it once per process (the edges kept are then chosen per threshold below)
        key = repr((keys, native, graph.base_length, graph.stride_length, graph.blend_length, graph.compare_length,
                    sorted(weights.items()), int(self.num_comparison)))
        if key in CONSTRUCTED:
            node_list, edge_list = CONSTRUCTED[key]
            graph.skel = skel
            graph.graph.add_nodes_from(node_list)
            graph.graph.add_edges_from((u, v, {"weights": w}) for u, v, w in edge_list)
            for name, value in dict(w_joints=None, **weights).items():
                setattr(graph, name, value)
            self.construct_reused_ = True
            return
        parallel = motion_graph.utils.run_parallel
        if not self.pool:
            motion_graph.utils.run_parallel = run_serially  # one worker: no Pool, no pickled clips (same graph)
        try:
            with contextlib.redirect_stderr(io.StringIO()):  # its tqdm progress bars
                graph.construct(w_joints=None, **weights, diff_threshold=np.inf,
                                num_comparison=self.num_comparison, num_workers=1)
        finally:
            motion_graph.utils.run_parallel = parallel
        if len(CONSTRUCTED) >= CONSTRUCTED_MAX:
            CONSTRUCTED.pop(next(iter(CONSTRUCTED)))
        CONSTRUCTED[key] = ([(n, dict(a)) for n, a in graph.graph.nodes(data=True)],
                             [(u, v, d["weights"]) for u, v, d in graph.graph.edges(data=True)])
        self.construct_reused_ = False

    def _reduce(self, graph, seconds: float, up: int) -> None:
        """Keep the transitions under the threshold (or the budget over ``seconds`` of database), then the largest
        strongly connected component; sets ``threshold_``, ``n_below_threshold_``, ``n_nodes_``,
        ``largest_scc_share_`` and ``transitions_`` (frames at the database's rate: ``up`` native frames each)."""
        nodes = graph.graph.nodes
        n_before = graph.graph.number_of_nodes()
        if n_before == 0:
            raise ValueError(f"fairmotion graph: no clip is longer than base + compare = {self.base + self.compare} "
                             "frames")
        edges = [(u, v, d["weights"]) for u, v, d in graph.graph.edges(data=True)]

        def plays_on(u, v):
            return (nodes[u]["motion_idx"] == nodes[v]["motion_idx"]
                    and nodes[u]["frame_end"] == nodes[v]["frame_start"])

        jump_edges = [(u, v, w) for u, v, w in edges if not plays_on(u, v)]
        jumps = np.array([w for _u, _v, w in jump_edges], float)
        if jumps.size == 0:
            raise ValueError("fairmotion graph: no pair of nodes to connect")
        if self.transitions_per_s is not None:
            keep = budget_keep(jumps, float(self.transitions_per_s), seconds)
            self.threshold_ = float(jumps[keep].max())
            graph.graph.remove_edges_from([(u, v) for (u, v, _w), k in zip(jump_edges, keep) if not k])
        else:
            self.threshold_ = (float(self.threshold) if self.threshold is not None
                               else float(np.quantile(jumps, float(self.threshold_quantile))))
            graph.graph.remove_edges_from([(u, v) for u, v, w in edges if w > self.threshold_])
        self.n_below_threshold_ = int(graph.graph.number_of_edges() - (len(edges) - jumps.size))
        graph.reduce(method="scc")
        self.n_nodes_ = graph.graph.number_of_nodes()
        if graph.graph.number_of_edges() == 0:
            raise ValueError(f"fairmotion graph: its largest strongly connected component at threshold "
                             f"{self.threshold_:.4g} has no edge: raise the threshold or add clips")
        self.largest_scc_share_ = self.n_nodes_ / n_before
        rows = [(nodes[u]["motion_idx"], nodes[u]["frame_end"] // up, nodes[v]["motion_idx"],
                 nodes[v]["frame_start"] // up, d["weights"])
                for u, v, d in graph.graph.edges(data=True) if not plays_on(u, v)]
        self.transitions_ = pd.DataFrame(rows, columns=["from_clip", "from_frame", "to_clip", "to_frame", "distance"])

    def run_notes(self) -> dict:
        """``transitions_kept``: the node pairs kept at the threshold (``n_below_threshold_``, before the
        reduction)."""
        return {"transitions_kept": float(self.n_below_threshold_)}

    def _start(self, start: Motion, native_start: Motion | None = None):
        """The reduced graph's node whose preceding frames are nearest the end of ``start``, and its placement;
        with ``native_start`` (and native-rate clips fitted), compared at the native rate: its last ``blend * k``
        frames against the native frames before each node."""
        if not np.isclose(start.fps, self.fps_):
            raise ValueError(f"start {start.name!r} is at {start.fps:g} fps, the database at {self.fps_:g} fps")
        up = self.upsample_
        pos, div = self._pos_, up
        if native_start is not None and self._native_pos_ is not None:
            if not np.isclose(native_start.fps, self.native_fps_) or native_start.columns != start.columns:
                raise ValueError(f"native start {native_start.name!r} is at {native_start.fps:g} fps, not "
                                 f"{self.native_fps_:g}, or on other DOF columns")
            start, pos, div = native_start, self._native_pos_, 1
        q = positions_m(start)
        m = min(self.blend * (up // div), start.n_frames)
        nodes = self._graph_.graph.nodes
        ids = [n for n in nodes if nodes[n]["frame_start"] // div >= m] or list(nodes)
        clouds = []
        for n in ids:
            c, f = int(nodes[n]["motion_idx"]), int(nodes[n]["frame_start"]) // div
            lo = max(f - m, 0)
            clouds.append(pos[c][lo:lo + m])
        w = np.full(m * q.shape[1], 1.0 / (m * q.shape[1]))
        d2, a, b, cp, cq = pair_terms(window_clouds(q[-m:], m), np.stack(clouds).reshape(len(ids), -1, 3), w)
        best = int(np.argmin(d2[0]))
        place = transform_from_terms(a[0, best], b[0, best], (cp[0][0], cp[1][0]), (cq[0][best], cq[1][best]))
        return ids[best], tuple(float(x) for x in place)

    def _fixes(self) -> tuple:
        return check_fixes(self.fixes)

    def generate(self, start: Motion, length: int, seed: int, native_start: Motion | None = None) -> Motion:
        """fairmotion's ``create_random_motion`` from the node nearest the end of ``start``, ``length`` frames.

        ``native_start``: the start at ``native_fps_`` (its last frame the start's last), which chooses the start
        node at the native rate when the graph was fitted on native-rate clips (ignored otherwise).

        The walk runs at ``native_fps_`` (``(length - 1) x upsample_ + 1`` frames) with the fixes of
        ``fixes_`` patched in for its duration; its output is taken back to the database's rate by keeping
        every ``upsample_``-th frame.

        Returns
        -------
        Motion (length, n_dof) on ``skeleton_`` at ``fps_``; ``meta``: ``seams`` (output frames where an
        appended piece starts: the first output frame at or after it), ``source_frames`` ((length, 2): clip and
        frame, -1 for blended frames), ``start_node`` (clip, frame), ``fairmotion_version``, ``fixes``.
        """
        self._check_start(start, length)
        if native_start is not None and self.native_db_ is not None:
            self._check_start(native_start, length, self.native_db_)  # the start fairmotion is given
        if isinstance(length, bool) or not isinstance(length, (int, np.integer)) or length < 1:
            raise ValueError(f"length must be an integer >= 1 (frames), got {length!r}")
        length = int(length)
        node, place = self._start(start, native_start)
        up = self.upsample_
        n_native = (length - 1) * up + 1
        nodes = self._graph_.graph.nodes
        self.fixes_ = self._fixes()  # the fixes act on the walk only: read at every walk (one graph for both rows)
        out, visited, pieces, blend_sources = self._walk(node, seed, n_native)
        src, seams = self._source_frames(out, visited, pieces, length)
        values = self._walk_values(out, length, place)
        self.last_walk_ = {"out_fps": float(out.fps), "pieces": [(int(a), int(b)) for a, b, _bl in pieces],
                           "blend_sources": np.array(blend_sources).reshape(-1, 3)}
        meta = {"seams": seams, "source_frames": src, "generator": "fairmotion",
                "start_node": (int(nodes[node]["motion_idx"]), int(nodes[node]["frame_start"]) // up),
                "fairmotion_version": self.fairmotion_version_, "fixes": self.fixes_}
        return check_generated(Motion(values, self.skeleton_, self.fps_, f"fairmotion_walk_seed{seed}", meta), length,
                               self.db_.skeleton, self.name)

    def _walk(self, node, seed: int, n_native: int):
        """fairmotion's ``create_random_motion`` from ``node`` for ``n_native`` frames at the native rate, with the
        fixes of ``fixes_`` patched in and Python's ``random`` seeded by ``seed`` (both restored afterwards):
        ``(out, visited, pieces, blend_sources)`` (the appended pieces and blends, :func:`walk_patches`)."""
        _, _, velocity, motion_ops, _ = _fairmotion()
        graph = self._graph_
        blend_sources = []
        pieces, swap = walk_patches(motion_ops, self.fixes_, blend_sources)
        saved = {name: getattr(motion_ops, name) for name in swap}
        state = random.getstate()
        for name, f in swap.items():
            setattr(motion_ops, name, f)
        try:
            # the walk stops once its output, at the output's frame rate (0.0.4: its default 60 fps whatever
            # the data's), lasts the requested seconds: ask for the frames at that rate, then, if the output is
            # built at the walk's rate (the output_rate fix, or a later release), at that rate
            for rate in dict.fromkeys((float(velocity.MotionWithVelocity().fps), self.native_fps_)):
                graph.motions = CopyOnRead(self._loaded_)  # 0.0.4's walk moves the poses it appends in place
                pieces.clear()
                blend_sources.clear()
                random.seed(seed)
                out, visited = graph.create_random_motion(length=n_native / rate, start_node=node)
                if out.num_frames() >= n_native:
                    break
        finally:
            for name, f in saved.items():
                setattr(motion_ops, name, f)
            random.setstate(state)
            graph.motions = self._loaded_
        if out.num_frames() < n_native:
            raise ValueError(f"fairmotion's walk stopped after {out.num_frames()} of {n_native} frames at "
                             f"{self.native_fps_:g} fps (a dead end)")
        return out, visited, pieces, blend_sources

    def _source_frames(self, out, visited, pieces, length: int):
        """``(source_frames, seams)`` of a walk's output at the database's rate: the clip and frame each output
        frame plays ((length, 2), -1 for blended frames) and the output frames where a blended piece starts."""
        up, nodes, n_out = self.upsample_, self._graph_.graph.nodes, out.num_frames()
        n_blend, t = 0, 0.0  # the frames append_and_blend blends: its running time, summed as it sums it
        while True:
            t += 1 / self.native_fps_
            if t > self._graph_.blend_length:
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
        src = src[np.arange(length) * up]  # back to the database's rate
        src[:, 1] = np.where(src[:, 1] >= 0, src[:, 1] // up, -1)
        src[src[:, 1] < 0] = -1
        seams = np.unique([-(-s // up) for s in seams]).astype(int)
        return src, seams[(seams > 0) & (seams < length)]

    def _walk_values(self, out, length: int, place) -> np.ndarray:
        """The DOF values ``(length, n_dof)`` of a walk's output at the database's rate, its root placed on the
        start (``place``: yaw and ground offset of :meth:`_start`)."""
        mats = np.array([np.asarray(out.poses[i].data, float) for i in np.arange(length) * self.upsample_])
        idx = {name: i for i, name in enumerate(self._names_)}  # mats: (length, joints, 4, 4), local
        rots = []
        for j in self.skeleton_.joints:
            rots.append(Rotation.from_matrix(mats[:, idx[j.name], :3, :3]) if j.name in idx
                        else Rotation.identity(length))
        scale = self.skeleton_.length_to_m
        root = mats[:, idx[self.skeleton_.joints[0].name], :3, 3]  # metres (BVH written in metres)
        theta, x0, z0 = place
        rots[0] = yaw_rotation(theta)[0] * rots[0]
        root = apply_floor_transform(root[:, None, :], theta, x0, z0)[:, 0] / scale
        return dof_values_from_local(self.skeleton_, rots, root)
