"""The measured faults of the one-geometry issue, reproduced through the public Scene API.

Each expected value is computed here from first principles (a hand formula or shapely), not
from the library's own clearance predicates.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point

from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene


def blocked_union(grid: np.ndarray, res: float, polygons=()) -> shapely.Geometry:
    """Blocked cells as boxes, the outside of the map as a frame, plus polygons (shapely)."""
    h, w = grid.shape
    boxes = [shapely.box(c * res, r * res, (c + 1) * res, (r + 1) * res) for r, c in zip(*np.nonzero(grid))]
    frame = shapely.box(-10, -10, w * res + 10, h * res + 10).difference(shapely.box(0, 0, w * res, h * res))
    return shapely.union_all([*boxes, frame, *polygons])


def clearance_of_path(points: np.ndarray, blocked: shapely.Geometry) -> float:
    return float(shapely.distance(LineString(points), blocked))


def test_radius_below_half_a_cell_wraps_the_square_with_full_clearance():
    g = np.zeros((5, 5), np.uint8)
    g[2, 2] = OBSTACLE
    scene = Scene.from_array(g, 0.5)
    path, length = scene.get_shortest_path(0, (0.6, 1.25), (1.9, 1.25), entire_path=True, robot=0.18)
    # By hand: tangents from each end to the circles of radius r at the square's two lower
    # corners (1.0, 1.0) and (1.5, 1.0), the arcs between, and the 0.5 m run under the square.
    r = 0.18
    d = math.hypot(0.4, 0.25)
    tangent = math.sqrt(d * d - r * r)
    # Direction from the corner to the tangent point, then the arc down to straight below.
    leave = math.atan2(0.25, -0.4) + math.acos(r / d)
    arc = (leave - (-math.pi / 2)) % (2 * math.pi)
    arc = 2 * math.pi - arc if arc > math.pi else arc
    expected = 2 * tangent + 2 * r * arc + 0.5
    assert length == pytest.approx(expected, abs=1e-9)
    assert length == pytest.approx(1.714, abs=1e-3)  # the figure
    assert clearance_of_path(path, blocked_union(g, 0.5)) >= r - 1e-6


def door_grid(res: float, width: float) -> tuple[np.ndarray, float]:
    """A 3 m x 2 m room split at x = 1.5 m by a one-cell wall with a centred door."""
    h, w = round(2.0 / res), round(3.0 / res)
    g = np.zeros((h, w), np.uint8)
    col = w // 2
    n = round(width / res)
    lo = (h - n) // 2
    g[:lo, col] = OBSTACLE
    g[lo + n :, col] = OBSTACLE
    return g, lo * res


def test_a_door_the_robot_fits_through_is_open_and_straight():
    # 0.40 m door at 0.05 m cells for a 0.36 m robot: 2 cm to spare on each side.
    g, y0 = door_grid(0.05, 0.40)
    scene = Scene.from_array(g, 0.05)
    mid = y0 + 0.20
    a, b = (0.5, mid), (2.5, mid)
    assert shapely.distance(LineString([a, b]), blocked_union(g, 0.05)) >= 0.18  # reference
    path, length = scene.get_shortest_path(0, a, b, entire_path=True, robot=0.18)
    assert length == pytest.approx(2.0, abs=1e-9)
    assert scene.geodesic_distance(0, b, a, robot=0.18) == pytest.approx(2.0, abs=1e-9)


def test_a_door_narrower_than_the_robot_is_closed():
    g, y0 = door_grid(0.05, 0.35)
    scene = Scene.from_array(g, 0.05)
    assert scene.geodesic_distance(0, (0.5, 1.0), (2.5, 1.0), robot=0.18) == math.inf


def test_a_point_with_clearance_just_over_the_radius_is_a_start_and_paths_are_symmetric():
    g = np.zeros((20, 20), np.uint8)
    g[:, 10] = OBSTACLE  # wall x in [1.0, 1.1] at 0.1 m cells
    g[8:12, 10] = 0  # a 0.4 m door
    scene = Scene.from_array(g, 0.1)
    p = (1.0 - 0.19, 0.5)  # 0.19 m from the wall: not a cell centre
    assert Point(p).distance(blocked_union(g, 0.1)) == pytest.approx(0.19)
    assert scene.is_usable(0, p, robot=0.18)
    assert not scene.is_usable(0, (1.0 - 0.17, 0.5), robot=0.18)
    q = (1.6, 1.7)
    _, there = scene.get_shortest_path(0, p, q, entire_path=True, robot=0.18)
    _, back = scene.get_shortest_path(0, q, p, entire_path=True, robot=0.18)
    assert there == pytest.approx(back, abs=1e-6)


def test_a_polygon_wall_thinner_than_a_cell_blocks_the_planner():
    wall = shapely.box(2.99, 0.0, 3.02, 3.0)
    scene = Scene.from_polygons(shapely.box(0, 0, 6, 4), [wall], resolution=0.1)
    path, length = scene.get_shortest_path(0, (1.0, 1.0), (5.0, 1.0), entire_path=True, robot=0.18)
    # Around the wall's top: at least the two straight lines to the top corners grown by r.
    top = 3.0 + 0.18
    assert length >= math.hypot(2.0, top - 1.0) + math.hypot(2.0, top - 1.0) - 1e-9
    assert shapely.distance(LineString(path), wall) >= 0.18 - 1e-6
