"""Batched robot-robot contacts: the robots of each world advance together, as the backend's.

The array twin of the robot-robot part of :func:`pointnav_kinematic.contacts.advance`, for
robots away from walls: within a world, every robot follows its chord at once; the world
moves to the earliest moment at which two robots closing on each other would overlap (by
more than ``_HIT``), places them ``_PLACE`` short of touching, resolves every robot's
contacts there (a blocked motion slides along the longest tangent of a robot contact that
goes into no other one, else stops; both parties' flags are set) and goes on with what is
left. Robots without motion still block the others. As in the backend, a world resolves
at most ``8`` events per moving robot; each world keeps its own clock, so the Python loop
is over event rounds only, never over worlds or robots.

Arrays have leading axes ``(num_worlds, n_robots)``; pair arrays add a second robot axis
``(W, R, R)``, entry ``[w, i, j]`` meaning robot ``i`` against robot ``j``.
"""

from __future__ import annotations

import math
from typing import Any

from pointnav_core.vector.sweep import enter_disc
from pointnav_core.vector.xp import Arrays

__all__ = ["advance_robots"]

_HIT = 0.5e-9
_PLACE = 1.0e-9
_ACTIVE = 2.0e-9
_EVENTS_PER_ROBOT = 8


def _hit_radius(radius: float) -> float:
    return max(radius - _HIT, _HIT)


def advance_robots(
    arrays: Arrays, x: Any, y: Any, mx: Any, my: Any, radius: float, present: Any = None
) -> tuple[Any, Any, Any]:
    """Move every world's robots by their chords ``(mx, my)`` (m), resolving robot contacts.

    Parameters
    ----------
    arrays : Arrays
        The array namespace (numpy or torch) the inputs live in.
    x, y, mx, my : float arrays (W, R)
        Start positions and chords over the step, in metres.
    radius : float
        Every robot's radius (m), >= 0.
    present : bool array (W, R), optional
        Robots that take part; absent ones neither move nor block. Default: all.

    Returns
    -------
    x, y : float arrays (W, R)
        End positions (m).
    contact : bool array (W, R)
        Whether each robot was blocked by, or blocked, another robot.
    """
    a = arrays
    xp = a.xp
    inf = math.inf
    n_worlds, n_robots = x.shape
    if present is None:
        present = xp.ones_like(x) > 0.0
    mx = xp.where(present, mx, 0.0 * mx)
    my = xp.where(present, my, 0.0 * my)
    span = xp.sqrt(mx * mx + my * my)
    moving = span > 0.0
    eye = a.arange(n_robots)
    upper = eye.reshape(1, -1, 1) < eye.reshape(1, 1, -1)
    # The backend's pair list: robots on the floor, not both still, within reach of each other.
    reach = 2.0 * radius + span[:, :, None] + span[:, None, :] + 4.0 * _ACTIVE
    gap2 = (x[:, :, None] - x[:, None, :]) ** 2 + (y[:, :, None] - y[:, None, :]) ** 2
    pair = (
        upper & present[:, :, None] & present[:, None, :]
        & (moving[:, :, None] | moving[:, None, :]) & (gap2 < reach * reach)
    )
    pair = pair | (pair.transpose(1, 2) if a.is_torch else xp.swapaxes(pair, 1, 2))
    hit_r = _hit_radius(2.0 * radius)
    left = xp.ones_like(x[:, 0])
    contact = xp.zeros_like(x) > 1.0
    no_event = xp.zeros_like(gap2) > 1.0

    def resolve(x: Any, y: Any, mx: Any, my: Any, forced: Any, left: Any, active: Any) -> tuple[Any, Any, Any]:
        # Every moving robot of an active world: slide along (or stop at) the robots it
        # touches if its motion goes into one; returns new chords and contact flags.
        ex, ey = x[:, :, None] - x[:, None, :], y[:, :, None] - y[:, None, :]
        dist = xp.sqrt(ex * ex + ey * ey)
        touching = pair & (dist <= 2.0 * radius + _ACTIVE)
        safe = xp.where(dist > 0.0, dist, 1.0)
        nx = xp.where(dist > 0.0, ex / safe, 1.0)
        ny = xp.where(dist > 0.0, ey / safe, 0.0)
        ox, oy = x[:, None, :], y[:, None, :]  # the other robot of each pair

        def blocks(tx: Any, ty: Any) -> Any:
            # (W, R, K) motions of robot i against its contacts j: (W, R, K, R).
            into = tx[..., None] * nx[:, :, None, :] + ty[..., None] * ny[:, :, None, :] < 0.0
            t = enter_disc(
                xp, x[:, :, None, None], y[:, :, None, None], tx[..., None], ty[..., None],
                ox[:, :, None, :], oy[:, :, None, :], hit_r,
            )
            lim = left[:, None, None, None]
            return touching[:, :, None, :] & into & (forced[:, :, None, :] | (t <= lim))

        go = ((mx != 0.0) | (my != 0.0)) & active[:, None]
        blocked = blocks(mx[..., None], my[..., None])[:, :, 0, :] & go[..., None]
        any_blocked = blocked.any(-1)
        hit = any_blocked | blocked.any(1)  # the robot it ran into is in contact too
        dot = mx[..., None] * nx + my[..., None] * ny
        tx, ty = mx[..., None] - dot * nx, my[..., None] - dot * ny
        length = tx * tx + ty * ty
        bad = blocks(tx, ty)
        bad = bad & (eye.reshape(1, 1, -1, 1) != eye.reshape(1, 1, 1, -1))  # along its own contact
        ok = touching & ~bad.any(-1) & (length > 0.0)
        score = xp.where(ok, length, -1.0)
        best = xp.argmax(score, -1)[..., None]
        take = (lambda v: xp.take_along_axis(v, best, -1)[..., 0]) if not a.is_torch else (
            lambda v: xp.gather(v, -1, best)[..., 0]
        )
        has = take(score) > 0.0
        sx, sy = xp.where(has, take(tx), 0.0), xp.where(has, take(ty), 0.0)
        return xp.where(any_blocked, sx, mx), xp.where(any_blocked, sy, my), hit

    active = pair.any(-1).any(-1)
    mx, my, hit = resolve(x, y, mx, my, no_event, left, active)
    contact = contact | hit
    # Worlds without pairs just move.
    x, y = xp.where(active[:, None], x, x + mx), xp.where(active[:, None], y, y + my)
    done = ~active
    budget = _EVENTS_PER_ROBOT * moving.sum(-1)
    for k in range(_EVENTS_PER_ROBOT * n_robots):
        live = ~done & (budget > k)
        if not a.any(live):
            break
        vx = mx[:, :, None] - mx[:, None, :]
        vy = my[:, :, None] - my[:, None, :]
        t = enter_disc(xp, x[:, :, None], y[:, :, None], vx, vy, x[:, None, :], y[:, None, :], hit_r)
        apart = (x[:, :, None] - x[:, None, :]) * vx + (y[:, :, None] - y[:, None, :]) * vy >= 0.0
        t = xp.where(pair & upper & ((vx != 0.0) | (vy != 0.0)) & ~((t == 0.0) & apart), t, inf)
        flat = t.reshape(n_worlds, -1)
        first = xp.argmin(flat, -1)
        t_first = (xp.take_along_axis(flat, first[:, None], -1) if not a.is_torch else xp.gather(flat, -1, first[:, None]))[:, 0]
        event = live & (t_first < left)
        free = live & ~event
        x = xp.where(free[:, None], x + mx * left[:, None], x)
        y = xp.where(free[:, None], y + my * left[:, None], y)
        left = xp.where(free, 0.0 * left, left)
        done = done | free
        if not a.any(event):
            break
        i, j = first // n_robots, first % n_robots
        rows = a.arange(n_worlds)
        ax, ay, bx, by = x[rows, i], y[rows, i], x[rows, j], y[rows, j]
        place = enter_disc(xp, ax, ay, mx[rows, i] - mx[rows, j], my[rows, i] - my[rows, j], bx, by, 2.0 * radius + _PLACE)
        step = xp.minimum(xp.maximum(place, 0.0 * place), t_first)
        step = xp.where(event, step, 0.0 * step)
        x, y = x + mx * step[:, None], y + my * step[:, None]
        left = left - step
        ii, jj = eye.reshape(1, -1, 1), eye.reshape(1, 1, -1)
        forced = event[:, None, None] & (
            ((ii == i[:, None, None]) & (jj == j[:, None, None])) | ((ii == j[:, None, None]) & (jj == i[:, None, None]))
        )
        nmx, nmy, hit = resolve(x, y, mx, my, forced, left, event)
        mx, my = xp.where(event[:, None], nmx, mx), xp.where(event[:, None], nmy, my)
        contact = contact | (hit & event[:, None])
    return x, y, contact
