"""The free squares ahead (``sensors.clearance``) and the compiled walks that jump over them.

The table is checked against a brute-force search for the largest free square, cell by
cell. The walks' jumps end just before a free square's far side, so the rays that matter are
those that run within ``TOUCH_EPS`` of a grid line (they graze the cells beyond it): rays
along grid lines and at small slopes from origins on or next to grid lines, in rooms with
large free squares. There the compiled scans must still equal the numpy path bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from pointnav_core.floor.maps import TraversableMap
from pointnav_core.scenes import Scene
from pointnav_core.sensors import TOUCH_EPS, ScanGeometry, cast_rays, scan_angles
from pointnav_core.sensors.clearance import QUADRANTS, quadrant_clearance
from pointnav_core.vector.scan import ScanTables, cast_batch
from pointnav_core.vector.xp import make_arrays


def _brute_side(free: np.ndarray, row: int, col: int, sx: int, sy: int) -> int:
    # Grow the square anchored at the cell diagonally behind until a cell is blocked or off.
    hp, wp = free.shape
    r0, c0 = row - sy, col - sx
    k = 0
    while True:
        rows = [r0 + sy * i for i in range(k + 1)]
        cols = [c0 + sx * j for j in range(k + 1)]
        if not all(0 <= r < hp for r in rows) or not all(0 <= c < wp for c in cols):
            return k
        if not free[np.ix_(rows, cols)].all():
            return k
        k += 1


@st.composite
def free_grids(draw):
    h = draw(st.integers(1, 12))
    w = draw(st.integers(1, 12))
    density = draw(st.sampled_from([0.0, 0.05, 0.3, 0.7]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    return rng.random((h, w)) >= density


@given(free_grids())
def test_the_table_is_the_largest_free_square_ahead(free):
    got = quadrant_clearance(free).reshape(*free.shape, 4)
    assert got.dtype == np.uint8
    for row in range(free.shape[0]):
        for col in range(free.shape[1]):
            for q, (sx, sy) in enumerate(QUADRANTS):
                assert got[row, col, q] == _brute_side(free, row, col, sx, sy), (row, col, q)


def test_sides_beyond_a_byte_are_clipped_to_255():
    got = quadrant_clearance(np.ones((300, 2), bool)).reshape(300, 2, 4)
    assert got[1, 1, 0] == 2  # two columns: the square is as wide as the floor
    wide = quadrant_clearance(np.ones((300, 300), bool)).reshape(300, 300, 4)
    assert wide[1, 1, 0] == 255  # 300 by hand, stored as 255 (a shorter, still free jump)
    assert wide[298, 298, 3] == 255
    assert wide[299, 299, 0] == 2  # anchored at (298, 298): rows and columns 298, 299 only
    assert wide[0, 0, 0] == 0  # the cell behind is off the array


def test_a_table_of_other_than_two_dimensions_is_refused():
    with pytest.raises(ValueError, match="free"):
        quadrant_clearance(np.ones(5, bool))


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
def test_scans_that_graze_the_jumps_far_sides_equal_the_numpy_path(case):
    pytest.importorskip("numba", reason="the compiled path is the `fast` extra")
    tmap, origins, yaws, angles, max_range = case
    geo = ScanGeometry(tmap)
    general = cast_rays(geo, origins, yaws, angles, max_range, method="array")
    np.testing.assert_array_equal(cast_rays(geo, origins, yaws, angles, max_range, method="numba"), general)
    # The batched kernel, one robot per world (no discs), on the same floor.
    scene = Scene.from_array(np.asarray(tmap.codes), tmap.resolution, origin=tuple(tmap.origin))
    tables = ScanTables([scene], 0, make_arrays("numpy"))
    n = len(origins)
    batched = cast_batch(tables, np.zeros(n, np.int64), origins[:, :1].copy(), origins[:, 1:].copy(),
                         yaws[:, None].copy(), np.ones((n, 1), bool), 0.0, angles, max_range, "numba")
    np.testing.assert_array_equal(batched[:, 0], general)
