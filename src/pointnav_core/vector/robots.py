"""Batched contacts of several robots per world: they advance together, as in the backend.

The array twin of :func:`pointnav_kinematic.contacts.advance` with robot-robot contacts:
within a world, every robot follows its chord at once; the world moves to the earliest
moment at which a robot would overlap a wall, or two robots closing on each other would
overlap (by more than ``_HIT``), places the parties ``_PLACE`` short of touching, resolves
every robot's contacts there (a blocked motion slides along the longest tangent of a
contact, wall or robot, that goes into no other one, else stops; both robots' flags are
set when robots meet) and goes on with what is left. Robots without motion still block the others. As in the backend, a world resolves
at most ``8`` events per moving robot; each world keeps its own clock, so the Python loop
is over event rounds only, never over worlds or robots.

Arrays have leading axes ``(num_worlds, n_robots)``; pair arrays add a second robot axis
``(W, R, R)``, entry ``[w, i, j]`` meaning robot ``i`` against robot ``j``.
"""

from __future__ import annotations

import math
from typing import Any

from pointnav_core.vector.contacts import nearest, window
from pointnav_core.vector.floors import FloorTables
from pointnav_core.vector.sweep import enter_disc, enter_rounded_square, square_distance
from pointnav_core.vector.xp import Arrays, cat, swap_last_two, take_along

__all__ = ["advance_robots", "robot_walls"]

_HIT = 0.5e-9
_PLACE = 1.0e-9
_ACTIVE = 2.0e-9
_EVENTS_PER_ROBOT = 8
_CONTACTS = 6  # nearest walls that may be contacts while sliding, as in vector.contacts

#: The geometry of a step, ``(W, ...)`` arrays: the walls ``x0, y0, x1, y1`` (m) and
#: validity (W, R, K); the pair list (W, R, R); radii (m, (W, R)); contact distances
#: ``r_i + r_j`` (m, (W, R, R)); hit radii against walls (W, R) and robots (W, R, R) (m).
Geometry = tuple[Any, Any, Any, Any, Any, Any, Any, Any, Any, Any]


def _hit_radius(radius: Any) -> Any:
    # A point robot is a disc of _HIT (the backend's _hit_radius), elementwise.
    return (radius - _HIT).clip(_HIT, None)


def advance_robots(
    arrays: Arrays, x: Any, y: Any, mx: Any, my: Any, radius: Any, present: Any = None, walls: Any = None
) -> tuple[Any, Any, Any]:
    """Move every world's robots by their chords ``(mx, my)`` (m), resolving their contacts.

    Parameters
    ----------
    arrays : Arrays
        The array namespace (numpy or torch) the inputs live in.
    x, y, mx, my : float arrays (W, R)
        Start positions and chords over the step, in metres.
    radius : float or float array broadcasting to (W, R)
        Every robot's radius (m), >= 0: one for all, or each robot's own (two robots touch
        at the sum of their radii, as in the backend).
    present : bool array (W, R), optional
        Robots that take part; absent ones neither move nor block. Default: all.
    walls : tuple of arrays (W, R, K), optional
        Each robot's walls within reach of its whole chord, in the backend's order: the
        squares' ``x0, y0, x1, y1`` (m) and a validity mask. Default: none (open space).

    Returns
    -------
    x, y : float arrays (W, R)
        End positions (m).
    contact : bool array (W, R)
        Whether each robot was blocked by a wall or another robot, or blocked one.
    """
    a = arrays
    xp = a.xp
    n_robots = x.shape[1]
    rad = xp.zeros_like(x) + radius  # (W, R)
    # The distance at which robots i and j touch: r_i + r_j, (W, R, R).
    rsum = rad[:, :, None] + rad[:, None, :]
    if present is None:
        present = xp.ones_like(x) > 0.0
    if walls is None:
        far = xp.zeros_like(x)[..., None] + 1e9
        walls = (far, far, far + 1.0, far + 1.0, far < 0.0)
    wx0, wy0, wx1, wy1, wvalid = walls
    wvalid = wvalid & present[..., None]
    start_x, start_y = x, y
    mx = xp.where(present, mx, 0.0 * mx)
    my = xp.where(present, my, 0.0 * my)
    span = xp.sqrt(mx * mx + my * my)
    moving = span > 0.0
    eye = a.arange(n_robots)
    upper = eye.reshape(1, -1, 1) < eye.reshape(1, 1, -1)
    pair = _pair_list(xp, x, y, rsum, span, moving, present, upper)
    geo = (wx0, wy0, wx1, wy1, wvalid, pair, rad, rsum, _hit_radius(rad), _hit_radius(rsum))
    left = xp.ones_like(x[:, 0])
    contact = xp.zeros_like(x) > 1.0
    no_pair = xp.zeros_like(rsum) > 1.0
    no_wall = xp.zeros_like(wx0) > 1.0
    active = moving.any(-1)
    x, y = x + 0.0, y + 0.0
    mx, my, hit = _resolve(a, x, y, mx, my, no_pair, no_wall, left, active, geo)
    contact = contact | hit
    mx, my = mx + 0.0, my + 0.0
    _events(a, x, y, mx, my, left, contact, ~active, _EVENTS_PER_ROBOT * moving.sum(-1), geo, upper)
    return _safety_net(xp, x, y, start_x, start_y, geo, contact)


def _take(xp: Any, v: Any, idx: Any) -> Any:
    return take_along(xp, v, idx)[..., 0]


def _pair_list(xp: Any, x: Any, y: Any, rsum: Any, span: Any, moving: Any, present: Any, upper: Any) -> Any:
    """The backend's pair list (W, R, R), both ways: robots on the floor, not both still,
    within reach (m) of each other over their chords (``span``, m)."""
    reach = rsum + span[:, :, None] + span[:, None, :] + 4.0 * _ACTIVE
    gap2 = (x[:, :, None] - x[:, None, :]) ** 2 + (y[:, :, None] - y[:, None, :]) ** 2
    pair = (
        upper & present[:, :, None] & present[:, None, :]
        & (moving[:, :, None] | moving[:, None, :]) & (gap2 < reach * reach)
    )
    return pair | swap_last_two(xp, pair)


def _resolve(
    a: Arrays, x: Any, y: Any, mx: Any, my: Any, forced_p: Any, forced_w: Any, left: Any, active: Any, geo: Geometry
) -> tuple[Any, Any, Any]:
    """Every moving robot of an ``active`` world at ``(x, y)`` (m): slide along (or stop at)
    what it touches if its chord ``(mx, my)`` (m) goes into it, for ``left`` of the step.

    Contacts are its walls, then the other robots; a ``forced`` one (the event just
    reached) blocks however shallow. The walls within ``_ACTIVE`` of touching are among the
    nearest few (a disc touches at most four squares): only those take part, in their
    original order. Returns the new chords (m) and whether each robot was blocked or blocked
    one.
    """
    xp = a.xp
    inf = math.inf
    wx0, wy0, wx1, wy1, wvalid, pair, rad, rsum, hit_w, hit_r = geo
    n_robots = x.shape[1]
    n_near = min(_CONTACTS, wx0.shape[-1])
    wd = square_distance(xp, x[..., None], y[..., None], wx0, wy0, wx1, wy1)[0]
    near = nearest(xp, xp.where(wvalid, wd, inf), n_near)
    cx0, cy0, cx1, cy1, cvalid, forced_w = (take_along(xp, v, near) for v in (wx0, wy0, wx1, wy1, wvalid, forced_w))
    wd, wnx, wny = square_distance(xp, x[..., None], y[..., None], cx0, cy0, cx1, cy1)
    wtouch = cvalid & (wd <= rad[..., None] + _ACTIVE)
    ex, ey = x[:, :, None] - x[:, None, :], y[:, :, None] - y[:, None, :]
    dist = xp.sqrt(ex * ex + ey * ey)
    ptouch = pair & (dist <= rsum + _ACTIVE)
    safe = xp.where(dist > 0.0, dist, 1.0)
    nx = cat(xp, [wnx, xp.where(dist > 0.0, ex / safe, 1.0)], -1)
    ny = cat(xp, [wny, xp.where(dist > 0.0, ey / safe, 0.0)], -1)
    touching = cat(xp, [wtouch, ptouch], -1)
    forced = cat(xp, [forced_w, forced_p], -1)
    px, py = x[:, :, None, None], y[:, :, None, None]

    def blocks(tx: Any, ty: Any) -> Any:
        # (W, R, T) motions of robot i against its contacts: (W, R, T, K + R).
        into = tx[..., None] * nx[:, :, None, :] + ty[..., None] * ny[:, :, None, :] < 0.0
        tw = enter_rounded_square(
            xp, px, py, tx[..., None], ty[..., None], cx0[:, :, None, :], cy0[:, :, None, :],
            cx1[:, :, None, :], cy1[:, :, None, :], hit_w[:, :, None, None],
        )
        tr = enter_disc(xp, px, py, tx[..., None], ty[..., None], x[:, None, None, :], y[:, None, None, :],
                        hit_r[:, :, None, :])
        t = cat(xp, [tw, tr], -1)
        return touching[:, :, None, :] & into & (forced[:, :, None, :] | (t <= left[:, None, None, None]))

    go = ((mx != 0.0) | (my != 0.0)) & active[:, None]
    blocked = blocks(mx[..., None], my[..., None])[:, :, 0, :] & go[..., None]
    any_blocked = blocked.any(-1)
    hit = any_blocked | blocked[..., n_near:].any(1)  # the robot it ran into too
    dot = mx[..., None] * nx + my[..., None] * ny
    tx, ty = mx[..., None] - dot * nx, my[..., None] - dot * ny
    length = tx * tx + ty * ty
    bad = blocks(tx, ty)
    ck = a.arange(n_near + n_robots)
    bad = bad & (ck.reshape(1, 1, -1, 1) != ck.reshape(1, 1, 1, -1))  # along its own contact
    ok = touching & ~bad.any(-1) & (length > 0.0)
    score = xp.where(ok, length, -1.0)
    best = xp.argmax(score, -1)[..., None]
    has = _take(xp, score, best) > 0.0
    sx, sy = xp.where(has, _take(xp, tx, best), 0.0), xp.where(has, _take(xp, ty, best), 0.0)
    return xp.where(any_blocked, sx, mx), xp.where(any_blocked, sy, my), hit


def _events(
    a: Arrays, x: Any, y: Any, mx: Any, my: Any, left: Any, contact: Any, done: Any, budget: Any, geo: Geometry,
    upper: Any,
) -> None:
    """Every world's events, round by round, each world on its own clock: in place, the
    positions ``x, y`` (m), chords ``mx, my`` (m), time ``left``, ``contact`` flags and
    ``done``, for at most ``budget`` (W,) events per world.

    Only the worlds still under way take part in a round: the Python loop is over rounds,
    never over worlds or robots.
    """
    xp = a.xp
    for k in range(_EVENTS_PER_ROBOT * x.shape[1]):
        live = ~done & (budget > k)
        if not a.any(live):
            break
        sel = a.nonzero(live)
        sub = tuple(v[sel] for v in geo)
        sx, sy, smx, smy, sleft = x[sel], y[sel], mx[sel], my[sel], left[sel]
        first, t_first = _first_event(xp, sx, sy, smx, smy, sleft, sub, upper)
        event = t_first < sleft
        free = ~event
        sx = xp.where(free[:, None], sx + smx * sleft[:, None], sx)
        sy = xp.where(free[:, None], sy + smy * sleft[:, None], sy)
        sleft = xp.where(free, xp.zeros_like(sleft), sleft)
        done[sel] = free
        if a.any(event):
            sx, sy, sleft, nmx, nmy, hit = _meet(a, sx, sy, smx, smy, sleft, first, t_first, event, sub)
            mx[sel], my[sel] = xp.where(event[:, None], nmx, smx), xp.where(event[:, None], nmy, smy)
            contact[sel] = contact[sel] | (hit & event[:, None])
        x[sel], y[sel], left[sel] = sx, sy, sleft
        if not a.any(event):
            break


def _first_event(xp: Any, x: Any, y: Any, mx: Any, my: Any, left: Any, geo: Geometry, upper: Any) -> tuple[Any, Any]:
    """Each world's first event within ``left`` of the step: its flat index (walls robot by
    robot and wall by wall, then pairs; the first wins a tie) and its time (inf if none)."""
    inf = math.inf
    wx0, wy0, wx1, wy1, wvalid, pair, _, _, hit_w, hit_r = geo
    n = x.shape[0]
    wd, wnx, wny = square_distance(xp, x[..., None], y[..., None], wx0, wy0, wx1, wy1)
    speed = xp.sqrt(mx * mx + my * my)
    towards = wvalid & (mx[..., None] * wnx + my[..., None] * wny < 0.0)
    towards = towards & ~(wd - hit_w[..., None] > (speed * left[:, None])[..., None])
    tw = enter_rounded_square(xp, x[..., None], y[..., None], mx[..., None], my[..., None], wx0, wy0, wx1, wy1,
                              hit_w[..., None])
    tw = xp.where(towards, tw, inf)
    vx = mx[:, :, None] - mx[:, None, :]
    vy = my[:, :, None] - my[:, None, :]
    tp = enter_disc(xp, x[:, :, None], y[:, :, None], vx, vy, x[:, None, :], y[:, None, :], hit_r)
    apart = (x[:, :, None] - x[:, None, :]) * vx + (y[:, :, None] - y[:, None, :]) * vy >= 0.0
    tp = xp.where(pair & upper & ((vx != 0.0) | (vy != 0.0)) & ~((tp == 0.0) & apart), tp, inf)
    flat = cat(xp, [tw.reshape(n, -1), tp.reshape(n, -1)], -1)
    first = xp.argmin(flat, -1)
    return first, _take(xp, flat, first[:, None])


def _meet(
    a: Arrays, x: Any, y: Any, mx: Any, my: Any, left: Any, first: Any, t_first: Any, event: Any, geo: Geometry
) -> tuple[Any, Any, Any, Any, Any, Any]:
    """Move every world with an ``event`` to ``_PLACE`` (m) short of its first contact
    (``first``, at ``t_first``) and resolve its robots' contacts there, that one forced.

    Returns the positions (m), the time left, the new chords (m) and the robots blocked.
    """
    xp = a.xp
    wx0, wy0, wx1, wy1, _, _, rad, rsum, _, _ = geo
    n, n_robots, n_walls = wx0.shape
    rows = a.arange(n)
    is_wall = first < n_robots * n_walls
    fw = xp.where(is_wall, first, 0)
    wi, wkk = fw // max(n_walls, 1), fw % max(n_walls, 1)
    fp = xp.where(is_wall, 0, first - n_robots * n_walls)
    i, j = xp.where(is_wall, wi, fp // n_robots), fp % n_robots
    ex0, ey0, ex1, ey1 = (v[rows, wi, wkk] for v in (wx0, wy0, wx1, wy1))
    place_w = enter_rounded_square(
        xp, x[rows, wi], y[rows, wi], mx[rows, wi], my[rows, wi], ex0, ey0, ex1, ey1, rad[rows, wi] + _PLACE
    )
    place_p = enter_disc(
        xp, x[rows, i], y[rows, i], mx[rows, i] - mx[rows, j], my[rows, i] - my[rows, j],
        x[rows, j], y[rows, j], rsum[rows, i, j] + _PLACE,
    )
    place = xp.where(is_wall, place_w, place_p)
    step = xp.minimum(xp.maximum(place, xp.zeros_like(place)), t_first)
    step = xp.where(event, step, xp.zeros_like(step))
    x, y = x + mx * step[:, None], y + my * step[:, None]
    left = left - step
    eye = a.arange(n_robots)
    ii, jj = eye.reshape(1, -1, 1), eye.reshape(1, 1, -1)
    pe = (event & ~is_wall)[:, None, None]
    forced_p = pe & (
        ((ii == i[:, None, None]) & (jj == j[:, None, None]))
        | ((ii == j[:, None, None]) & (jj == i[:, None, None]))
    )
    we = (event & is_wall)[:, None, None]
    forced_w = we & (ii == wi[:, None, None]) & (a.arange(n_walls).reshape(1, 1, -1) == wkk[:, None, None])
    mx, my, hit = _resolve(a, x, y, mx, my, forced_p, forced_w, left, event, geo)
    return x, y, left, mx, my, hit


def _safety_net(xp: Any, x: Any, y: Any, start_x: Any, start_y: Any, geo: Geometry, contact: Any) -> tuple[Any, Any, Any]:
    """Against rounding: a robot in contact never ends deeper in a wall than at its start
    ``(start_x, start_y)`` (m); such a robot stays there. Returns the end positions (m) and
    ``contact``."""
    inf = math.inf
    wx0, wy0, wx1, wy1, wvalid, _, rad, _, _, _ = geo
    d_end = square_distance(xp, x[..., None], y[..., None], wx0, wy0, wx1, wy1)[0]
    d_start = square_distance(xp, start_x[..., None], start_y[..., None], wx0, wy0, wx1, wy1)[0]
    depth_end = xp.amax(xp.where(wvalid, rad[..., None] - d_end, -inf), -1)
    depth_start = xp.amax(xp.where(wvalid, rad[..., None] - d_start, -inf), -1)
    moved = (x != start_x) | (y != start_y)
    undo = contact & moved & (depth_end > _HIT) & (depth_end > depth_start)
    return xp.where(undo, start_x, x), xp.where(undo, start_y, y), contact


def robot_walls(floors: FloorTables, scene: Any, x: Any, y: Any, mx: Any, my: Any, radius: Any, max_travel: float) -> tuple[Any, ...]:
    """Each robot's walls within reach of its chord, the few that can matter: ``(W, R, K)`` arrays.

    Parameters
    ----------
    floors : FloorTables
    scene : int array (W, R)
        Each robot's scene index.
    x, y, mx, my : float arrays (W, R)
        Start positions and chords (m).
    radius : float or float array broadcasting to (W, R)
        Robot radius (m), one for all or each robot's own.
    max_travel : float
        The longest chord of any step (m).

    Returns
    -------
    tuple
        ``x0, y0, x1, y1`` of the squares (m) and their validity mask, in the backend's
        (row-major) order, for :func:`advance_robots`.
    """
    xp = floors.arrays.xp
    n_worlds, n_robots = x.shape
    rad = xp.zeros_like(x) + radius
    flat = [v.reshape(-1) for v in (scene, x, y, mx, my, rad)]
    sc, fx, fy, fmx, fmy, frad = flat
    # One window for the largest robot; each robot then keeps the walls within its own reach.
    largest = float(frad.max()) if frad.shape[0] else 0.0
    wx0, wy0, wx1, wy1, valid = window(floors, sc, fx, fy, largest + max_travel + 4.0 * _ACTIVE)
    d0 = square_distance(xp, fx[:, None], fy[:, None], wx0, wy0, wx1, wy1)[0]
    reach = frad + xp.sqrt(fmx * fmx + fmy * fmy) + 4.0 * _ACTIVE
    in_reach = valid & (d0 <= reach[:, None])
    k = max(int(in_reach.sum(-1).max()) if in_reach.shape[0] else 0, 1)
    order = nearest(xp, xp.where(in_reach, d0, math.inf), k)
    out = [take_along(xp, v, order).reshape(n_worlds, n_robots, k) for v in (wx0, wy0, wx1, wy1, in_reach)]
    return tuple(out)
