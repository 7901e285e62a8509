"""The compiled ray casting (numba, ``method="numba"``) gives the numpy path's ranges.

``cast_rays`` has two paths: the array code of ``pointnav_core.sensors.raycast`` (the
general path) and the kernel of ``pointnav_core.sensors.raycast_jit`` (the fast path, which
skips clear squares of the grid and culls polygon edges by angle). Both evaluate the same
expressions, so their ranges must be equal, not merely close: over the small random scenes
of ``test_scan_props`` and over larger ones with many polygons, open space (where the fast
path jumps) and several robots. Both paths also meet the shapely reference there.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely
import shapely.affinity
from hypothesis import given
from hypothesis import strategies as st

from pointnav_core.floor.maps import TraversableMap
from pointnav_core.floorplans import FloorPlan
from pointnav_core.sensors import ScanGeometry, cast_rays, scan_angles
from pointnav_core.sensors.raycast import cast_pose_compiled

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from scan_reference import assert_within, blocked_shapes, reference_ranges
from test_scan_props import scan_scenes

pytest.importorskip("numba", reason="the compiled path is the `fast` extra")


def _both(geo, origins, yaws, angles, max_range, discs=None, own=None):
    fast = cast_rays(geo, origins, yaws, angles, max_range, discs=discs, own_disc=own, method="numba")
    general = cast_rays(geo, origins, yaws, angles, max_range, discs=discs, own_disc=own, method="array")
    np.testing.assert_array_equal(fast, general)
    return fast


@given(scan_scenes())
def test_small_scenes_give_equal_ranges(case):
    tmap, _, origin, yaw, angles, max_range, discs = case
    _both(ScanGeometry(tmap), [origin], [yaw], angles, max_range, discs=discs)


@given(scan_scenes())
def test_the_scans_one_pose_path_gives_equal_ranges(case):
    tmap, _, origin, yaw, angles, max_range, _ = case
    geo = ScanGeometry(tmap)
    yaws = np.array([yaw], dtype=np.float64)
    heading = np.concatenate([np.cos(yaws), np.sin(yaws)])
    directions = (np.cos(np.asarray(angles, dtype=np.float64)), np.sin(np.asarray(angles, dtype=np.float64)))
    got = cast_pose_compiled(geo, np.array([origin], dtype=np.float64), heading, directions, max_range)
    np.testing.assert_array_equal(got, cast_rays(geo, [origin], [yaw], angles, max_range, method="array")[0])


@st.composite
def open_scenes(draw):
    """A larger floor, mostly free, with scattered blocks and many (rotated) polygons;
    several robots (radii 0.3 to 5 cells) as origins and as discs."""
    h = draw(st.integers(10, 60))
    w = draw(st.integers(10, 60))
    res = draw(st.sampled_from([0.05, 0.1, 0.5]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    codes = (rng.random((h, w)) < draw(st.sampled_from([0.0, 0.02, 0.1]))).astype(np.uint8)
    ox, oy = draw(st.floats(-5.0, 5.0)), draw(st.floats(-5.0, 5.0))
    polygons = []
    for _ in range(draw(st.integers(0, 8))):
        cx = ox + rng.uniform(0.0, w * res)
        cy = oy + rng.uniform(0.0, h * res)
        box = shapely.box(cx, cy, cx + rng.uniform(0.02, 4.0) * res, cy + rng.uniform(0.02, 8.0) * res)
        if draw(st.booleans()):  # on the grid's lines (origins at cell centres meet it)
            box = shapely.box(*np.round(np.asarray(box.bounds) / res * 2.0) * res / 2.0)
        else:
            box = shapely.affinity.rotate(box, rng.uniform(0.0, 180.0), origin="centroid")
        if box.area > 0.0:
            polygons.append(box)
    geometry = None
    if polygons:
        geometry = FloorPlan(outline=shapely.box(ox, oy, ox + w * res, oy + h * res), obstacles=tuple(polygons))
    tmap = TraversableMap(codes, res, (ox, oy), geometry=geometry)
    n = draw(st.integers(1, 6))
    if draw(st.booleans()):  # cell centres: rays meet grid vertices and polygon ends exactly
        cells = rng.integers(0, [w, h], size=(n, 2))
        origins = np.array([ox, oy]) + (cells + 0.5) * res
    else:
        origins = np.array([ox, oy]) + rng.uniform(0.0, 1.0, (n, 2)) * [w * res, h * res]
    yaws = draw(st.sampled_from([0.0, math.pi / 2])) + rng.uniform(0.0, 1.0, n) * draw(st.sampled_from([0.0, math.pi]))
    radii = rng.uniform(0.3, 5.0, n) * res
    discs = np.column_stack([origins, radii])
    angles = scan_angles(draw(st.integers(1, 96)), draw(st.sampled_from([2 * math.pi, math.pi, 1.0])))
    max_range = draw(st.floats(0.5, 80.0)) * res
    return tmap, polygons, origins, yaws, angles, max_range, discs


@given(open_scenes())
def test_open_scenes_give_equal_ranges_and_meet_the_reference(case):
    tmap, polygons, origins, yaws, angles, max_range, discs = case
    geo = ScanGeometry(tmap)
    got = _both(geo, origins, yaws, angles, max_range, discs=discs, own=np.arange(len(origins)))
    # The first robot against the shapely reference (the others' discs in view).
    shapes = blocked_shapes(tmap.codes, tmap.resolution, tmap.origin, polygons)
    loose, strict = reference_ranges(shapes, origins[0], yaws[0] + angles, max_range, discs[1:])
    assert_within(got[0], loose, strict, atol=1e-4)


@pytest.fixture(scope="module")
def big_floor():
    """A 2000 x 2000 floor at 0.05 m: rooms of free space between random blocky walls."""
    from scipy import ndimage

    rng = np.random.default_rng(7)
    seeds = rng.random((2000, 2000)) < 0.002
    codes = ndimage.binary_dilation(seeds, np.ones((5, 9), bool)).astype(np.uint8)
    tmap = TraversableMap(codes, 0.05, (-50.0, -50.0))
    return tmap, ScanGeometry(tmap)


@given(st.data())
def test_a_2000_by_2000_floor_gives_equal_ranges_that_meet_the_reference(big_floor, data):
    tmap, geo = big_floor
    res = tmap.resolution
    n = data.draw(st.integers(1, 4))
    cells = np.array(data.draw(st.lists(st.tuples(st.integers(0, 1999), st.integers(0, 1999)), min_size=n, max_size=n)))
    origins = np.array(tmap.origin) + (cells + np.array(data.draw(st.sampled_from([0.5, 0.37])))) * res
    yaws = np.array(data.draw(st.lists(st.floats(-math.pi, math.pi), min_size=n, max_size=n)))
    radii = np.array(data.draw(st.lists(st.floats(0.3, 5.0), min_size=n, max_size=n))) * res
    discs = np.column_stack([origins, radii])
    angles = scan_angles(64, 2 * math.pi)
    max_range = data.draw(st.sampled_from([1.0, 5.6]))
    got = _both(geo, origins, yaws, angles, max_range, discs=discs, own=np.arange(n))
    # The reference sees a window around the first origin, wider than max_range (its frame,
    # where the window is cut inside the map, is out of reach).
    margin = math.ceil(max_range / res) + 3
    c0, r0 = np.maximum(cells[0] - margin, 0)
    c1, r1 = np.minimum(cells[0] + margin + 1, 2000)
    window = tmap.codes[r0:r1, c0:c1]
    corner = (tmap.origin[0] + c0 * res, tmap.origin[1] + r0 * res)
    shapes = blocked_shapes(window, res, corner)
    loose, strict = reference_ranges(shapes, origins[0], yaws[0] + angles, max_range, discs[1:])
    assert_within(got[0], loose, strict, atol=1e-4)
