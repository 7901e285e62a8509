"""Floor plans: the FloorPlan value, rasterisation, and the seeded generators."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import shapely
from scipy import ndimage
from shapely.geometry import Point, Polygon, box

from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.floorplans import FloorPlan, clutter, maze, rasterize, rooms

GENERATORS = {"rooms": rooms, "maze": maze, "clutter": clutter}


def eroded_components(plan, resolution=0.05, radius=0.2):
    codes, origin = plan.rasterize(resolution)
    usable = TraversableMap(codes, resolution, origin).usable(radius)
    _, n = ndimage.label(usable)  # 4-connectivity, as the planner
    return n, usable


# --------------------------------------------------------------------------- FloorPlan
def test_floor_plan_is_keyword_only_and_frozen():
    with pytest.raises(TypeError):
        FloorPlan(box(0, 0, 1, 1))  # type: ignore[misc]
    plan = FloorPlan(outline=box(0, 0, 1, 1))
    assert plan.obstacles == ()
    with pytest.raises(dataclasses.FrozenInstanceError):
        plan.outline = box(0, 0, 2, 2)  # type: ignore[misc]


def test_floor_plan_stores_obstacles_as_a_tuple():
    obstacles = [box(0, 0, 1, 1), box(2, 2, 3, 3)]
    plan = FloorPlan(outline=box(0, 0, 4, 4), obstacles=obstacles)
    obstacles.append(box(3, 0, 4, 1))
    assert plan.obstacles == (box(0, 0, 1, 1), box(2, 2, 3, 3))
    assert plan.size == (4.0, 4.0)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"outline": Point(0, 0)}, TypeError, r"^outline must be a shapely Polygon, got Point"),
        ({"outline": [(0, 0), (1, 0), (1, 1)]}, TypeError, r"^outline must be a shapely Polygon"),
        ({"outline": Polygon()}, ValueError, r"^outline must be a non-empty Polygon"),
        (
            {"outline": Polygon([(0, 0), (1, 1), (1, 0), (0, 1)])},
            ValueError,
            r"^outline must be a valid Polygon: Self-intersection",
        ),
        (
            {"outline": box(0, 0, 1, 1), "obstacles": box(0, 0, 1, 1)},
            TypeError,
            r"^obstacles must be an iterable",
        ),
        ({"outline": box(0, 0, 1, 1), "obstacles": "ab"}, TypeError, r"^obstacles must be an iterable"),
        (
            {"outline": box(0, 0, 1, 1), "obstacles": [box(0, 0, 1, 1), Point(0, 0).buffer(1).boundary]},
            TypeError,
            r"^obstacles\[1\] must be a shapely Polygon, got LineString",
        ),
    ],
)
def test_floor_plan_validates_its_fields(kwargs, error, message):
    with pytest.raises(error, match=message):
        FloorPlan(**kwargs)


# --------------------------------------------------------------------------- rasterize
def test_rasterize_puts_void_outside_obstacle_inside_and_free_elsewhere():
    # An L with a hole-free outline; one obstacle, and one partly outside the outline.
    outline = Polygon([(0, 0), (4, 0), (4, 2), (2, 2), (2, 4), (0, 4)])
    obstacles = [box(0.5, 0.5, 1.5, 1.0), box(3.0, 1.0, 5.0, 3.0)]
    codes, origin = rasterize(outline, obstacles, resolution=0.5)
    assert origin == (0.0, 0.0)
    assert codes.shape == (8, 8) and codes.dtype == np.uint8
    expected = np.zeros((8, 8), dtype=np.uint8)
    expected[4:, 4:] = VOID  # the cut-away corner, and the obstacle's part out there
    expected[1, 1:3] = OBSTACLE
    expected[2:4, 6:8] = OBSTACLE
    assert np.array_equal(codes, expected)


def test_rasterize_agrees_with_a_point_by_point_reference():
    rng = np.random.default_rng(7)
    outline = Point(0.3, -0.2).buffer(3.0, quad_segs=5)
    discs = rng.uniform([-3, -3, 0.1], [3, 3, 0.8], (12, 3))
    obstacles = [Point(x, y).buffer(r, quad_segs=3) for x, y, r in discs]
    codes, origin = rasterize(outline, obstacles, resolution=0.13)
    floor = TraversableMap(codes, 0.13, origin)
    for (row, col), code in np.ndenumerate(codes):
        centre = Point(floor.cell_to_world([row, col]))
        if not outline.intersects(centre):
            assert code == VOID
        elif any(o.intersects(centre) for o in obstacles):
            assert code == OBSTACLE
        else:
            assert code == FREE


def test_rasterize_grid_covers_the_outline_bounds_in_whole_cells():
    outline = box(0.36, -0.29, 1.0, 0.44)
    codes, origin = rasterize(outline, [], resolution=0.1)
    assert origin == pytest.approx((0.3, -0.3))  # snapped outward to multiples of 0.1
    assert codes.shape == (8, 7)  # y in [-0.3, 0.5), x in [0.3, 1.0)
    assert codes[:, 0].tolist() == [VOID] * 8  # centres at x = 0.35 < 0.36
    assert codes[-1].tolist() == [VOID] * 7  # centres at y = 0.45 > 0.44
    assert (codes[:-1, 1:] == FREE).all()


def test_rasterize_counts_a_centre_on_a_boundary_as_inside():
    # Cell centres at 0.25, 0.75, ...: the obstacle's edge passes through a column of them.
    codes, _ = rasterize(box(0, 0, 2, 2), [box(0.75, 0, 1.2, 2)], resolution=0.5)
    assert (codes[:, 1] == OBSTACLE).all()
    assert (codes[:, 2] == FREE).all()  # centre 1.25 is beyond 1.2


def test_rasterize_is_vectorised_enough_for_a_million_cells():
    plan = rooms(0, size=(20.0, 15.0))
    codes, _ = plan.rasterize(0.017)
    assert codes.size > 1_000_000


@pytest.mark.parametrize("resolution", [0.0, -1.0, math.nan, math.inf, "coarse"])
def test_rasterize_refuses_a_bad_resolution(resolution):
    with pytest.raises(ValueError, match=r"^resolution must be a finite number > 0"):
        rasterize(box(0, 0, 1, 1), [], resolution=resolution)


def test_rasterize_refuses_a_grid_too_large_to_build():
    with pytest.raises(ValueError, match=r"^resolution 0.0001 m/cell is too fine"):
        rasterize(box(0, 0, 10, 10), [], resolution=1e-4)


def test_rasterize_refuses_non_polygons():
    with pytest.raises(TypeError, match=r"^obstacles\[0\] must be a shapely Polygon, got Point$"):
        rasterize(box(0, 0, 1, 1), [Point(0, 0)], resolution=0.1)
    two = shapely.union(box(0, 0, 1, 1), box(2, 2, 3, 3))
    with pytest.raises(TypeError, match=r"^outline .* got MultiPolygon \(split it with shapely.get_parts\)"):
        rasterize(two, [], resolution=0.1)


def test_rasterize_leaves_its_arguments_unprepared():
    outline, obstacle = box(0, 0, 1, 1), box(0, 0, 0.5, 0.5)
    rasterize(outline, [obstacle], resolution=0.1)
    assert not shapely.is_prepared(outline) and not shapely.is_prepared(obstacle)


# --------------------------------------------------------------------------- generators
@pytest.mark.parametrize("name", GENERATORS)
def test_generator_is_deterministic_for_a_seed(name):
    make = GENERATORS[name]
    assert make(11) == make(11)
    assert make(np.random.default_rng(11)) == make(11)


@pytest.mark.parametrize("name", GENERATORS)
def test_generator_differs_between_seeds(name):
    make = GENERATORS[name]
    plans = [make(seed) for seed in range(4)]
    assert len({shapely.to_wkb(shapely.union_all(p.obstacles)) for p in plans}) == 4


@pytest.mark.parametrize("name", GENERATORS)
@pytest.mark.parametrize("size", [(10.0, 10.0), (30.0, 12.0), (12.5, 27.0)])
def test_generator_fills_the_requested_size_centred_on_the_origin(name, size):
    plan = GENERATORS[name](3, size=size)
    assert plan.outline.bounds == pytest.approx((-size[0] / 2, -size[1] / 2, size[0] / 2, size[1] / 2))
    assert all(plan.outline.covers(o) for o in plan.obstacles)


@pytest.mark.parametrize("name", GENERATORS)
@pytest.mark.parametrize("seed", range(4))
def test_generated_free_space_is_one_component_for_a_robot_of_radius_0_2(name, seed):
    n, usable = eroded_components(GENERATORS[name](seed), resolution=0.05, radius=0.2)
    assert n == 1
    assert usable.mean() > 0.2


@pytest.mark.parametrize("name", GENERATORS)
def test_generated_outline_is_walled_all_round(name):
    plan = GENERATORS[name](5)
    codes, _ = plan.rasterize(0.05)
    free = codes == FREE
    void = codes == VOID
    # No free cell touches a void cell, even diagonally.
    assert not (ndimage.binary_dilation(void, np.ones((3, 3), bool)) & free).any()
    assert not (free[0].any() or free[-1].any() or free[:, 0].any() or free[:, -1].any())


def test_rooms_default_is_a_house_of_several_rooms():
    plan = rooms(0)
    assert plan.size == (20.0, 15.0)
    walls_only = FloorPlan(outline=plan.outline, obstacles=rooms(0, furniture=0).obstacles)
    codes, origin = walls_only.rasterize(0.05)
    # Closing the doors: rooms are the components of the free space eroded by 0.7 m.
    n_rooms = ndimage.label(TraversableMap(codes, 0.05, origin).usable(0.7))[1]
    assert 5 <= n_rooms <= 25


def test_rooms_l_shape_probability_is_honoured():
    assert all(len(rooms(s, l_shape=0.0).outline.exterior.coords) == 5 for s in range(5))
    assert all(len(rooms(s, l_shape=1.0).outline.exterior.coords) == 7 for s in range(5))
    assert rooms(0, l_shape=1.0).outline.area < 20.0 * 15.0


def test_rooms_furniture_zero_leaves_only_walls():
    plan = rooms(2, furniture=0)
    furnished = rooms(2)
    assert len(furnished.obstacles) > len(plan.obstacles)
    # Walls are axis-aligned boxes (and the outer ring): no discs or turned boxes.
    for obstacle in plan.obstacles[1:]:
        assert obstacle.equals(box(*obstacle.bounds))


def test_rooms_furniture_stays_clear_of_doors():
    # Every door is at least 0.8 m wide: a 0.35 m robot still gets from room to room.
    for seed in range(3):
        n, _ = eroded_components(rooms(seed, furniture=6.0), resolution=0.05, radius=0.3)
        assert n == 1


def test_maze_is_perfect_free_space_is_one_simply_connected_region():
    plan = maze(4)
    walls = shapely.union_all(plan.obstacles)
    assert isinstance(walls, Polygon)  # no wall island: no loop in the corridors
    assert len(walls.interiors) == 1  # one free region


def test_maze_corridors_are_at_least_the_requested_width():
    plan = maze(6, size=(12.0, 9.0), corridor=1.0, wall=0.2)
    n, _ = eroded_components(plan, resolution=0.05, radius=0.4)
    assert n == 1


def test_maze_cell_count_follows_corridor_and_wall():
    plan = maze(0, size=(6.2, 3.8), corridor=1.0, wall=0.2)  # 5 x 3 cells of 1.2 m, +0.2 m
    walls = shapely.union_all(plan.obstacles)
    corridors = plan.outline.difference(walls)
    # A spanning tree of 15 cells: free area is 15 cells plus 14 openings of 1 x 0.2 m.
    assert corridors.area == pytest.approx(15 * 1.0 + 14 * 0.2)


def test_clutter_places_the_requested_number_of_obstacles():
    plan = clutter(1, n_obstacles=40, grouped=0.0)
    assert len(plan.obstacles) == 41  # the wall ring first
    ring = plan.obstacles[0]
    assert min(ring.distance(o) for o in plan.obstacles[1:]) >= 0.8


def test_clutter_default_density_is_one_obstacle_per_8_square_metres():
    assert len(clutter(1, grouped=0.0).obstacles) == 1 + 50
    assert len(clutter(1, size=(12.0, 10.0), grouped=0.0).obstacles) == 1 + 15


def test_clutter_places_fewer_when_the_hall_is_full_and_stays_connected():
    plan = clutter(2, size=(8.0, 8.0), n_obstacles=100, grouped=0.0)
    assert 1 < len(plan.obstacles) < 101
    n, _ = eroded_components(plan, resolution=0.05, radius=0.2)
    assert n == 1


def test_clutter_groups_are_gap_apart_and_never_enclose_a_pocket():
    plan = clutter(3, n_obstacles=120, grouped=0.9, size=(15.0, 15.0))
    groups = np.array(plan.obstacles, dtype=object)
    assert 1 < len(groups) < 60  # most shapes were grouped
    assert all(len(g.interiors) == 0 for g in groups[1:])
    gaps = shapely.distance(groups[:, None], groups[None, :])
    assert gaps[~np.eye(len(groups), dtype=bool)].min() >= 0.8
    for radius in (0.1, 0.2, 0.3):
        n, _ = eroded_components(plan, resolution=0.05, radius=radius)
        assert n == 1


@pytest.mark.parametrize(
    ("name", "kwargs", "message"),
    [
        ("rooms", {"size": (20.0,)}, r"^size must be two numbers"),
        ("rooms", {"size": (20.0, -1.0)}, r"^size must be two finite numbers > 0"),
        ("rooms", {"size": (2.5, 15.0)}, r"^size must be at least min_room \+ 2 \* outer_wall"),
        ("rooms", {"wall": 0.0}, r"^wall must be a finite number > 0"),
        ("rooms", {"outer_wall": math.nan}, r"^outer_wall must be a finite number > 0"),
        ("rooms", {"door_width": (1.2, 0.8)}, r"^door_width must be \(min, max\) with min <= max"),
        ("rooms", {"min_room": 1.0}, r"^min_room must be at least the widest door"),
        ("rooms", {"max_room": 2.0}, r"^max_room must be >= min_room"),
        ("rooms", {"l_shape": 1.5}, r"^l_shape must be a probability in \[0, 1\]"),
        ("rooms", {"furniture": -1}, r"^furniture must be a finite number >= 0"),
        ("rooms", {"clearance": 0}, r"^clearance must be a finite number > 0"),
        ("maze", {"size": (1.0, 1.0)}, r"^size must fit at least 2 cells"),
        ("maze", {"corridor": -1.0}, r"^corridor must be a finite number > 0"),
        ("maze", {"wall": math.inf}, r"^wall must be a finite number > 0"),
        ("clutter", {"n_obstacles": -1}, r"^n_obstacles must be an integer >= 0 or None"),
        ("clutter", {"n_obstacles": 2.5}, r"^n_obstacles must be an integer >= 0 or None"),
        ("clutter", {"obstacle_size": (0.0, 1.0)}, r"^obstacle_size must be two finite numbers > 0"),
        ("clutter", {"discs": -0.1}, r"^discs must be a probability"),
        ("clutter", {"grouped": "often"}, r"^grouped must be a probability"),
        ("clutter", {"gap": 0.0}, r"^gap must be a finite number > 0"),
        ("clutter", {"size": (3.0, 3.0)}, r"^size must leave room for the largest obstacle"),
    ],
)
def test_generator_refuses_a_bad_parameter_and_names_it(name, kwargs, message):
    with pytest.raises(ValueError, match=message):
        GENERATORS[name](0, **kwargs)
