"""A generic kinematic skeleton shared by the ASF/AMC and BVH readers.

Conventions (the Acclaim ones, which BVH maps onto losslessly):

* Every joint has a rest-pose ``offset``: where the joint *starts* relative to
  the start of its parent, in world axes at rest. For an ASF bone this is the
  parent bone's ``direction * length``; for a BVH joint it is its ``OFFSET``.
* ``tail`` is where the joint's segment *ends* relative to its start (ASF:
  ``direction * length``; BVH: the first child's offset or the End Site).
* ``axis`` (degrees, ``axis_order`` e.g. ``"XYZ"``) is the ASF local frame C.
  The local rotation of a joint is ``L = C @ M @ C^-1`` where ``M`` is built
  from the joint's rotational DOF values (degrees) as an *extrinsic* Euler
  rotation in the order the DOF are listed (Acclaim convention: ``rx ry rz``
  gives ``M = Rz Ry Rx``).
* Any joint may have translation DOF (``tx ty tz``, BVH position channels on
  any joint): its translation from the parent is then ``T_j = offset_j + t_j``
  per frame (for the root, ``T`` is its world position), else ``offset_j``.
* World rotation ``W_j = W_parent @ L_j``; world start of a joint
  ``s_j = s_parent + W_parent @ T_j``; world end ``e_j = s_j + W_j @ tail_j``.
* The world frame the studies use is Y up, Z forward
  (:mod:`animsynth.kinematics`); the data layer turns a file in another frame
  into it.
* A motion is a ``(frames, n_dof)`` array whose columns are
  :meth:`Skeleton.columns`: joints in :attr:`Skeleton.joints` order, each
  joint's DOF in its listed order, named ``"<joint>.<dof>"`` (``root.tx`` ...).
  For the CMU skeleton the root's 6 DOF come first, so dropping the first six
  columns gives the 56 joint angles that Gauch & Peters use.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

ROT_DOFS = ("rx", "ry", "rz")
TRANS_DOFS = ("tx", "ty", "tz")

#: Bone order of CMU AMC files (and hence of the 62 columns), root first.
CMU_BONE_ORDER = (
    "root", "lowerback", "upperback", "thorax", "lowerneck", "upperneck", "head",
    "rclavicle", "rhumerus", "rradius", "rwrist", "rhand", "rfingers", "rthumb",
    "lclavicle", "lhumerus", "lradius", "lwrist", "lhand", "lfingers", "lthumb",
    "rhipjoint", "rfemur", "rtibia", "rfoot", "rtoes",
    "lhipjoint", "lfemur", "ltibia", "lfoot", "ltoes",
)
# (rhipjoint/lhipjoint have no DOF: they appear in no AMC line and no column.)


@dataclass
class Joint:
    """One joint (ASF bone or BVH joint). See the module docstring."""

    name: str
    parent: int
    offset: np.ndarray
    tail: np.ndarray
    dofs: list[str] = field(default_factory=list)
    axis: np.ndarray = field(default_factory=lambda: np.zeros(3))
    axis_order: str = "XYZ"
    limits: list[tuple[float, float]] = field(default_factory=list)
    direction: np.ndarray | None = None  # ASF unit direction (None for BVH joints)
    length: float | None = None  # ASF length

    @property
    def rot_dofs(self) -> list[str]:
        return [d for d in self.dofs if d in ROT_DOFS]

    def axis_rotation(self) -> Rotation:
        """The ASF local frame C as a rotation (extrinsic, in ``axis_order``)."""
        return Rotation.from_euler(self.axis_order.lower(), self.axis, degrees=True)


@dataclass
class Skeleton:
    """A tree of joints in topological order (every parent before its children).

    Attributes
    ----------
    joints : list of Joint
    length_to_m : float
        Factor converting lengths (offsets, root translation) to metres.
    angle_unit : str
        ``"deg"``: angles held by the skeleton (axis frames) and by motions on
        it are always degrees.
    name : str
    file_angle_unit : str
        ``"deg"`` or ``"rad"``: the angle unit the source file declared (ASF
        ``:units angle``). An AMC file without a ``:DEGREES`` / ``:RADIANS``
        header is read in this unit.
    roles : dict of str -> str
        Joint-role overrides ``{role: joint name}`` (config ``joint_roles``);
        see :mod:`animsynth.joints`.
    """

    joints: list[Joint]
    length_to_m: float = 1.0
    angle_unit: str = "deg"
    name: str = "skeleton"
    file_angle_unit: str = "deg"
    roles: dict = field(default_factory=dict)

    def __post_init__(self):
        for i, j in enumerate(self.joints):
            if j.parent >= i:
                raise ValueError(f"joint {j.name!r} comes before its parent")
        self._index = {j.name: i for i, j in enumerate(self.joints)}

    # -- lookup ---------------------------------------------------------
    @property
    def names(self) -> list[str]:
        return [j.name for j in self.joints]

    def index(self, name: str) -> int:
        try:
            return self._index[name]
        except KeyError:
            raise KeyError(f"skeleton {self.name!r} has no joint {name!r}") from None

    def __getitem__(self, name: str) -> Joint:
        return self.joints[self.index(name)]

    def parents(self) -> np.ndarray:
        return np.array([j.parent for j in self.joints], dtype=int)

    def columns(self) -> list[str]:
        """Names of the DOF columns of a motion on this skeleton, in order."""
        return [f"{j.name}.{d}" for j in self.joints for d in j.dofs]

    @property
    def n_dof(self) -> int:
        return sum(len(j.dofs) for j in self.joints)

    def dof_slices(self) -> dict[str, slice]:
        """Column slice of each joint's DOF in a motion array."""
        out, k = {}, 0
        for j in self.joints:
            out[j.name] = slice(k, k + len(j.dofs))
            k += len(j.dofs)
        return out

    def children(self, i: int) -> list[int]:
        return [k for k, j in enumerate(self.joints) if j.parent == i]

    # -- serialisation (stored inside parsed-trial .npz files) ----------
    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "length_to_m": self.length_to_m,
            "angle_unit": self.angle_unit,
            "file_angle_unit": self.file_angle_unit,
            "roles": dict(self.roles),
            "joints": [
                {
                    "name": j.name,
                    "parent": j.parent,
                    "offset": np.asarray(j.offset, float).tolist(),
                    "tail": np.asarray(j.tail, float).tolist(),
                    "dofs": list(j.dofs),
                    "axis": np.asarray(j.axis, float).tolist(),
                    "axis_order": j.axis_order,
                    "limits": [list(map(float, lim)) for lim in j.limits],
                    "direction": None if j.direction is None else np.asarray(j.direction, float).tolist(),
                    "length": j.length,
                }
                for j in self.joints
            ],
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Skeleton":
        joints = [
            Joint(
                name=j["name"],
                parent=int(j["parent"]),
                offset=np.asarray(j["offset"], float),
                tail=np.asarray(j["tail"], float),
                dofs=list(j["dofs"]),
                axis=np.asarray(j["axis"], float),
                axis_order=j["axis_order"],
                limits=[tuple(x) for x in j["limits"]],
                direction=None if j.get("direction") is None else np.asarray(j["direction"], float),
                length=j.get("length"),
            )
            for j in d["joints"]
        ]
        return cls(joints, float(d["length_to_m"]), d.get("angle_unit", "deg"), d.get("name", "skeleton"),
                   d.get("file_angle_unit", "deg"), dict(d.get("roles") or {}))

    def to_json(self) -> str:
        return json.dumps(self.to_dict())

    @classmethod
    def from_json(cls, s: str) -> "Skeleton":
        return cls.from_dict(json.loads(s))
