"""Planar geometry for the kinematic backend: swept discs, grid squares, polygon edges.

Scalar functions here take and return plain floats: they run once per contact candidate
inside a Python loop, where numpy's per-call overhead would dominate.

A robot is a disc of radius ``r``. An obstacle is an axis-aligned cell square or an edge of
a floor plan's obstacle polygon. The set of centre positions where a disc of radius ``R``
overlaps a square is the *rounded square* (the square grown by ``R``): the union of the
square stretched by ``R`` along x, the square stretched by ``R`` along y, and four discs of
radius ``R`` at its corners. For a segment it is the *capsule*: a rectangle of half-width
``R`` along the segment and two discs of radius ``R`` at its ends. A moving disc first
touches the obstacle when its centre enters that region.
"""

from __future__ import annotations

import array
import math

import numpy as np
from scipy import ndimage

from pointnav_core.backends.kit import FloorGrid
from pointnav_core.floor.maps import OBSTACLE, VOID, TraversableMap
from pointnav_kinematic.polygons import EdgeIndex, Segment

__all__ = [
    "FloorGeometry",
    "enter_box",
    "enter_capsule",
    "enter_disc",
    "enter_rounded_square",
    "enter_wall",
    "segment_distance",
    "square_distance",
    "wall_distance",
]


_INF = math.inf


def enter_box(
    px: float, py: float, dx: float, dy: float, x0: float, y0: float, x1: float, y1: float
) -> float:
    """First ``t >= 0`` at which ``p + t*d`` is inside the open box ``(x0, x1) x (y0, y1)``.

    Returns 0 if ``p`` is already inside and ``inf`` if the line never enters ahead.

    Examples
    --------
    >>> enter_box(0.0, 0.5, 1.0, 0.0, 2.0, 0.0, 3.0, 1.0)
    2.0
    >>> enter_box(0.0, 1.0, 1.0, 0.0, 2.0, 0.0, 3.0, 1.0)  # sliding along the top face
    inf
    """
    lo, hi = -_INF, _INF
    if dx != 0.0:
        a = (x0 - px) / dx
        b = (x1 - px) / dx
        if a > b:
            a, b = b, a
        lo, hi = a, b
    elif not x0 < px < x1:
        return _INF
    if dy != 0.0:
        a = (y0 - py) / dy
        b = (y1 - py) / dy
        if a > b:
            a, b = b, a
        if a > lo:
            lo = a
        if b < hi:
            hi = b
    elif not y0 < py < y1:
        return _INF
    if lo < hi and hi > 0.0:
        return lo if lo > 0.0 else 0.0
    return _INF


def enter_disc(
    px: float, py: float, dx: float, dy: float, cx: float, cy: float, radius: float
) -> float:
    """First ``t >= 0`` at which ``p + t*d`` is inside the open disc ``|q - c| < radius``.

    Returns 0 if ``p`` is already inside and ``inf`` if the line never enters ahead.

    Examples
    --------
    >>> enter_disc(0.0, 0.0, 1.0, 0.0, 3.0, 0.0, 1.0)
    2.0
    >>> enter_disc(0.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0)  # grazing is not entering
    inf
    """
    fx = px - cx
    fy = py - cy
    c = fx * fx + fy * fy - radius * radius
    if c < 0.0:
        return 0.0
    b = fx * dx + fy * dy
    if b >= 0.0:
        return _INF
    a = dx * dx + dy * dy
    disc = b * b - a * c
    if disc <= 0.0:
        return _INF
    # c / (-b + sqrt) is the smaller root without cancellation.
    return c / (-b + math.sqrt(disc))


def enter_rounded_square(
    px: float,
    py: float,
    dx: float,
    dy: float,
    x0: float,
    y0: float,
    x1: float,
    y1: float,
    radius: float,
) -> float:
    """First ``t >= 0`` at which a disc of ``radius`` centred at ``p + t*d`` overlaps a square.

    The square is ``[x0, x1] x [y0, y1]``; touching is not overlapping. Returns 0 if the
    disc overlaps it already and ``inf`` if it never will along the line.

    Examples
    --------
    >>> enter_rounded_square(0.0, 0.5, 1.0, 0.0, 2.0, 0.0, 3.0, 1.0, 0.5)
    1.5
    >>> round(enter_rounded_square(0.0, 3.0, 1.0, -1.0, 2.0, 0.0, 3.0, 1.0, 0.5), 6)  # corner
    1.646447
    """
    t = enter_box(px, py, dx, dy, x0 - radius, y0, x1 + radius, y1)
    t2 = enter_box(px, py, dx, dy, x0, y0 - radius, x1, y1 + radius)
    if t2 < t:
        t = t2
    if t > 0.0 and radius > 0.0:
        for cx, cy in ((x0, y0), (x1, y0), (x0, y1), (x1, y1)):
            t2 = enter_disc(px, py, dx, dy, cx, cy, radius)
            if t2 < t:
                t = t2
    return t


def enter_capsule(
    px: float, py: float, dx: float, dy: float, seg: Segment, radius: float
) -> float:
    """First ``t >= 0`` at which a disc of ``radius`` centred at ``p + t*d`` overlaps a segment.

    Touching is not overlapping. Returns 0 if the disc overlaps it already and ``inf`` if
    it never will along the line.

    Examples
    --------
    >>> seg = (2.0, -1.0, 2.0, 1.0, 0.0, 1.0, 2.0)  # x = 2, -1 <= y <= 1
    >>> enter_capsule(0.0, 0.0, 1.0, 0.0, seg, 0.5)
    1.5
    >>> enter_capsule(0.0, 1.5, 1.0, 0.0, seg, 0.5)  # grazing the end disc
    inf
    """
    ax, ay, bx, by, ux, uy, length = seg
    # The rectangle part, in the segment's frame: s along it, q across it.
    rx = px - ax
    ry = py - ay
    t = enter_box(
        rx * ux + ry * uy, ry * ux - rx * uy, dx * ux + dy * uy, dy * ux - dx * uy,
        0.0, -radius, length, radius,
    )
    if t > 0.0 and radius > 0.0:
        t2 = enter_disc(px, py, dx, dy, ax, ay, radius)
        if t2 < t:
            t = t2
        t2 = enter_disc(px, py, dx, dy, bx, by, radius)
        if t2 < t:
            t = t2
    return t


def segment_distance(px: float, py: float, seg: Segment) -> tuple[float, float, float]:
    """Distance from a point to a segment and the unit normal from the segment to the point.

    Returns
    -------
    (float, float, float)
        ``(distance, nx, ny)``: distance in metres (never negative: a segment has no
        inside) and the unit vector from the nearest point of the segment towards ``p``;
        on the segment itself, its left normal.

    Examples
    --------
    >>> segment_distance(3.0, 0.5, (2.0, -1.0, 2.0, 1.0, 0.0, 1.0, 2.0))
    (1.0, 1.0, 0.0)
    >>> segment_distance(2.0, 4.0, (2.0, -1.0, 2.0, 1.0, 0.0, 1.0, 2.0))  # past the end
    (3.0, 0.0, 1.0)
    """
    ax, ay, _, _, ux, uy, length = seg
    s = (px - ax) * ux + (py - ay) * uy
    s = 0.0 if s < 0.0 else length if s > length else s
    vx = px - (ax + s * ux)
    vy = py - (ay + s * uy)
    dist = math.sqrt(vx * vx + vy * vy)
    if dist > 0.0:
        return dist, vx / dist, vy / dist
    return 0.0, -uy, ux


def square_distance(
    px: float, py: float, x0: float, y0: float, x1: float, y1: float
) -> tuple[float, float, float]:
    """Signed distance from a point to the square ``[x0, x1] x [y0, y1]`` and its normal.

    Returns
    -------
    (float, float, float)
        ``(distance, nx, ny)``: distance in metres (negative inside: minus the depth) and
        the unit outward normal at the nearest boundary point, which points from the
        square towards ``p``.

    Examples
    --------
    >>> square_distance(3.0, 0.5, 0.0, 0.0, 1.0, 1.0)
    (2.0, 1.0, 0.0)
    >>> square_distance(0.5, 0.9, 0.0, 0.0, 1.0, 1.0)[0] < 0  # inside
    True
    """
    qx = x0 if px < x0 else x1 if px > x1 else px
    qy = y0 if py < y0 else y1 if py > y1 else py
    vx = px - qx
    vy = py - qy
    dist = math.sqrt(vx * vx + vy * vy)
    if dist > 0.0:
        return dist, vx / dist, vy / dist
    # On the boundary or inside: leave through the nearest face.
    faces = ((px - x0, -1.0, 0.0), (x1 - px, 1.0, 0.0), (py - y0, 0.0, -1.0), (y1 - py, 0.0, 1.0))
    depth, nx, ny = min(faces)
    return -depth, nx, ny


class FloorGeometry(FloorGrid):
    """One floor's blocked set, preprocessed for fast motion queries.

    A :class:`~pointnav_core.backends.kit.FloorGrid` (cell lookups, the exact disc test)
    with the clearance tables and wall indices of the kinematic backend's motion.

    Parameters
    ----------
    tmap : TraversableMap
        The floor: its grid, and through ``tmap.collision`` the obstacle polygons of the
        floor plan it was built from, if any.
    height : float
        World z of the floor in metres.

    Attributes
    ----------
    edge : bytes
        Row-major flags of *edge* obstacle cells: obstacles with a side neighbour that is
        not an obstacle (or off the map). A disc approaching from free space meets an edge
        cell first, so contact queries only look at these.
    edges : EdgeIndex
        The boundary segments of the obstacle polygons.
    """

    def __init__(self, tmap: TraversableMap, height: float) -> None:
        super().__init__(tmap, height)
        codes = np.asarray(tmap.codes)
        # Buckets of a few cells: one step's search box spans one to four of them.
        self.edges = EdgeIndex(self.collision.polygons, bucket=4.0 * self.res)
        obstacle = codes == OBSTACLE
        self.has_obstacles = bool(obstacle.any())
        pad = np.pad(obstacle, 1, constant_values=False)
        interior = pad[:-2, 1:-1] & pad[2:, 1:-1] & pad[1:-1, :-2] & pad[1:-1, 2:]
        self.edge = (obstacle & ~interior).astype(np.uint8).tobytes()
        # Lower bounds, in metres, on the distance from ANY point of a cell to the nearest
        # obstacle square or polygon / VOID-or-off-map square: centre-to-centre distance
        # minus two half diagonals (one for each square).
        slack = math.sqrt(2.0)
        blocking = obstacle
        self._polygon_off_map = False
        if len(self.edges):
            blocking = obstacle | self.edges.touched_cells(codes.shape, self.res, tmap.origin)
            x0, y0, x1, y1 = shapely_bounds(self.collision.polygons)
            self._polygon_off_map = not (
                x0 >= self.ox
                and y0 >= self.oy
                and x1 <= self.ox + self.width * self.res
                and y1 <= self.oy + self.rows * self.res
            )
        if blocking.any():
            edt = ndimage.distance_transform_edt(~blocking)
            self._clear_obstacle = (np.asarray(edt) - slack) * self.res
        else:
            self._clear_obstacle = np.full(codes.shape, np.inf)
        void = np.pad(codes == VOID, 1, constant_values=True)  # off the map is VOID
        edt_void = np.asarray(ndimage.distance_transform_edt(~void))[1:-1, 1:-1]
        self._clear_void = (edt_void - slack) * self.res
        self._fast: dict[float, array.array[float]] = {}

    def fast_clearance(self, radius: float) -> array.array[float]:
        """Per-cell travel budget (m) within which a disc of ``radius`` meets nothing.

        A disc of ``radius`` whose centre starts anywhere in cell ``i`` and moves less
        than ``fast_clearance(radius)[i]`` metres (along any path) neither touches an
        obstacle square or polygon nor puts its centre over VOID. Row-major, cached per
        radius.
        """
        grid = self._fast.get(radius)
        if grid is None:
            void = self._clear_void
            if self._polygon_off_map:  # the disc may reach a polygon beyond the map's edge
                void = void - radius
            budget = np.minimum(self._clear_obstacle - radius, void)
            # A plain array of doubles: indexing it gives Python floats as fast as a
            # memoryview does, and unlike a memoryview it pickles (as its values).
            grid = array.array("d", np.ascontiguousarray(budget, dtype=np.float64).ravel().tobytes())
            self._fast[radius] = grid
        return grid

    def edge_squares(
        self, xmin: float, ymin: float, xmax: float, ymax: float
    ) -> list[tuple[float, float, float, float]]:
        """Edge obstacle squares ``(x0, y0, x1, y1)`` meeting the box, in row-major order."""
        if not self.has_obstacles:
            return []
        inv, res, ox, oy = self.inv_res, self.res, self.ox, self.oy
        c0 = max(math.floor((xmin - ox) * inv), 0)
        c1 = min(math.floor((xmax - ox) * inv), self.width - 1)
        r0 = max(math.floor((ymin - oy) * inv), 0)
        r1 = min(math.floor((ymax - oy) * inv), self.rows - 1)
        edge, width = self.edge, self.width
        out = []
        for row in range(r0, r1 + 1):
            base = row * width
            # Skip obstacle-free stretches of the row in C rather than cell by cell.
            col = edge.find(1, base + c0, base + c1 + 1)
            while col >= 0:
                x0 = ox + (col - base) * res
                y0 = oy + row * res
                out.append((x0, y0, x0 + res, y0 + res))
                col = edge.find(1, col + 1, base + c1 + 1)
        return out

    def walls(
        self, xmin: float, ymin: float, xmax: float, ymax: float
    ) -> list[tuple[float, ...]]:
        """Edge obstacle squares (4-tuples) and polygon edges (:data:`Segment`) near the box."""
        out: list[tuple[float, ...]] = list(self.edge_squares(xmin, ymin, xmax, ymax))
        if len(self.edges):
            out.extend(self.edges.near(xmin, ymin, xmax, ymax))
        return out


def shapely_bounds(polygons: tuple) -> tuple[float, float, float, float]:
    """Bounding box ``(xmin, ymin, xmax, ymax)`` in metres of a non-empty set of polygons."""
    b = np.array([p.bounds for p in polygons])
    return float(b[:, 0].min()), float(b[:, 1].min()), float(b[:, 2].max()), float(b[:, 3].max())


def wall_distance(px: float, py: float, wall: tuple[float, ...]) -> tuple[float, float, float]:
    """:func:`square_distance` or :func:`segment_distance`, as the wall's kind asks."""
    if len(wall) == 4:
        return square_distance(px, py, *wall)
    return segment_distance(px, py, wall)  # type: ignore[arg-type]


def enter_wall(
    px: float, py: float, dx: float, dy: float, wall: tuple[float, ...], radius: float
) -> float:
    """:func:`enter_rounded_square` or :func:`enter_capsule`, as the wall's kind asks."""
    if len(wall) == 4:
        return enter_rounded_square(px, py, dx, dy, *wall, radius)
    return enter_capsule(px, py, dx, dy, wall, radius)  # type: ignore[arg-type]
