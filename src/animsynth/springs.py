"""Critically damped springs, as in Holden's motion-matching reference: motion matching's inertialization and
trajectory, and foot locking's blend back, move offsets, angles and positions in time with them."""

from __future__ import annotations

import numpy as np

from .kinematics import wrap_radians

LN2 = float(np.log(2.0))


def halflife_to_damping(halflife: float) -> float:
    """Damping of the reference's critically damped spring of half-life ``halflife`` seconds: ``4 ln 2 / halflife``
    (its envelope ``e^(-damping t / 2)`` halves in half a half-life; from rest the offset is 0.597 of its start
    after one half-life, :func:`decay_spring`)."""
    return 4.0 * LN2 / float(halflife)


def decay_spring(x, v, halflife: float, dt: float):
    """A critically damped spring towards zero after ``dt`` seconds: ``(x, v)`` of offset and its velocity.

    With ``y = damping / 2`` and ``j = v0 + y x0``: ``x(t) = e^(-y t) (x0 + j t)``, ``v(t) = e^(-y t) (v0 - j y t)``.
    After one half-life from rest the offset is ``(1 + 2 ln 2) / 4 = 0.597`` of where it started.
    """
    y = halflife_to_damping(halflife) / 2.0
    x = np.asarray(x, float)
    v = np.asarray(v, float)
    j = v + x * y
    e = np.exp(-y * dt)
    return e * (x + j * dt), e * (v - j * y * dt)


def spring_angle(x, v, goal, halflife: float, dt):
    """Angle after ``dt`` seconds (any shape broadcasting) of a critically damped spring from ``x`` (radians,
    rate ``v``) to ``goal`` the shortest way round: :func:`decay_spring` of the wrapped offset ``x - goal``."""
    offset = wrap_radians(x - goal)
    return decay_spring(offset, v, halflife, dt)[0] + x - offset


def spring_position(x, v, a, goal_velocity, halflife: float, dt):
    """Position after ``dt`` seconds (any shape broadcasting) of the reference's velocity spring: a point at
    ``x`` with velocity ``v`` and acceleration ``a`` whose velocity is drawn to ``goal_velocity`` by a
    critically damped spring of half-life ``halflife``."""
    y = halflife_to_damping(halflife) / 2.0
    dt = np.asarray(dt, float)
    j0 = np.asarray(v, float) - goal_velocity
    j1 = np.asarray(a, float) + j0 * y
    e = np.exp(-y * dt)
    return (e * (-j1 / y ** 2 + (-j0 - j1 * dt) / y) + j1 / y ** 2 + j0 / y + goal_velocity * dt + x)
