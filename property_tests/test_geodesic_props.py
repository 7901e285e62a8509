"""Properties of maps, erosion, sampling and geodesic paths on random grids."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pointnav_core.floor.maps import FREE
from pointnav_core.geodesic.paths import path_length
from pointnav_core.scenes import Scene
from pointnav_core.testing.strategies import maps_with_points, traversable_maps


def scene_of(tmap):
    return Scene([tmap])


def segment_is_free(tmap, radius, a, b, step=0.05):
    """Dense independent check: every sample along a-b lies in a usable cell."""
    n = max(2, int(math.ceil(np.hypot(*(np.subtract(b, a))) / (step * tmap.resolution))) + 1)
    t = np.linspace(0.0, 1.0, n)[:, None]
    pts = np.asarray(a) * (1 - t) + np.asarray(b) * t
    return bool(tmap.is_usable(pts, radius).all())


@given(traversable_maps(), st.data())
def test_world_cell_round_trip_and_bounds(tmap, data):
    h, w = tmap.shape
    r = data.draw(st.integers(-3, h + 3))
    c = data.draw(st.integers(-3, w + 3))
    cell = np.array([r, c])
    assert np.array_equal(tmap.world_to_cell(tmap.cell_to_world(cell)), cell)
    inside = 0 <= r < h and 0 <= c < w
    assert bool(tmap.in_bounds(cell)) == inside
    expected = tmap.codes[r, c] if inside else 2
    assert int(tmap.cell_class_at(tmap.cell_to_world(cell))) == expected


@given(traversable_maps(), st.floats(0.0, 3.0), st.floats(0.0, 3.0))
def test_erosion_shrinks_monotonically_and_keeps_the_radius(tmap, a, b):
    small, large = sorted((a * tmap.resolution, b * tmap.resolution))
    u_small, u_large = tmap.usable(small), tmap.usable(large)
    assert not (u_large & ~u_small).any()
    blocked = np.argwhere(tmap.codes != FREE)
    h, w = tmap.shape
    for r, c in np.argwhere(u_large):
        # At least `large` from every blocked cell square and from the map's outside.
        if len(blocked):
            gap = np.maximum(np.abs(blocked - [r, c]) - 0.5, 0.0)
            assert np.hypot(gap[:, 0], gap[:, 1]).min() * tmap.resolution >= large - 1e-9
        assert (min(r, c, h - 1 - r, w - 1 - c) + 0.5) * tmap.resolution >= large - 1e-9


@given(maps_with_points(n_points=2))
def test_paths_are_usable_free_and_as_long_as_reported(case):
    tmap, radius, (a, b) = case
    scene = scene_of(tmap)
    path, dist = scene.get_shortest_path(0, a, b, entire_path=True, robot=radius)
    # Components join cell centres the disc moves between straight, so they are truly
    # connected; a passage no row of centres runs through may split one (the planner
    # still finds the way), so only this direction holds.
    same_component = tmap.component_at(a, radius) == tmap.component_at(b, radius) > 0
    if same_component:
        assert path is not None
    if path is None:
        return
    assert np.allclose(path[0], a) and np.allclose(path[-1], b)
    assert tmap.is_usable(path, radius).all()
    for p, q in zip(path[:-1], path[1:]):
        assert segment_is_free(tmap, radius, p, q)
    # Arcs are drawn as pieces of at most 2 degrees outside the circle, each longer than
    # its arc by a factor tan(a/2)/(a/2) <= 1 + 1.1e-4; straight parts are exact.
    assert dist - 1e-9 <= path_length(path) <= dist * (1 + 1.1e-4) + 1e-9
    assert dist >= math.dist(a, b) - 1e-9


@given(maps_with_points(n_points=3))
@settings(max_examples=40)
def test_geodesic_is_symmetric_and_obeys_the_triangle_inequality(case):
    tmap, radius, (a, b, c) = case
    scene = scene_of(tmap)
    d = lambda p, q: scene.get_shortest_path(0, p, q, entire_path=True, robot=radius)[1]  # noqa: E731
    ab, ba = d(a, b), d(b, a)
    if math.isinf(ab):  # unreachable: inf both ways (the one convention for no path)
        assert math.isinf(ba)
        return
    cell = tmap.resolution
    assert abs(ab - ba) <= cell
    bc, ac = d(b, c), d(a, c)
    if not math.isinf(bc):
        assert ac <= ab + bc + cell


@given(maps_with_points(n_points=2))
@settings(max_examples=40)
def test_field_lookup_is_the_length_of_a_real_path(case):
    tmap, radius, (a, b) = case
    scene = scene_of(tmap)
    _, dist = scene.get_shortest_path(0, a, b, entire_path=True, robot=radius)
    lookup = scene.goal_field(0, b, robot=radius).distance(*a)
    if dist == math.inf:
        assert lookup == math.inf
        return
    # The lookup follows the checked root of a's cell: a real path from the cell centre,
    # so never shorter than the geodesic (less twice the offset from the centre).
    assert math.isfinite(lookup)
    assert lookup >= dist - 2 * math.sqrt(0.5) * tmap.resolution - 1e-9
    assert lookup >= math.dist(a, b) - 1e-9


@given(maps_with_points(n_points=1), st.integers(0, 2**32 - 1))
def test_random_points_are_usable_and_stay_in_the_reference_component(case, seed):
    tmap, radius, (ref,) = case
    scene = scene_of(tmap)
    rng = np.random.default_rng(seed)
    floor, p = scene.get_random_point(robot=radius, rng=rng)
    assert floor == 0 and p[2] == tmap.height
    assert tmap.is_usable(p[:2], radius)
    _, q = scene.get_random_point(0, reference_point=ref, robot=radius, rng=rng)
    assert tmap.component_at(q[:2], radius) == tmap.component_at(ref, radius)
    assert scene.get_shortest_path(0, ref, q[:2], robot=radius)[1] is not None


@given(traversable_maps(), st.floats(0.0, 3.0))
def test_usable_cells_are_the_exact_clearance_test_at_every_centre(tmap, radius_cells):
    # The distance-transform fast path of usable() against the exact test it shortcuts.
    radius = radius_cells * tmap.resolution
    h, w = tmap.shape
    rows, cols = np.mgrid[0:h, 0:w]
    centres = tmap.cell_to_world(np.stack([rows, cols], axis=-1))
    assert (tmap.usable(radius) == tmap.collision.points_clear(centres, radius)).all()
