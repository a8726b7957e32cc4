"""Every motion generator of the side-by-side comparison, behind one interface.

Each generator is a scikit-learn-style estimator::

    gen = make_generator(name, cfg).fit(database)   # database: list of Motion, one skeleton, one fps
    motion = gen.generate(start, length, seed)      # start: Motion of >= 2 frames (the context)

``generate`` returns a :class:`~animsynth.motion.Motion` of exactly ``length`` frames on the
database's skeleton and frame rate, all DOF (root included), continuing the start: its first frame
is the frame after the start's last one. ``meta["seams"]`` holds the frame indices ``t >= 1`` where
frame ``t`` does not follow frame ``t - 1`` in the source (a transition or a blend start; empty
for a generator without seams), ``meta["source_frames"]`` the ``(clip, frame)`` of the database frame
each output frame plays (``-1`` where the frame is synthesised). The entry from the start into the
generated frames is scored as a seam by the family for every generator but ``replay``
(:mod:`animsynth.compare.jobs`), whatever a generator records.

Generators (``GENERATORS``):

``delaunay``, ``knn``
    Gauch & Peters field following (:mod:`animsynth.simplicial`): PCA of the database's joint
    angles, the training vectors, the interpolated vector field and Euler steps from the start's
    latent point (moved by a seeded jitter, so seeds differ), decoded to joint angles. Root motion
    (an extension: the paper has no root) is the capture's own root step of the database frame
    nearest in latent space, integrated from the start (:func:`animsynth.resequencing.play_path`).
``isomap``, ``stisomap``
    re-sequencing on the neighbourhood graph (:mod:`animsynth.resequencing`): L2 between
    linearised joint rotations, the smallest k that connects the graph (ST-Isomap: with the
    spatio-temporal adjustment and the adjacent temporal neighbours always in), Dijkstra paths
    from the database frame nearest the start to seeded random targets, chained until ``length``
    frames, played with the root integrated.
``motion_graph``
    the classic motion graph of Kovar, Gleicher & Pighin 2002 (:mod:`animsynth.compare.motiongraph`).
``fairmotion``
    fairmotion 0.0.4's motion graph as released, on the same clips fed at its native 60 fps
    (:mod:`animsynth.compare.fairmotion_peer`), when its package is installed
    (:func:`animsynth.compare.settings.unavailable` gives the reason when not).
``fairmotion_fixed``
    the same with upstream's later fixes of its walk (output rate, blend source, rigid turn of the
    appended piece), each a named patch (:data:`animsynth.compare.fairmotion_peer.FIXES`).

The graph generators (:data:`GRAPHS`) keep the same transition budget, ``compare.transitions_per_s``
(:func:`animsynth.compare.motiongraph.budget_count`).
``motion_matching``
    motion matching with inertialization and the reference's foot locking and leg IK (Clavet 2016; the
    baseline of Holden et al. 2020; :mod:`animsynth.compare.motionmatching`), its query trajectory a
    steady "gamepad" from the start; deterministic (every seed gives the same motion).
``motion_matching_pose``
    the same with the trajectory weights at 0: matching on the pose only.
``genmm``
    generative motion matching (Li et al. 2023; :mod:`animsynth.compare.genmm`) in keyframe mode from the
    start; seeds differ by the initial noise.
``replay``
    the held-out capture itself (upper bound for realism; the same for every seed).
``concat``
    random database segments appended (lower bound): root position made continuous, no blending,
    no alignment of heading.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.spatial import cKDTree

from ..kinematics import root_rotation, root_translation, set_root
from ..motion import Motion
from ..generator import Database, Generator, align_root, check_generated
from ..simplicial.generator import FieldFollower

log = logging.getLogger("animsynth.compare.generators")

__all__ = ["GENERATORS", "REFERENCES", "GRAPHS", "FAIRMOTION_ROWS", "DETERMINISTIC", "Database", "Generator",
           "FieldFollower", "Resequencer", "Replay", "Concat", "make_generator", "align_root",
           "check_generated"]

#: every generator name, in the order of the tables
GENERATORS = ("delaunay", "knn", "isomap", "stisomap", "motion_graph", "fairmotion", "fairmotion_fixed",
              "motion_matching", "motion_matching_pose", "genmm", "replay", "concat")
#: the motion-graph generators: one transition budget for all of them
GRAPHS = ("motion_graph", "fairmotion", "fairmotion_fixed")
#: the generators that run fairmotion's package
FAIRMOTION_ROWS = ("fairmotion", "fairmotion_fixed")
#: the two reference rows (bounds, not methods)
REFERENCES = ("replay", "concat")
#: the generators whose motion the seed does not change (seed diversity 0)
DETERMINISTIC = ("motion_matching", "motion_matching_pose", "replay")


# ----------------------------------------------------------------------------- re-sequencers


class Resequencer(Generator):
    """Isomap / ST-Isomap re-sequencing: Dijkstra paths on the neighbourhood graph between seeded targets.

    Parameters
    ----------
    method : {"isomap", "stisomap"}
    n_candidates : int, neighbours listed per frame (doubled until the smallest connecting k fits)
    k : int or None, neighbours of the graph; None or smaller than the smallest k that connects the
        graph: that k (as the re-sequencing study)
    min_target_gap_s : float, a random target lies at least this far (seconds of database) from the
        current frame in the same clip
    stisomap : dict, the re-sequencing study's ``stisomap`` block (seconds; ST-Isomap only)

    Attributes
    ----------
    db_ : Database
    graph_ : scipy.sparse csr matrix (N, N), the weighted neighbourhood graph
    k_ : int, neighbours used; min_k_ : the smallest connecting k
    """

    def __init__(self, method: str = "isomap", n_candidates: int = 20, k=None, min_target_gap_s: float = 0.5,
                 stisomap: dict | None = None):
        self.method = method
        self.n_candidates = n_candidates
        self.k = k
        self.min_target_gap_s = min_target_gap_s
        self.stisomap = stisomap
        self.name = method

    def fit(self, database) -> "Resequencer":
        from ..resequencing import sparse as sp
        from ..resequencing.features import motion_features
        from ..resequencing.settings import st_parameters

        if self.method not in ("isomap", "stisomap"):
            raise ValueError(f"re-sequencing method must be isomap or stisomap, got {self.method!r}")
        if self.method == "stisomap" and not self.stisomap:
            raise ValueError("stisomap needs its parameters (the re-sequencing study's stisomap block)")
        self.db_ = db = Database(database)
        feats, seq = sp.concat_features([motion_features(c) for c in db.clips])
        X = np.vstack([f.linearised(False) for f in feats])
        n = X.shape[0]

        def pair(i, j):
            return np.linalg.norm(X[i] - X[j], axis=1)

        m = min(int(self.n_candidates), n - 1)
        while True:
            dist, idx = sp.l2_neighbours(X, m)
            always = None
            if self.method == "stisomap":
                st = st_parameters(self.stisomap, db.fps)
                dist, idx, _ = sp.st_neighbours(dist, idx, seq, pair_distance=pair, **st)
                always = sp.st_always_edges(seq, st["temporal_window"], st["c_atn"], pair)
            try:
                kmin = sp.sparse_min_connected_k(idx, always=None if always is None else always[0])
                break
            except sp.CandidateCountError:
                if m >= n - 1:
                    raise
                m = min(2 * m, n - 1)
        self.min_k_ = int(kmin)
        self.k_ = max(self.min_k_, int(self.k or 0))
        if self.k_ > idx.shape[1]:
            dist, idx = sp.l2_neighbours(X, min(self.k_, n - 1))
            if self.method == "stisomap":
                dist, idx, _ = sp.st_neighbours(dist, idx, seq, pair_distance=pair, **st)
        self.graph_ = sp.sparse_knn_graph(dist, idx, self.k_, always=always)
        self.features_ = X
        self.tree_ = cKDTree(X)
        return self

    def generate(self, start: Motion, length: int, seed: int) -> Motion:
        from ..resequencing.features import motion_features
        from ..resequencing.paths import shortest_path_frames

        self._check_start(start, length)
        db, length = self.db_, int(length)
        x = motion_features(start).linearised(False)[-1]
        path = [int(self.tree_.query(x)[1])]
        rng = np.random.default_rng(seed)
        gap = max(1, int(round(float(self.min_target_gap_s) * db.fps)))
        n = db.n_frames
        while len(path) < length + 1:
            cur = path[-1]
            far = (db.clip != db.clip[cur]) | (np.abs(db.frame - db.frame[cur]) >= gap)
            choices = np.flatnonzero(far)
            target = int(rng.choice(choices)) if choices.size else int((cur + 1 + rng.integers(n - 1)) % n)
            p, _ = shortest_path_frames(self.graph_, cur, target)
            path.extend(int(f) for f in p[1:])
        path = np.asarray(path[:length + 1], np.int64)
        values = db.play(path, start.values[-1])[1:]
        seams = db.seams(path)  # positions in path; output frame t = path position t + 1
        seams = seams[seams >= 2] - 1
        return self._motion(values, length, seams, db.sources(path[1:]))


# ----------------------------------------------------------------------------- references


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


# ----------------------------------------------------------------------------- the factory


def make_generator(name: str, cfg: dict, held_out: Motion | None = None) -> Generator:
    """An unfitted generator from the ``compare`` config block (``cfg``).

    Parameters
    ----------
    name : one of :data:`GENERATORS`, or a key of ``cfg["user_generators"]`` (a user's class:
        :class:`animsynth.compare.user.UserGenerator`)
    cfg : dict, the ``compare`` block with ``stisomap`` (the re-sequencing study's block) added
    held_out : Motion, the held-out clip (``replay`` only)
    """
    if name in ("delaunay", "knn"):
        return FieldFollower(method=name, **cfg["field"])
    if name in ("isomap", "stisomap"):
        return Resequencer(method=name, stisomap=cfg.get("stisomap"), **cfg["resequencing_graph"])
    if name == "motion_graph":
        from .motiongraph import MotionGraph

        return MotionGraph(**cfg["motion_graph"], transitions_per_s=cfg.get("transitions_per_s"))
    if name in FAIRMOTION_ROWS:
        from .fairmotion_peer import FIXES, FairmotionGraph

        return FairmotionGraph(**cfg["fairmotion"], transitions_per_s=cfg.get("transitions_per_s"),
                               fixes=FIXES if name == "fairmotion_fixed" else ())
    if name in ("motion_matching", "motion_matching_pose"):
        from .motionmatching import make_motion_matching

        mm = dict(cfg["motion_matching"])
        return make_motion_matching(mm, trajectory_weight=0.0 if name == "motion_matching_pose" else None, name=name)
    if name == "genmm":
        from .genmm import make_genmm

        gm = dict(cfg["genmm"])
        if gm.get("alpha", 0.01) is None:  # null in the config: no completeness normalisation
            gm["alpha"] = float("inf")
        return make_genmm(gm, name=name)
    if name == "replay":
        return Replay(held_out)
    if name == "concat":
        return Concat(**cfg["concat"])
    user = cfg.get("user_generators") or {}
    if name in user:  # a researcher's own class (compare.user_generators; animsynth.compare.user)
        from .user import UserGenerator

        return UserGenerator(name, user[name])
    raise ValueError(f"config key 'compare.generators': unknown generator {name!r} (one of {list(GENERATORS)})")
