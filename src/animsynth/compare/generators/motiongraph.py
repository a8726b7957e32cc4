"""The classic motion graph of Kovar, Gleicher & Pighin ("Motion Graphs", SIGGRAPH 2002), written from the paper.

Why it is written here
----------------------
No maintained library implements Kovar et al.'s graph. The one public motion-graph module, fairmotion's
``tasks/motion_graph`` (the peer row, :mod:`animsynth.compare.generators.fairmotion_peer`), builds a different graph:
fixed-length segments as nodes, a joint-angle and end-effector similarity at the segment boundaries, every
pair below a threshold an edge, no point-cloud alignment and no local-minimum selection. What comes from
libraries here: forward kinematics (:mod:`animsynth.kinematics`), the all-pairs window terms as three matrix
products (numpy / BLAS), local minima (``scipy.ndimage.minimum_filter``), strongly connected components and
Dijkstra (``scipy.sparse.csgraph``), rotations and their interpolation (``scipy.spatial.transform.Rotation``).
Written here, each in a few lines: the paper's closed-form alignment, the graph bookkeeping, the walk and the
transition blend.

The method (the paper's steps)
------------------------------
Candidate transitions. Frame ``i`` of clip A and frame ``j`` of clip B are compared through point clouds
    over windows of ``k`` frames: ``A_i .. A_{i+k-1}`` (the window that *starts* at A_i) and
    ``B_{j-k+1} .. B_j`` (the window that *ends* at B_j). The points are the joint positions of every frame
    of the window (forward kinematics, metres). ``D(A_i, B_j) = min_{theta, x0, z0} sum_n w_n
    |p_n - T(theta, x0, z0) p'_n|^2``, ``T`` a rotation by ``theta`` about the vertical (y) axis followed by
    the floor translation ``(x0, 0, z0)``, solved in closed form (:func:`.point_clouds.floor_alignment`). With
    ``sum w_n = 1`` D is a weighted mean squared distance (m^2); we report and threshold ``sqrt(D)``, the
    RMS point distance in metres (monotone in D: the same minima).
Transition points: the local minima of D over ``(i, j)`` below a threshold.
Creating transitions. A transition from A_i to B_j blends the ``k`` frame pairs of the two windows after
    B has been moved by the aligning transform: for ``p = 0 .. k-1`` the root position is interpolated
    linearly and every joint rotation spherically, with A's weight
    ``alpha(p) = 2((p+1)/k)^3 - 3((p+1)/k)^2 + 1`` (``alpha(k-1) = 0``: the last blended frame is B_j).
    Playback then continues at ``B_{j+1}``.
Pruning: only the largest strongly connected component is kept (no dead ends; every node reaches every
    other).
Extracting motion: random walks (:meth:`MotionGraph.generate`) and a shortest path to the node nearest a
    target pose (:meth:`MotionGraph.search`; the paper's branch-and-bound over a user error function is
    replaced by Dijkstra on the playback time, the plainest well-defined graph search).

Choices the paper leaves open (ours)
------------------------------------
* The graph is kept at frame level: a node is "about to play database frame g"; its out-edges are the
  next frame of the same clip (one frame long) and the transitions that leave there (``blend`` frames
  long). Kovar's compressed graph (nodes only at transition points, edges = pieces of clips) is this graph
  with its chains of single-exit nodes merged; a walk that picks uniformly among the out-edges at every
  node is the walk on the compressed graph.
* Weights: uniform over joints and over the frames of the window unless ``joint_weights`` is given (the
  paper allows joint weights and a taper towards the end of the window and names no values).
* Local minima: of D over a ``(2r+1) x (2r+1)`` neighbourhood (``minima_radius`` r) within each pair of
  clips. Within one clip, overlapping windows (``|i - (j-k+1)| < k``) are no candidates: the diagonal
  ``D = 0`` there is the clip playing on.
* Threshold (``threshold``, metres RMS): ``None`` resolves it from the data as the ``threshold_quantile``
  quantile of the candidate local minima (default the median: half the candidates become transitions).
  This default was chosen so that it means the same for any skeleton, unit and database; it is not tuned
  to any published number (the paper leaves the threshold to the user and names none).
* ``blend`` b <= k blends only the last b frame pairs of the two windows (b = k is the paper's transition).
* Start of generation: the walk starts at the database frame that follows the frame whose preceding window
  is nearest (the same aligned distance) to the last frames of ``start``, and the whole output is moved by
  that alignment, so it continues the start context in place and heading.
* Not implemented: the paper's constraint handling during transitions (foot-plant annotations and the
  footskate clean-up of Kovar, Schreiner & Gleicher 2002). Transitions here blend only; foot sliding they
  cause is measured by the compare metrics, not repaired.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.ndimage import minimum_filter
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components, dijkstra
from scipy.spatial.transform import Rotation

from ...generator import Database, Generator, check_generated
from ...kinematics import dof_values_from_local, forward_kinematics, local_rotations, root_translation, yaw_rotation
from ...motion import Motion
from .point_clouds import (apply_floor_transform, compose_floor_transforms, normalised_weights, pair_terms,
                           positions_m, transform_from_terms, window_clouds)

__all__ = ["MotionGraph", "kovar_alpha", "budget_count", "budget_keep"]


# --------------------------------------------------------------------------------------------------
# the transition budget and the blend
# --------------------------------------------------------------------------------------------------
def budget_count(transitions_per_s: float, database_seconds: float) -> int:
    """Transitions a graph keeps under the transition budget: ``round(transitions_per_s * database_seconds)``,
    at least 1.

    The budget is the one strictness rule of every graph generator of the comparison (ours and both
    fairmotion rows): each keeps the same number of its best candidate transitions per second of database.
    A quantile of candidate distances would not be equally strict: our candidates are the local minima of a
    frame-by-frame distance matrix, fairmotion's every pair of its nodes, so the same quantile keeps very
    different numbers of transitions (docs/compare/generators.md, "Equal strictness").
    """
    if not (np.isfinite(transitions_per_s) and transitions_per_s > 0):
        raise ValueError(f"transitions_per_s must be a positive number, got {transitions_per_s!r}")
    return max(1, int(round(float(transitions_per_s) * float(database_seconds))))


def budget_keep(distances, transitions_per_s: float, database_seconds: float) -> np.ndarray:
    """Boolean mask of the :func:`budget_count` smallest ``distances`` (ties broken by order, so exactly that
    many are kept, or all when there are fewer candidates)."""
    d = np.asarray(distances, float)
    n = min(budget_count(transitions_per_s, database_seconds), d.size)
    keep = np.zeros(d.size, bool)
    keep[np.argsort(d, kind="stable")[:n]] = True
    return keep


def kovar_alpha(n: int) -> np.ndarray:
    """Blend weights of the source clip over an ``n``-frame transition: ``2((p+1)/n)^3 - 3((p+1)/n)^2 + 1``.

    Returns array (n,), decreasing from about 1 to exactly 0 (the last frame is the target clip's).
    """
    u = (np.arange(n) + 1.0) / n
    return 2.0 * u**3 - 3.0 * u**2 + 1.0


# --------------------------------------------------------------------------------------------------
# the graph
# --------------------------------------------------------------------------------------------------
class MotionGraph(Generator):
    """Kovar et al.'s motion graph on a database of clips (see the module docstring for the method).

    Parameters
    ----------
    window : int
        ``k``: frames (at the database's frame rate) of the point-cloud windows and of a transition
        (10: 1/3 s at 30 fps).
    threshold : float or None
        Largest RMS aligned point distance (metres) of a transition; ``None``: resolved from the data as
        the ``threshold_quantile`` quantile of the candidate local minima.
    threshold_quantile : float
        In (0, 1]; used when ``threshold`` is None.
    transitions_per_s : float or None
        The transition budget (:func:`budget_count`): keep the ``transitions_per_s x database seconds``
        candidates of smallest distance (before pruning); overrides ``threshold`` and ``threshold_quantile``.
    blend : int or None
        Frames blended per transition, ``1 <= blend <= window``; ``None``: ``window`` (the paper's).
    minima_radius : int
        Local minima over a ``(2r+1)^2`` neighbourhood of the distance matrix.
    joint_weights : array (joints,), optional
        Point weight of every joint (uniform if omitted), the same in every frame of the window.

    Attributes
    ----------
    transitions_ : pandas.DataFrame
        The transitions of the pruned graph, one row each: ``from_clip, from_frame`` (A, i: where the
        blended window starts in A), ``to_clip, to_frame`` (B, j: where it ends in B; playback goes on at
        j + 1), ``distance`` (m, RMS), ``theta`` (rad), ``x0``, ``z0`` (m): the floor transform moving B
        onto A.
    threshold_ : float
        The threshold used (metres; with a budget, the distance of the last kept candidate).
    n_candidates_ : int
        Candidate transitions (local minima, before the threshold).
    n_below_threshold_ : int
        Candidates at or below the threshold (before pruning).
    n_nodes_ : int
        Frames (nodes of the frame-level graph) in the largest strongly connected component.
    largest_scc_share_ : float
        ``n_nodes_`` / frames of the database.
    in_graph_ : list of bool arrays (frames of each clip,)
        Which frames of each clip are nodes of the pruned graph.
    skeleton_, fps_ : the output skeleton (the first clip's) and frame rate.
    window_, blend_ : int
    clip_names_ : list of str
    db_ : Database, the clips (:class:`animsynth.generator.Database`)
    """

    name = "motion_graph"

    def __init__(self, window: int = 10, threshold: float | None = None, threshold_quantile: float = 0.5,
                 blend: int | None = None, minima_radius: int = 1, joint_weights=None,
                 transitions_per_s: float | None = None):
        self.window = window
        self.transitions_per_s = transitions_per_s
        self.threshold = threshold
        self.threshold_quantile = threshold_quantile
        self.blend = blend
        self.minima_radius = minima_radius
        self.joint_weights = joint_weights

    # ---------------------------------------------------------------- build
    def _check_params(self):
        k = self.window
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
            raise ValueError(f"window must be an integer >= 1 (frames), got {k!r}")
        b = k if self.blend is None else self.blend
        if isinstance(b, bool) or not isinstance(b, (int, np.integer)) or not 1 <= b <= k:
            raise ValueError(f"blend must be an integer in [1, window={k}] (frames) or None, got {self.blend!r}")
        r = self.minima_radius
        if isinstance(r, bool) or not isinstance(r, (int, np.integer)) or r < 1:
            raise ValueError(f"minima_radius must be an integer >= 1, got {r!r}")
        if self.threshold is not None and not (np.isfinite(self.threshold) and self.threshold >= 0):
            raise ValueError(f"threshold must be a finite distance >= 0 (metres) or None, got {self.threshold!r}")
        if not 0.0 < float(self.threshold_quantile) <= 1.0:
            raise ValueError(f"threshold_quantile must be in (0, 1], got {self.threshold_quantile!r}")
        return int(k), int(b), int(r)

    def fit(self, database, native_clips=None) -> "MotionGraph":
        """Build the graph on ``database`` (list of Motion: one DOF layout, one frame rate; ``native_clips``: ignored,
        it runs at the working rate).

        Every clip needs at least ``window + 2`` frames. Clips on skeletons with other bone lengths are
        compared through their own forward kinematics; the output is on the first clip's skeleton: frames of
        another subject's clip are played with that subject's joint rotations and root translation on the
        first subject's bones (feet may then float or sink by the difference in leg length).

        The paper's steps, one method each: :meth:`_check_database`, :meth:`_candidates` (point-cloud distances
        of every pair of windows and their local minima), :meth:`_threshold` (the transitions kept),
        :meth:`_prune` (the largest strongly connected component of the frame-level graph) and
        :meth:`_store_frames` (what the output is assembled from).
        """
        k, b, r = self._check_params()
        clips = self._check_database(database, k)
        pos = [positions_m(c) for c in clips]
        n_joints = pos[0].shape[1]
        if any(p.shape[1] != n_joints for p in pos):
            raise ValueError("motion graph: the clips' skeletons have different joint counts")
        jw = normalised_weights(self.joint_weights, n_joints)
        lengths = np.array([c.n_frames for c in clips])
        rows, cols, cand, terms = self._candidates(pos, lengths, np.tile(jw, k) / k, k, r)
        keep = self._threshold(cand, float(lengths.sum()) / float(clips[0].fps))
        rows, cols, cand = rows[keep], cols[keep], cand[keep]
        a, bb, cen = terms
        theta, x0, z0 = transform_from_terms(a[rows, cols], bb[rows, cols],
                                             (cen[0][rows], cen[1][rows]), (cen[0][cols], cen[1][cols]))
        del terms, a, bb
        self._prune(lengths, rows, cols, cand, (theta, x0, z0), k, b)
        self._store_frames(clips, pos, jw, k, b)
        self.db_ = Database(clips)
        return self

    def run_notes(self) -> dict:
        """``transitions_kept``: the candidates at or below the threshold (``n_below_threshold_``, before pruning)."""
        return {"transitions_kept": float(self.n_below_threshold_)}

    @staticmethod
    def _check_database(database, k: int) -> list:
        """The clips of ``database`` as a list, checked: not empty, one DOF layout, one frame rate, each at least
        ``k + 2`` frames."""
        clips = list(database)
        if not clips:
            raise ValueError("motion graph: the database is empty")
        first = clips[0]
        for c in clips:
            if c.skeleton.columns() != first.skeleton.columns():
                raise ValueError(f"motion graph: clip {c.name!r} has other DOF columns than {first.name!r}")
            if not np.isclose(c.fps, first.fps):
                raise ValueError(f"motion graph: clip {c.name!r} is at {c.fps:g} fps, {first.name!r} at "
                                 f"{first.fps:g} fps (resample the database to one rate first)")
            if c.n_frames < k + 2:
                raise ValueError(f"motion graph: clip {c.name!r} has {c.n_frames} frames, fewer than "
                                 f"window + 2 = {k + 2}")
        return clips

    @staticmethod
    def _candidates(pos: list, lengths: np.ndarray, w: np.ndarray, k: int, r: int):
        """Candidate transitions: the local minima of the aligned window distance inside each pair of clips.

        Parameters
        ----------
        pos : list of arrays (frames, J, 3), every clip's joint positions (m)
        lengths : int array (clips,)
        w : array (k * J,), the point weights of a window (summing to 1)
        k, r : the window and the local-minimum radius

        Returns
        -------
        rows, cols : int arrays (candidates,), the windows (indices into all clips' windows, clip by clip) of A
            (starting at A_i) and of B (ending at B_j)
        cand : array (candidates,), their RMS distance (m)
        terms : ``(a, b, centroids)`` of :func:`pair_terms` for every pair of windows (the transforms of the
            kept candidates come from them)
        """
        n_win = lengths - k + 1
        win_off = np.concatenate([[0], np.cumsum(n_win)])
        clouds = np.concatenate([window_clouds(p, k) for p in pos])
        d2, a, bb, cen, _ = pair_terms(clouds, clouds, w)
        dist = np.sqrt(d2)
        del d2
        rows, cols = [], []
        for ca in range(len(lengths)):
            ra = slice(win_off[ca], win_off[ca + 1])
            for cb in range(len(lengths)):
                rb = slice(win_off[cb], win_off[cb + 1])
                block = dist[ra, rb]
                is_min = block <= minimum_filter(block, size=2 * r + 1, mode="nearest")
                i, s = np.nonzero(is_min)
                ok = s <= lengths[cb] - k - 1  # the frame after the window's end, B_{j+1}, exists
                if ca == cb:
                    ok &= np.abs(i - s) >= k  # overlapping windows of one clip: the clip playing on
                rows.append(i[ok] + win_off[ca])
                cols.append(s[ok] + win_off[cb])
        rows = np.concatenate(rows)
        cols = np.concatenate(cols)
        return rows, cols, dist[rows, cols], (a, bb, cen)

    def _threshold(self, cand: np.ndarray, database_seconds: float) -> np.ndarray:
        """Which candidates become transitions (bool (candidates,)): the transition budget's smallest, else those
        at or below the threshold (given, or the ``threshold_quantile`` quantile of the candidates). Sets
        ``n_candidates_``, ``threshold_`` and ``n_below_threshold_``."""
        self.n_candidates_ = int(cand.size)
        if cand.size == 0:
            raise ValueError("motion graph: no candidate transitions (local minima) in the database")
        if self.transitions_per_s is not None:
            keep = budget_keep(cand, float(self.transitions_per_s), database_seconds)
            self.threshold_ = float(cand[keep].max())
        else:
            self.threshold_ = (float(self.threshold) if self.threshold is not None
                               else float(np.quantile(cand, float(self.threshold_quantile))))
            keep = cand <= self.threshold_
        self.n_below_threshold_ = int(keep.sum())
        return keep

    def _prune(self, lengths: np.ndarray, rows: np.ndarray, cols: np.ndarray, cand: np.ndarray, transforms,
               k: int, b: int) -> None:
        """The frame-level graph (every frame to the next of its clip, the kept transitions from their first
        blended frame of A to B_{j+1}) pruned to its largest strongly connected component. Sets
        ``n_nodes_``, ``largest_scc_share_``, ``in_graph_``, ``transitions_`` and the walk's arrays."""
        theta, x0, z0 = transforms
        offsets = np.concatenate([[0], np.cumsum(lengths)])
        n_win = lengths - k + 1
        win_off = np.concatenate([[0], np.cumsum(n_win)])
        win_clip = np.repeat(np.arange(len(lengths)), n_win)
        win_start = np.arange(win_off[-1]) - win_off[win_clip]
        ca, i = win_clip[rows], win_start[rows]
        cb, s = win_clip[cols], win_start[cols]
        leave = offsets[ca] + i + (k - b)  # first blended frame of A
        land = offsets[cb] + s + k  # B_{j+1}, j = s + k - 1

        # frame-level graph: next frame of the same clip, and the transitions
        n = int(offsets[-1])
        clip_of = np.repeat(np.arange(len(lengths)), lengths)
        has_next = np.ones(n, bool)
        has_next[offsets[1:] - 1] = False
        nat_from = np.nonzero(has_next)[0]
        src = np.concatenate([nat_from, leave])
        dst = np.concatenate([nat_from + 1, land])
        wts = np.concatenate([np.ones(nat_from.size), np.full(leave.size, float(b))])
        g = csr_matrix((wts, (src, dst)), shape=(n, n))
        _, labels = connected_components(g, directed=True, connection="strong")
        counts = np.bincount(labels)
        in_scc = labels == int(np.argmax(counts))
        self.n_nodes_ = int(in_scc.sum())
        if self.n_nodes_ < 2:
            raise ValueError(f"motion graph: no cycle through the transitions at threshold {self.threshold_:.4g} m "
                             f"({self.n_below_threshold_} transitions): raise the threshold or add clips")
        self.largest_scc_share_ = self.n_nodes_ / n

        tr = in_scc[leave] & in_scc[land]
        order = np.lexsort((land[tr], leave[tr]))
        sel = np.nonzero(tr)[0][order]
        self._leave_ = leave[sel]
        self._land_ = land[sel]
        self._theta_, self._x0_, self._z0_ = theta[sel], x0[sel], z0[sel]
        self._tr_dist_ = cand[sel]
        self._tr_ptr_ = np.searchsorted(self._leave_, np.arange(n + 1))
        self._has_next_ = has_next
        self._nat_ok_ = has_next & in_scc & np.concatenate([in_scc[1:], [False]])
        self._in_scc_ = in_scc
        self.in_graph_ = [in_scc[offsets[c]:offsets[c + 1]].copy() for c in range(len(lengths))]
        self._clip_of_ = clip_of
        self._frame_of_ = np.arange(n) - offsets[clip_of]
        self._offsets_ = offsets
        self.transitions_ = pd.DataFrame({
            "from_clip": ca[sel], "from_frame": i[sel], "to_clip": cb[sel], "to_frame": s[sel] + k - 1,
            "distance": self._tr_dist_, "theta": self._theta_, "x0": self._x0_, "z0": self._z0_})

        keep_edges = np.concatenate([self._nat_ok_[nat_from], tr])
        self._graph_ = csr_matrix((wts[keep_edges], (src[keep_edges], dst[keep_edges])), shape=(n, n))

    def _store_frames(self, clips: list, pos: list, jw: np.ndarray, k: int, b: int) -> None:
        """Per-frame data for the output (local rotations, root translation and positions in metres) and the
        fitted attributes that describe it."""
        first = clips[0]
        self._quat_ = np.concatenate([np.stack([r.as_quat() for r in local_rotations(c.skeleton, c.values)], 1)
                                      for c in clips])
        self._root_ = np.concatenate([root_translation(c.skeleton, c.values) * c.skeleton.length_to_m
                                      for c in clips])
        self._pos_ = np.concatenate(pos)
        self._jw_ = jw
        self.skeleton_ = first.skeleton
        self.fps_ = float(first.fps)
        self.window_, self.blend_ = k, b
        self.clip_names_ = [c.name for c in clips]

    # ---------------------------------------------------------------- queries
    def _check_length(self, length) -> int:
        if isinstance(length, bool) or not isinstance(length, (int, np.integer)) or length < 1:
            raise ValueError(f"length must be an integer >= 1 (frames), got {length!r}")
        return int(length)

    def _start_node(self, start: Motion):
        """Graph node after the database frame nearest the end of ``start``, and the transform placing it."""
        if not np.isclose(start.fps, self.fps_):
            raise ValueError(f"start {start.name!r} is at {start.fps:g} fps, the database at {self.fps_:g} fps")
        q = positions_m(start)
        if q.shape[1] != self._pos_.shape[1]:
            raise ValueError(f"start {start.name!r} has {q.shape[1]} joints, the database {self._pos_.shape[1]}")
        m = min(self.window_, start.n_frames)
        w = np.tile(self._jw_, m) / m
        ends, clouds = [], []
        for c in range(len(self._offsets_) - 1):
            lo, hi = self._offsets_[c], self._offsets_[c + 1]
            clouds.append(window_clouds(self._pos_[lo:hi], m))
            ends.append(np.arange(lo + m - 1, hi))
        ends = np.concatenate(ends)
        clouds = np.concatenate(clouds)
        n = len(self._in_scc_)
        ok = self._has_next_[ends] & self._in_scc_[np.minimum(ends + 1, n - 1)]
        if not ok.any():
            raise ValueError("motion graph: no graph node follows a database window")
        d2, a, b, cp, cq = pair_terms(window_clouds(q[-m:], m), clouds[ok], w)
        best = int(np.argmin(d2[0]))
        theta, x0, z0 = transform_from_terms(a[0, best], b[0, best], (cp[0][0], cp[1][0]),
                                              (cq[0][best], cq[1][best]))
        return int(ends[ok][best]) + 1, (float(theta), float(x0), float(z0))

    def _out_transitions(self, g: int) -> np.ndarray:
        return np.arange(self._tr_ptr_[g], self._tr_ptr_[g + 1])

    def _play_on(self, g: int, steps: list, n_out: int, length: int, choose) -> tuple[list, int]:
        """The walk from node ``g`` until ``length`` output frames (the one play-on loop of :meth:`generate` and
        :meth:`search`).

        At every node ``choose(nat, transitions)`` picks the out-edge: ``nat`` (bool) says whether the next frame
        of the clip is in the graph, ``transitions`` (int array) are the indices of the transitions that leave
        there; it returns ``None`` to play on, else the index of the transition taken. Appends to ``steps``
        (database frames >= 0, transitions as ``-1 - index``) and returns ``(steps, output frames)``.
        """
        while n_out < length:
            t = choose(bool(self._nat_ok_[g]), self._out_transitions(g))
            if t is None:
                steps.append(g)
                n_out += 1
                g += 1
            else:
                steps.append(-1 - t)
                n_out += self.blend_
                g = int(self._land_[t])
        return steps, n_out

    def generate(self, start: Motion, length: int, seed: int, native_start: Motion | None = None) -> Motion:
        """A seeded random walk of ``length`` frames from the node nearest the end of ``start``.

        At every node the walk picks uniformly among its out-edges (play on, or one of the transitions that
        leave there). ``native_start``: ignored (it runs at the working rate).

        Returns
        -------
        Motion (length, n_dof) on ``skeleton_`` at ``fps_``; ``meta``: ``seams`` (int array: output frames
        where a transition's blend starts), ``source_frames`` ((length, 2) int: database clip and frame of
        every output frame, -1 for blended frames), ``start_node`` (clip, frame), ``n_transitions``.
        """
        self._check_start(start, length)
        length = self._check_length(length)
        node, place = self._start_node(start)
        rng = np.random.default_rng(seed)

        def uniform(nat: bool, trs: np.ndarray):
            pick = int(rng.integers(nat + trs.size))
            return None if nat and pick == 0 else int(trs[pick - nat])

        steps, _ = self._play_on(node, [], 0, length, uniform)
        return check_generated(self._assemble(steps, place, length, f"motion_graph_walk_seed{seed}",
                                              {"start_node": self._source(node)}), length, self.db_.skeleton, self.name)

    def search(self, start: Motion, target, length: int) -> Motion:
        """Shortest playback (Dijkstra over frames) from the start node to the node nearest ``target``.

        Parameters
        ----------
        start : Motion
            The context (as in :meth:`generate`).
        target : array (n_dof,)
            A pose on ``skeleton_`` (DOF values); the goal is the graph node whose pose is nearest after the
            floor alignment (one-frame point clouds).
        length : int
            Frames of the output. After the goal the motion plays on deterministically (the next frame of
            the clip, else the transition of smallest distance).

        Returns
        -------
        Motion as :meth:`generate`, ``meta`` also: ``target_node`` (clip, frame), ``target_frame`` (output
        frame that plays the goal frame, -1 if the path is longer than ``length``), ``path_frames`` (frames
        of the shortest path up to and including the goal).
        """
        self._check_start(start, length)
        length = self._check_length(length)
        node, place = self._start_node(start)
        tgt = np.asarray(target, float).reshape(-1)
        if tgt.shape != (self.skeleton_.n_dof,):
            raise ValueError(f"target must be one pose of {self.skeleton_.n_dof} DOF values, got shape "
                             f"{np.shape(target)}")
        tp = forward_kinematics(self.skeleton_, tgt[None], ends=True) * self.skeleton_.length_to_m
        nodes = np.nonzero(self._in_scc_)[0]
        d2, *_ = pair_terms(tp, self._pos_[nodes], self._jw_)
        goal = int(nodes[int(np.argmin(d2[0]))])
        _, pred = dijkstra(self._graph_, indices=node, return_predecessors=True)
        path = [goal]
        while path[-1] != node:
            p = int(pred[path[-1]])
            if p < 0:  # cannot happen inside one strongly connected component
                raise RuntimeError("motion graph: goal not reachable from the start node")
            path.append(p)
        path.reverse()
        steps, n_out = [], 0
        for u, v in zip(path[:-1], path[1:]):
            if v == u + 1 and self._nat_ok_[u]:
                steps.append(u)
                n_out += 1
            else:
                trs = self._out_transitions(u)
                trs = trs[self._land_[trs] == v]
                t = int(trs[np.argmin(self._tr_dist_[trs])])
                steps.append(-1 - t)
                n_out += self.blend_
        target_frame = n_out if n_out < length else -1
        path_frames = n_out + 1

        def nearest(nat: bool, trs: np.ndarray):
            return None if nat else int(trs[np.argmin(self._tr_dist_[trs])])

        steps, n_out = self._play_on(goal, steps, n_out, length, nearest)
        found = self._assemble(steps, place, length, "motion_graph_search",
                               {"start_node": self._source(node), "target_node": self._source(goal),
                                "target_frame": target_frame, "path_frames": path_frames})
        return check_generated(found, length, self.db_.skeleton, self.name)

    def _source(self, g: int) -> tuple[int, int]:
        return int(self._clip_of_[g]), int(self._frame_of_[g])

    # ---------------------------------------------------------------- output
    def _assemble(self, steps, place, length: int, name: str, meta: dict) -> Motion:
        """Frames of a walk: ``steps`` are database frames (>= 0) or transitions (-1 - index)."""
        b = self.blend_
        alpha_tr = kovar_alpha(b)
        ia, ib, alpha, ga, gb, blend_starts = [], [], [], [], [], []
        cur = place
        n_out = 0
        for st in steps:
            if st >= 0:
                ia.append(st)
                ib.append(st)
                alpha.append(1.0)
                ga.append(cur)
                gb.append(cur)
                n_out += 1
            else:
                t = -1 - st
                nxt = compose_floor_transforms(cur, (self._theta_[t], self._x0_[t], self._z0_[t]))
                lv, ld = int(self._leave_[t]), int(self._land_[t])
                blend_starts.append(n_out)
                ia.extend(range(lv, lv + b))
                ib.extend(range(ld - b, ld))
                alpha.extend(alpha_tr)
                ga.extend([cur] * b)
                gb.extend([nxt] * b)
                cur = nxt
                n_out += b
        ia = np.asarray(ia[:length])
        ib = np.asarray(ib[:length])
        alpha = np.asarray(alpha[:length])
        ga = np.asarray(ga[:length], float)
        gb = np.asarray(gb[:length], float)
        blend_starts = np.asarray([s for s in blend_starts if s < length], int)
        seams = blend_starts[blend_starts > 0]

        def placed(idx, tf):
            rot = yaw_rotation(tf[:, 0]) * Rotation.from_quat(self._quat_[idx, 0])
            root = apply_floor_transform(self._root_[idx][:, None, :], tf[:, 0], tf[:, 1], tf[:, 2])[:, 0]
            return rot, root

        rot_a, root_a = placed(ia, ga)
        rot_b, root_b = placed(ib, gb)
        u = 1.0 - alpha  # weight of the target clip
        root = alpha[:, None] * root_a + u[:, None] * root_b
        n_j = self._quat_.shape[1]
        rots = [rot_a * Rotation.from_rotvec((rot_a.inv() * rot_b).as_rotvec() * u[:, None])]
        for j in range(1, n_j):
            ra = Rotation.from_quat(self._quat_[ia, j])
            rb = Rotation.from_quat(self._quat_[ib, j])
            rots.append(ra * Rotation.from_rotvec((ra.inv() * rb).as_rotvec() * u[:, None]))
        values = dof_values_from_local(self.skeleton_, rots, root / self.skeleton_.length_to_m)
        src = np.stack([self._clip_of_[ia], self._frame_of_[ia]], 1)
        src[alpha < 1.0] = -1
        meta = dict(meta, seams=seams, source_frames=src, n_transitions=int(blend_starts.size),
                    generator="motion_graph")
        return Motion(values, self.skeleton_, self.fps_, name, meta)
