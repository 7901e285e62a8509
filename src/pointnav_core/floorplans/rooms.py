"""The ``rooms`` generator: a house split into rooms by walls with doors, and furniture."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely import affinity
from shapely.geometry import Point, Polygon, box

from pointnav_core.errors import ArgumentError
from pointnav_core.floorplans.args import (
    Seed,
    check_pair,
    check_positive,
    check_probability,
    check_range,
    rng_from,
)
from pointnav_core.floorplans.plan import FloorPlan

__all__ = ["rooms"]
# A door never starts closer than this to the end of its wall (m), so that a wall meeting the
# end cannot narrow it.
_DOOR_MARGIN = 0.3
# Furniture stays out of a box this deep (m) on both sides of every door.
_DOOR_APPROACH = 1.0


@dataclass
class _Room:
    """An axis-aligned room interior (faces of its walls) and the doors in its four sides.

    ``doors[side]`` lists ``(lo, hi)`` intervals along the side: y intervals for the
    ``"left"``/``"right"`` sides (x = x0 / x1), x intervals for ``"bottom"``/``"top"``.
    """

    x0: float
    y0: float
    x1: float
    y1: float
    doors: dict[str, list[tuple[float, float]]] = field(
        default_factory=lambda: {"left": [], "right": [], "bottom": [], "top": []}
    )


def rooms(
    seed: Seed = None,
    size: tuple[float, float] = (20.0, 15.0),
    *,
    min_room: float = 2.5,
    max_room: float = 6.0,
    wall: float = 0.12,
    outer_wall: float = 0.2,
    door_width: tuple[float, float] = (0.8, 1.2),
    l_shape: float = 0.5,
    furniture: float = 2.5,
    clearance: float = 0.8,
) -> FloorPlan:
    """Generate a house: outer walls, rooms split by interior walls with doors, furniture.

    The house (a rectangle, or with probability ``l_shape`` an L with one corner cut away) is
    split recursively by straight interior walls until no room is longer than ``max_room``
    (a few rooms are split further at random); no room is narrower than ``min_room``. Every
    interior wall has one door, placed away from the wall's ends, and no later wall ends in a
    door, so every room is reachable. Furniture is axis-aligned boxes against walls (or in
    corners) and free-standing boxes (some rotated) and round tables; it stays out of a
    1 m deep approach zone on both sides of each door and at least ``clearance`` away from
    everything it does not stand against, so the free space stays one connected region for
    robots narrower than ``clearance``.

    Parameters
    ----------
    seed : int, numpy SeedSequence or Generator, or None
        Seed of ``np.random.default_rng``; the same seed gives the same plan.
    size : (float, float), default (20.0, 15.0)
        Outer width (x) and height (y) of the house, in metres.
    min_room : float, default 2.5
        Smallest room side in metres; at least the widest door plus 0.6 m.
    max_room : float, default 6.0
        Rooms with a longer side are split when they can be (m), >= ``min_room``.
    wall : float, default 0.12
        Interior wall thickness (m).
    outer_wall : float, default 0.2
        Outer wall thickness (m).
    door_width : (float, float), default (0.8, 1.2)
        Range of door widths (m).
    l_shape : float, default 0.5
        Probability of an L-shaped house (when the size leaves room for one).
    furniture : float, default 2.5
        Mean number of furniture pieces tried per room (Poisson); 0 for empty rooms. A piece
        that does not fit is left out.
    clearance : float, default 0.8
        Smallest passage left by furniture (m).

    Returns
    -------
    FloorPlan
        Outline: the house's outer boundary, centred on the origin. Obstacles: the outer wall
        ring, interior wall segments, furniture.

    Raises
    ------
    ValueError
        When a parameter is out of range; the message names it.

    Examples
    --------
    >>> plan = rooms(seed=0)
    >>> plan.size
    (20.0, 15.0)
    >>> plan == rooms(seed=0)
    True
    """
    rng = rng_from(seed)
    args = _Params.checked(
        size, min_room, max_room, wall, outer_wall, door_width, l_shape, furniture, clearance
    )
    outline, ring, walls, keepouts, todo = _house(rng, args)
    leaves = _split_rooms(rng, todo, walls, keepouts, args)
    pieces = _furnish(rng, leaves, keepouts, args)
    return _mirrored(rng, outline, [ring, *walls, *pieces])


def _mirrored(rng: np.random.Generator, outline: Polygon, geoms: list[Polygon]) -> FloorPlan:
    """The plan, mirrored in x and/or y at random (the house was built in one orientation)."""
    sx, sy = rng.choice([-1.0, 1.0], size=2)
    if sx != 1.0 or sy != 1.0:
        outline = affinity.scale(outline, sx, sy, origin=(0, 0))
        geoms = [affinity.scale(g, sx, sy, origin=(0, 0)) for g in geoms]
    return FloorPlan(outline=outline, obstacles=tuple(geoms))


@dataclass(frozen=True)
class _Params:
    """The checked arguments of :func:`rooms` (lengths in metres)."""

    width: float
    height: float
    min_room: float
    max_room: float
    wall: float
    outer_wall: float
    door_lo: float
    door_hi: float
    l_shape: float
    furniture: float
    clearance: float

    @classmethod
    def checked(
        cls,
        size: tuple[float, float],
        min_room: float,
        max_room: float,
        wall: float,
        outer_wall: float,
        door_width: tuple[float, float],
        l_shape: float,
        furniture: float,
        clearance: float,
    ) -> _Params:
        """Check :func:`rooms`'s arguments, in its order; raise ``ArgumentError`` naming one."""
        width, height = check_pair(size, "size", "(width, height) in metres")
        wall = check_positive(wall, "wall")
        outer_wall = check_positive(outer_wall, "outer_wall")
        door_lo, door_hi = check_range(door_width, "door_width")
        min_room = check_positive(min_room, "min_room")
        if min_room < door_hi + 2 * _DOOR_MARGIN:
            raise ArgumentError(
                f"min_room must be at least the widest door plus {2 * _DOOR_MARGIN} m "
                f"({door_hi + 2 * _DOOR_MARGIN} m), got {min_room}"
            )
        max_room = check_positive(max_room, "max_room")
        if max_room < min_room:
            raise ArgumentError(f"max_room must be >= min_room ({min_room} m), got {max_room}")
        l_shape = check_probability(l_shape, "l_shape")
        furniture = float(furniture)
        if not (math.isfinite(furniture) and furniture >= 0.0):
            raise ArgumentError(
                f"furniture must be a finite number >= 0 (pieces per room), got {furniture!r}"
            )
        clearance = check_positive(clearance, "clearance")
        if min(width, height) < min_room + 2 * outer_wall:
            raise ArgumentError(
                f"size must be at least min_room + 2 * outer_wall = "
                f"{min_room + 2 * outer_wall} m on each side, got {size!r}"
            )
        return cls(
            width, height, min_room, max_room, wall, outer_wall, door_lo, door_hi, l_shape,
            furniture, clearance,
        )  # fmt: skip


def _split_rooms(
    rng: np.random.Generator,
    todo: list[_Room],
    walls: list[Polygon],
    keepouts: list[Polygon],
    args: _Params,
) -> list[_Room]:
    """Split the rooms in ``todo`` until none can be; returns the rooms left.

    The walls and door approach zones of the splits are appended to ``walls`` and
    ``keepouts``; ``todo`` is emptied.
    """
    leaves: list[_Room] = []
    while todo:
        room = todo.pop()
        split = _split_room(
            rng, room, args.min_room, args.max_room, args.wall, args.door_lo, args.door_hi,
            args.clearance,
        )  # fmt: skip
        if split is None:
            leaves.append(room)
            continue
        children, new_walls, keepout = split
        walls.extend(new_walls)
        keepouts.append(keepout)
        todo.extend(children)
    return leaves


def _furnish(
    rng: np.random.Generator, leaves: list[_Room], keepouts: list[Polygon], args: _Params
) -> list[Polygon]:
    """Furniture for each room: a Poisson number of pieces tried, those that fit kept."""
    keepout_array = np.array(keepouts, dtype=object)
    pieces: list[Polygon] = []
    for room in leaves:
        for _ in range(rng.poisson(args.furniture)):
            piece = _place_furniture(rng, room, pieces, keepout_array, args.clearance)
            if piece is not None:
                pieces.append(piece)
    return pieces


def _house(
    rng: np.random.Generator, args: _Params
) -> tuple[Polygon, Polygon, list[Polygon], list[Polygon], list[_Room]]:
    """The house's outline, its outer wall ring, and its first rooms.

    A rectangle, or with probability ``l_shape`` an L whose two parts are split by a wall
    with a door. Returns ``(outline, ring, walls, keepouts, rooms)``: the interior walls and
    door approach zones made so far, and the rooms still to split.
    """
    width, height, t, wall = args.width, args.height, args.outer_wall, args.wall
    door_lo, door_hi, clearance = args.door_lo, args.door_hi, args.clearance
    x0, y0, x1, y1 = -width / 2, -height / 2, width / 2, height / 2
    # Canonical orientation: the notch of an L is the top-right corner; mirrored at the end.
    notch_w = rng.uniform(0.3, 0.5) * width
    notch_h = rng.uniform(0.3, 0.5) * height
    use_l = rng.random() < args.l_shape
    strip_h = height - notch_h - 2 * t  # inner height of the full-width strip
    block_w = width - notch_w - 2 * t  # inner width of the block above it
    block_h = notch_h - wall  # inner height of the block above the dividing wall
    if use_l and min(strip_h, block_w, block_h) >= args.min_room:
        outline = Polygon(
            [
                (x0, y0),
                (x1, y0),
                (x1, y1 - notch_h),
                (x1 - notch_w, y1 - notch_h),
                (x1 - notch_w, y1),
                (x0, y1),
            ]
        )
        ix1, iy1 = x1 - notch_w - t, y1 - notch_h - t  # inner corner of the notch
        inner = Polygon(
            [
                (x0 + t, y0 + t),
                (x1 - t, y0 + t),
                (x1 - t, iy1),
                (ix1, iy1),
                (ix1, y1 - t),
                (x0 + t, y1 - t),
            ]
        )
        strip = _Room(x0 + t, y0 + t, x1 - t, iy1)
        block = _Room(x0 + t, iy1 + wall, ix1, y1 - t)
        # The dividing wall continues the strip's top face to the notch.
        door = _door_interval(rng, x0 + t, ix1, door_lo, door_hi)
        walls = _wall_with_door(x0 + t, iy1, ix1, iy1 + wall, door, axis=0)
        strip.doors["top"].append(door)
        block.doors["bottom"].append(door)
        keepouts = [
            box(
                door[0] - clearance,
                iy1 - _DOOR_APPROACH,
                door[1] + clearance,
                iy1 + wall + _DOOR_APPROACH,
            )
        ]
        todo = [strip, block]
    else:
        outline = box(x0, y0, x1, y1)
        inner = box(x0 + t, y0 + t, x1 - t, y1 - t)
        walls, keepouts = [], []
        todo = [_Room(x0 + t, y0 + t, x1 - t, y1 - t)]
    ring = Polygon(outline.exterior.coords, [inner.exterior.coords])
    return outline, ring, walls, keepouts, todo


def _door_interval(
    rng: np.random.Generator, lo: float, hi: float, door_lo: float, door_hi: float
) -> tuple[float, float]:
    """A door ``(start, end)`` on a wall running from ``lo`` to ``hi``, clear of both ends."""
    door = rng.uniform(door_lo, door_hi)
    start = rng.uniform(lo + _DOOR_MARGIN, hi - _DOOR_MARGIN - door)
    return (start, start + door)


def _wall_with_door(
    x0: float, y0: float, x1: float, y1: float, door: tuple[float, float], axis: int
) -> list[Polygon]:
    """The two pieces of wall box ``(x0, y0, x1, y1)`` either side of a door along ``axis``."""
    if axis == 0:  # the wall runs along x; the door is an x interval
        return [box(x0, y0, door[0], y1), box(door[1], y0, x1, y1)]
    return [box(x0, y0, x1, door[0]), box(x0, door[1], x1, y1)]


def _allowed(
    lo: float, hi: float, forbidden: list[tuple[float, float]]
) -> list[tuple[float, float]]:
    """The parts of ``[lo, hi]`` outside every forbidden interval."""
    parts = [(lo, hi)] if lo <= hi else []
    for a, b in forbidden:
        parts = [p for (s, e) in parts for p in ((s, min(e, a)), (max(s, b), e)) if p[0] < p[1]]
    return parts


def _split_room(
    rng: np.random.Generator,
    room: _Room,
    min_room: float,
    max_room: float,
    wall: float,
    door_lo: float,
    door_hi: float,
    clearance: float,
) -> tuple[list[_Room], list[Polygon], Polygon] | None:
    """Split a room in two by a wall with a door, or return None to keep it whole."""
    w, h = room.x1 - room.x0, room.y1 - room.y0
    if max(w, h) <= max_room and rng.random() >= 0.2:
        return None
    # Split across the longer side (cut x when wide); near-square rooms either way.
    if w > 1.25 * h:
        axes = [0, 1]
    elif h > 1.25 * w:
        axes = [1, 0]
    else:
        axes = [0, 1] if rng.random() < 0.5 else [1, 0]
    for axis in axes:
        if axis == 0:  # a vertical wall at x = c, avoiding doors in the top and bottom sides
            lo, hi, other = room.x0, room.x1, room.doors["bottom"] + room.doors["top"]
        else:  # a horizontal wall at y = c, avoiding doors in the left and right sides
            lo, hi, other = room.y0, room.y1, room.doors["left"] + room.doors["right"]
        pad = wall / 2 + _DOOR_MARGIN
        parts = _allowed(
            lo + min_room + wall / 2,
            hi - min_room - wall / 2,
            sorted((a - pad, b + pad) for a, b in other),
        )
        if not parts:
            continue
        lengths = np.array([e - s for s, e in parts])
        k = rng.choice(len(parts), p=lengths / lengths.sum())
        c = rng.uniform(*parts[k])
        a, b = c - wall / 2, c + wall / 2
        if axis == 0:
            door = _door_interval(rng, room.y0, room.y1, door_lo, door_hi)
            first = _Room(room.x0, room.y0, a, room.y1)
            second = _Room(b, room.y0, room.x1, room.y1)
            first.doors["left"] = list(room.doors["left"])
            second.doors["right"] = list(room.doors["right"])
            first.doors["right"] = [door]
            second.doors["left"] = [door]
            for side in ("bottom", "top"):
                first.doors[side] = [d for d in room.doors[side] if d[1] <= c]
                second.doors[side] = [d for d in room.doors[side] if d[0] >= c]
            walls = _wall_with_door(a, room.y0, b, room.y1, door, axis=1)
            keepout = box(
                a - _DOOR_APPROACH,
                door[0] - clearance,
                b + _DOOR_APPROACH,
                door[1] + clearance,
            )
        else:
            door = _door_interval(rng, room.x0, room.x1, door_lo, door_hi)
            first = _Room(room.x0, room.y0, room.x1, a)
            second = _Room(room.x0, b, room.x1, room.y1)
            first.doors["bottom"] = list(room.doors["bottom"])
            second.doors["top"] = list(room.doors["top"])
            first.doors["top"] = [door]
            second.doors["bottom"] = [door]
            for side in ("left", "right"):
                first.doors[side] = [d for d in room.doors[side] if d[1] <= c]
                second.doors[side] = [d for d in room.doors[side] if d[0] >= c]
            walls = _wall_with_door(room.x0, a, room.x1, b, door, axis=0)
            keepout = box(
                door[0] - clearance,
                a - _DOOR_APPROACH,
                door[1] + clearance,
                b + _DOOR_APPROACH,
            )
        return [first, second], walls, keepout
    return None


def _place_furniture(
    rng: np.random.Generator,
    room: _Room,
    placed: list[Polygon],
    keepouts: NDArray[np.object_],
    clearance: float,
    tries: int = 10,
) -> Polygon | None:
    """One piece of furniture in ``room`` that keeps doors and passages clear, or None.

    A piece either stands flush against one wall (or two, in a corner) and keeps
    ``clearance`` from every other wall, or stands free with ``clearance`` all round; it
    keeps ``clearance`` from every other piece and stays out of the door approach zones.
    """
    w, h = room.x1 - room.x0, room.y1 - room.y0
    for _ in range(tries):
        if rng.random() < 0.55:
            piece = _against_wall(rng, room, w, h, clearance)
        else:
            piece = _free_standing(rng, room, clearance)
        if piece is None:
            continue
        if keepouts.size and shapely.intersects(keepouts, piece).any():
            continue
        if placed and (shapely.distance(np.array(placed, dtype=object), piece) < clearance).any():
            continue
        return piece
    return None


def _against_wall(
    rng: np.random.Generator, room: _Room, w: float, h: float, clearance: float
) -> Polygon | None:
    """An axis-aligned box flush against a random side of the room (sofa, bed, shelf)."""
    side = int(rng.integers(4))
    along, across = (w, h) if side in (0, 1) else (h, w)  # sides 0, 1: bottom, top
    length = rng.uniform(0.6, 2.0)
    depth = rng.uniform(0.35, 0.9)
    if depth > across - clearance:
        return None
    if length > along - clearance:  # a piece in a corner keeps clear of the far end
        return None
    where = rng.random()
    if where < 0.2:
        start = 0.0  # in the corner at the start of the side
    elif where < 0.4:
        start = along - length  # in the corner at its end
    else:
        lo, hi = clearance, along - clearance - length
        if lo > hi:
            return None
        start = rng.uniform(lo, hi)
    if side == 0:
        return box(room.x0 + start, room.y0, room.x0 + start + length, room.y0 + depth)
    if side == 1:
        return box(room.x0 + start, room.y1 - depth, room.x0 + start + length, room.y1)
    if side == 2:
        return box(room.x0, room.y0 + start, room.x0 + depth, room.y0 + start + length)
    return box(room.x1 - depth, room.y0 + start, room.x1, room.y0 + start + length)


def _free_standing(rng: np.random.Generator, room: _Room, clearance: float) -> Polygon | None:
    """A box (some rotated) or a round table with ``clearance`` to every wall."""
    cx = rng.uniform(room.x0, room.x1)
    cy = rng.uniform(room.y0, room.y1)
    kind = rng.random()
    if kind < 0.25:
        piece = Point(cx, cy).buffer(rng.uniform(0.3, 0.6), quad_segs=8)
    else:
        length, depth = rng.uniform(0.5, 1.8), rng.uniform(0.4, 1.0)
        piece = box(cx - length / 2, cy - depth / 2, cx + length / 2, cy + depth / 2)
        if kind < 0.6:
            piece = affinity.rotate(
                piece, rng.uniform(0.0, math.pi), origin=(cx, cy), use_radians=True
            )
    xmin, ymin, xmax, ymax = piece.bounds
    if (
        xmin < room.x0 + clearance
        or ymin < room.y0 + clearance
        or xmax > room.x1 - clearance
        or ymax > room.y1 - clearance
    ):
        return None
    return piece
