"""The free squares ahead (``sensors.clearance``) and the compiled walks that jump over them.

The table is checked against a brute-force search for the largest free square, cell by
cell; ``open_radius`` against shapely's distance from points of each cell to the blocked
cells' squares. (The walks' jumps end just before a free square's far side, so the rays
that matter are those that run within ``TOUCH_EPS`` of a grid line: the compiled scans
equal the array path there too, ``check_grazing_scans`` in ``tests/pairs_scan.py``, run by
``property_tests/test_compiled_paths.py``.)
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st

from pointnav_core.sensors.clearance import QUADRANTS, open_radius, quadrant_clearance


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


@given(free_grids(), st.integers(0, 2**32 - 1))
def test_no_point_of_a_cell_is_nearer_a_blocked_cell_than_its_open_radius(free, seed):
    got = open_radius(free)
    assert got.shape == free.shape
    blocked = [shapely.box(c, r, c + 1, r + 1) for r, c in zip(*np.nonzero(~free))]
    if not blocked:
        assert np.isinf(got).all()
        return
    walls = shapely.union_all(blocked)
    rng = np.random.default_rng(seed)
    for row in range(free.shape[0]):
        for col in range(free.shape[1]):
            # The cell's corners and random points in it (cell units, x = column).
            pts = np.vstack([[[0, 0], [0, 1], [1, 0], [1, 1]], rng.random((6, 2))]) + [col, row]
            nearest = shapely.distance(shapely.points(pts), walls).min()
            assert got[row, col] <= nearest + 1e-12, (row, col)
            # Not loose by more than a diagonal (the centre is no farther than the blocked centre).
            assert got[row, col] >= nearest - np.sqrt(2.0) - 1e-12, (row, col)
