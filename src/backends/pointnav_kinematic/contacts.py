"""Contact resolution for the kinematic backend: robots that move together through one sub-step.

Within a sub-step every robot follows a straight chord at constant speed, all robots at the
same time. :func:`advance` moves them all to the earliest moment at which one would overlap
a wall or another robot (found exactly by sweeping the discs, so nothing tunnels at any
speed), resolves the contacts there and carries on with what is left of the sub-step:

- a robot whose own motion goes into a contact slides along it (the part of its velocity
  tangent to the contact, if that is clear of every other contact) or, in ``"stop"`` mode,
  stops; both parties' contact flags are set;
- a motion that does not go into an obstacle (driving parallel along a wall the disc
  touches, or away from it) is not a contact;
- two robots closing on each other stop where they first touch, each having moved under its
  own motion until then, so the gap between them is split by their speeds.

Tolerances, in metres: a motion hits something only when it would overlap it by more than
``_HIT``; a blocked robot is placed ``_PLACE`` short of touching; anything within
``_ACTIVE`` of touching is a contact that later motion must respect. A disc resting exactly
against a wall (clearance ``r``) can therefore drive along it without ever hitting it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from pointnav_kinematic.geometry import enter_disc, enter_wall, wall_distance

__all__ = ["advance"]

_HIT = 0.5e-9
_PLACE = 1.0e-9
_ACTIVE = 2.0e-9
_EVENTS_PER_ROBOT = 8  # contacts resolved per robot and sub-step before the rest is dropped


def _hit_radius(radius: float) -> float:
    # A point robot is a disc of _HIT: it may not cross a polygon edge of zero thickness.
    return max(radius - _HIT, _HIT)


def advance(robots: Sequence[Any], stop: bool) -> None:
    """Move every robot by its chord over one sub-step, resolving contacts on the way.

    Parameters
    ----------
    robots : sequence of robot states
        Objects with float attributes ``x``, ``y``, ``radius``, ``mx``, ``my`` (the chord:
        displacement over the whole sub-step, in metres), ``floor``, ``geom`` (their
        :class:`~pointnav_kinematic.geometry.FloorGeometry`) and the flags ``contact`` and
        ``stopped``, which are set here. None of them may be falling. Robots without
        motion still block the others.
    stop : bool
        Whether a blocked robot stops for the rest of the step (``"stop"`` mode) instead of
        sliding.
    """
    moving = [rb for rb in robots if rb.mx != 0.0 or rb.my != 0.0]
    if not moving:
        return
    # Sliding only shortens motion, so a robot stays within its chord's length of where it
    # started: one wall query per robot covers the whole sub-step.
    span = {}
    for rb in robots:
        span[id(rb)] = math.hypot(rb.mx, rb.my)
    for rb in moving:
        reach = rb.radius + span[id(rb)] + 4.0 * _ACTIVE
        rb.walls = rb.geom.walls(rb.x - reach, rb.y - reach, rb.x + reach, rb.y + reach)
    pairs = []
    for i, a in enumerate(robots):
        for b in robots[i + 1 :]:
            if a.floor != b.floor or (span[id(a)] == 0.0 and span[id(b)] == 0.0):
                continue
            reach = a.radius + b.radius + span[id(a)] + span[id(b)] + 4.0 * _ACTIVE
            if (a.x - b.x) ** 2 + (a.y - b.y) ** 2 < reach * reach:
                pairs.append((a, b))
    start = [(rb.x, rb.y) for rb in moving]
    left = 1.0  # fraction of the sub-step still to go
    # Contacts the robots rest against already: slide along them (or stop) before sweeping.
    _resolve(moving, pairs, left, (None, None), stop)
    for _ in range(_EVENTS_PER_ROBOT * len(moving)):
        t_first, event = _first_hit(moving, pairs, left)
        if event is None:
            for rb in moving:
                rb.x += rb.mx * left
                rb.y += rb.my * left
            left = 0.0
            break
        t = min(max(_place_time(event), 0.0), t_first)
        for rb in moving:
            rb.x += rb.mx * t
            rb.y += rb.my * t
        left -= t
        _resolve(moving, pairs, left, event, stop)
    # Anything left after that many contacts is dropped: the robots stay where they are.
    for rb, (x0, y0) in zip(moving, start):
        if rb.contact and (rb.x != x0 or rb.y != y0):
            _undo_if_deeper(rb, x0, y0)


def _first_hit(
    moving: list[Any], pairs: list[tuple[Any, Any]], left: float
) -> tuple[float, tuple[Any, Any] | None]:
    """Earliest time (fraction of the sub-step) within ``left`` at which anything hits."""
    t_first = left
    event = None
    for rb in moving:
        mx, my = rb.mx, rb.my
        if mx == 0.0 and my == 0.0:
            continue
        x, y = rb.x, rb.y
        hit_r = _hit_radius(rb.radius)
        speed = math.hypot(mx, my)
        for wall in rb.walls:
            # Walls are convex: moving along their outward normal never brings the disc
            # closer (that includes leaving an overlap), and a wall farther than the motion
            # reaches is out of play. Both are cheaper to rule out than to sweep.
            dist, nx, ny = wall_distance(x, y, wall)
            if mx * nx + my * ny >= 0.0 or dist - hit_r > speed * t_first:
                continue
            t = enter_wall(x, y, mx, my, wall, hit_r)
            if t < t_first:
                t_first, event = t, (rb, wall)
    for a, b in pairs:
        vx, vy = a.mx - b.mx, a.my - b.my
        if vx == 0.0 and vy == 0.0:
            continue
        t = enter_disc(a.x, a.y, vx, vy, b.x, b.y, _hit_radius(a.radius + b.radius))
        if t < t_first:
            if t == 0.0 and (a.x - b.x) * vx + (a.y - b.y) * vy >= 0.0:
                continue
            t_first, event = t, (a, b)
    return t_first, event


def _place_time(event: tuple[Any, Any]) -> float:
    """When the event's parties come within ``_PLACE`` of touching (0 if they are already)."""
    rb, other = event
    if isinstance(other, tuple):
        return enter_wall(rb.x, rb.y, rb.mx, rb.my, other, rb.radius + _PLACE)
    return enter_disc(
        rb.x, rb.y, rb.mx - other.mx, rb.my - other.my, other.x, other.y,
        rb.radius + other.radius + _PLACE,
    )


def _resolve(
    moving: list[Any], pairs: list[tuple[Any, Any]], left: float, event: tuple[Any, Any], stop: bool
) -> None:
    """Slide or stop every robot whose remaining motion goes into a contact it touches."""
    for rb in moving:
        mx, my = rb.mx, rb.my
        if mx == 0.0 and my == 0.0:
            continue
        contacts = _contacts(rb, pairs, event)
        blocked = [c for c in contacts if _blocks(rb, c, mx, my, left)]
        if not blocked:
            continue
        rb.contact = True
        for c in blocked:
            if c[2] is not None and not isinstance(c[2], tuple):
                c[2].contact = True  # the robot it ran into
        if stop:
            rb.mx = rb.my = 0.0
            rb.stopped = True
            continue
        rb.mx, rb.my = _slide(rb, mx, my, blocked, contacts, left)


def _contacts(rb: Any, pairs: list[tuple[Any, Any]], event: tuple[Any, Any]) -> list[tuple]:
    """Walls and robots within ``_ACTIVE`` of touching ``rb``: ``(nx, ny, what, forced)``.

    ``(nx, ny)`` is the unit normal pointing from the contact to ``rb``; ``what`` is the
    wall tuple or the other robot; ``forced`` marks the contact of the event just reached,
    which blocks an inward motion however shallow.
    """
    x, y, r = rb.x, rb.y, rb.radius
    out = []
    for wall in rb.walls:
        dist, nx, ny = wall_distance(x, y, wall)
        if dist <= r + _ACTIVE:
            out.append((nx, ny, wall, event[0] is rb and event[1] is wall))
    for a, b in pairs:
        if a is rb:
            other = b
        elif b is rb:
            other = a
        else:
            continue
        ex, ey = x - other.x, y - other.y
        dist = math.hypot(ex, ey)
        if dist <= r + other.radius + _ACTIVE:
            normal = (ex / dist, ey / dist) if dist > 0.0 else (1.0, 0.0)
            forced = event in ((rb, other), (other, rb))
            out.append((*normal, other, forced))
    return out


def _blocks(rb: Any, contact: tuple, mx: float, my: float, left: float) -> bool:
    """Whether motion (mx, my) per sub-step, for ``left`` of it, goes into ``contact``.

    Into means towards it and, over what is left of the sub-step, deeper than ``_HIT`` into
    it: a motion along a wall the disc touches, or one that only grazes a corner, is free.
    Other robots count as standing still here: each robot answers for its own motion.
    """
    nx, ny, what, forced = contact
    if mx * nx + my * ny >= 0.0:
        return False
    if forced:
        return True
    if isinstance(what, tuple):
        t = enter_wall(rb.x, rb.y, mx, my, what, _hit_radius(rb.radius))
    else:
        t = enter_disc(rb.x, rb.y, mx, my, what.x, what.y, _hit_radius(rb.radius + what.radius))
    return t <= left


def _slide(
    rb: Any, mx: float, my: float, blocked: list[tuple], contacts: list[tuple], left: float
) -> tuple[float, float]:
    """The longest tangent of a contact that goes into no contact, else zero.

    In 2D the best motion that keeps clear of all contacts lies on one contact's tangent,
    or is zero (a concave corner). That contact need not be one the motion goes into: in a
    passage exactly as wide as the disc, a motion that grazes one side into the corner of
    the other is saved by the tangent of the side it grazes.
    """
    best = (0.0, 0.0)
    best_len = 0.0
    for along in contacts:
        nx, ny = along[0], along[1]
        dot = mx * nx + my * ny
        tx, ty = mx - dot * nx, my - dot * ny
        length = tx * tx + ty * ty
        if length <= best_len:
            continue
        # The tangent runs along its own contact by construction, rounding aside.
        if all(c is along or not _blocks(rb, c, tx, ty, left) for c in contacts):
            best, best_len = (tx, ty), length
    return best


def _undo_if_deeper(rb: Any, x0: float, y0: float) -> None:
    """Safety net against rounding: never end a sub-step deeper in a wall than it began."""
    r = rb.radius
    depth = max((r - wall_distance(rb.x, rb.y, w)[0] for w in rb.walls), default=-math.inf)
    if depth > _HIT:
        before = max((r - wall_distance(x0, y0, w)[0] for w in rb.walls), default=-math.inf)
        if depth > before:
            rb.x, rb.y = x0, y0
