"""The named fixes of fairmotion 0.0.4's walk (:data:`FIXES`) and the swaps of its functions they are applied
through (:func:`walk_patches`), for :class:`animsynth.compare.generators.fairmotion_peer.FairmotionGraph`.

Four defects of 0.0.4's walk were changed upstream after the release (never released). The peer runs as
released (``fixes=()``, the row ``fairmotion``) and with each fix applied as a small patch of the walk
(``fixes=FIXES``, the row ``fairmotion_fixed``); each patch swaps one thing for the duration of one walk and is
undone afterwards:

``output_rate``
    ``create_random_motion`` builds its output at fairmotion's default 60 fps, so away from 60 fps the cut
    before each appended piece lands at the wrong frame. Patch: the empty output motion takes the appended
    pieces' frame rate before the first append (upstream passes the graph's rate to the output motion).
``blend_source``
    ``append_and_blend`` starts the blend's source time at ``fps * frame`` instead of ``frame / fps``, so every
    blend draws its source from past the end of the previous piece: its last pose, held still. Patch: for
    each append, the previous motion's ``get_pose_by_time`` is offset by the difference of the two times, so
    the source plays on from the blend's first frame (the overlap frames the walk cuts for it), as upstream's
    "overlapping" blend does.
``rigid_turn``
    ``append_and_blend`` turns the appended piece with ``ops.motion.rotate`` (``transform(local=False)``), which
    rotates every pose's orientation about the vertical but leaves its root path where it was, so a piece
    walks sideways or backwards after a turn. Patch: ``ops.motion.rotate`` turns the piece rigidly about its
    first pose's root (orientation and path), as upstream's ``transform(..., pivot=0)`` does.
``cut_copy``
    ``ops.motion.cut`` deep-copies the clip but hands back the Pose objects of the loaded clip itself
    (``motion.poses[start:end]``), and ``append_and_blend`` moves the appended piece's poses in place
    (``translate``, ``rotate``). The walk cuts each node with ``frames_blend`` extra frames, so consecutive
    pieces of one clip share those frames: placing one piece displaces the first frames of the next piece read
    from the same clip (and of any later visit), which then jumps back where its own frames were not moved
    (the paper run of 2026-12-05, this fix and the 60 fps source together, on the 19 clips of the run before:
    the fixed row's median 95th percentile of the per-frame velocity jump 1.69 -> 1.22 m/s, the largest jump
    over every clip and seed 96.7 -> 25.3 m/s; docs/compare/results.md). Patch: ``cut`` returns the
    poses of its own deep copy (``cut_motion.poses[start:end]``, and its velocities cut alike), as upstream's
    fix in the same commit as the three above does; the loaded clips are then never moved by a walk.

Every walk swaps, for its duration, fairmotion's ``ops.motion.append_and_blend`` and ``ops.motion.blend`` for
recorders that call them unchanged (apart from the fixes ``output_rate`` and ``blend_source``) and note where each
appended piece starts and the root of every blend's source pose; the fixes ``rigid_turn`` and ``cut_copy`` swap
``ops.motion.rotate`` and ``ops.motion.cut``.
"""

from __future__ import annotations

import copy

import numpy as np

__all__ = ["FIXES", "check_fixes", "walk_patches"]

#: The fixes of the walk that upstream made after 0.0.4 (module docstring), in the order they are named.
FIXES = ("output_rate", "blend_source", "rigid_turn", "cut_copy")


def check_fixes(fixes) -> tuple:
    """``fixes`` as a tuple, each one of :data:`FIXES` (else ValueError)."""
    fixes = tuple(fixes)
    unknown = [f for f in fixes if f not in FIXES]
    if unknown:
        raise ValueError(f"fairmotion fixes {unknown} unknown; choose from {list(FIXES)}")
    return fixes


def walk_patches(motion_ops, fixes, blend_sources: list):
    """What one walk swaps into fairmotion's ``ops.motion`` (``motion_ops``) with the fixes ``fixes`` (checked,
    :func:`check_fixes`).

    Parameters
    ----------
    motion_ops : module, fairmotion's ``ops.motion``
    fixes : tuple of str, the fixes of :data:`FIXES` to apply
    blend_sources : list, to which the recorder of ``blend`` appends the root position (3,) of every blend's
        source pose

    Returns
    -------
    pieces : list, to which the recorder of ``append_and_blend`` appends ``(first output frame, frames, blended)``
        of every appended piece
    swap : dict ``{name: replacement}`` of ``ops.motion`` functions (``append_and_blend`` and ``blend`` always,
        ``rotate`` with ``rigid_turn``, ``cut`` with ``cut_copy``)
    """
    from fairmotion.ops import conversions

    original = motion_ops.append_and_blend
    original_blend = motion_ops.blend
    pieces = []

    def recorder(motion1, motion2, blend_length=0):
        if "output_rate" in fixes and motion1.num_frames() == 0:
            # fix: the empty output motion takes the appended pieces' rate (released: its default 60 fps)
            motion1.fps, motion1.fps_inv = motion2.fps, 1.0 / motion2.fps
        if "blend_source" in fixes and motion1.num_frames() > 0:
            # fix: the blend's source time starts at frame_source / fps (released: fps * frame_source)
            frame_source = motion1.time_to_frame(motion1.length() - blend_length)
            shift = motion1.fps * frame_source - frame_source / motion1.fps
            by_time = motion1.get_pose_by_time
            motion1.get_pose_by_time = lambda t: by_time(t - shift)
        try:
            out = original(motion1, motion2, blend_length=blend_length)
        finally:
            motion1.__dict__.pop("get_pose_by_time", None)
        out.__dict__.pop("get_pose_by_time", None)
        pieces.append((out.num_frames() - motion2.num_frames(), motion2.num_frames(), motion1.num_frames() > 0))
        return out

    def blend_recorder(pose1, pose2, alpha=0.5):
        blend_sources.append(np.array(conversions.T2p(pose1.get_root_transform()), float))
        return original_blend(pose1, pose2, alpha)

    def rigid_rotate(motion, R, local=False):
        # fix: turn the piece rigidly about its first pose's root, orientation and path (released: the
        # orientation only, ``transform(local=False)``)
        if local or not motion.poses:
            return motion_ops.transform(motion, conversions.R2T(R), local)
        pivot = np.array(conversions.T2p(motion.poses[0].get_root_transform()), float)
        for pose in motion.poses:
            R0, p0 = conversions.T2Rp(pose.get_root_transform())
            pose.set_root_transform(conversions.Rp2T(np.dot(R, R0), pivot + np.dot(R, p0 - pivot)), local=False)
        return motion

    def copying_cut(motion, frame_start, frame_end):
        # fix: the cut piece's poses are its own copy's (released: the loaded clip's Pose objects themselves,
        # which append_and_blend then moves in place)
        cut_motion = copy.deepcopy(motion)
        cut_motion.name = f"{motion.name}_{frame_start}_{frame_end}"
        cut_motion.poses = cut_motion.poses[frame_start:frame_end]
        if hasattr(cut_motion, "vels"):
            cut_motion.vels = cut_motion.vels[frame_start:frame_end]
        return cut_motion

    swap = {"append_and_blend": recorder, "blend": blend_recorder}
    if "rigid_turn" in fixes:
        swap["rotate"] = rigid_rotate
    if "cut_copy" in fixes:
        swap["cut"] = copying_cut
    return pieces, swap
