"""The tangent-graph planner against hand calculations and an independent continuous reference.

The reference (``geodesic_reference.ContinuousGeodesic``) grows every blocked cell square by
the radius with shapely (16 segments per quarter circle, so slightly inscribed: its
distances are at most a hair shorter than the exact ones), builds the visibility graph of
the grown outline's vertices and runs Dijkstra. It shares no code with the planner.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from geodesic_reference import ContinuousGeodesic
from shapely.geometry import box

from pointnav_core.floor.collision import FloorCollision
from pointnav_core.floor.maps import TraversableMap
from pointnav_core.geodesic.paths import path_length
from pointnav_core.geodesic.planner import Planner, planner_for


def test_radius_below_half_a_cell_is_not_ignored():
    # The geometry issue's first case: a 0.5 m square at (1.0..1.5, 1.0..1.5), r = 0.18.
    g = np.zeros((5, 5), np.uint8)
    g[2, 2] = 1
    planner = planner_for(TraversableMap(g, 0.5), 0.18)
    path, dist = planner.shortest_path((0.6, 1.25), (1.9, 1.25))
    # By hand: tangent to the corner circle, the arc to the square's top offset line, the
    # 0.5 m straight along it, and the same back down.
    r = 0.18
    L = math.hypot(0.4, 0.25)
    turn = math.atan2(0.25, 0.4) + math.asin(r / L)
    want = 2 * (math.sqrt(L * L - r * r) + r * turn) + 0.5
    assert dist == pytest.approx(want, abs=1e-9)
    assert dist == pytest.approx(1.714, abs=1e-3)
    assert path_length(path) == pytest.approx(dist, abs=1e-4)
    square = box(1.0, 1.0, 1.5, 1.5)
    assert shapely.distance(square, shapely.LineString(path)) >= r - 1e-6


def _random_grid(seed: int) -> tuple[np.ndarray, float, float]:
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(8, 14, 2))
    grid = rng.random((h, w)) < 0.12
    res = float(rng.choice([0.1, 0.5]))
    r = float(rng.uniform(0.15, 1.0)) * res
    return grid, res, r


@pytest.mark.parametrize("seed", range(8))
def test_distances_match_the_continuous_reference(seed):
    grid, res, r = _random_grid(seed)
    h, w = grid.shape
    squares = [box(c * res, rr * res, (c + 1) * res, (rr + 1) * res) for rr, c in zip(*np.nonzero(grid))]
    outline = box(0, 0, w * res, h * res)
    ref = ContinuousGeodesic(outline, squares, r, quad_segs=16)
    planner = Planner(FloorCollision(grid, res, (0.0, 0.0)), r)
    rng = np.random.default_rng(1000 + seed)
    checked = 0
    for _ in range(150):
        a, b = rng.uniform((0, 0), (w * res, h * res), (2, 2))
        if not (planner.is_clear(*a) and planner.is_clear(*b)):
            continue
        # Skip points the inscribed reference cannot decide (within a hair of the boundary).
        d_a = shapely.distance(shapely.union_all(squares + [outline.exterior]), shapely.points(a)) if squares else math.inf
        d_b = shapely.distance(shapely.union_all(squares + [outline.exterior]), shapely.points(b)) if squares else math.inf
        if min(d_a, d_b) < r + 1e-3:
            continue
        want = ref.distance(a, b)
        path, got = planner.shortest_path(a, b)
        if not math.isfinite(want):
            assert path is None
            checked += 1
            continue
        assert path is not None, (a, b, want)
        checked += 1
        # The reference is inscribed: never longer than the exact value.
        assert got >= want - 1e-6
        assert got <= want * 1.002 + 1e-6
        back = planner.shortest_path(b, a)[1]
        assert back == pytest.approx(got, abs=1e-6)
        if squares:
            blocked = shapely.union_all(squares + [outline.exterior])
            assert shapely.distance(blocked, shapely.LineString(path)) >= r - 1e-6
    assert checked > 0


def test_goal_field_exact_queries_equal_the_single_pair_search():
    grid, res, r = _random_grid(3)
    planner = Planner(FloorCollision(grid, res, (0.0, 0.0)), r)
    h, w = grid.shape
    rng = np.random.default_rng(7)
    pts = [p for p in rng.uniform((0, 0), (w * res, h * res), (40, 2)) if planner.is_clear(*p)]
    goal = pts[0]
    field = planner.goal_field(goal)
    for p in pts[1:]:
        _, d = planner.shortest_path(p, goal)
        got = field.point_distance(p)
        if d is None:
            assert got == math.inf
        else:
            assert got == pytest.approx(d, abs=1e-6)


def test_lookup_at_a_cell_centre_is_the_exact_distance():
    # GoalField.distance re-derives the tangent in scalar math on the hot path; at a usable
    # cell's centre it follows that centre's exact root, so it gives the exact query's value.
    from pointnav_core import scenes

    scene = scenes.rooms(seed=3)
    tmap = scene.floors[0]
    planner = planner_for(tmap, 0.18)
    _, goal = scene.get_random_point(0, robot=0.18, rng=5)
    field = planner.goal_field(goal[:2])
    cells = np.flatnonzero(planner.usable.ravel())[::13]
    rows, cols = np.divmod(cells, tmap.shape[1])
    px = tmap.origin[0] + (cols + 0.5) * tmap.resolution
    py = tmap.origin[1] + (rows + 0.5) * tmap.resolution
    got = np.array([field.distance(x, y) for x, y in zip(px, py)])
    want = np.array([field.point_distance((x, y)) for x, y in zip(px, py)])
    assert len(cells) > 100 and field._table["done"].sum() > 4  # several blocks, each settled on its first lookup
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)