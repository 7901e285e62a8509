"""Batched contact resolution: robots near obstacles advance with swept-disc contacts.

The array twin of :func:`pointnav_kinematic.contacts.advance` for one robot per world
(no robot-robot contacts): each robot moves along its chord to the first wall it would
overlap (by more than ``_HIT``), stops ``_PLACE`` short of it, slides along the longest
tangent of a contact that goes into no other contact, and goes on with what is
left of the motion. The backend resolves up to 8 contacts per robot and sub-step; here
every robot runs :data:`EVENTS` rounds at once (a robot done early just idles), so the
rule is the same. The walls are the edge obstacle squares within reach of each robot's
cell (:meth:`FloorTables.stencil`, gathered per robot), in row-major order, as the backend
lists them; only the :data:`CONTACTS` nearest take part in sliding (a disc touches at
most four squares).
"""

from __future__ import annotations

import math
from typing import Any

from pointnav_core.errors import ArgumentError
from pointnav_core.vector.floors import FloorTables
from pointnav_core.vector.sweep import enter_rounded_square, square_distance
from pointnav_core.vector.xp import Arrays, copy, sort, stable_argsort, take_along

__all__ = ["CONTACTS", "EVENTS", "advance", "nearest"]

_HIT = 0.5e-9
_PLACE = 1.0e-9
_ACTIVE = 2.0e-9
#: Contact events resolved per robot and step (the backend's _EVENTS_PER_ROBOT).
EVENTS = 8
#: Nearest walls kept as possible contacts of a robot while it slides.
CONTACTS = 6


def window(floors: FloorTables, scene: Any, x: Any, y: Any, reach: float) -> tuple[Any, Any, Any, Any, Any]:
    """The edge obstacle squares within ``reach`` (m) of each robot's cell: corners and mask, (M, P).

    In row-major order, as the backend lists them (slots that hold no wall in between,
    masked out); a robot off the map has none. The squares are those of the cell's
    stencil (:meth:`FloorTables.stencil`), gathered here for the robots that need them.
    """
    if floors.has_polygons:  # FloorTables lets them in only where the compiled contacts run
        raise ArgumentError("the array contacts collide with grid cells only, and a floor has obstacle polygons")
    a = floors.arrays
    xp = a.xp
    dr, dc, ok = floors.stencil(reach)
    row0, col0, inside = floors.cells(scene, x, y)
    sc = scene.reshape(-1, 1)
    row, col = row0[:, None] + dr[scene], col0[:, None] + dc[scene]
    on_map = ok[scene] & inside[:, None] & (row >= 0) & (row < floors.rows[sc]) & (col >= 0) & (col < floors.width[sc])
    ids = xp.where(on_map, floors.offset[sc] + row * floors.width[sc] + col, xp.zeros_like(row))
    valid = on_map & floors.edge[ids]
    res = floors.res[sc]
    # Slots that hold no wall move far away, so that no distance test lands inside one.
    x0 = xp.where(valid, floors.ox[sc] + col * res, 1e9)
    y0 = floors.oy[sc] + row * res
    return x0, y0, x0 + res, y0 + res, valid


def nearest(xp: Any, dist: Any, k: int) -> Any:
    """Indices of the ``k`` smallest distances of each row, in their original order."""
    # A stable sort: of walls at equal distances (common on a grid) the first ones are kept
    # on numpy, torch and in the compiled kernel alike (torch's default sort is not stable).
    return sort(xp, stable_argsort(xp, dist)[..., :k])


def _walls_in_reach(
    floors: FloorTables, scene: Any, x: Any, y: Any, rcol: Any, max_span: float, max_travel: float
) -> tuple[Any, Any, Any, Any, Any, Any]:
    """The walls ``(M, K)`` each robot may meet this chord, nearest first: ends ``x0, y0,
    x1, y1`` (m), validity and square distance from the start (m)."""
    xp = floors.arrays.xp
    largest = float(rcol.max()) if rcol.shape[0] else 0.0
    reach = rcol + max_span + 4.0 * _ACTIVE
    wx0, wy0, wx1, wy1, valid = window(floors, scene, x, y, largest + max_travel + 4.0 * _ACTIVE)
    d0 = square_distance(xp, x[:, None], y[:, None], wx0, wy0, wx1, wy1)[0]
    # Only walls within reach of the start can be met (sliding only shortens the motion):
    # keep the most any robot has, nearest first, so that every later test is on few walls.
    in_reach = valid & (d0 <= reach)
    k = max(int(in_reach.sum(-1).max()) if in_reach.shape[0] else 0, 1)
    order = nearest(xp, xp.where(in_reach, d0, math.inf), k)
    return tuple(take_along(xp, v, order) for v in (wx0, wy0, wx1, wy1, in_reach, d0))


def _slide(
    xp: Any, a: Arrays, n_contacts: int, x: Any, y: Any, mx: Any, my: Any, left: Any, forced_all: Any,
    dist_all: Any, wx0: Any, wy0: Any, wx1: Any, wy1: Any, valid: Any, rcol: Any, hit_r: Any,
) -> tuple[Any, Any, Any]:
    """The moving robots' chords after sliding along the walls they touch, and whether a
    wall blocked them (the backend's contact resolution); ``(M,)`` rows, ``(M, K)`` walls."""
    # The walls within _ACTIVE of touching are among the nearest few: slide against those.
    near = nearest(xp, xp.where(valid, dist_all, math.inf), n_contacts)
    cx0, cy0, cx1, cy1, cvalid, forced = (
        take_along(xp, v, near) for v in (wx0, wy0, wx1, wy1, valid, forced_all)
    )
    dist, nx, ny = square_distance(xp, x[:, None], y[:, None], cx0, cy0, cx1, cy1)
    touching = cvalid & (dist <= rcol + _ACTIVE)

    def blocks(tx: Any, ty: Any) -> Any:  # (M, K) motions against (M, C) contacts
        into = tx[..., None] * nx[:, None, :] + ty[..., None] * ny[:, None, :] < 0.0
        t = enter_rounded_square(
            xp, x[:, None, None], y[:, None, None], tx[..., None], ty[..., None],
            cx0[:, None, :], cy0[:, None, :], cx1[:, None, :], cy1[:, None, :], hit_r[:, None],
        )
        return touching[:, None, :] & into & (forced[:, None, :] | (t <= left[:, None, None]))

    moving = (mx != 0.0) | (my != 0.0)
    blocked = blocks(mx[:, None], my[:, None])[:, 0, :] & moving[:, None]
    any_blocked = blocked.any(-1)
    dot = mx[:, None] * nx + my[:, None] * ny
    tx, ty = mx[:, None] - dot * nx, my[:, None] - dot * ny
    length = tx * tx + ty * ty
    bad = blocks(tx, ty)
    eye = a.arange(bad.shape[-1])
    bad = bad & (eye.reshape(1, -1, 1) != eye.reshape(1, 1, -1))  # a tangent runs along its own contact
    # Any contact's tangent may save the motion, not only a blocking one's (a passage
    # exactly as wide as the disc), as in the backend.
    ok = touching & ~bad.any(-1) & (length > 0.0)
    # The longest clear tangent, the first of a tie (the backend keeps the first).
    score = xp.where(ok, length, -1.0)
    best = xp.argmax(score, -1)
    has = take_along(xp, score, best[:, None])[:, 0] > 0.0
    sx = xp.where(has, take_along(xp, tx, best[:, None])[:, 0], 0.0)
    sy = xp.where(has, take_along(xp, ty, best[:, None])[:, 0], 0.0)
    return xp.where(any_blocked, sx, mx), xp.where(any_blocked, sy, my), any_blocked



def _no_deeper(xp: Any, start: tuple[Any, Any], end: tuple[Any, Any], contact: Any, walls: tuple[Any, ...],
               rcol: Any) -> tuple[Any, Any]:
    """``end``, except that a robot in contact that would end deeper in a wall than at
    ``start`` stays there (a safety net against rounding; positions in m)."""
    (start_x, start_y), (x, y) = start, end
    wx0, wy0, wx1, wy1, valid, d0 = walls
    depth_end = xp.amax(xp.where(valid, rcol - square_distance(xp, x[:, None], y[:, None], wx0, wy0, wx1, wy1)[0], -math.inf), -1)
    depth_start = xp.amax(xp.where(valid, rcol - d0, -math.inf), -1)
    moved = (x != start_x) | (y != start_y)
    undo = contact & moved & (depth_end > _HIT) & (depth_end > depth_start)
    return xp.where(undo, start_x, x), xp.where(undo, start_y, y)


def advance(
    floors: FloorTables, scene: Any, x: Any, y: Any, mx: Any, my: Any, radius: Any, max_travel: float
) -> tuple[Any, Any, Any]:
    """Move robots by their chords ``(mx, my)`` (m) with contacts; new ``x``, ``y`` and contact flags.

    Parameters
    ----------
    floors : FloorTables
    scene : int array (M,)
        Each robot's scene index.
    x, y, mx, my : float arrays (M,)
        Start positions and chords, in metres.
    radius : float or float array (M,)
        Robot radius (m): one for all, or each robot's own.
    max_travel : float
        The longest chord any step may have (m): the walls are gathered within it.
    """
    a, xp, inf = floors.arrays, floors.arrays.xp, math.inf
    span = xp.sqrt(mx * mx + my * my)
    max_span = float(span.max()) if span.shape[0] else 0.0
    # Each robot's radius as a column (M, 1), against its (M, K) walls.
    rcol = (xp.zeros_like(x) + radius)[:, None]
    if max_span > max_travel:
        raise ArgumentError(f"a chord of {max_span} m is longer than max_travel {max_travel} m")
    wx0, wy0, wx1, wy1, valid, d0 = _walls_in_reach(floors, scene, x, y, rcol, max_span, max_travel)
    n_contacts = min(CONTACTS, valid.shape[1])
    hit_r = (rcol - _HIT).clip(_HIT, None)
    start_x, start_y = x, y
    contact = xp.zeros_like(x) > 1.0
    left = xp.ones_like(x)
    done = span == 0.0
    forced_all = xp.zeros_like(wx0) > 1.0

    def resolve(x: Any, y: Any, mx: Any, my: Any, left: Any, forced_all: Any) -> tuple[Any, Any, Any]:
        # Only a moving robot within _ACTIVE of some wall can be blocked: the others keep going.
        dist_all = square_distance(xp, x[:, None], y[:, None], wx0, wy0, wx1, wy1)[0]
        need = a.nonzero((valid & (dist_all <= rcol + _ACTIVE)).any(-1) & ((mx != 0.0) | (my != 0.0)))
        hit = xp.zeros_like(x) > 1.0
        if not need.shape[0]:
            return mx, my, hit
        sub = (v[need] for v in (x, y, mx, my, left, forced_all, dist_all, wx0, wy0, wx1, wy1, valid, rcol, hit_r))
        smx, smy, shit = _slide(xp, a, n_contacts, *sub)
        mx, my = copy(xp, mx), copy(xp, my)
        mx[need], my[need], hit[need] = smx, smy, shit
        return mx, my, hit

    mx, my, hit = resolve(x, y, mx, my, left, forced_all)
    contact = contact | hit
    for _ in range(EVENTS):
        dist, nx, ny = square_distance(xp, x[:, None], y[:, None], wx0, wy0, wx1, wy1)
        speed = xp.sqrt(mx * mx + my * my)
        towards = (mx[:, None] * nx + my[:, None] * ny < 0.0) & valid
        towards = towards & ~(dist - hit_r > (speed * left)[:, None])
        t = enter_rounded_square(xp, x[:, None], y[:, None], mx[:, None], my[:, None], wx0, wy0, wx1, wy1, hit_r)
        t = xp.where(towards, t, inf)
        first = xp.argmin(t, -1)
        t_first = take_along(xp, t, first[:, None])[:, 0]
        event = (t_first < left) & ~done
        # No event: the rest of the motion, and this robot is done.
        free = ~event & ~done
        x = xp.where(free, x + mx * left, x)
        y = xp.where(free, y + my * left, y)
        left = xp.where(free, 0.0, left)
        done = done | free
        if not a.any(event):
            break
        ex0, ey0, ex1, ey1 = (take_along(xp, v, first[:, None])[:, 0] for v in (wx0, wy0, wx1, wy1))
        place = enter_rounded_square(xp, x, y, mx, my, ex0, ey0, ex1, ey1, rcol[:, 0] + _PLACE)
        step = xp.minimum(xp.maximum(place, xp.zeros_like(place)), t_first)
        step = xp.where(event, step, 0.0)
        x, y = x + mx * step, y + my * step
        left = left - step
        forced_all = event[:, None] & (a.arange(valid.shape[1]).reshape(1, -1) == first[:, None])
        nmx, nmy, hit = resolve(x, y, mx, my, left, forced_all)
        mx, my = xp.where(event, nmx, mx), xp.where(event, nmy, my)
        contact = contact | (hit & event)
    x, y = _no_deeper(xp, (start_x, start_y), (x, y), contact, (wx0, wy0, wx1, wy1, valid, d0), rcol)
    return x, y, contact
