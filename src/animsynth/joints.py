"""Joint roles: the body parts a study needs, found by role, not by joint name.

Studies that need a body part (the Lee et al. joint-group weights, the foot
metrics of re-sequencing, the global DOF) ask for a *role* and get the joint
of the skeleton that plays it. One name map covers the CMU ASF bone names and
the common BVH conventions; a config override (``joint_roles``, stored on the
skeleton as :attr:`Skeleton.roles`) names the joint of any role explicitly.

A role is the joint whose *rotation* is the body part's (as Lee et al. weight
them) and whose segment *end* is the point the foot metrics track:

===============  ==========  ===========================  =========================
role             CMU ASF     BVH (CMU conversion, Mixamo,  Blender / rigify-style
                             LAFAN1, most exporters)
===============  ==========  ===========================  =========================
pelvis           root        Hips                          hips, pelvis
spine            lowerback   Spine, LowerBack              spine
chest            thorax      Spine1, Spine2, Chest         chest
neck             lowerneck   Neck                          neck
head             head        Head                          head
left_hip         lfemur      LeftUpLeg, LeftThigh          thigh.L, upper_leg.L
left_knee        ltibia      LeftLeg, LeftShin             shin.L, lower_leg.L
left_ankle       lfoot       LeftFoot                      foot.L
left_toe         ltoes       LeftToeBase, LeftToe          toe.L
left_shoulder    lhumerus    LeftArm, LeftUpArm, lShldr    upper_arm.L
left_elbow       lradius     LeftForeArm                   forearm.L, lower_arm.L
left_wrist       lwrist      LeftHand                      hand.L
===============  ==========  ===========================  =========================

and the same with ``right_`` / ``r`` / ``Right`` / ``.R``. Note that the BVH
joint ``LeftShoulder`` is the *clavicle* (CMU ``lclavicle``); the shoulder
joint is ``LeftArm``. In cgspeed's 3ds Max-friendly CMU conversions
(``LeftCollar``, ``LeftShoulder``, ``LeftElbow``) ``LeftShoulder`` is the upper
arm: name it with ``joint_roles`` (config/cmu.yaml does for 131). Names match case-insensitively, after dropping a
namespace prefix (``mixamorig:LeftArm``) and the separators ``_ - . space``
(``upper_arm.L`` = ``upperarml``). ``pelvis`` falls back to the skeleton's
root joint. Anything else that does not resolve raises :class:`JointRoleError`
naming the role, the names looked for and the joints available.
"""

from __future__ import annotations

import re

__all__ = ["ROLES", "FOOT_ROLES", "JointRoleError", "resolve_role", "resolve_roles", "check_role_overrides", "normalise_name"]


class JointRoleError(ValueError):
    """A role has no joint in the skeleton (the message names the role and the joints available)."""


_SIDED = {
    "hip": ["{s}femur", "{side}upleg", "{side}thigh", "{side}upperleg", "{side}hip", "thigh{s}", "upperleg{s}",
            "{s}thigh", "{s}upleg", "{s}upperleg"],
    "knee": ["{s}tibia", "{side}leg", "{side}shin", "{side}lowerleg", "{side}knee", "{side}calf", "shin{s}",
             "lowerleg{s}", "calf{s}", "{s}shin", "{s}lowerleg", "{s}knee", "{s}calf", "{s}leg"],
    "ankle": ["{s}foot", "{side}foot", "{side}ankle", "foot{s}", "ankle{s}", "{s}ankle"],
    "toe": ["{s}toes", "{side}toebase", "{side}toe", "{side}toes", "{side}toeend", "toe{s}", "toes{s}", "{s}toe",
            "{s}toebase"],
    "shoulder": ["{s}humerus", "{side}arm", "{side}uparm", "{side}upperarm", "upperarm{s}", "uparm{s}",
                 "{s}upperarm", "{s}uparm", "{s}humerus", "{s}shldr", "{side}shldr"],
    "elbow": ["{s}radius", "{side}forearm", "{side}lowerarm", "{side}elbow", "forearm{s}", "lowerarm{s}",
              "{s}forearm", "{s}lowerarm", "{s}elbow"],
    "wrist": ["{s}wrist", "{side}hand", "{side}wrist", "hand{s}", "wrist{s}", "{s}hand"],
}
_CENTRE = {
    "pelvis": ["root", "hips", "pelvis", "hip"],
    "spine": ["lowerback", "spine", "abdomen", "spine0"],
    "chest": ["thorax", "chest", "spine1", "spine2", "upperchest", "upperback"],
    "neck": ["lowerneck", "neck", "neck1"],
    "head": ["head"],
}

#: Every role and the normalised joint names that play it, in order of preference.
ROLES: dict[str, tuple[str, ...]] = dict((k, tuple(v)) for k, v in _CENTRE.items())
for _part, _pats in _SIDED.items():
    for _s, _side in (("l", "left"), ("r", "right")):
        ROLES[f"{_side}_{_part}"] = tuple(p.format(s=_s, side=_side) for p in _pats)

#: The roles every foot metric tracks (re-sequencing's foot skate, compare's skating and contacts), in this
#: order: the end of the ankle's segment is the ball of the foot, the end of the toe's the toe tip.
FOOT_ROLES = ("left_ankle", "left_toe", "right_ankle", "right_toe")


def normalise_name(name: str) -> str:
    """Joint name as matched against :data:`ROLES`: namespace dropped, lower case, no ``_ - . space``."""
    return re.sub(r"[\s_.\-]+", "", str(name).rsplit(":", 1)[-1].rsplit("|", 1)[-1]).lower()


def _names_and_overrides(skeleton_or_names, overrides):
    if hasattr(skeleton_or_names, "joints"):
        names = [j.name for j in skeleton_or_names.joints]
        base = dict(getattr(skeleton_or_names, "roles", None) or {})
    else:
        names, base = list(skeleton_or_names), {}
    base.update(overrides or {})
    return names, base


def check_role_overrides(names, overrides: dict | None, where: str = "joint_roles") -> None:
    """Raise :class:`JointRoleError` for an override of an unknown role or naming a joint not in ``names``.

    ``where`` names the setting: a config key (``"config key joint_roles"``: the message starts
    ``config key joint_roles.ROLE:``) or a command-line option (``"argument --role"``: it starts
    ``argument --role: ROLE=JOINT:``).
    """
    names = list(names)
    for role, joint in (overrides or {}).items():
        label = f"{where}: {role}={joint}" if where.startswith("argument ") else f"{where}.{role}"
        if role not in ROLES:
            raise JointRoleError(f"{label}: unknown joint role {role!r}; roles are {', '.join(ROLES)}")
        if joint not in names:
            raise JointRoleError(f"{label}: the skeleton has no joint {joint!r}; its joints are "
                                 f"{', '.join(names)}")


def resolve_role(skeleton_or_names, role: str, overrides: dict | None = None) -> str:
    """The joint name that plays ``role``.

    Parameters
    ----------
    skeleton_or_names : Skeleton or sequence of str
        A skeleton (its :attr:`roles` overrides apply) or joint names in
        skeleton order (the first is the root).
    role : str
        A key of :data:`ROLES`.
    overrides : dict, optional
        ``{role: joint name}``, applied over the skeleton's own.

    Raises
    ------
    JointRoleError
        Unknown role, an override naming a missing joint, or no joint found.
    """
    if role not in ROLES:
        raise JointRoleError(f"unknown joint role {role!r}; roles are {', '.join(ROLES)}")
    names, ov = _names_and_overrides(skeleton_or_names, overrides)
    if role in ov:
        check_role_overrides(names, {role: ov[role]})
        return ov[role]
    norm = {}
    for n in names:
        norm.setdefault(normalise_name(n), n)
    for cand in ROLES[role]:
        if cand in norm:
            return norm[cand]
    if role == "pelvis" and names:
        return names[0]
    raise JointRoleError(f"no joint for role {role!r} (looked for {', '.join(ROLES[role][:6])}, ...); joints "
                         f"available: {', '.join(names)}; name it with the config key joint_roles.{role} "
                         f"(command line: --role {role}=JOINT)")


def resolve_roles(skeleton_or_names, roles, overrides: dict | None = None) -> list[str]:
    """:func:`resolve_role` for several roles; the joint names in the same order."""
    return [resolve_role(skeleton_or_names, r, overrides) for r in roles]
