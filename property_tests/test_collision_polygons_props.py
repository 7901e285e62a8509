"""The compiled polygon clearance test equals shapely's ``dwithin`` (the path without numba).

Random polygons (boxes, rotated thin walls, triangles, polygons with holes, multipolygons)
and random segments (points, short and long, inside, outside and across), at random radii:
``FloorCollision.segments_clear`` gives the same answer with numba's polygon kernel and with
shapely's STRtree query, except where shapely's own distance lies within 1e-9 m of the
reach, where the two are equally right.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.affinity import rotate
from shapely.geometry import MultiPolygon, Polygon, box

from pointnav_core.floor.collision import TOUCH_TOL, FloorCollision
from pointnav_core.utils.compiled import kernel, numpy_paths

pytest.importorskip("numba")


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
def test_compiled_polygon_test_equals_shapely(polys, seed, radius) -> None:
    rng = np.random.default_rng(seed)
    geo = FloorCollision(np.zeros((60, 60), bool), 0.1, (0.0, 0.0), polygons=polys)
    a = rng.uniform(0.0, 6.0, (200, 2))
    b = a + rng.normal(0.0, 1.0, (200, 2)) * rng.choice([0.0, 0.1, 1.0, 3.0], (200, 1))
    assert kernel("pointnav_core.floor._collision_kernel", "polygons_hit") is not None
    got = geo.segments_clear(a, b, radius)
    with numpy_paths():
        want = geo.segments_clear(a, b, radius)
    reach = max(radius - 2 * TOUCH_TOL, TOUCH_TOL / 2)
    lines = np.array([shapely.LineString([p, q]) if (p != q).any() else shapely.Point(p) for p, q in zip(a, b)])
    dist = shapely.distance(shapely.union_all(polys), lines)
    sure = np.abs(dist - reach) > 1e-9
    np.testing.assert_array_equal(got[sure], want[sure])
    # The one-segment call (planners' and worlds' point tests) answers as the array call.
    one = np.array([geo.segment_clear(*p, *q, radius) for p, q in zip(a.tolist(), b.tolist())])
    np.testing.assert_array_equal(one, got)
