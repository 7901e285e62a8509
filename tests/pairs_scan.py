"""Plain and compiled paths of the range scan and its noise: the checks of
``property_tests/test_compiled_paths.py`` for ``sensors._raycast_kernel`` and
``sensors._noise_kernel``.

Each check takes ``plain_paths``, the context its plain side runs in (``numpy_paths()``).

``cast_rays`` has two paths: the array code of ``pointnav_core.sensors.raycast`` (the
general path, ``method="array"``) and the kernel of ``pointnav_core.sensors.raycast_jit``
(``method="numba"``, which skips clear squares of the grid and culls polygon edges by angle).
Both evaluate the same expressions, so their ranges must be equal, not merely close: over the
small random scenes of ``test_scan_props``, over larger ones with many polygons, open space
(where the fast path jumps) and several robots, over a 2000 x 2000 floor, and over scans that
graze the jumps' far sides (origins on or within ``TOUCH_EPS`` of grid lines, rays along the
axes and diagonals or drifting by a few ``TOUCH_EPS``). Both paths also meet the shapely
reference there.

:func:`~pointnav_core.sensors.noise.scan_noise` hashes every ray's word either with numpy
whole-array passes or in one compiled loop; for random keys (the whole uint64 range),
robots, steps, batch shapes, ray counts and channels both give the same bits.
(``tests/test_scan_noise.py`` checks the numpy path against splitmix64 written out with
Python ints.)
"""

from __future__ import annotations

import functools
import math
import sys
from collections.abc import Callable
from contextlib import AbstractContextManager
from pathlib import Path

import numpy as np
import shapely
import shapely.affinity
from hypothesis import given, settings
from hypothesis import strategies as st
from scan_reference import assert_within, blocked_shapes, reference_ranges

from pointnav_core.floor.maps import TraversableMap
from pointnav_core.floorplans import FloorPlan
from pointnav_core.scenes import Scene
from pointnav_core.sensors import TOUCH_EPS, ScanGeometry, cast_rays, scan_angles
from pointnav_core.sensors.noise import scan_noise
from pointnav_core.sensors.raycast import cast_pose_compiled
from pointnav_core.vector.scan import ScanTables, cast_batch
from pointnav_core.vector.xp import make_arrays

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "property_tests"))
from test_scan_props import scan_scenes  # noqa: E402  (the small scenes of the scan's own tests)

Plain = Callable[[], AbstractContextManager[None]]


def _both(plain_paths, geo, origins, yaws, angles, max_range, discs=None, own=None):
    fast = cast_rays(geo, origins, yaws, angles, max_range, discs=discs, own_disc=own, method="numba")
    with plain_paths():
        general = cast_rays(geo, origins, yaws, angles, max_range, discs=discs, own_disc=own, method="array")
    np.testing.assert_array_equal(fast, general)
    return fast


@given(scan_scenes())
def check_small_scenes(plain_paths: Plain, case) -> None:
    tmap, _, origin, yaw, angles, max_range, discs = case
    _both(plain_paths, ScanGeometry(tmap), [origin], [yaw], angles, max_range, discs=discs)


@given(scan_scenes())
def check_one_pose(plain_paths: Plain, case) -> None:
    tmap, _, origin, yaw, angles, max_range, _ = case
    geo = ScanGeometry(tmap)
    yaws = np.array([yaw], dtype=np.float64)
    heading = np.concatenate([np.cos(yaws), np.sin(yaws)])
    directions = (np.cos(np.asarray(angles, dtype=np.float64)), np.sin(np.asarray(angles, dtype=np.float64)))
    got = cast_pose_compiled(geo, np.array([origin], dtype=np.float64), heading, directions, max_range)
    with plain_paths():
        want = cast_rays(geo, [origin], [yaw], angles, max_range, method="array")[0]
    np.testing.assert_array_equal(got, want)


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
def check_open_scenes(plain_paths: Plain, case) -> None:
    tmap, polygons, origins, yaws, angles, max_range, discs = case
    geo = ScanGeometry(tmap)
    got = _both(plain_paths, geo, origins, yaws, angles, max_range, discs=discs, own=np.arange(len(origins)))
    # The first robot against the shapely reference (the others' discs in view).
    shapes = blocked_shapes(tmap.codes, tmap.resolution, tmap.origin, polygons)
    loose, strict = reference_ranges(shapes, origins[0], yaws[0] + angles, max_range, discs[1:])
    assert_within(got[0], loose, strict, atol=1e-4)


@functools.lru_cache(maxsize=1)
def big_floor() -> tuple[TraversableMap, ScanGeometry]:
    """A 2000 x 2000 floor at 0.05 m: rooms of free space between random blocky walls."""
    from scipy import ndimage

    rng = np.random.default_rng(7)
    seeds = rng.random((2000, 2000)) < 0.002
    codes = ndimage.binary_dilation(seeds, np.ones((5, 9), bool)).astype(np.uint8)
    tmap = TraversableMap(codes, 0.05, (-50.0, -50.0))
    return tmap, ScanGeometry(tmap)


# 60 examples (the ci profile's 200 took about a minute, 100 took 53 s on CI's 2 cores): each
# casts on a 2000 x 2000 floor.
@settings(max_examples=60)
@given(st.data())
def check_big_floor(plain_paths: Plain, data) -> None:
    tmap, geo = big_floor()
    res = tmap.resolution
    n = data.draw(st.integers(1, 4))
    cells = np.array(data.draw(st.lists(st.tuples(st.integers(0, 1999), st.integers(0, 1999)), min_size=n, max_size=n)))
    origins = np.array(tmap.origin) + (cells + np.array(data.draw(st.sampled_from([0.5, 0.37])))) * res
    yaws = np.array(data.draw(st.lists(st.floats(-math.pi, math.pi), min_size=n, max_size=n)))
    radii = np.array(data.draw(st.lists(st.floats(0.3, 5.0), min_size=n, max_size=n))) * res
    discs = np.column_stack([origins, radii])
    angles = scan_angles(64, 2 * math.pi)
    max_range = data.draw(st.sampled_from([1.0, 5.6]))
    got = _both(plain_paths, geo, origins, yaws, angles, max_range, discs=discs, own=np.arange(n))
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


@st.composite
def grazing_scans(draw):
    """Rooms with big free squares and a few blocks; origins on, or within TOUCH_EPS-scale
    offsets of, grid lines; rays along the axes and diagonals or at slopes of a few cells
    over the range, so that crossings run within TOUCH_EPS of grid lines far from the origin."""
    h = draw(st.integers(8, 40))
    w = draw(st.integers(8, 40))
    res = draw(st.sampled_from([0.05, 0.1, 0.5]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    codes = np.zeros((h, w), np.uint8)
    for _ in range(draw(st.integers(0, 6))):
        r, c = rng.integers(0, [h, w])
        codes[r : r + rng.integers(1, 4), c : c + rng.integers(1, 4)] = 1
    ox, oy = draw(st.sampled_from([0.0, -1.3, 2.25])), draw(st.sampled_from([0.0, 0.7, -3.5]))
    tmap = TraversableMap(codes, res, (ox, oy))
    offsets = [0.0, 0.5 * TOUCH_EPS, -0.5 * TOUCH_EPS, 1.5 * TOUCH_EPS, -1.5 * TOUCH_EPS, 1e-12, 0.5 * res]
    n = draw(st.integers(1, 4))
    cells = rng.integers(0, [w + 1, h + 1], size=(n, 2))
    off = np.array([[draw(st.sampled_from(offsets)), draw(st.sampled_from(offsets))] for _ in range(n)])
    origins = np.array([ox, oy]) + cells * res + off
    # Headings: exact axes and diagonals, or a slope that drifts by a few TOUCH_EPS or a
    # fraction of a cell over the whole range.
    base = draw(st.sampled_from([0.0, math.pi / 4, math.pi / 2, 3 * math.pi / 4, math.pi, -math.pi / 2]))
    drift = draw(st.sampled_from([0.0, 1e-11, -1e-11, 1e-9, 3e-9, -3e-9, 1e-3, 0.05]))
    yaws = base + drift * rng.uniform(-1.0, 1.0, n)
    angles = scan_angles(draw(st.sampled_from([4, 8, 16, 32])), 2 * math.pi)
    max_range = draw(st.floats(1.0, 60.0)) * res
    return tmap, origins, yaws, angles, max_range


@given(grazing_scans())
def check_grazing_scans(plain_paths: Plain, case) -> None:
    tmap, origins, yaws, angles, max_range = case
    geo = ScanGeometry(tmap)
    with plain_paths():
        general = cast_rays(geo, origins, yaws, angles, max_range, method="array")
    np.testing.assert_array_equal(cast_rays(geo, origins, yaws, angles, max_range, method="numba"), general)
    # The batched kernel, one robot per world (no discs), on the same floor.
    scene = Scene.from_array(np.asarray(tmap.codes), tmap.resolution, origin=tuple(tmap.origin))
    tables = ScanTables([scene], 0, make_arrays("numpy"))
    n = len(origins)
    batched = cast_batch(tables, np.zeros(n, np.int64), origins[:, :1].copy(), origins[:, 1:].copy(),
                         yaws[:, None].copy(), np.ones((n, 1), bool), 0.0, angles, max_range, "numba")
    np.testing.assert_array_equal(batched[:, 0], general)


@settings(max_examples=60, deadline=None)
@given(
    worlds=st.integers(1, 6), robots=st.integers(1, 4), n_rays=st.integers(1, 40),
    seed=st.integers(0, 2**32 - 1), noise_std=st.sampled_from([0.0, 0.01, 0.3]),
    dropout=st.sampled_from([0.0, 0.05, 0.5]),
)
def check_noise(
    worlds: int, robots: int, n_rays: int, seed: int, noise_std: float, dropout: float, plain_paths: Plain
) -> None:
    """:func:`~pointnav_core.sensors.noise.scan_noise`: the compiled hashing and numpy's
    whole-array passes give the same bits."""
    rng = np.random.default_rng(seed)
    episode = rng.integers(0, 2**64, (worlds, 1, 1), dtype=np.uint64)
    robot = np.arange(robots)[None, :, None]
    step = rng.integers(0, 10_000, (worlds, robots, 1))
    args = (episode, robot, step, n_rays, noise_std, dropout)
    with plain_paths():
        want = scan_noise(*args, method="array")
    got = scan_noise(*args, method="numba")
    for w, g in zip(want, got, strict=True):
        assert (w is None) == (g is None)
        if w is not None:
            assert w.shape == (worlds, robots, n_rays)
            np.testing.assert_array_equal(g, w)
    if noise_std == 0.0 and dropout == 0.0:
        assert got == (None, None)
