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
import logging
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

log = logging.getLogger("animsynth.skeleton")

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


# ---------------------------------------------------------------------------------------------------------------
# is it the same skeleton? (rest offsets, not only joint names and channels)
# ---------------------------------------------------------------------------------------------------------------
#: Two skeletons are the same when every rest offset and End Site agrees within this many metres (after the
#: rest-frame turn of :func:`compare_skeletons`). 1 mm: a file prints offsets to 1e-6 of its unit (1e-6 mm to
#: 1e-3 mm for the units in use), so a re-export of the same skeleton agrees far closer; a difference of 1 mm per
#: bone moves a joint at the end of a 6-bone chain by at most 6 mm, below what the position metrics resolve
#: (they report centimetres), while any real difference of body proportions is larger.
SAME_SKELETON_TOL_M = 1e-3
#: Retargeting keeps each joint's local rotation, which carries the motion over only when the bones point the
#: same way at rest: a bone (both at least :data:`DIRECTION_MIN_M` long) whose rest direction differs by more
#: than this many degrees (after the rest-frame turn) is a different rest pose (A pose against T pose); such a
#: pair is refused.
RETARGET_MAX_ANGLE_DEG = 30.0
#: Bones shorter than this (metres) in either skeleton give no rest direction to compare.
DIRECTION_MIN_M = 0.01


@dataclass
class SkeletonDifference:
    """What :func:`compare_skeletons` found.

    Attributes
    ----------
    joints_match : bool, the same joint names with the same parents (by name)
    why : str, what differs when they do not
    largest_m : float, largest rest offset / End Site difference in metres, after ``turn``
    joint : str, the joint where it is
    turn : Rotation, the rest-frame turn ``Q`` with ``b's offsets ~= Q a's`` (identity unless the rest pose of
        one is the other's turned, as a Blender Z-up export is)
    largest_angle_deg : float, largest angle between the two rest directions of a bone (after ``turn``)
    tol_m : float, the tolerance used
    """

    joints_match: bool
    why: str = ""
    largest_m: float = 0.0
    joint: str = ""
    turn: Rotation = field(default_factory=Rotation.identity)
    largest_angle_deg: float = 0.0
    tol_m: float = SAME_SKELETON_TOL_M

    @property
    def turn_deg(self) -> float:
        return float(np.degrees(self.turn.magnitude()))

    @property
    def same(self) -> bool:
        """The same skeleton (maybe with its rest frame turned): every offset within ``tol_m``."""
        return self.joints_match and self.largest_m <= self.tol_m


def _rest_vectors(sk: Skeleton, names: list[str]) -> np.ndarray:
    """(2 * len(names), 3) metres: every joint's offset (the root's: zero, its translation DOF carry it) and tail."""
    out = []
    for n in names:
        j = sk[n]
        off = np.zeros(3) if j.parent < 0 else np.asarray(j.offset, float)
        out += [off * sk.length_to_m, np.asarray(j.tail, float) * sk.length_to_m]
    return np.asarray(out)


def compare_skeletons(a: Skeleton, b: Skeleton, tol_m: float = SAME_SKELETON_TOL_M) -> SkeletonDifference:
    """Compare two skeletons' joints and rest offsets (in metres, in the canonical frame the loader turned them
    into).

    The joints must have the same names and parents. The rest vectors compared are every non-root joint's
    ``offset`` and every joint's ``tail`` (End Site), times each skeleton's ``length_to_m``; the root's offset
    is left out (its translation DOF carry it). When a single rotation ``Q`` (the best fit, Kabsch) brings
    ``a``'s rest vectors onto ``b``'s within ``tol_m``, or turns by more than :data:`RETARGET_MAX_ANGLE_DEG`
    (the rest pose written in other axes, as Blender's Z-up export writes it: the loader turns the root only,
    the children's offsets stay turned), the difference is measured after ``Q``; otherwise ``Q`` is the
    identity (different bone lengths alone do not turn a rest frame).

    Parameters
    ----------
    a, b : Skeleton
    tol_m : float, metres (default :data:`SAME_SKELETON_TOL_M`)

    Returns
    -------
    SkeletonDifference
    """
    if sorted(a.names) != sorted(b.names):
        only_a = [n for n in a.names if n not in b._index][:3]
        only_b = [n for n in b.names if n not in a._index][:3]
        return SkeletonDifference(False, f"{len(a.names)} joints vs {len(b.names)}; only in the first: "
                                         f"{only_a}, only in the second: {only_b}", tol_m=tol_m)
    parent = lambda sk, n: sk.joints[sk[n].parent].name if sk[n].parent >= 0 else None  # noqa: E731
    moved = [n for n in a.names if parent(a, n) != parent(b, n)]
    if moved:
        return SkeletonDifference(False, f"joint {moved[0]!r} hangs from {parent(a, moved[0])!r} in one and from "
                                         f"{parent(b, moved[0])!r} in the other", tol_m=tol_m)
    names = list(b.names)
    va, vb = _rest_vectors(a, names), _rest_vectors(b, names)

    def largest(Q):
        d = np.linalg.norm(vb - Q.apply(va), axis=1)
        k = int(np.argmax(d)) if d.size else 0
        return (float(d[k]) if d.size else 0.0), (names[k // 2] if d.size else "")

    Q = Rotation.identity()
    big, where = largest(Q)
    if big > tol_m and np.linalg.norm(va) > 0 and np.linalg.norm(vb) > 0:
        fit, _ = Rotation.align_vectors(vb, va)
        fit_big, fit_where = largest(fit)
        if fit_big < big and (fit_big <= tol_m or np.degrees(fit.magnitude()) > RETARGET_MAX_ANGLE_DEG):
            Q, big, where = fit, fit_big, fit_where
    qa = Q.apply(va)
    la, lb = np.linalg.norm(qa, axis=1), np.linalg.norm(vb, axis=1)
    ok = (la >= DIRECTION_MIN_M) & (lb >= DIRECTION_MIN_M)
    cos = np.sum(qa[ok] * vb[ok], axis=1) / (la[ok] * lb[ok])
    angle = float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).max()) if ok.any() else 0.0
    return SkeletonDifference(True, "", big, where, Q, angle, tol_m)


# ---------------------------------------------------------------------------------------------------------------
# one figure for several subjects? (a converter that retargets every subject onto its generic skeleton)
# ---------------------------------------------------------------------------------------------------------------
def shared_figure_pairs(skeletons: dict, subjects: dict, tol_m: float = SAME_SKELETON_TOL_M) -> list[tuple]:
    """Pairs of trials of *different* subjects whose skeletons are the same (:func:`compare_skeletons`).

    Two real people never share every bone length to ``tol_m``; trials of two subjects on one skeleton were
    retargeted onto a generic figure (cgspeed's ``ROOT hip`` BVH release puts every subject on one), so their
    foot heights and skating are the figure's, not the subjects'. Trials of one subject share a skeleton by
    design and are not paired.

    Parameters
    ----------
    skeletons : {trial id: Skeleton}
        Each trial's skeleton as parsed (lengths times its ``length_to_m``, so the unit does not matter).
    subjects : {trial id: subject}
        Every trial of ``skeletons``.
    tol_m : float
        Metres (default :data:`SAME_SKELETON_TOL_M`): every rest offset and End Site within it.

    Returns
    -------
    list of (trial_a, trial_b, largest_m)
        ``trial_a`` before ``trial_b`` in the order of ``skeletons``; ``largest_m`` the largest rest-vector
        difference (metres).
    """
    missing = [t for t in skeletons if t not in subjects]
    if missing:
        raise KeyError(f"trial {missing[0]!r} has a skeleton but no subject")
    trials = list(skeletons)
    names = {t: sorted(skeletons[t].names) for t in trials}
    out = []
    for i, a in enumerate(trials):
        for b in trials[i + 1:]:
            if str(subjects[a]) == str(subjects[b]) or names[a] != names[b]:  # compare_skeletons' first test
                continue
            d = compare_skeletons(skeletons[a], skeletons[b], tol_m)
            if d.same:
                out.append((a, b, float(d.largest_m)))
    return out


def shared_figures(skeletons: dict, subjects: dict, tol_m: float = SAME_SKELETON_TOL_M) -> dict[str, list[str]]:
    """For every subject, the other subjects it shares a skeleton with (:func:`shared_figure_pairs`).

    Returns
    -------
    dict
        ``{subject: sorted list of other subjects}`` for every subject of ``subjects`` (in first-seen order); an
        empty list: the subject is on its own figure (``own``), otherwise on a generic one (``generic``).
    """
    out: dict[str, set] = {str(subjects[t]): set() for t in subjects}
    for a, b, _ in shared_figure_pairs(skeletons, subjects, tol_m):
        out[str(subjects[a])].add(str(subjects[b]))
        out[str(subjects[b])].add(str(subjects[a]))
    return {s: sorted(v) for s, v in out.items()}


def figure_kinds(shared: dict) -> dict[str, str]:
    """``{subject: "own" | "generic"}`` from :func:`shared_figures` (``generic``: it shares its figure)."""
    return {s: ("generic" if others else "own") for s, others in shared.items()}
