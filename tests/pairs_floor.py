"""Plain and compiled paths of the floor's collision tests, its cell draws and the tangent
graph's sight bounds: the checks of ``property_tests/test_compiled_paths.py`` for
``floor._collision_kernel``, ``floor._draw_kernel``, ``geodesic._sight_kernel`` and
``geodesic._edges_kernel`` and ``floor._component_kernel``.

Each check takes ``plain_paths``, the context its plain side runs in (``numpy_paths()``).

- :meth:`FloorCollision.segments_clear` (and the one-segment ``segment_clear``) answers the
  same with its numba kernels as with its numpy arrays, for random grids (random blocked
  cells, outside blocked or not), radii (0 included) and segments of every kind (points,
  axis-aligned, on grid lines, crossing the map's edge, far off it). The numpy path itself is
  checked against shapely in ``property_tests/test_geometry_agreement.py`` and
  ``tests/test_collision.py``.
- On obstacle polygons (boxes, rotated thin walls, triangles, polygons with holes,
  multipolygons) the compiled polygon test equals shapely's ``dwithin`` (the path without
  numba), except where shapely's own distance lies within 1e-9 m of the reach, where the two
  are equally right.
- :func:`pointnav_core.floor.draw.draw_cell` draws the same cells with its row spans kernel
  as with its arrays (which ``tests/test_sampling.py`` checks against ``math.hypot``).
- :func:`pointnav_core.geodesic.sight.node_sights` gives the same bounds, bit for bit, with
  numba and as plain Python, ``edges._misses_full`` (the cheap rejection of candidate
  tangent segments) the same answers with its kernel and with its numpy samples, and
  ``edges.build_edges`` the same edges, in the same order, with its candidate pair kernel
  and with the KD-tree.
- :meth:`TraversableMap.component_at` gives one point off the cell centres the same label
  with its kernel as with its arrays (which ``tests/test_reachability.py`` checks against
  components found by hand): random grids and rooms of obstacle polygons, radii, points
  near, on and between cell centres, on blocked cells and off the map.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager

import numpy as np
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.affinity import rotate
from shapely.geometry import MultiPolygon, Polygon, box

from pointnav_core.floor.collision import TOUCH_TOL, FloorCollision
from pointnav_core.geodesic import edges, sight
from pointnav_core.geodesic.planner import Planner
from pointnav_core.utils.compiled import kernel

Plain = Callable[[], AbstractContextManager[None]]


#: Random grid floors: a seed for their cells, their size, blocked share, cell size, and a radius.
GRIDS = {
    "seed": st.integers(0, 2**31 - 1),
    "rows": st.integers(1, 40),
    "cols": st.integers(1, 40),
    "density": st.floats(0.0, 0.5),
    "radius": st.one_of(st.just(0.0), st.floats(0.0, 0.6)),
    "resolution": st.sampled_from([0.05, 0.1, 0.5]),
}


@settings(max_examples=80, deadline=None)
@given(**GRIDS, outside_blocked=st.booleans(), n=st.integers(1, 60))
def check_cell_test(
    seed: int, rows: int, cols: int, density: float, radius: float, resolution: float, outside_blocked: bool, n: int,
    plain_paths: Plain,
) -> None:
    """:meth:`FloorCollision.segments_clear` and ``segment_clear`` (the cell kernels)."""
    rng = np.random.default_rng(seed)
    origin = (float(rng.uniform(-2, 2)), float(rng.uniform(-2, 2)))
    geo = FloorCollision(rng.random((rows, cols)) < density, resolution, origin, outside_blocked=outside_blocked)
    size = np.array([cols, rows]) * resolution
    a = origin + rng.uniform(-0.3, 1.3, (n, 2)) * size
    b = a + rng.normal(0.0, 0.3, (n, 2)) * size
    kind = rng.integers(0, 5, n)
    b[kind == 0] = a[kind == 0]  # points
    b[kind == 1, 1] = a[kind == 1, 1]  # horizontal
    b[kind == 2, 0] = a[kind == 2, 0]  # vertical
    on_lines = kind == 3  # ends on grid lines and vertices
    a[on_lines] = origin + np.round((a[on_lines] - origin) / resolution) * resolution
    b[on_lines] = origin + np.round((b[on_lines] - origin) / resolution) * resolution
    a[kind == 4] += 50.0 * size  # far off the map
    got = geo.segments_clear(a, b, radius)
    with plain_paths():
        assert kernel("pointnav_core.floor._collision_kernel", "cells_hit") is None
        want = geo.segments_clear(a, b, radius)
    np.testing.assert_array_equal(got, want)
    assert kernel("pointnav_core.floor._collision_kernel", "cells_hit") is not None
    # The one-segment call (planners' and worlds' point tests), compiled and not.
    pairs = list(zip(a.tolist(), b.tolist()))
    one = np.array([geo.segment_clear(*p, *q, radius) for p, q in pairs])
    with plain_paths():
        plain = np.array([geo.segment_clear(*p, *q, radius) for p, q in pairs])
    np.testing.assert_array_equal(one, want)
    np.testing.assert_array_equal(plain, want)


@st.composite
def polygons(draw: st.DrawFn):
    kind = draw(st.sampled_from(["box", "wall", "triangle", "holed", "multi"]))
    x, y = draw(st.floats(0.5, 4.5)), draw(st.floats(0.5, 4.5))
    if kind == "box":
        return box(x, y, x + draw(st.floats(0.05, 1.5)), y + draw(st.floats(0.05, 1.5)))
    if kind == "wall":
        return rotate(box(x, y, x + draw(st.floats(0.5, 3.0)), y + draw(st.floats(0.005, 0.08))), draw(st.floats(0, 180)))
    if kind == "triangle":
        pts = [(x, y)] + [(x + draw(st.floats(-1, 1)), y + draw(st.floats(-1, 1))) for _ in range(2)]
        poly = Polygon(pts)
        return poly if poly.is_valid and poly.area > 1e-4 else box(x, y, x + 0.3, y + 0.3)
    if kind == "holed":
        outer = box(x, y, x + 1.5, y + 1.5)
        return outer.difference(box(x + 0.4, y + 0.4, x + 1.1, y + 1.1))
    return MultiPolygon([box(x, y, x + 0.3, y + 0.3), box(x + 0.6, y, x + 0.9, y + 0.5)])


@settings(max_examples=80, deadline=None)
@given(polys=st.lists(polygons(), min_size=1, max_size=6), seed=st.integers(0, 2**31 - 1), radius=st.floats(0.0, 0.6))
def check_polygon_test(polys, seed, radius, plain_paths: Plain) -> None:
    """:meth:`FloorCollision.segments_clear` on obstacle polygons (the polygon kernel)."""
    rng = np.random.default_rng(seed)
    geo = FloorCollision(np.zeros((60, 60), bool), 0.1, (0.0, 0.0), polygons=polys)
    a = rng.uniform(0.0, 6.0, (200, 2))
    b = a + rng.normal(0.0, 1.0, (200, 2)) * rng.choice([0.0, 0.1, 1.0, 3.0], (200, 1))
    assert kernel("pointnav_core.floor._collision_kernel", "polygons_hit") is not None
    got = geo.segments_clear(a, b, radius)
    with plain_paths():
        want = geo.segments_clear(a, b, radius)
    reach = max(radius - 2 * TOUCH_TOL, TOUCH_TOL / 2)
    lines = np.array([shapely.LineString([p, q]) if (p != q).any() else shapely.Point(p) for p, q in zip(a, b)])
    dist = shapely.distance(shapely.union_all(polys), lines)
    sure = np.abs(dist - reach) > 1e-9
    np.testing.assert_array_equal(got[sure], want[sure])
    # The one-segment call (planners' and worlds' point tests) answers as the array call.
    one = np.array([geo.segment_clear(*p, *q, radius) for p, q in zip(a.tolist(), b.tolist())])
    np.testing.assert_array_equal(one, got)


def floor_collision(seed: int, rows: int, cols: int, density: float, resolution: float, outside: bool) -> FloorCollision:
    """A random floor: blocked cells of ``density``, a random origin, open outside or not."""
    rng = np.random.default_rng(seed)
    blocked = rng.random((rows, cols)) < density
    origin = (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)))
    return FloorCollision(blocked, resolution, origin, outside_blocked=outside)


@settings(max_examples=20, deadline=None)  # the plain path is Python: small floors
@given(
    seed=st.integers(0, 2**31 - 1),
    rows=st.integers(2, 14),
    cols=st.integers(2, 14),
    density=st.floats(0.0, 0.4),
    radius=st.floats(1e-6, 0.5),
    resolution=st.sampled_from([0.05, 0.1, 0.25, 0.5]),
    outside=st.booleans(),
)
def check_sights(seed, rows, cols, density, radius, resolution, outside, plain_paths: Plain) -> None:
    """:func:`~pointnav_core.geodesic.sight.node_sights` (the sight-ray kernel), bit for bit."""
    geo = floor_collision(seed, rows, cols, density, resolution, outside)
    planner = Planner(geo, radius)
    assert kernel("pointnav_core.geodesic._sight_kernel", "sight_rays") is not None
    got, got_profile = sight.node_sights(geo, planner.radius, planner.cx, planner.cy, planner.phi0, planner.span)
    with plain_paths():
        assert kernel("pointnav_core.geodesic._sight_kernel", "sight_rays") is None
        want, want_profile = sight.node_sights(geo, planner.radius, planner.cx, planner.cy, planner.phi0, planner.span)
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(got_profile, want_profile)
    assert (got > 0).all() and (got_profile.max(axis=1) >= got * (1 - 1e-6)).all()


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    rows=st.integers(2, 40),
    cols=st.integers(2, 40),
    density=st.floats(0.0, 0.5),
    radius=st.floats(0.0, 0.3),
    resolution=st.sampled_from([0.05, 0.1, 0.25]),
    outside=st.booleans(),
    n_segments=st.integers(0, 60),
    step=st.sampled_from([2.0, 0.5, 0.3, 1.0]),
)
def check_fully_blocked_samples(
    seed: int, rows: int, cols: int, density: float, radius: float, resolution: float, outside: bool,
    n_segments: int, step: float, plain_paths: Plain,
) -> None:
    """``_misses_full`` (the cheap rejection of candidate tangent segments) gives the same
    answer, segment by segment, with its numba kernel and with its numpy samples, for
    segments on and off the map, of zero length, along cell edges and across the map."""
    rng = np.random.default_rng(seed)
    geo = floor_collision(seed, rows, cols, density, resolution, outside)
    origin = geo.origin
    planner = Planner(geo, radius)
    lo = np.array(origin) - 0.2 * np.array([cols, rows]) * resolution
    hi = np.array(origin) + 1.2 * np.array([cols, rows]) * resolution
    a = rng.uniform(lo, hi, (n_segments, 2))
    b = rng.uniform(lo, hi, (n_segments, 2))
    b[: n_segments // 5] = a[: n_segments // 5]  # zero length
    # Along a row of cell edges.
    k = slice(n_segments // 5, 2 * n_segments // 5)
    a[k, 1] = b[k, 1] = origin[1] + resolution * rng.integers(0, rows + 1, len(a[k]))
    assert kernel("pointnav_core.geodesic._sight_kernel", "misses_full") is not None
    got = edges._misses_full(planner, a, b, step)
    with plain_paths():
        want = edges._misses_full(planner, a, b, step)
    np.testing.assert_array_equal(got, want)
    assert got.dtype == np.bool_ and got.shape == (n_segments,)
    # A segment with an end in a fully blocked cell (or off a closed map) is rejected.
    full = planner.fully_blocked_mask()
    col = np.floor((a[:, 0] - origin[0]) / resolution).astype(np.int64) + 1
    row = np.floor((a[:, 1] - origin[1]) / resolution).astype(np.int64) + 1
    on = (col >= 0) & (col < full.shape[1]) & (row >= 0) & (row < full.shape[0])
    end_bad = np.where(on, full[np.clip(row, 0, full.shape[0] - 1), np.clip(col, 0, full.shape[1] - 1)], outside)
    assert not (got & end_bad).any()



@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    rows=st.integers(2, 45),
    cols=st.integers(2, 45),
    density=st.floats(0.0, 0.4),
    radius=st.one_of(st.just(0.0), st.floats(0.0, 0.5)),
    resolution=st.sampled_from([0.05, 0.1, 0.25, 0.5]),
    outside=st.booleans(),
)
def check_edges(
    seed: int, rows: int, cols: int, density: float, radius: float, resolution: float, outside: bool,
    plain_paths: Plain,
) -> None:
    """``edges.build_edges`` (the candidate pair kernel) stores the same tangent edges as the
    KD-tree and numpy: the same lists, bit for bit, in the same order where departures tie
    (grid corners in a row leave at one position)."""
    geo = floor_collision(seed, rows, cols, density, resolution, outside)
    # Both with compiled sights (check_sights holds them equal to the plain ones).
    fast, plain = Planner(geo, radius), Planner(geo, radius)
    assert kernel("pointnav_core.geodesic._edges_kernel", "edge_pairs") is not None
    fast.build_all_edges()
    with plain_paths():
        assert kernel("pointnav_core.geodesic._edges_kernel", "edge_pairs") is None
        plain.build_all_edges()
    assert fast.edge_store == plain.edge_store
    assert len(fast.edge_store) == 2 * fast.n_nodes


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    rows=st.integers(1, 50),
    cols=st.integers(1, 50),
    density=st.floats(0.0, 0.4),
    resolution=st.sampled_from([0.05, 0.1, 0.3, 0.5]),
    cells=st.one_of(st.sampled_from([0.0, 0.5, 5.0, 10.0, 12.5, 15.0]), st.floats(0.0, 80.0)),
    centred=st.booleans(),
)
def check_draw(
    seed: int, rows: int, cols: int, density: float, resolution: float, cells: float, centred: bool,
    plain_paths: Plain,
) -> None:
    """:func:`pointnav_core.floor.draw.draw_cell` (the row spans kernel) draws the same cell for
    the same random numbers, on grids with walls splitting rows, reaches on 3-4-5 bounds or
    any, from a cell centre or off it."""
    from pointnav_core.floor.draw import draw_cell
    from pointnav_core.floor.maps import TraversableMap

    rng = np.random.default_rng(seed)
    origin = (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)))
    tmap = TraversableMap(rng.random((rows, cols)) >= density, resolution=resolution, origin=origin)
    usable = np.argwhere(tmap.usable(0.0))
    if not len(usable):
        return
    cell = usable[rng.integers(len(usable))]
    ref = tmap.cell_to_world(cell) + (0.0 if centred else rng.uniform(-0.49, 0.49, 2) * resolution)
    label = int(tmap.components(0.0)[cell[0], cell[1]])
    reach = cells * resolution
    got = [draw_cell(tmap, 0.0, label, ref, reach, np.random.default_rng(s)) for s in range(8)]
    with plain_paths():
        assert kernel("pointnav_core.floor._draw_kernel", "row_spans") is None
        want = [draw_cell(tmap, 0.0, label, ref, reach, np.random.default_rng(s)) for s in range(8)]
    assert got == want


@settings(max_examples=60, deadline=None)
@given(**GRIDS, with_polygons=st.booleans())
def check_point_component(seed: int, rows: int, cols: int, density: float, radius: float, resolution: float,
                          with_polygons: bool, plain_paths: Plain) -> None:
    """``component_at`` of one point: the same label by ``point_component`` and by the arrays."""
    from pointnav_core.floor.maps import TraversableMap
    from pointnav_core.floorplans import FloorPlan

    rng = np.random.default_rng(seed)
    origin = (float(rng.uniform(-2, 2)), float(rng.uniform(-2, 2)))
    codes = (rng.random((rows, cols)) < density).astype(np.uint8)
    size = np.array([cols, rows]) * resolution
    geometry = None
    if with_polygons:  # a few boxes, some turned, over the grid
        corner = np.array(origin) + rng.uniform(0.0, 1.0, (3, 2)) * size
        boxes = [rotate(box(*c, *(c + rng.uniform(0.5, 3.0, 2) * resolution)), float(rng.uniform(0, 90))) for c in corner]
        geometry = FloorPlan(outline=box(*origin, *(np.array(origin) + size)), obstacles=tuple(boxes))
    tmap = TraversableMap(codes, resolution, origin, geometry=geometry)
    kind = rng.integers(0, 4, 40)
    points = np.array(origin) + rng.uniform(-0.1, 1.1, (40, 2)) * size
    centres = np.array(origin) + (np.floor((points - origin) / resolution) + 0.5) * resolution
    points[kind == 0] = centres[kind == 0]  # on a centre (the float path, no kernel)
    points[kind == 1] = centres[kind == 1] + rng.uniform(-0.05, 0.05, (int((kind == 1).sum()), 2)) * resolution
    points[kind == 2] = np.array(origin) + np.round((points[kind == 2] - origin) / resolution) * resolution  # vertices
    got = [int(tmap.component_at(p, radius)) for p in points]
    with plain_paths():
        assert kernel("pointnav_core.floor._component_kernel", "point_component") is None
        want = [int(tmap.component_at(p, radius)) for p in points]
    assert got == want
    assert kernel("pointnav_core.floor._component_kernel", "point_component") is not None
