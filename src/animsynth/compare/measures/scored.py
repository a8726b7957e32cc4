"""What a measure is given: one generated motion with the intermediates its measures share (:class:`ScoredMotion`),
or one run of a generator on a clip, every seed (:class:`RunOutputs`).

Every intermediate is computed on first use and kept for the other measures of the same motion: forward
kinematics runs once per motion for every measure that reads positions or world rotations, the pose features once
for the window, novelty, repetition and diversity measures, and so on. This is the pattern of scikit-learn's
multimetric scorer (``sklearn.metrics._scorer._MultimetricScorer``), which calls an estimator's ``predict`` once for
every scorer that needs it; here the cached values are the motion's, not an estimator's predictions.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

__all__ = ["ScoredMotion", "RunOutputs"]


class ScoredMotion:
    """One generated motion joined to the start it continues, and what its measures share.

    Parameters
    ----------
    clip : animsynth.compare.protocol.Clip
        The held-out clip the motion continues (its start, its database, its held-out frames).
    ref : animsynth.compare.scoring.Reference
        The clip's database side, computed once per clip.
    motion : Motion
        The generated frames (without the start), at the clip's rate.
    generator : str
        The generator's name.
    mcfg : dict
        The ``compare.metrics`` block.
    roles : dict, optional
        Joint-role overrides (config ``joint_roles``).
    entry_seam : bool
        Whether the entry (generated frame 0) is a seam: the generator's declared
        :attr:`animsynth.generator.Generator.entry_seam` (every generator but the replay of the capture).

    Attributes
    ----------
    fps : float
    context : int, the start frames (the generated frame ``t`` is frame ``context + t`` of :attr:`pos`)
    n_frames : int, the generated frames
    """

    def __init__(self, clip, ref, motion, generator: str, mcfg: dict, roles: dict | None = None,
                 entry_seam: bool = True):
        self.clip, self.ref, self.motion, self.generator = clip, ref, motion, generator
        self.entry_seam = bool(entry_seam)
        self.mcfg, self.roles = mcfg, roles
        self.fps = float(motion.fps)
        self.context = int(clip.context)
        self.n_frames = int(motion.n_frames)
        self._shared: dict = {}

    def setting(self, key: str) -> float:
        """The ``compare.metrics`` value ``key`` as a float."""
        return float(self.mcfg[key])

    @cached_property
    def joined(self):
        """The start and the generated frames as one Motion, shape (context + n_frames, n_dof)."""
        from ...motion import Motion

        m = self.motion
        return Motion(np.vstack([self.clip.start.values, m.values]), m.skeleton, self.fps, m.name)

    @cached_property
    def _fk(self) -> tuple[np.ndarray, np.ndarray]:
        from .pose import positions_and_quaternions

        j = self.joined
        return positions_and_quaternions(j.skeleton, j.values, start=self.context)

    @property
    def pos(self) -> np.ndarray:
        """Joint positions (m) of the start and the generated frames, shape (context + n_frames, J, 3)."""
        return self._fk[0]

    @property
    def quaternions(self) -> np.ndarray:
        """World rotations of the generated frames, shape (n_frames, J, 4), sign continuous from the first."""
        return self._fk[1]

    @property
    def generated_pos(self) -> np.ndarray:
        """Joint positions (m) of the generated frames, shape (n_frames, J, 3)."""
        return self.pos[self.context:]

    @cached_property
    def seams(self) -> np.ndarray:
        """The seams (generated-frame indices) the generator reports, with the entry (0) when it is one
        (:attr:`entry_seam`)."""
        s = np.asarray(self.motion.meta.get("seams", []), np.int64)
        return np.union1d(s, [0]) if self.entry_seam else s

    @cached_property
    def facing(self) -> np.ndarray:
        """The facing of the start and the generated frames, shape (context + n_frames, 2)."""
        from .pose import facing

        return facing(self.joined, self.roles)

    @cached_property
    def features(self) -> np.ndarray:
        """Pose features of the generated frames (:func:`~.pose.pose_features`), shape (n_frames, 3 J)."""
        from .pose import pose_features

        return pose_features(self.generated_pos, self.facing[self.context:])

    def shared(self, key: str, compute):
        """``compute(self)``, computed once per motion for every measure that asks for ``key`` (an intermediate that
        several measures of one module read, such as the still frames)."""
        if key not in self._shared:
            self._shared[key] = compute(self)
        return self._shared[key]


@dataclass(frozen=True)
class RunOutputs:
    """One generator's run on one clip, every seed: what the records a run gives read (``needs`` ``"generator"``
    and ``"seeds"``).

    Attributes
    ----------
    generator : the fitted generator (:class:`animsynth.generator.Generator`; its :meth:`run_notes`)
    features : list of ndarray, each seed's pose features of its generated frames (:attr:`ScoredMotion.features`)
    """

    generator: object
    features: list
