"""The floor collision geometry against an independent shapely reference.

The reference builds the blocked set from first principles (one shapely box per blocked
cell, a frame around the map, the polygons) and measures distances with shapely; the
library's exact stadium/prefix-sum test must agree with ``distance >= r`` everywhere except
within 1e-7 m of the boundary, where touching is allowed either way.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import Point, box

from pointnav_core.floor.collision import FloorCollision, convex_corners


def reference_blocked(grid: np.ndarray, res: float, origin: tuple[float, float], polygons=()):
    ox, oy = origin
    h, w = grid.shape
    squares = [box(ox + c * res, oy + r * res, ox + (c + 1) * res, oy + (r + 1) * res) for r, c in zip(*np.nonzero(grid))]
    inside = box(ox, oy, ox + w * res, oy + h * res)
    frame = inside.buffer(1000.0, join_style="mitre").difference(inside)
    return shapely.union_all([*squares, frame, *polygons])


def reference_clear(blocked, a: np.ndarray, b: np.ndarray, r: float) -> tuple[np.ndarray, np.ndarray]:
    geoms = [Point(p) if (p == q).all() else shapely.LineString([p, q]) for p, q in zip(a, b)]
    d = shapely.distance(blocked, geoms)
    return d >= r, np.abs(d - r) < 1e-7


@pytest.mark.parametrize("seed", range(12))
def test_segments_agree_with_shapely_on_random_grids(seed):
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(3, 14, 2))
    res = float(rng.choice([0.05, 0.1, 0.5]))
    r = float(rng.uniform(0.0, 3.0)) * res  # radius from zero to three cells
    grid = rng.random((h, w)) < 0.25
    origin = (float(rng.uniform(-2, 2)), float(rng.uniform(-2, 2)))
    geo = FloorCollision(grid, res, origin)
    blocked = reference_blocked(grid, res, origin)
    lo = np.array(origin)
    hi = lo + np.array([w, h]) * res
    a = rng.uniform(lo, hi, (300, 2))
    b = rng.uniform(lo, hi, (300, 2))
    b[:40] = a[:40]  # points
    b[40:80] = a[40:80] + rng.normal(0, res, (40, 2))  # short segments
    want, ambiguous = reference_clear(blocked, a, b, r)
    got = geo.segments_clear(a, b, r)
    assert ((got == want) | ambiguous).all()


def test_polygons_thinner_than_a_cell_block():
    # The thin wall of the geometry issue: box(2.99, 0, 3.02, 3) covers no cell centre at 0.1 m.
    grid = np.zeros((30, 60), bool)
    wall = box(2.99, 0.0, 3.02, 3.0)
    geo = FloorCollision(grid, 0.1, (0.0, 0.0), polygons=[wall])
    assert not geo.segments_clear([1.0, 1.5], [5.0, 1.5], 0.18)
    assert not geo.points_clear([3.1, 1.5], 0.18)
    assert geo.points_clear([3.2, 1.5], 0.18)  # 0.18 m from the wall's face: touching


@pytest.mark.parametrize("seed", range(6))
def test_polygon_segments_agree_with_shapely(seed):
    rng = np.random.default_rng(100 + seed)
    grid = rng.random((20, 20)) < 0.05
    polys = [
        shapely.affinity.rotate(box(x, y, x + rng.uniform(0.05, 0.6), y + rng.uniform(0.02, 0.3)), rng.uniform(0, 180))
        for x, y in rng.uniform(0.3, 1.6, (5, 2))
    ]
    geo = FloorCollision(grid, 0.1, (0.0, 0.0), polygons=polys)
    blocked = reference_blocked(grid, 0.1, (0.0, 0.0), polys)
    a = rng.uniform(0, 2, (300, 2))
    b = rng.uniform(0, 2, (300, 2))
    b[:50] = a[:50]
    r = float(rng.uniform(0.01, 0.3))
    want, ambiguous = reference_clear(blocked, a, b, r)
    assert ((geo.segments_clear(a, b, r) == want) | ambiguous).all()


def test_convex_corners_of_one_square():
    r, c, q = convex_corners(np.array([[False, False, False], [False, True, False], [False, False, False]]), outside_blocked=False)
    got = sorted(zip(r.tolist(), c.tolist(), q.tolist()))
    # Vertex (i, j) is the corner below-left of cell (i, j): the square's four corners.
    assert got == [(1, 1, 2), (1, 2, 3), (2, 1, 1), (2, 2, 0)]


def test_touching_is_allowed_and_overlap_is_not():
    grid = np.zeros((4, 4), bool)
    grid[1, 1] = True  # square [1, 2] x [1, 2] at 1 m cells
    geo = FloorCollision(grid, 1.0, (0.0, 0.0))
    assert geo.points_clear([2.5, 1.5], 0.5)
    assert not geo.points_clear([2.5, 1.5], 0.5 + 1e-6)
    # A segment that runs along the face at exactly the radius is clear.
    assert geo.segments_clear([2.5, 0.5], [2.5, 3.5], 0.5)
