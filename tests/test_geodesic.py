"""Geodesic distances and paths: exact values on hand-made maps, caching, bad input."""

import math

import numpy as np
import pytest

from pointnav_core.floor.collision import FloorCollision
from pointnav_core.floor.maps import OBSTACLE, VOID, TraversableMap
from pointnav_core.geodesic import Planner
from pointnav_core.geodesic.paths import path_length, resample_path
from pointnav_core.geodesic.planner import planner_for
from pointnav_core.scenes import Scene


def wall_scene():
    """20 x 30 m, 1 m cells: a vertical wall (col 10, rows 5..14) and a horizontal one."""
    grid = np.ones((20, 30), bool)
    grid[5:15, 10] = False
    grid[10, 10:25] = False
    return Scene.from_array(grid, resolution=1.0)


def test_open_floor_distance_is_the_straight_line_from_the_true_points():
    scene = Scene.from_array(np.ones((50, 50), bool), resolution=0.1)
    path, dist = scene.get_shortest_path(0, (0.33, 0.41), (4.02, 3.17), entire_path=True)
    assert dist == pytest.approx(math.hypot(4.02 - 0.33, 3.17 - 0.41), abs=1e-9)
    assert np.allclose(path, [[0.33, 0.41], [4.02, 3.17]])


def test_path_bends_at_the_wall_corner_and_its_length_is_exact():
    scene = wall_scene()
    path, dist = scene.get_shortest_path(0, (2.5, 12.5), (28.5, 2.5), entire_path=True)
    # Around the top of the vertical wall: the corner of cell (4, 9) touching cell (5, 10).
    corner = (10.0, 5.0)
    expected = math.dist((2.5, 12.5), corner) + math.dist(corner, (28.5, 2.5))
    assert dist == pytest.approx(expected, abs=1e-5)
    # A point robot plans as a disc of 1 micrometre: the path wraps the corner that closely.
    assert np.hypot(*(path - corner).T).min() == pytest.approx(0.0, abs=1e-5)
    assert path_length(path) == pytest.approx(dist)


def test_short_path_keeps_num_waypoints_spaced_and_padded_with_target():
    scene = Scene.from_array(np.ones((20, 20), bool), resolution=0.1, num_waypoints=10)
    path, dist = scene.get_shortest_path(0, (0.15, 0.15), (0.95, 0.15))
    assert path.shape == (10, 2)
    assert np.allclose(np.diff(path[:5, 0]), 0.2)
    assert np.allclose(path[-1], (0.95, 0.15))
    assert dist == pytest.approx(0.8)


def test_unreachable_blocked_and_off_map_targets_give_none():
    grid = np.ones((10, 10), bool)
    grid[:, 5] = False
    scene = Scene.from_array(grid, resolution=1.0)
    assert scene.get_shortest_path(0, (1.5, 1.5), (8.5, 1.5)) == (None, math.inf)  # other side
    assert scene.get_shortest_path(0, (1.5, 1.5), (5.5, 1.5)) == (None, math.inf)  # on the wall
    assert scene.get_shortest_path(0, (1.5, 1.5), (50.0, 1.5)) == (None, math.inf)  # off map
    assert scene.get_shortest_path(0, (-3.0, 1.5), (2.5, 1.5)) == (None, math.inf)  # source off
    assert scene.geodesic_distance(0, (1.5, 1.5), (8.5, 1.5)) == math.inf


def test_robot_radius_closes_a_narrow_door():
    grid = np.ones((30, 30), bool)
    grid[15, :] = False
    grid[15, 14:17] = True  # a 0.3 m door at 0.1 m cells
    scene = Scene.from_array(grid, resolution=0.1)
    assert scene.get_shortest_path(0, (1.5, 0.5), (1.5, 2.5), robot=0.1)[1] is not None
    assert scene.get_shortest_path(0, (1.5, 0.5), (1.5, 2.5), robot=0.2) == (None, math.inf)


def test_diagonal_squeeze_between_blocked_corners_is_not_a_path():
    grid = np.array([[1, 0], [0, 1]], bool)
    scene = Scene.from_array(grid, resolution=1.0)
    assert scene.get_shortest_path(0, (0.5, 0.5), (1.5, 1.5)) == (None, math.inf)


def test_goal_field_is_cached_and_queries_are_lookups():
    scene = wall_scene()
    a = scene.goal_field(0, (28.5, 2.5))
    b = scene.goal_field(0, (28.5, 2.5))
    assert a.field is b.field
    assert a.distance(2.5, 12.5) == pytest.approx(scene.get_shortest_path(0, (2.5, 12.5), (28.5, 2.5))[1])


def test_goal_field_cache_is_bounded_in_bytes(monkeypatch):
    scene = Scene.from_array(np.ones((10, 10), bool), resolution=1.0)
    planner = scene.planner(0)
    one = scene.goal_field(0, (0.5, 0.5)).field
    one.distance(1.5, 1.5)  # builds its per-step table
    monkeypatch.setattr(Planner, "field_cache_bytes", 3 * one.nbytes)
    for i in range(20):
        scene.goal_field(0, (0.5 + 0.01 * i, 0.5)).distance(1.5, 1.5)
    assert sum(f.nbytes for f in planner._fields.values()) <= 3 * one.nbytes
    assert len(planner._fields) >= 2


def test_floors_are_planned_separately():
    ground = np.ones((10, 10), bool)
    upper = np.ones((10, 10), bool)
    upper[:, 5] = False
    scene = Scene.from_array([ground, upper], resolution=1.0, heights=[0.0, 3.0])
    assert scene.get_shortest_path(1, (1.5, 1.5), (8.5, 1.5)) == (None, math.inf)
    assert scene.get_shortest_path(0, (1.5, 1.5), (8.5, 1.5))[1] == pytest.approx(7.0)
    assert scene.get_floor_height(1) == 3.0


def test_straight_moves_touching_a_blocked_corner_are_not_clear():
    grid = np.ones((3, 3), bool)
    grid[1, 1] = False
    planner = planner_for(TraversableMap(grid, 1.0), 0.0)
    # Through the blocked cell's corner point (1, 1).
    assert not planner.segment_clear([0.5, 0.5], [2.5, 2.5])
    # Grazing the blocked cell's corner point (1, 2): a point robot plans as a 1 um disc.
    assert not planner.segment_clear([0.5, 1.5], [1.5, 2.5])
    assert planner.segment_clear([0.5, 0.5], [0.5, 2.5])
    assert not planner.segment_clear([0.5, 0.5], [1.0, 1.0])


def test_resample_path_pads_with_the_end_point():
    out = resample_path([[0.0, 0.0], [0.0, 0.5]], 0.2, 5)
    assert out[:, 1].tolist() == pytest.approx([0.0, 0.2, 0.4, 0.5, 0.5])


def test_void_cells_are_not_paths():
    grid = np.zeros((5, 5), np.uint8)
    grid[:, 2] = VOID
    scene = Scene.from_array(grid, resolution=1.0)
    assert scene.get_shortest_path(0, (0.5, 0.5), (4.5, 0.5)) == (None, math.inf)
    grid[:, 2] = OBSTACLE
    grid[2, 2] = 0
    assert Scene.from_array(grid, 1.0).get_shortest_path(0, (0.5, 0.5), (4.5, 0.5))[1] is not None


def test_field_lookup_matches_exact_queries_in_a_generated_house():
    from pointnav_core import scenes

    scene = scenes.rooms(seed=0)
    rng = np.random.default_rng(0)
    rel = []
    for _ in range(150):
        _, a = scene.get_random_point(0, robot=0.18, rng=rng)
        _, b = scene.get_random_point(0, reference_point=a, robot=0.18, rng=rng)
        field = scene.goal_field(0, b, robot=0.18)
        lookup, exact = field.distance(*a[:2]), field.exact_distance(a[:2])
        # The lookup is the length of a real path from the point (through a checked root),
        # so never shorter than the geodesic.
        assert lookup >= exact - 1e-9
        rel.append(lookup / exact - 1.0 if exact > 0 else 0.0)
    rel = np.array(rel)
    assert np.quantile(rel, 0.95) <= 1e-3
    assert rel.max() <= 0.01


@pytest.mark.parametrize("max_length", [0.05, 1.0, 6.0, 1e9])
def test_field_path_with_max_length_draws_the_whole_paths_beginning(max_length):
    """A follower asks only for the path's beginning: a prefix of the whole path, long enough."""
    scene = wall_scene()
    start, goal = (2.5, 12.5), (28.5, 2.5)
    field = scene.goal_field(0, goal, robot=0.3)
    whole, length = field.path(start)
    part, part_length = field.path(start, max_length=max_length)
    assert part_length == length  # the length is always the whole path's
    assert np.array_equal(part, whole[: len(part)])
    # It reaches max_length along the path, or it is the whole path.
    steps = np.hypot(*np.diff(part, axis=0).T)
    assert steps.sum() >= max_length or len(part) == len(whole)
    # And stops at the first arc that gets there: dropping that arc falls short.
    if len(part) < len(whole):
        assert steps.sum() - steps[-1] < max_length + 2 * math.pi * 0.3


def test_a_drawn_arc_through_a_passage_exactly_as_wide_as_the_robot_keeps_clear_of_both_sides():
    # Corners (0.7, 1.0) and (1.0, 0.6) are exactly 0.5 m = 2 r apart: the path must pass
    # the midpoint touching both. An arc around one corner drawn with vertices outside its
    # circle put one 3.6e-6 m into the other corner's square before (found by hypothesis).
    shapely = pytest.importorskip("shapely")
    grid = np.zeros((11, 16), np.uint8)
    grid[0, 0] = OBSTACLE
    grid[0:6, 10] = OBSTACLE
    grid[10, 0:7] = OBSTACLE
    tmap = TraversableMap(grid, resolution=0.1)
    scene = Scene([tmap])
    radius = 0.25
    path, dist = scene.get_shortest_path(0, (0.35, 0.25), (1.35, 0.25), entire_path=True, robot=radius)
    assert path is not None
    # Independent reference: the blocked squares and the map's outside, as shapely geometry.
    squares = [shapely.box(c * 0.1, r * 0.1, (c + 1) * 0.1, (r + 1) * 0.1) for r, c in np.argwhere(grid != 0)]
    outside = shapely.box(-10, -10, 11.6, 11.1).difference(shapely.box(0, 0, 1.6, 1.1))
    blocked = shapely.union_all([*squares, outside])
    touch = 1e-9
    assert all(blocked.distance(shapely.Point(p)) >= radius - touch for p in path)
    assert all(blocked.distance(shapely.LineString([p, q])) >= radius - touch for p, q in zip(path[:-1], path[1:]))
    # Through the passage's midpoint, and as long as reported (arcs drawn outside the circle).
    assert min(math.dist(p, (0.85, 0.8)) for p in path) < 1e-6
    assert dist - 1e-9 <= path_length(path) <= dist * (1 + 1.1e-4) + 1e-9


@pytest.mark.parametrize("degrees", [2.0, 10.0, 30.0])
def test_a_path_round_one_corner_is_drawn_in_as_many_pieces_as_its_piece_asks(degrees):
    # A 1 m block whose top right corner is (2, 2); a 0.3 m disc from (1.5, 2.3) to
    # (2.3, 1.5) runs along the block's top, wraps the corner a quarter turn and runs down its
    # right side. By hand: 0.5 + 0.5 + 0.3 * pi / 2 m, and the quarter turn drawn as
    # ceil(90 / degrees) pieces whose inner vertices stand 0.3 / cos(piece / 2) m from the
    # corner, between the arc's ends (2, 2.3) and (2.3, 2).
    grid = np.zeros((40, 40), np.uint8)
    grid[10:20, 10:20] = OBSTACLE
    planner = Scene.from_array(grid, 0.1).planner(0, 0.3)
    path, length = planner.shortest_path((1.5, 2.3), (2.3, 1.5), math.radians(degrees))
    assert length == pytest.approx(1.0 + 0.3 * math.pi / 2, abs=1e-9)
    pieces = math.ceil(90.0 / degrees - 1e-9)
    assert len(path) == pieces + 4  # the ends, the arc's ends and its inner vertices
    np.testing.assert_allclose(path[[0, 1, -2, -1]], [(1.5, 2.3), (2.0, 2.3), (2.3, 2.0), (2.3, 1.5)], atol=1e-9)
    inner = path[2:-2]
    piece = math.pi / 2 / pieces
    np.testing.assert_allclose(np.hypot(inner[:, 0] - 2.0, inner[:, 1] - 2.0), 0.3 / math.cos(piece / 2), rtol=1e-12)
    # Clockwise from straight up, half a piece in, then a piece apart.
    angles = np.arctan2(inner[:, 1] - 2.0, inner[:, 0] - 2.0)
    np.testing.assert_allclose(angles, math.pi / 2 - piece * (np.arange(pieces) + 0.5), atol=1e-12)


@pytest.mark.parametrize("piece", [0.0, -0.1, math.pi, float("nan"), True, "0.1"])
def test_a_drawn_piece_out_of_range_is_refused_naming_it(piece):
    planner = Scene.from_array(np.zeros((10, 10), np.uint8), 0.1).planner(0, 0.1)
    with pytest.raises(ValueError, match=r"piece must be a number of radians in \(0, pi / 2\]"):
        planner.shortest_path((0.2, 0.2), (0.8, 0.8), piece)


def test_a_floor_geometry_past_its_byte_budget_is_refused_naming_the_budget(monkeypatch):
    from pointnav_core import scenes
    from pointnav_core.geodesic import cache

    monkeypatch.setenv(cache.ENV_VAR, "off")  # built here, so that tracemalloc sees it
    scene = scenes.clutter(seed=1)
    planner = Planner(FloorCollision.from_map(scene.floors[0]), 0.18)
    monkeypatch.setattr(Planner, "geometry_bytes", 200_000)
    with pytest.raises(ValueError, match=r"needs more than Planner.geometry_bytes = 0 MiB"):
        planner.goal_field((5.05, 5.05))
    monkeypatch.setattr(Planner, "geometry_bytes", 2**30)
    planner = Planner(FloorCollision.from_map(scene.floors[0]), 0.18)
    planner.build_all_edges()
    # The estimate is of the right size: within a factor of 2 of what tracemalloc sees.
    import tracemalloc

    tracemalloc.start()
    again = Planner(FloorCollision.from_map(scene.floors[0]), 0.18)
    again.build_all_edges()
    again.arc_graph()
    used, _ = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert 0.5 * used <= again.geometry_nbytes <= 2 * used
