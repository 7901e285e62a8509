"""Properties of the range scan over random scenes and poses, against first principles.

The reference (``tests/scan_reference.py``) intersects shapely rays with every blocked cell
square, a frame around the map, the obstacle polygons and the other robots' discs.
Robots' radii run from 0.3 to 5 cells.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import shapely
from hypothesis import given
from hypothesis import strategies as st

from pointnav_core.floor.maps import TraversableMap
from pointnav_core.sensors import ScanGeometry, cast_rays, scan_angles

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from scan_reference import assert_within, blocked_shapes, reference_ranges


@st.composite
def scan_scenes(draw):
    """A floor grid (with polygons), an origin anywhere on it, other robots, rays."""
    h = draw(st.integers(1, 8))
    w = draw(st.integers(1, 8))
    res = draw(st.sampled_from([0.05, 0.1, 0.25, 0.5, 1.0]))
    codes = np.array(draw(st.lists(st.sampled_from([0, 0, 1, 2]), min_size=h * w, max_size=h * w)), np.uint8)
    codes = codes.reshape(h, w)
    ox = draw(st.floats(-3.0, 3.0))
    oy = draw(st.floats(-3.0, 3.0))
    polygons = []
    for _ in range(draw(st.integers(0, 2))):
        x0 = ox + draw(st.floats(0.0, w * res))
        y0 = oy + draw(st.floats(0.0, h * res))
        polygons.append(
            shapely.box(x0, y0, x0 + draw(st.floats(0.01, 1.0)) * res, y0 + draw(st.floats(0.01, 3.0)) * res)
        )
    geometry = None
    if polygons:
        from pointnav_core.floorplans import FloorPlan

        geometry = FloorPlan(outline=shapely.box(ox, oy, ox + w * res, oy + h * res), obstacles=tuple(polygons))
    tmap = TraversableMap(codes, res, (ox, oy), geometry=geometry)
    at_centre = draw(st.booleans())
    if at_centre:  # cell centres and axis-aligned rays meet grid vertices exactly
        px = ox + (draw(st.integers(0, w - 1)) + 0.5) * res
        py = oy + (draw(st.integers(0, h - 1)) + 0.5) * res
    else:
        px = ox + draw(st.floats(0.0, w * res))
        py = oy + draw(st.floats(0.0, h * res))
    discs = [
        (ox + draw(st.floats(-res, (w + 1) * res)), oy + draw(st.floats(-res, (h + 1) * res)),
         draw(st.floats(0.3, 5.0)) * res)
        for _ in range(draw(st.integers(0, 3)))
    ]
    yaw = draw(st.sampled_from([0.0, math.pi / 2, math.pi / 4]) | st.floats(-math.pi, math.pi))
    n_rays = draw(st.integers(1, 24))
    fov = draw(st.sampled_from([2 * math.pi, math.pi]) | st.floats(0.1, 2 * math.pi))
    max_range = draw(st.floats(0.1, 12.0)) * res
    return tmap, polygons, (px, py), yaw, scan_angles(n_rays, fov), max_range, np.array(discs).reshape(-1, 3)


@given(scan_scenes())
def test_ranges_agree_with_the_shapely_reference(case):
    tmap, polygons, origin, yaw, angles, max_range, discs = case
    got = cast_rays(ScanGeometry(tmap), [origin], [yaw], angles, max_range, discs=discs)[0]
    shapes = blocked_shapes(tmap.codes, tmap.resolution, tmap.origin, polygons)
    loose, strict = reference_ranges(shapes, origin, yaw + angles, max_range, discs)
    assert got.dtype == np.float64 and got.shape == angles.shape
    assert_within(got, loose, strict, atol=1e-4)
    assert ((got >= 0.0) & (got <= max_range)).all()


@given(scan_scenes())
def test_a_ray_never_passes_a_blocked_cell(case):
    tmap, polygons, origin, yaw, angles, max_range, _ = case
    got = cast_rays(ScanGeometry(tmap), [origin], [yaw], angles, max_range)[0]
    blocked = shapely.union_all(blocked_shapes(tmap.codes, tmap.resolution, tmap.origin, polygons))
    px, py = origin
    for d, a in zip(got.tolist(), (yaw + angles).tolist()):
        short = d - 1e-6
        if short <= 0.0:
            continue
        ray = shapely.LineString([(px, py), (px + short * math.cos(a), py + short * math.sin(a))])
        assert not ray.intersects(blocked), (d, a)


@given(scan_scenes(), st.integers(2, 4))
def test_many_robots_at_once_equal_one_at_a_time(case, n):
    tmap, _, origin, yaw, angles, max_range, _ = case
    geo = ScanGeometry(tmap)
    origins = np.array([origin] * n) + np.linspace(0.0, 0.3 * tmap.resolution, n)[:, None]
    yaws = yaw + np.linspace(0.0, 1.0, n)
    discs = np.column_stack([origins, np.full(n, 0.3 * tmap.resolution)])
    together = cast_rays(geo, origins, yaws, angles, max_range, discs=discs, own_disc=np.arange(n))
    for i in range(n):
        alone = cast_rays(geo, origins[i : i + 1], yaws[i : i + 1], angles, max_range, discs=discs, own_disc=[i])
        np.testing.assert_array_equal(together[i], alone[0])
