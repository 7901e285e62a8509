"""Floor plans as shapely geometry: seeded procedural generators, and rasterisation to a grid.

A :class:`FloorPlan` is a floor outline (outside it there is no floor: VOID) and obstacle
polygons inside it (walls and furniture: OBSTACLE). :func:`rasterize` turns any outline and
obstacles into the cell codes of a :class:`~pointnav_core.maps.TraversableMap`.

Three generators build house-like plans, deterministically for a seed:

==============  ==================================================================
:func:`rooms`   a house (rectangular or L-shaped) split into rooms by interior
                walls, one door per wall, furniture kept off the doors
:func:`maze`    a perfect maze (exactly one route between any two places)
:func:`clutter` an open hall with many boxes and discs
==============  ==================================================================

Every plan is centred on the world origin and its outline is the outer boundary of its outer
walls. The free space of every generated plan is one connected region for a robot narrower
than the plan's clearance (``clearance`` for :func:`rooms`, ``corridor`` for :func:`maze`,
``gap`` for :func:`clutter`; 0.8 m or more at the defaults). Each generator guarantees this
by construction; on a grid, allow about two cells of slack (a robot of radius 0.2 m on a
0.1 m grid is safe at the defaults), which the test suite checks on rasterised, eroded grids.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely import affinity
from shapely.geometry import MultiPolygon, Point, Polygon, box

from pointnav_core import validation
from pointnav_core.maps import FREE, OBSTACLE, VOID

__all__ = ["FloorPlan", "clutter", "maze", "rasterize", "rooms"]

Seed = int | np.random.SeedSequence | np.random.Generator | None

# Tolerance for snapping a bound that should be a whole number of cells (0.3 / 0.1 is not 3).
_SNAP_TOL = 1e-9
# Refuse grids beyond this many cells: the cell-centre arrays alone would take gigabytes.
_MAX_CELLS = 100_000_000


@dataclass(frozen=True, kw_only=True, repr=False)
class FloorPlan:
    """The geometry of one floor: an outline and the obstacles inside it, in metres.

    Parameters
    ----------
    outline : shapely.Polygon
        The floor's outer boundary; outside it there is no floor (VOID). Must be valid and
        non-empty.
    obstacles : iterable of shapely.Polygon, default ()
        Walls and furniture (OBSTACLE), each valid and non-empty; stored as a tuple.

    Raises
    ------
    TypeError
        When ``outline`` or an obstacle is not a shapely ``Polygon``.
    ValueError
        When a polygon is empty or invalid (the message says why, and which obstacle).

    Examples
    --------
    >>> plan = FloorPlan(outline=box(0, 0, 4, 3), obstacles=[box(1, 1, 2, 2)])
    >>> plan
    FloorPlan(outline=<Polygon, bounds (0, 0, 4, 3), 4 vertices>, obstacles=<1 polygons>)
    >>> plan.obstacles == (box(1, 1, 2, 2),)
    True
    >>> codes, origin = plan.rasterize(1.0)
    >>> codes
    array([[0, 0, 0, 0],
           [0, 1, 0, 0],
           [0, 0, 0, 0]], dtype=uint8)
    """

    outline: Polygon
    obstacles: tuple[Polygon, ...] = field(default=())

    def __post_init__(self) -> None:
        _check_polygon(self.outline, "outline")
        if isinstance(self.obstacles, (str, bytes)) or not isinstance(self.obstacles, Iterable):
            raise TypeError(
                f"obstacles must be an iterable of shapely Polygons, got {type(self.obstacles).__name__}"
            )
        obstacles = tuple(self.obstacles)
        for i, obstacle in enumerate(obstacles):
            _check_polygon(obstacle, f"obstacles[{i}]")
        object.__setattr__(self, "obstacles", obstacles)

    def __repr__(self) -> str:
        bounds = ", ".join(f"{v:g}" for v in self.outline.bounds)
        return (
            f"FloorPlan(outline=<Polygon, bounds ({bounds}), {len(self.outline.exterior.coords) - 1} "
            f"vertices>, obstacles=<{len(self.obstacles)} polygons>)"
        )

    @property
    def size(self) -> tuple[float, float]:
        """Width and height of the outline's bounding box, in metres."""
        xmin, ymin, xmax, ymax = self.outline.bounds
        return (xmax - xmin, ymax - ymin)

    def rasterize(self, resolution: float) -> tuple[NDArray[np.uint8], tuple[float, float]]:
        """Cell codes and origin of this plan at ``resolution`` metres per cell; see :func:`rasterize`."""
        return rasterize(self.outline, self.obstacles, resolution)


def _check_polygon(geom: object, name: str) -> None:
    if not isinstance(geom, Polygon):
        hint = " (split it with shapely.get_parts)" if isinstance(geom, MultiPolygon) else ""
        raise TypeError(f"{name} must be a shapely Polygon, got {type(geom).__name__}{hint}")
    if geom.is_empty:
        raise ValueError(f"{name} must be a non-empty Polygon")
    if not geom.is_valid:
        raise ValueError(f"{name} must be a valid Polygon: {shapely.is_valid_reason(geom)}")


def _check_positive(value: float, name: str, unit: str = "m") -> float:
    return validation.real(name, value, minimum=0.0, strict=True, unit=unit)


def _check_pair(value: Sequence[float], name: str, meaning: str) -> tuple[float, float]:
    try:
        a, b = validation.vector(name, value, sizes=(2,))
    except ValueError:
        raise ValueError(f"{name} must be two numbers {meaning}, got {value!r}") from None
    if not (a > 0.0 and b > 0.0):
        raise ValueError(f"{name} must be two finite numbers > 0 {meaning}, got {value!r}")
    return float(a), float(b)


def _check_range(value: Sequence[float], name: str) -> tuple[float, float]:
    lo, hi = _check_pair(value, name, "(min, max) in metres")
    if lo > hi:
        raise ValueError(f"{name} must be (min, max) with min <= max, got {value!r}")
    return lo, hi


def _rng(seed: object) -> np.random.Generator:
    """A Generator from ``seed``: None, an int >= 0, a SeedSequence or a Generator."""
    if seed is None or isinstance(seed, (np.random.SeedSequence, np.random.Generator)):
        return np.random.default_rng(seed)
    return np.random.default_rng(validation.integer("seed", seed, minimum=0))


def _check_probability(value: float, name: str) -> float:
    if not (validation.is_real(value) and 0.0 <= value <= 1.0):
        raise ValueError(f"{name} must be a probability in [0, 1], got {value!r}")
    return float(value)


# --------------------------------------------------------------------------- rasterize
def rasterize(
    outline: Polygon,
    obstacles: Iterable[Polygon],
    resolution: float,
) -> tuple[NDArray[np.uint8], tuple[float, float]]:
    """Turn a floor outline and obstacle polygons into a grid of cell codes.

    The grid covers ``outline.bounds``, snapped outward to whole multiples of ``resolution``
    (so that grids of the same resolution share cell boundaries). Each cell takes the class of
    its centre: VOID outside the outline, OBSTACLE inside any obstacle, FREE otherwise. Both
    tests are closed: a centre exactly on a boundary is inside, so a wall face on a row of
    centres blocks it.

    Parameters
    ----------
    outline : shapely.Polygon
        Where the floor is, in metres.
    obstacles : iterable of shapely.Polygon
        What blocks it (may be empty). Parts outside the outline are VOID there.
    resolution : float
        Metres per cell, > 0.

    Returns
    -------
    codes : ndarray of uint8, shape (H, W)
        :data:`~pointnav_core.maps.FREE`, :data:`~pointnav_core.maps.OBSTACLE` or
        :data:`~pointnav_core.maps.VOID` per cell; row grows with +y, column with +x.
    origin : (float, float)
        World ``(x, y)`` in metres of the outer corner of cell ``(0, 0)``.

    Raises
    ------
    TypeError
        When ``outline`` or an obstacle is not a shapely Polygon.
    ValueError
        When ``resolution`` is not a finite positive number, or is so fine that the grid
        would exceed 100 million cells.

    See Also
    --------
    FloorPlan.rasterize : the same for a plan.
    pointnav_core.maps.TraversableMap : wraps ``codes``, ``resolution`` and ``origin``.

    Notes
    -----
    Sampling cell centres places every boundary within half a cell of its true position, and
    an obstacle thinner than one cell can fall between two rows of centres and vanish: use a
    resolution no coarser than the thinnest wall. Cost is one vectorised point-in-polygon test
    per cell (shapely's ``intersects_xy`` on prepared geometry), about 0.5 s per million cells.

    Examples
    --------
    >>> L = Polygon([(0, 0), (3, 0), (3, 1), (1, 1), (1, 2), (0, 2)])
    >>> codes, origin = rasterize(L, [box(2, 0, 3, 0.5)], resolution=0.5)
    >>> codes[::-1]  # printed with +y up
    array([[0, 0, 2, 2, 2, 2],
           [0, 0, 2, 2, 2, 2],
           [0, 0, 0, 0, 0, 0],
           [0, 0, 0, 0, 1, 1]], dtype=uint8)
    >>> origin
    (0.0, 0.0)
    >>> rasterize(box(0.05, 0, 1, 1), [], resolution=0.5)[1]  # bounds snapped outward
    (0.0, 0.0)
    """
    _check_polygon(outline, "outline")
    obstacles = tuple(obstacles)
    for i, obstacle in enumerate(obstacles):
        _check_polygon(obstacle, f"obstacles[{i}]")
    resolution = _check_positive(resolution, "resolution", "m/cell")

    xmin, ymin, xmax, ymax = outline.bounds
    col0 = math.floor(xmin / resolution + _SNAP_TOL)
    row0 = math.floor(ymin / resolution + _SNAP_TOL)
    width = max(1, math.ceil(xmax / resolution - _SNAP_TOL) - col0)
    height = max(1, math.ceil(ymax / resolution - _SNAP_TOL) - row0)
    if width * height > _MAX_CELLS:
        raise ValueError(
            f"resolution {resolution} m/cell is too fine for an outline of "
            f"{xmax - xmin:.3g} x {ymax - ymin:.3g} m: {height} x {width} cells "
            f"(at most {_MAX_CELLS} allowed)"
        )
    origin = (col0 * resolution, row0 * resolution)
    xs = origin[0] + (np.arange(width) + 0.5) * resolution
    ys = origin[1] + (np.arange(height) + 0.5) * resolution
    cx, cy = np.meshgrid(xs, ys)

    # Prepare private copies: ``shapely.prepare`` mutates its argument.
    floor = shapely.from_wkb(shapely.to_wkb(outline))
    shapely.prepare(floor)
    inside = shapely.intersects_xy(floor, cx, cy)
    codes = np.full((height, width), VOID, dtype=np.uint8)
    codes[inside] = FREE
    if obstacles:
        blocked = shapely.union_all(obstacles)
        shapely.prepare(blocked)
        hit = shapely.intersects_xy(blocked, cx[inside], cy[inside])
        rows, cols = np.nonzero(inside)
        codes[rows[hit], cols[hit]] = OBSTACLE
    return codes, origin


# --------------------------------------------------------------------------- rooms
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
    rng = _rng(seed)
    width, height = _check_pair(size, "size", "(width, height) in metres")
    wall = _check_positive(wall, "wall")
    outer_wall = _check_positive(outer_wall, "outer_wall")
    door_lo, door_hi = _check_range(door_width, "door_width")
    min_room = _check_positive(min_room, "min_room")
    if min_room < door_hi + 2 * _DOOR_MARGIN:
        raise ValueError(
            f"min_room must be at least the widest door plus {2 * _DOOR_MARGIN} m "
            f"({door_hi + 2 * _DOOR_MARGIN} m), got {min_room}"
        )
    max_room = _check_positive(max_room, "max_room")
    if max_room < min_room:
        raise ValueError(f"max_room must be >= min_room ({min_room} m), got {max_room}")
    l_shape = _check_probability(l_shape, "l_shape")
    furniture = float(furniture)
    if not (math.isfinite(furniture) and furniture >= 0.0):
        raise ValueError(f"furniture must be a finite number >= 0 (pieces per room), got {furniture!r}")
    clearance = _check_positive(clearance, "clearance")
    if min(width, height) < min_room + 2 * outer_wall:
        raise ValueError(
            f"size must be at least min_room + 2 * outer_wall = {min_room + 2 * outer_wall} m "
            f"on each side, got {size!r}"
        )

    x0, y0, x1, y1 = -width / 2, -height / 2, width / 2, height / 2
    t = outer_wall
    # Canonical orientation: the notch of an L is the top-right corner; mirrored at the end.
    notch_w = rng.uniform(0.3, 0.5) * width
    notch_h = rng.uniform(0.3, 0.5) * height
    use_l = rng.random() < l_shape
    strip_h = height - notch_h - 2 * t  # inner height of the full-width strip
    block_w = width - notch_w - 2 * t  # inner width of the block above it
    block_h = notch_h - wall  # inner height of the block above the dividing wall
    if use_l and min(strip_h, block_w, block_h) >= min_room:
        outline = Polygon(
            [(x0, y0), (x1, y0), (x1, y1 - notch_h), (x1 - notch_w, y1 - notch_h),
             (x1 - notch_w, y1), (x0, y1)]
        )
        ix1, iy1 = x1 - notch_w - t, y1 - notch_h - t  # inner corner of the notch
        inner = Polygon(
            [(x0 + t, y0 + t), (x1 - t, y0 + t), (x1 - t, iy1), (ix1, iy1),
             (ix1, y1 - t), (x0 + t, y1 - t)]
        )
        strip = _Room(x0 + t, y0 + t, x1 - t, iy1)
        block = _Room(x0 + t, iy1 + wall, ix1, y1 - t)
        # The dividing wall continues the strip's top face to the notch.
        door = _door_interval(rng, x0 + t, ix1, door_lo, door_hi)
        walls = _wall_with_door(x0 + t, iy1, ix1, iy1 + wall, door, axis=0)
        strip.doors["top"].append(door)
        block.doors["bottom"].append(door)
        keepouts = [box(door[0] - clearance, iy1 - _DOOR_APPROACH, door[1] + clearance,
                        iy1 + wall + _DOOR_APPROACH)]
        todo = [strip, block]
    else:
        outline = box(x0, y0, x1, y1)
        inner = box(x0 + t, y0 + t, x1 - t, y1 - t)
        walls, keepouts = [], []
        todo = [_Room(x0 + t, y0 + t, x1 - t, y1 - t)]
    ring = Polygon(outline.exterior.coords, [inner.exterior.coords])

    leaves: list[_Room] = []
    while todo:
        room = todo.pop()
        split = _split_room(rng, room, min_room, max_room, wall, door_lo, door_hi, clearance)
        if split is None:
            leaves.append(room)
            continue
        children, new_walls, keepout = split
        walls.extend(new_walls)
        keepouts.append(keepout)
        todo.extend(children)

    keepout_array = np.array(keepouts, dtype=object)
    pieces: list[Polygon] = []
    for room in leaves:
        for _ in range(rng.poisson(furniture)):
            piece = _place_furniture(rng, room, pieces, keepout_array, clearance)
            if piece is not None:
                pieces.append(piece)

    sx, sy = rng.choice([-1.0, 1.0], size=2)
    geoms = [ring, *walls, *pieces]
    if sx != 1.0 or sy != 1.0:
        outline = affinity.scale(outline, sx, sy, origin=(0, 0))
        geoms = [affinity.scale(g, sx, sy, origin=(0, 0)) for g in geoms]
    return FloorPlan(outline=outline, obstacles=tuple(geoms))


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


def _allowed(lo: float, hi: float, forbidden: list[tuple[float, float]]) -> list[tuple[float, float]]:
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
            keepout = box(a - _DOOR_APPROACH, door[0] - clearance, b + _DOOR_APPROACH, door[1] + clearance)
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
            keepout = box(door[0] - clearance, a - _DOOR_APPROACH, door[1] + clearance, b + _DOOR_APPROACH)
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
            piece = affinity.rotate(piece, rng.uniform(0.0, math.pi), origin=(cx, cy), use_radians=True)
    xmin, ymin, xmax, ymax = piece.bounds
    if (
        xmin < room.x0 + clearance
        or ymin < room.y0 + clearance
        or xmax > room.x1 - clearance
        or ymax > room.y1 - clearance
    ):
        return None
    return piece


# --------------------------------------------------------------------------- maze
def maze(
    seed: Seed = None,
    size: tuple[float, float] = (16.0, 16.0),
    *,
    corridor: float = 1.2,
    wall: float = 0.15,
) -> FloorPlan:
    """Generate a perfect maze: exactly one route between any two places, no loops.

    The plan is a grid of ``nx x ny`` cells, as many as fit ``corridor + wall`` metres apart;
    corridors are widened so that the maze fills ``size`` exactly. The passages are a random
    spanning tree of the cell grid (recursive backtracker, so long winding corridors), and the
    walls are drawn as rectangles, merged along straight runs.

    Parameters
    ----------
    seed : int, numpy SeedSequence or Generator, or None
        Seed of ``np.random.default_rng``; the same seed gives the same maze.
    size : (float, float), default (16.0, 16.0)
        Outer width (x) and height (y), in metres.
    corridor : float, default 1.2
        Smallest corridor width (m).
    wall : float, default 0.15
        Wall thickness (m), outer walls included.

    Returns
    -------
    FloorPlan
        Outline: the maze's outer boundary, centred on the origin. Obstacles: the outer wall
        ring, then the interior walls.

    Raises
    ------
    ValueError
        When a parameter is out of range, or ``size`` leaves room for fewer than 2 cells.

    Examples
    --------
    >>> plan = maze(seed=1, size=(4.2, 2.2), corridor=0.8, wall=0.2)  # 4 x 2 cells of 1 m
    >>> codes, origin = plan.rasterize(0.1)
    >>> codes.shape, origin
    ((22, 42), (-2.1, -1.1))
    >>> len(plan.obstacles)  # the outer ring and the merged runs of interior wall
    4
    >>> plan == maze(seed=1, size=(4.2, 2.2), corridor=0.8, wall=0.2)
    True
    """
    rng = _rng(seed)
    width, height = _check_pair(size, "size", "(width, height) in metres")
    corridor = _check_positive(corridor, "corridor")
    wall = _check_positive(wall, "wall")
    pitch = corridor + wall
    nx = math.floor((width - wall) / pitch + _SNAP_TOL)
    ny = math.floor((height - wall) / pitch + _SNAP_TOL)
    if nx < 1 or ny < 1 or nx * ny < 2:
        raise ValueError(
            f"size must fit at least 2 cells of corridor + wall = {pitch} m (plus one wall), "
            f"got {size!r}"
        )
    x0, y0 = -width / 2, -height / 2
    px, py = (width - wall) / nx, (height - wall) / ny
    xs = x0 + px * np.arange(nx + 1)  # left edge of each vertical wall line
    ys = y0 + py * np.arange(ny + 1)  # bottom edge of each horizontal wall line

    # Recursive backtracker; open_x[j, i]: passage between cells (j, i) and (j, i + 1).
    open_x = np.zeros((ny, nx - 1), dtype=bool)
    open_y = np.zeros((ny - 1, nx), dtype=bool)
    visited = np.zeros((ny, nx), dtype=bool)
    start = (int(rng.integers(ny)), int(rng.integers(nx)))
    visited[start] = True
    stack = [start]
    while stack:
        j, i = stack[-1]
        steps = [
            (dj, di)
            for dj, di in ((0, 1), (0, -1), (1, 0), (-1, 0))
            if 0 <= j + dj < ny and 0 <= i + di < nx and not visited[j + dj, i + di]
        ]
        if not steps:
            stack.pop()
            continue
        dj, di = steps[int(rng.integers(len(steps)))]
        if di:
            open_x[j, min(i, i + di)] = True
        else:
            open_y[min(j, j + dj), i] = True
        visited[j + dj, i + di] = True
        stack.append((j + dj, i + di))

    # Far edge of each wall line; clipped, as x0 + px * nx + wall can round past -x0.
    xe, ye = np.minimum(xs + wall, -x0), np.minimum(ys + wall, -y0)
    walls: list[Polygon] = []
    # Vertical wall line k (1 .. nx-1) between columns k-1 and k: closed where not open.
    for k in range(1, nx):
        for j0, j1 in _runs(~open_x[:, k - 1]):
            walls.append(box(xs[k], ys[j0], xe[k], ye[j1]))
    for k in range(1, ny):
        for i0, i1 in _runs(~open_y[k - 1, :]):
            walls.append(box(xs[i0], ys[k], xe[i1], ye[k]))
    outline, ring = _walled_box(width, height, wall)
    return FloorPlan(outline=outline, obstacles=(ring, *walls))


def _walled_box(width: float, height: float, wall: float) -> tuple[Polygon, Polygon]:
    """A ``width x height`` outline centred on the origin, and its outer wall ring."""
    outline = box(-width / 2, -height / 2, width / 2, height / 2)
    inner = box(-width / 2 + wall, -height / 2 + wall, width / 2 - wall, height / 2 - wall)
    return outline, Polygon(outline.exterior.coords, [inner.exterior.coords])


def _runs(closed: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """``(first, end)`` of each run of True in ``closed``, ``end`` exclusive."""
    edges = np.diff(np.concatenate([[0], closed.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


# --------------------------------------------------------------------------- clutter
def clutter(
    seed: Seed = None,
    size: tuple[float, float] = (20.0, 20.0),
    *,
    n_obstacles: int | None = None,
    obstacle_size: tuple[float, float] = (0.3, 1.5),
    discs: float = 0.3,
    grouped: float = 0.3,
    gap: float = 0.8,
    wall: float = 0.2,
) -> FloorPlan:
    """Generate an open hall cluttered with boxes (randomly rotated) and discs.

    Shapes stand at least ``gap`` from the walls and from each other, except that some
    (a fraction ``grouped`` of the tries) are laid across an existing group of shapes: through
    the point its first shape is centred on, and at least half outside it. A group becomes one
    obstacle polygon: the union of its shapes, closed with a disc of diameter ``gap`` so that
    the narrow wedges between shapes are filled. Groups have no holes or pockets and stand
    ``gap`` apart, so the free space stays one connected region for every robot narrower than
    ``gap``.

    Parameters
    ----------
    seed : int, numpy SeedSequence or Generator, or None
        Seed of ``np.random.default_rng``; the same seed gives the same plan.
    size : (float, float), default (20.0, 20.0)
        Outer width (x) and height (y), in metres.
    n_obstacles : int or None, default None
        How many shapes to place, >= 0; None places one per 8 m² of floor (50 at the default
        size). Up to ``20 * n_obstacles`` positions are tried; when the hall fills up first,
        fewer are placed.
    obstacle_size : (float, float), default (0.3, 1.5)
        Range of box sides and disc diameters (m).
    discs : float, default 0.3
        Probability that an obstacle is a disc rather than a box.
    grouped : float, default 0.3
        Probability that an obstacle is laid across an existing group.
    gap : float, default 0.8
        Smallest passage between groups, and between a group and the walls (m).
    wall : float, default 0.2
        Outer wall thickness (m).

    Returns
    -------
    FloorPlan
        Outline: the hall's outer boundary, centred on the origin. Obstacles: the outer wall
        ring, then one polygon per group of shapes (a single box or disc for most).

    Raises
    ------
    ValueError
        When a parameter is out of range; the message names it.

    Examples
    --------
    >>> plan = clutter(seed=3, n_obstacles=10, grouped=0.0)
    >>> len(plan.obstacles)  # the wall ring and 10 shapes
    11
    >>> len(clutter(seed=3, n_obstacles=10, grouped=1.0).obstacles)  # all in one group
    2
    """
    rng = _rng(seed)
    width, height = _check_pair(size, "size", "(width, height) in metres")
    if n_obstacles is None:
        n_obstacles = round(width * height / 8.0)
    if isinstance(n_obstacles, bool) or not isinstance(n_obstacles, (int, np.integer)) or n_obstacles < 0:
        raise ValueError(f"n_obstacles must be an integer >= 0 or None, got {n_obstacles!r}")
    size_lo, size_hi = _check_range(obstacle_size, "obstacle_size")
    discs = _check_probability(discs, "discs")
    grouped = _check_probability(grouped, "grouped")
    gap = _check_positive(gap, "gap")
    wall = _check_positive(wall, "wall")
    margin = wall + gap  # shapes keep ``gap`` from the wall
    hall = (-width / 2 + margin, -height / 2 + margin, width / 2 - margin, height / 2 - margin)
    if hall[2] - hall[0] < size_hi or hall[3] - hall[1] < size_hi:
        raise ValueError(
            f"size must leave room for the largest obstacle: at least "
            f"obstacle_size[1] + 2 * (wall + gap) = {size_hi + 2 * (wall + gap)} m a side, got {size!r}"
        )
    outline, ring = _walled_box(width, height, wall)

    # Each group is one obstacle polygon: a single shape, or the closed union of several.
    groups: list[Polygon] = []
    anchors: list[tuple[float, float]] = []  # the point every shape of a group contains
    placed = 0
    for _ in range(20 * int(n_obstacles)):
        if placed == n_obstacles:
            break
        join = groups and rng.random() < grouped
        is_disc = rng.random() < discs
        extent, other = rng.uniform(size_lo, size_hi, size=2)
        angle = rng.uniform(0.0, math.pi)
        if join:
            g = int(rng.integers(len(groups)))
            # Put the anchor at a random point well inside the new shape (in its own frame).
            u, v = rng.uniform(-0.8, 0.8, size=2)
            if is_disc:
                v = 0.0  # a point on the diameter at ``angle``
            du, dv = u * extent / 2, v * other / 2
            ax, ay = anchors[g]
            cx = ax - (du * math.cos(angle) - dv * math.sin(angle))
            cy = ay - (du * math.sin(angle) + dv * math.cos(angle))
        else:
            g = -1
            cx, cy = rng.uniform(hall[0], hall[2]), rng.uniform(hall[1], hall[3])
        if is_disc:
            shape = Point(cx, cy).buffer(extent / 2, quad_segs=8)
        else:
            shape = affinity.rotate(
                box(cx - extent / 2, cy - other / 2, cx + extent / 2, cy + other / 2),
                angle,
                origin=(cx, cy),
                use_radians=True,
            )
        xmin, ymin, xmax, ymax = shape.bounds
        if xmin < hall[0] or ymin < hall[1] or xmax > hall[2] or ymax > hall[3]:
            continue
        if g >= 0:
            if not shape.contains(Point(anchors[g])):
                continue
            if shape.difference(groups[g]).area < 0.5 * shape.area:  # mostly new, not a pile
                continue
            # Close the union with a disc of radius gap / 2: this fills the narrow wedges
            # between shapes, whose tips a robot could enter but not turn round in (on a grid
            # they leave isolated usable cells). The closing stays in the convex hull.
            union = shapely.union(groups[g], shape)
            closed = union.buffer(gap / 2, quad_segs=8).buffer(-gap / 2, quad_segs=8)
            # Rounding in the buffers can leave specks beside the body, or pinholes in it.
            body = max(shapely.get_parts(shapely.union(closed, union)), key=lambda p: p.area)
            candidate = Polygon(body.exterior)
        else:
            candidate = shape
        others = [group for k, group in enumerate(groups) if k != g]
        if others and (shapely.distance(np.array(others, dtype=object), candidate) < gap).any():
            continue
        placed += 1
        if g >= 0:
            groups[g] = candidate
        else:
            groups.append(candidate)
            anchors.append((cx, cy))
    return FloorPlan(outline=outline, obstacles=(ring, *groups))
