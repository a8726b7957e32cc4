"""The registry of the side-by-side comparison: generator names -> estimators and their settings.

This module holds no method code. Every generator is a scikit-learn-style estimator on the one interface
(:mod:`animsynth.generator`), defined where its method lives: the families' own estimators (the same ones their
paper steps and the command line call) and this package's modules. :func:`make_generator` builds one from the
``compare`` config block::

    gen = make_generator(name, cfg).fit(database)   # database: list of Motion, one skeleton, one fps
    motion = gen.generate(start, length, seed)      # start: Motion of >= 2 frames (the context)

``generate`` returns a :class:`~animsynth.motion.Motion` of exactly ``length`` frames on the
database's skeleton and frame rate, all DOF (root included), continuing the start: its first frame
is the frame after the start's last one. ``meta["seams"]`` holds the frame indices ``t >= 1`` where
frame ``t`` does not follow frame ``t - 1`` in the source (a transition or a blend start; empty
for a generator without seams), ``meta["source_frames"]`` the ``(clip, frame)`` of the database frame
each output frame plays (``-1`` where the frame is synthesised). The entry from the start into the
generated frames is scored as a seam for every generator that declares ``entry_seam`` (all but ``replay``:
:class:`animsynth.generator.Generator`), whatever a generator records.

Generators (``GENERATORS``):

``delaunay``, ``knn``
    Gauch & Peters field following (:class:`animsynth.simplicial.generator.FieldFollower`): PCA of the database's joint
    angles, the training vectors, the interpolated vector field and Euler steps from the start's
    latent point (moved by a seeded jitter, so seeds differ), decoded to joint angles. Root motion
    (an extension: the paper has no root) is the capture's own root step of the database frame
    nearest in latent space, integrated from the start (:func:`animsynth.generator.play_path`).
``isomap``, ``stisomap``
    re-sequencing on the neighbourhood graph (:class:`animsynth.resequencing.generator.Resequencer`): L2 between
    linearised joint rotations, the smallest k that connects the graph (ST-Isomap: with the
    spatio-temporal adjustment and the adjacent temporal neighbours always in), Dijkstra paths
    from the database frame nearest the start to seeded random targets, chained until ``length``
    frames, played with the root integrated.
``motion_graph``
    the classic motion graph of Kovar, Gleicher & Pighin 2002 (:mod:`animsynth.compare.generators.motiongraph`).
``fairmotion``
    fairmotion 0.0.4's motion graph as released, on the same clips fed at its native 60 fps
    (:mod:`animsynth.compare.generators.fairmotion_peer`), when its package is installed
    (:func:`animsynth.compare.settings.unavailable` gives the reason when not).
``fairmotion_fixed``
    the same with upstream's later fixes of its walk (output rate, blend source, rigid turn of the
    appended piece, ``cut`` copying its poses), each a named patch (:data:`animsynth.compare.generators.fairmotion_fixes.FIXES`).

The graph generators (motion_graph, fairmotion, fairmotion_fixed) keep the same transition budget, ``compare.transitions_per_s``
(:func:`animsynth.compare.generators.motiongraph.budget_count`).
``motion_matching``
    motion matching with inertialization and the reference's foot locking and leg IK (Clavet 2016; the
    baseline of Holden et al. 2020; :mod:`animsynth.compare.generators.motionmatching`), its query trajectory a
    steady "gamepad" from the start; deterministic (every seed gives the same motion).
``motion_matching_pose``
    the same with the trajectory weights at 0: matching on the pose only.
``motion_matching_traj``
    the same with the held-out future as its query trajectory (``query = "future_trajectory"``,
    :class:`animsynth.compare.generators.motionmatching.MotionMatchingTrajectory`; the runner passes the held-out frames
    after the start): it sees where the capture went next, information no other generator is given, so it
    is a different protocol (following a known path), not a better generator.

Every generator's ``query`` (:class:`animsynth.generator.Generator`) says what it is given: ``"start"`` (the
start alone; all but ``motion_matching_traj`` and the bound ``replay``) or ``"future_trajectory"``.
``genmm``
    generative motion matching (Li et al. 2023; :mod:`animsynth.compare.generators.genmm`) in keyframe mode from the
    start; seeds differ by the initial noise.
``replay``
    the held-out capture itself (upper bound for realism; the same for every seed; :mod:`.references`): its query
    is the held-out future, which it plays.
``concat``
    random database segments appended (lower bound; :mod:`.references`): root position made continuous, no blending,
    no alignment of heading.
"""

from __future__ import annotations

import logging

from ...generator import Generator
from ...resequencing.generator import Resequencer
from ...simplicial.generator import FieldFollower
from .names import FAIRMOTION_ROWS, GENERATORS
from .references import Concat, Replay

log = logging.getLogger("animsynth.compare.generators.registry")

__all__ = ["make_generator"]

# ----------------------------------------------------------------------------- the factory


def make_generator(name: str, cfg: dict) -> Generator:
    """An unfitted generator from the ``compare`` config block (``cfg``).

    Parameters
    ----------
    name : one of :data:`GENERATORS`, or a key of ``cfg["user_generators"]`` (a user's class:
        :class:`animsynth.compare.generators.user.UserGenerator`, run in a child process unless ``cfg["user_process"]`` is
        false, with the time limit ``cfg["user_timeout_s"]`` per call and the folders ``cfg["user_guard"]``
        guarded)
    cfg : dict, the ``compare`` block with ``stisomap`` (the re-sequencing study's block) added
    """
    if name in ("delaunay", "knn"):
        return FieldFollower(method=name, **cfg["field"])
    if name in ("isomap", "stisomap"):
        return Resequencer(method=name, stisomap=cfg.get("stisomap"), **cfg["resequencing_graph"])
    if name == "motion_graph":
        from .motiongraph import MotionGraph

        return MotionGraph(**cfg["motion_graph"], transitions_per_s=cfg.get("transitions_per_s"))
    if name in FAIRMOTION_ROWS:
        from .fairmotion_fixes import FIXES
        from .fairmotion_peer import FairmotionGraph

        return FairmotionGraph(**cfg["fairmotion"], transitions_per_s=cfg.get("transitions_per_s"),
                               fixes=FIXES if name == "fairmotion_fixed" else ())
    if name in ("motion_matching", "motion_matching_pose", "motion_matching_traj"):
        from .motionmatching import make_motion_matching

        mm = dict(cfg["motion_matching"])
        return make_motion_matching(mm, trajectory_weight=0.0 if name == "motion_matching_pose" else None, name=name,
                                    future_trajectory=name == "motion_matching_traj")
    if name == "genmm":
        from .genmm import make_genmm

        gm = dict(cfg["genmm"])
        if gm.get("alpha", 0.01) is None:  # null in the config: no completeness normalisation
            gm["alpha"] = float("inf")
        return make_genmm(gm, name=name)
    if name == "replay":
        return Replay()
    if name == "concat":
        return Concat(**cfg["concat"])
    user = cfg.get("user_generators") or {}
    if name in user:  # a researcher's own class (compare.user_generators; animsynth.compare.generators.user)
        from .user import UserGenerator

        return UserGenerator(name, user[name], timeout_s=cfg.get("user_timeout_s"),
                             process=bool(cfg.get("user_process", True)), guard=cfg.get("user_guard") or ())
    raise ValueError(f"config key 'compare.generators': unknown generator {name!r} (one of {list(GENERATORS)})")
