"""Swept-disc contact tests against axis-aligned squares, as array functions.

The batched twins of :mod:`pointnav_kinematic.geometry`'s scalar ``enter_box``,
``enter_disc``, ``enter_rounded_square`` and ``square_distance``: the same formulas, one
element per (robot, wall) pair, so that the batched engine finds the same contacts as the
kinematic backend. Every function takes arrays that broadcast together and an array
namespace ``xp`` (numpy or torch, see :mod:`pointnav_core.vector.xp`); distances are in
metres and times are fractions of the motion ``d``.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["enter_box", "enter_disc", "enter_rounded_square", "square_distance"]

_INF = math.inf


def _safe(xp: Any, d: Any) -> Any:
    # A divisor that is never 0; the quotients it gives are masked out where d == 0.
    return xp.where(d != 0.0, d, 1.0)


def enter_box(xp: Any, px: Any, py: Any, dx: Any, dy: Any, x0: Any, y0: Any, x1: Any, y1: Any) -> Any:
    """First ``t >= 0`` at which ``p + t*d`` is in the open box ``(x0, x1) x (y0, y1)``; inf if never."""
    sx, sy = _safe(xp, dx), _safe(xp, dy)
    ax, bx = (x0 - px) / sx, (x1 - px) / sx
    ay, by = (y0 - py) / sy, (y1 - py) / sy
    movex, movey = dx != 0.0, dy != 0.0
    lo = xp.where(movex, xp.minimum(ax, bx), -_INF)
    hi = xp.where(movex, xp.maximum(ax, bx), _INF)
    lo = xp.where(movey, xp.maximum(lo, xp.minimum(ay, by)), lo)
    hi = xp.where(movey, xp.minimum(hi, xp.maximum(ay, by)), hi)
    inside_x = movex | ((x0 < px) & (px < x1))
    inside_y = movey | ((y0 < py) & (py < y1))
    ok = inside_x & inside_y & (lo < hi) & (hi > 0.0)
    return xp.where(ok, xp.maximum(lo, xp.zeros_like(lo)), _INF)


def enter_disc(xp: Any, px: Any, py: Any, dx: Any, dy: Any, cx: Any, cy: Any, radius: Any) -> Any:
    """First ``t >= 0`` at which ``p + t*d`` is in the open disc ``|q - c| < radius``; inf if never."""
    fx, fy = px - cx, py - cy
    c = fx * fx + fy * fy - radius * radius
    b = fx * dx + fy * dy
    a = dx * dx + dy * dy
    disc = b * b - a * c
    root = xp.sqrt(xp.maximum(disc, xp.zeros_like(disc)))
    denom = -b + root
    t = c / xp.where(denom != 0.0, denom, 1.0)
    t = xp.where((b >= 0.0) | (disc <= 0.0), _INF, t)
    return xp.where(c < 0.0, 0.0, t)


def enter_rounded_square(
    xp: Any, px: Any, py: Any, dx: Any, dy: Any, x0: Any, y0: Any, x1: Any, y1: Any, radius: Any
) -> Any:
    """First ``t >= 0`` at which a disc of ``radius`` at ``p + t*d`` overlaps the square; inf if never.

    ``radius`` (m) is a float or an array that broadcasts with the others (one per robot).
    """
    t = xp.minimum(
        enter_box(xp, px, py, dx, dy, x0 - radius, y0, x1 + radius, y1),
        enter_box(xp, px, py, dx, dy, x0, y0 - radius, x1, y1 + radius),
    )
    if isinstance(radius, (int, float)) and radius <= 0.0:
        return t  # a point robot: the square itself, no rounded corners
    corners = t
    for cx, cy in ((x0, y0), (x1, y0), (x0, y1), (x1, y1)):
        corners = xp.minimum(corners, enter_disc(xp, px, py, dx, dy, cx, cy, radius))
    return xp.where((t > 0.0) & (radius > 0.0), corners, t)


def square_distance(xp: Any, px: Any, py: Any, x0: Any, y0: Any, x1: Any, y1: Any) -> tuple[Any, Any, Any]:
    """Signed distance (m, negative inside) from points to squares, and the outward unit normal."""
    qx = xp.minimum(xp.maximum(px, x0), x1)
    qy = xp.minimum(xp.maximum(py, y0), y1)
    vx, vy = px - qx, py - qy
    dist = xp.sqrt(vx * vx + vy * vy)
    out = dist > 0.0
    safe = xp.where(out, dist, 1.0)
    nx, ny = vx / safe, vy / safe
    if bool(out.all()):  # the common case: no point on or in a square
        return dist, nx, ny
    # Inside or on the boundary: leave through the nearest face (the first of a tie).
    faces = xp.stack([px - x0, x1 - px, py - y0, y1 - py], -1)
    face = xp.argmin(faces, -1)
    depth = xp.amin(faces, -1)
    fnx = xp.where(face == 0, -1.0, xp.where(face == 1, 1.0, 0.0 * depth))
    fny = xp.where(face == 2, -1.0, xp.where(face == 3, 1.0, 0.0 * depth))
    return xp.where(out, dist, -depth), xp.where(out, nx, fnx), xp.where(out, ny, fny)
