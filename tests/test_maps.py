"""TraversableMap: cell geometry, bounds, erosion and components."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import box

from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, BoundedCache, TraversableMap
from pointnav_core.floorplans import FloorPlan


def test_cell_centres_round_trip_exactly_with_negative_origin():
    m = TraversableMap(np.zeros((7, 9), np.uint8), resolution=0.1, origin=(-3.3, 2.05))
    cells = np.argwhere(np.ones(m.shape, bool))
    assert np.array_equal(m.world_to_cell(m.cell_to_world(cells)), cells)


def test_row_index_grows_with_y_and_column_with_x():
    m = TraversableMap(np.zeros((4, 5), np.uint8), resolution=1.0, origin=(10.0, 20.0))
    assert m.world_to_cell([10.5, 23.9]).tolist() == [3, 0]
    assert m.world_to_cell([14.9, 20.1]).tolist() == [0, 4]


def test_points_off_the_map_are_void_and_never_wrap():
    grid = np.zeros((3, 3), np.uint8)
    grid[2, 2] = OBSTACLE
    m = TraversableMap(grid, resolution=1.0)
    # (-0.5, -0.5) would wrap to cell (-1, -1) == (2, 2) with naive indexing.
    assert m.cell_class_at([-0.5, -0.5]) == VOID
    assert m.cell_class_at([[3.5, 0.5], [0.5, 3.5], [1.5, 1.5]]).tolist() == [VOID, VOID, FREE]
    assert not m.in_bounds(m.world_to_cell([-0.5, -0.5]))
    assert m.is_usable([-0.5, -0.5]) == False  # noqa: E712


def test_boolean_grids_mean_free_and_obstacle():
    m = TraversableMap(np.array([[True, False]]), resolution=1.0)
    assert m.codes.tolist() == [[FREE, OBSTACLE]]


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"grid": np.zeros((0, 3)), "resolution": 1.0}, "grid"),
        ({"grid": np.zeros(3, np.uint8), "resolution": 1.0}, "grid"),
        ({"grid": np.full((2, 2), 7, np.uint8), "resolution": 1.0}, "cell codes"),
        ({"grid": np.zeros((2, 2), np.float32), "resolution": 1.0}, "grid"),
        ({"grid": np.zeros((2, 2), np.uint8), "resolution": 0.0}, "resolution"),
        ({"grid": np.zeros((2, 2), np.uint8), "resolution": math.nan}, "resolution"),
        ({"grid": np.zeros((2, 2), np.uint8), "resolution": 1.0, "origin": (0, math.inf)}, "origin"),
    ],
)
def test_bad_constructor_arguments_name_the_parameter(kwargs, name):
    with pytest.raises(ValueError, match=name):
        TraversableMap(**kwargs)


def test_negative_or_nan_radius_is_rejected():
    m = TraversableMap(np.zeros((3, 3), np.uint8), resolution=1.0)
    for bad in (-0.1, math.nan, math.inf):
        with pytest.raises(ValueError, match="radius"):
            m.usable(bad)


def test_erosion_uses_a_euclidean_disc_not_a_square_block():
    grid = np.zeros((21, 21), np.uint8)
    grid[10, 10] = OBSTACLE
    m = TraversableMap(grid, resolution=1.0)
    usable = m.usable(3.0)
    # A disc of radius 3 around centre (13, 13) reaches the obstacle square's corner at
    # distance hypot(2.5, 2.5) = 3.54 > 3: usable. A 7x7 block erosion would block it.
    assert usable[13, 13]
    # Straight below at distance 2.5 to the square: blocked.
    assert not usable[13, 10]
    assert usable[14, 10]


def test_erosion_matches_exact_disc_square_overlap_everywhere():
    rng = np.random.default_rng(3)
    grid = np.where(rng.random((30, 30)) < 0.08, OBSTACLE, FREE).astype(np.uint8)
    m = TraversableMap(grid, resolution=0.1)
    blocked = np.argwhere(grid != FREE)
    for radius in (0.0, 0.04, 0.05, 0.07, 0.12, 0.18, 0.26):
        usable = m.usable(radius)
        for r, c in np.argwhere(np.ones_like(usable)):
            # Distance from the cell centre to each blocked square and to the map's outside.
            gap = np.maximum(np.abs(blocked - [r, c]) - 0.5, 0.0)
            d_obstacle = np.hypot(gap[:, 0], gap[:, 1]).min() * 0.1 if len(blocked) else np.inf
            d_edge = (min(r, c, 29 - r, 29 - c) + 0.5) * 0.1
            expected = grid[r, c] == FREE and min(d_obstacle, d_edge) >= radius - 1e-12
            assert usable[r, c] == expected, (radius, r, c)


def test_erosion_is_cached_per_radius_and_read_only():
    m = TraversableMap(np.zeros((5, 5), np.uint8), resolution=1.0)
    assert m.usable(1.0) is m.usable(1.0)
    with pytest.raises(ValueError):
        m.usable(1.0)[0, 0] = False


def test_components_use_side_adjacency_like_the_planner():
    grid = np.array([[FREE, OBSTACLE], [OBSTACLE, FREE]], np.uint8)
    labels = TraversableMap(grid, resolution=1.0).components(0.0)
    assert labels[0, 0] != labels[1, 1]  # touching corners do not connect


def test_polygon_maps_erode_against_the_polygons():
    outline = box(0, 0, 4, 4)
    plan = FloorPlan(outline=outline, obstacles=(box(1.0, 1.0, 3.0, 3.0),))
    grid = np.zeros((40, 40), np.uint8)
    grid[10:30, 10:30] = OBSTACLE
    m = TraversableMap(grid, 0.1, geometry=plan)
    usable = m.usable(0.2)
    # Cell centre 0.25 m left of the obstacle edge: clearance 0.25 >= 0.2.
    assert usable[20, 7]
    assert not usable[20, 8]  # clearance 0.15


def test_bounded_cache_drops_least_recently_used():
    cache = BoundedCache(2)
    cache.get_or_create("a", lambda: 1)
    cache.get_or_create("b", lambda: 2)
    cache.get_or_create("a", lambda: 0)  # touch a
    cache.get_or_create("c", lambda: 3)
    assert "a" in cache and "c" in cache and "b" not in cache
    with pytest.raises(ValueError, match="maxsize"):
        BoundedCache(0)


def test_a_usable_cell_centre_belongs_to_its_own_cells_component_and_a_nudged_point_agrees():
    # Two rooms joined by nothing: a wall down the middle. A cell centre's component is its
    # own cell's label (it reaches itself at distance 0); a point a hair off the centre
    # takes the general path (nearest centre it reaches straight) and must agree.
    grid = np.zeros((12, 21), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    grid[:, 10] = OBSTACLE
    tmap = TraversableMap(grid, resolution=0.1)
    labels = tmap.components(0.05)
    usable = np.argwhere(labels > 0)
    centres = tmap.cell_to_world(usable)
    got = tmap.component_at(centres, 0.05)
    assert np.array_equal(got, labels[usable[:, 0], usable[:, 1]])
    assert len(set(got.tolist())) == 2
    nudged = centres + 1e-7
    fits = tmap.is_usable(nudged, 0.05)  # a centre touching a wall may not fit once nudged
    assert fits.sum() > len(fits) // 2
    assert np.array_equal(tmap.component_at(nudged[fits], 0.05), got[fits])
    # Blocked and off-map points are in no component.
    assert tmap.component_at(np.array([[1.05, 0.55], [-1.0, -1.0]]), 0.05).tolist() == [0, 0]


@settings(max_examples=200, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    resolution=st.sampled_from([0.05, 0.1, 0.3, 0.5, 1.0]),
    radius=st.floats(0.0, 0.4),
    kind=st.sampled_from(["centre", "inside", "edge", "off"]),
)
def test_one_point_component_at_is_the_general_paths(seed, resolution, radius, kind):
    # One point takes a float fast path (a usable cell's exact centre); two points take the
    # array path: the same label for the same point.
    rng = np.random.default_rng(seed)
    tmap = TraversableMap(rng.random((12, 15)) < 0.8, resolution=resolution, origin=tuple(rng.uniform(-3, 3, 2)))
    cell = np.array([rng.integers(12), rng.integers(15)])
    point = tmap.cell_to_world(cell)
    if kind == "inside":
        point = point + rng.uniform(-0.49, 0.49, 2) * resolution
    elif kind == "edge":
        point = point + 0.5 * resolution
    elif kind == "off":
        point = point + 20 * resolution
    one = int(tmap.component_at(point, radius))
    assert one == int(tmap.component_at(np.stack([point, point]), radius)[0])
    assert tmap.component_at(point, radius).shape == ()
