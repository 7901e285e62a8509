"""The swept-disc cell test: the compiled path equals the numpy path.

For random grids (random blocked cells, outside blocked or not), radii (0 included) and
segments of every kind (points, axis-aligned, on grid lines, crossing the map's edge, far
off it), :meth:`pointnav_core.floor.collision.FloorCollision.segments_clear` answers the same
with its numba kernel as with its numpy arrays (the ``fast`` extra's path and the path
without it). So does the one-segment call, :meth:`FloorCollision.segment_clear`. The numpy path itself is checked against shapely in
``property_tests/test_geometry_agreement.py`` and ``tests/test_collision.py``.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pointnav_core.floor.collision import FloorCollision
from pointnav_core.utils.compiled import kernel, numpy_paths

pytest.importorskip("numba")


@settings(max_examples=80, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    rows=st.integers(1, 40),
    cols=st.integers(1, 40),
    density=st.floats(0.0, 0.5),
    radius=st.one_of(st.just(0.0), st.floats(0.0, 0.6)),
    resolution=st.sampled_from([0.05, 0.1, 0.5]),
    outside_blocked=st.booleans(),
    n=st.integers(1, 60),
)
def test_compiled_cell_test_equals_the_numpy_path(
    seed: int, rows: int, cols: int, density: float, radius: float, resolution: float, outside_blocked: bool, n: int
) -> None:
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
    with numpy_paths():
        assert kernel("pointnav_core.floor._collision_kernel", "cells_hit") is None
        want = geo.segments_clear(a, b, radius)
    np.testing.assert_array_equal(got, want)
    assert kernel("pointnav_core.floor._collision_kernel", "cells_hit") is not None
    # The one-segment call (planners' and worlds' point tests), compiled and not.
    pairs = list(zip(a.tolist(), b.tolist()))
    one = np.array([geo.segment_clear(*p, *q, radius) for p, q in pairs])
    with numpy_paths():
        plain = np.array([geo.segment_clear(*p, *q, radius) for p, q in pairs])
    np.testing.assert_array_equal(one, want)
    np.testing.assert_array_equal(plain, want)
