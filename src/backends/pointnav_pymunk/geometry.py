"""Static geometry for the pymunk backend: obstacle grids and polygons as convex pieces.

The shapes robots collide with are the floor's blocked set for motion
(:class:`~pointnav_core.floor.collision.FloorCollision`, less VOID): every OBSTACLE cell square
plus the obstacle polygons the floor was built from, so a hand-edited OBSTACLE cell with no
polygon under it and a polygon thinner than a cell both stop a robot. pymunk's polygon
shapes are convex (it takes the hull of whatever it is given), and every shape costs a
little in the broad phase, so both are turned into as few convex pieces as practical:

- OBSTACLE cells merged into axis-aligned rectangles (:func:`merge_cells`, greedy row-run
  merging: runs of cells along a row, stacked while the next row has the same run);
  rectangles that lie inside one obstacle polygon add nothing and are dropped;
- each convex obstacle polygon as it is, each other one cut into convex pieces
  (:func:`convex_pieces`: horizontal slabs between vertex heights, where every piece is a
  trapezoid, then neighbouring pieces glued back while they stay convex).

VOID is no shape at all: a robot falls there (the backend checks the grid), it does not
bump into anything.
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import ArrayLike
from shapely.geometry import Polygon, box

from pointnav_core.errors import ArgumentError, ArgumentTypeError
from pointnav_core.floor.maps import OBSTACLE, TraversableMap

__all__ = ["convex_pieces", "floor_pieces", "merge_cells", "min_thickness"]

#: Relative area tolerance (of a polygon's area) under which it counts as convex.
_CONVEX_RTOL = 1e-9


def merge_cells(mask: ArrayLike) -> list[tuple[int, int, int, int]]:
    """Cover the True cells of a 2D mask with few disjoint rectangles (greedy row runs).

    Parameters
    ----------
    mask : array_like of bool, shape (H, W)
        Cells to cover (e.g. ``codes == OBSTACLE``).

    Returns
    -------
    list of (int, int, int, int)
        Rectangles ``(row0, col0, row1, col1)``, half-open (rows ``row0 .. row1 - 1``,
        columns ``col0 .. col1 - 1``), sorted. They are disjoint and their union is
        exactly the True cells.

    Examples
    --------
    >>> merge_cells([[1, 1, 0], [1, 1, 0], [0, 1, 1]])
    [(0, 0, 2, 2), (2, 1, 3, 3)]
    >>> merge_cells([[0, 0], [0, 0]])
    []
    >>> merge_cells([[1, 0, 1]])  # two runs in one row
    [(0, 0, 1, 1), (0, 2, 1, 3)]
    """
    cells = np.asarray(mask, dtype=bool)
    if cells.ndim != 2:
        raise ArgumentError(f"mask must be a 2D array, got shape {cells.shape}")
    rects: list[tuple[int, int, int, int]] = []
    open_runs: dict[tuple[int, int], int] = {}  # (col0, col1) -> first row
    for row in range(cells.shape[0]):
        edges = np.diff(np.concatenate(([0], cells[row].view(np.int8), [0])))
        starts = np.flatnonzero(edges == 1).tolist()
        ends = np.flatnonzero(edges == -1).tolist()
        runs = set(zip(starts, ends))
        for run in [r for r in open_runs if r not in runs]:
            rects.append((open_runs.pop(run), run[0], row, run[1]))
        for run in sorted(runs):
            open_runs.setdefault(run, row)
    for run, row0 in open_runs.items():
        rects.append((row0, run[0], cells.shape[0], run[1]))
    return sorted(rects)


def _is_convex(poly: Polygon) -> bool:
    if poly.interiors:
        return False
    hull = poly.convex_hull.area
    return hull - poly.area <= _CONVEX_RTOL * max(hull, 1e-300)


def _ring(poly: Polygon) -> list[tuple[float, float]]:
    return [(float(x), float(y)) for x, y in list(poly.exterior.coords)[:-1]]


#: Pieces smaller than this (m^2) are slivers of floating-point cuts and are dropped.
_MIN_AREA = 1e-12


def _polygons(geom: object) -> list[Polygon]:
    parts = shapely.get_parts(geom)
    return [p for p in parts if isinstance(p, Polygon) and p.area > _MIN_AREA]


def convex_pieces(polygon: Polygon) -> list[list[tuple[float, float]]]:
    """Cut a polygon (holes allowed) into convex pieces whose union is the polygon.

    A convex polygon without holes is returned whole. Any other one is cut by horizontal
    lines through all its vertices: inside a slab no vertex lies strictly between the two
    lines, so every piece there is a trapezoid (convex). Pieces of consecutive slabs that
    share an edge are then glued together while their union stays convex, so a convex
    stretch of the outline becomes one piece again.

    Parameters
    ----------
    polygon : shapely.Polygon
        A valid, non-empty polygon in metres.

    Returns
    -------
    list of list of (float, float)
        The pieces' vertex rings (counter-clockwise or not; pymunk takes the hull), in
        metres.

    Examples
    --------
    >>> from shapely.geometry import box
    >>> convex_pieces(box(0, 0, 2, 1))
    [[(2.0, 0.0), (2.0, 1.0), (0.0, 1.0), (0.0, 0.0)]]
    >>> ell = box(0, 0, 2, 1).union(box(0, 0, 1, 2))  # an L: two pieces
    >>> len(convex_pieces(ell))
    2
    >>> walls = box(0, 0, 4, 4).difference(box(1, 1, 3, 3))  # a frame with a hole
    >>> pieces = convex_pieces(walls)
    >>> len(pieces), sum(Polygon(p).area for p in pieces)
    (4, 12.0)
    """
    if not isinstance(polygon, Polygon) or polygon.is_empty:
        raise ArgumentTypeError(f"polygon must be a non-empty shapely Polygon, got {polygon!r}")
    if _is_convex(polygon):
        return [_ring(polygon)]
    xmin, ymin, xmax, ymax = polygon.bounds
    ys = sorted(
        {float(y) for ring in (polygon.exterior, *polygon.interiors) for _, y in ring.coords}
    )
    pad = 1.0 + (xmax - xmin)
    pieces: list[Polygon] = []
    previous: list[int] = []  # indices in ``pieces`` of the last slab's (glued) pieces
    for y0, y1 in zip(ys, ys[1:]):
        if y1 <= y0:
            continue
        slab = polygon.intersection(box(xmin - pad, y0, xmax + pad, y1))
        current = []
        for part in sorted(_polygons(slab), key=lambda p: p.bounds):
            glued = False
            for i in previous:
                union = pieces[i].union(part)
                if isinstance(union, Polygon) and _is_convex(union):
                    pieces[i] = shapely.normalize(union.simplify(0.0))
                    current.append(i)
                    glued = True
                    break
            if not glued:
                pieces.append(part)
                current.append(len(pieces) - 1)
        previous = current
    return [_ring(p) for p in pieces]


def min_thickness(polygon: Polygon) -> float:
    """A thickness scale of a polygon in metres: twice its area over its perimeter.

    Close to the width of a long thin wall and equal to the radius of a disc; used to size
    sub-steps so that nothing passes through the thinnest obstacle.

    Examples
    --------
    >>> from shapely.geometry import box
    >>> round(min_thickness(box(0, 0, 10, 0.1)), 4)
    0.099
    """
    length = polygon.length
    return 2.0 * polygon.area / length if length > 0.0 else 0.0


def floor_pieces(tmap: TraversableMap) -> tuple[list[list[tuple[float, float]]], float]:
    """Convex pieces covering one floor's OBSTACLE cells and obstacle polygons.

    Parameters
    ----------
    tmap : TraversableMap
        The floor. Its OBSTACLE cells and the polygons of its collision geometry
        (``tmap.collision.polygons``, the floor plan's obstacles) are both used.

    Returns
    -------
    pieces : list of list of (float, float)
        Vertex rings in world metres; their union is the OBSTACLE cell squares and the
        polygons.
    thickness : float
        Metres: the smaller of the cell size and the thinnest polygon's
        :func:`min_thickness`.

    Examples
    --------
    >>> m = TraversableMap([[0, 1, 1], [0, 1, 1]], resolution=0.5, origin=(1.0, 0.0))
    >>> floor_pieces(m)
    ([[(1.5, 0.0), (2.5, 0.0), (2.5, 1.0), (1.5, 1.0)]], 0.5)
    """
    res = float(tmap.resolution)
    ox, oy = (float(v) for v in tmap.origin)
    polygons = [part for obstacle in tmap.collision.polygons for part in _polygons(obstacle)]
    tree = shapely.STRtree(polygons) if polygons else None
    pieces: list[list[tuple[float, float]]] = []
    thickness = res
    for r0, c0, r1, c1 in merge_cells(np.asarray(tmap.codes) == OBSTACLE):
        x0, x1 = ox + c0 * res, ox + c1 * res
        y0, y1 = oy + r0 * res, oy + r1 * res
        rect = box(x0, y0, x1, y1)
        if tree is not None and len(tree.query(rect, predicate="within")):
            continue  # covered by a polygon's own pieces
        pieces.append([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
    for part in polygons:
        pieces.extend(convex_pieces(part))
        thickness = min(thickness, min_thickness(part))
    return pieces, thickness
