"""The :class:`Motion` container shared by the readers and every family.

A motion is a ``(frames, n_dof)`` float array on a
:class:`~animsynth.skeleton.Skeleton` whose columns are
``skeleton.columns()`` (for CMU: 62 columns, the 6 root DOF first, then the 56
joint angles in CMU AMC bone order), plus its frame rate and a name.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .atomic import atomic_path
from .errors import MotionFormatError
from .skeleton import Skeleton


@dataclass
class Motion:
    """A motion on a skeleton.

    Attributes
    ----------
    values : ndarray, shape (frames, n_dof)
        DOF values: translations in skeleton length units, angles in degrees.
    skeleton : Skeleton
    fps : float
    name : str
    meta : dict
    """

    values: np.ndarray
    skeleton: Skeleton
    fps: float = 120.0
    name: str = ""
    meta: dict = field(default_factory=dict)

    @property
    def columns(self) -> list[str]:
        return self.skeleton.columns()

    @property
    def n_frames(self) -> int:
        return int(self.values.shape[0])

    def without_root(self) -> np.ndarray:
        """The joint DOF with the root joint's dropped (CMU: the 56 joint angles; a BVH joint other than the
        root with translation DOF keeps them here, in skeleton length units)."""
        n_root = len(self.skeleton.joints[0].dofs)
        return self.values[:, n_root:]

    # -- .npz storage used between workflow rules -------------------------
    def save_npz(self, path) -> None:
        with atomic_path(path, suffix=".npz") as tmp:
            np.savez_compressed(
                tmp,
                values=self.values,
                columns=np.array(self.columns),
                fps=np.float64(self.fps),
                name=np.array(self.name),
                skeleton=np.array(self.skeleton.to_json()),
            )

    @classmethod
    def load_npz(cls, path) -> "Motion":
        with np.load(path, allow_pickle=False) as z:
            sk = Skeleton.from_json(str(z["skeleton"]))
            m = cls(np.array(z["values"], float), sk, float(z["fps"]), str(z["name"]))
            if list(z["columns"]) != sk.columns():
                raise MotionFormatError(path, None, "stored columns do not match the stored skeleton")
        return m
