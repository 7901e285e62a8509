"""The tangent graph's sight bounds: the compiled ray march equals the numpy one.

For random floors (random blocked cells, sometimes a closed outside), robot radii, points
anywhere on and off the map and ray counts, :func:`pointnav_core.tangent_edges.sight_radii`
gives the same bounds, bit for bit, with its numba kernel and with its numpy loop (the
``fast`` extra's path and the path without it).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

from pointnav_core import tangent_edges
from pointnav_core._compiled import kernel, numpy_paths

pytest.importorskip("numba")


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    rows=st.integers(1, 60),
    cols=st.integers(1, 60),
    density=st.floats(0.0, 0.6),
    radius=st.floats(0.0, 0.5),
    resolution=st.sampled_from([0.05, 0.1, 0.25]),
    n_points=st.integers(0, 40),
    n_rays=st.integers(1, 48),
)
def test_compiled_sight_radii_equal_the_numpy_loop(
    seed: int, rows: int, cols: int, density: float, radius: float, resolution: float, n_points: int, n_rays: int
) -> None:
    rng = np.random.default_rng(seed)
    blocked = np.pad(rng.random((rows, cols)) < density, 1, constant_values=bool(rng.random() < 0.5))
    edt = ndimage.distance_transform_edt(~blocked)
    origin = (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)))
    # Points on the map, on cell edges, and off it.
    xs = origin[0] + rng.uniform(-0.2, 1.2, n_points) * cols * resolution
    ys = origin[1] + rng.uniform(-0.2, 1.2, n_points) * rows * resolution
    xs[: n_points // 4] = origin[0] + np.round(xs[: n_points // 4] - origin[0], 1)
    assert kernel("pointnav_core._sight_kernel", "march") is not None
    got = tangent_edges.sight_radii(edt, xs, ys, origin, resolution, radius, n_rays)
    with numpy_paths():
        assert kernel("pointnav_core._sight_kernel", "march") is None
        want = tangent_edges.sight_radii(edt, xs, ys, origin, resolution, radius, n_rays)
    np.testing.assert_array_equal(got, want)
    assert got.shape == (n_points,) and not np.isnan(got).any()
    # Every bound covers at least the two cells added to the longest ray.
    assert (got >= 2.0 * resolution - 1e-12).all() or not n_points
    assert math.isfinite(float(got.sum()))


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
def test_compiled_fully_blocked_samples_equal_the_numpy_ones(
    seed: int, rows: int, cols: int, density: float, radius: float, resolution: float, outside: bool,
    n_segments: int, step: float,
) -> None:
    """``_misses_full`` (the cheap rejection of candidate tangent segments) gives the same
    answer, segment by segment, with its numba kernel and with its numpy samples, for
    segments on and off the map, of zero length, along cell edges and across the map."""
    from pointnav_core.collision import FloorCollision
    from pointnav_core.tangent_graph import Planner

    rng = np.random.default_rng(seed)
    blocked = rng.random((rows, cols)) < density
    origin = (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)))
    geo = FloorCollision(blocked, resolution, origin, outside_blocked=outside)
    planner = Planner(geo, radius)
    lo = np.array(origin) - 0.2 * np.array([cols, rows]) * resolution
    hi = np.array(origin) + 1.2 * np.array([cols, rows]) * resolution
    a = rng.uniform(lo, hi, (n_segments, 2))
    b = rng.uniform(lo, hi, (n_segments, 2))
    b[: n_segments // 5] = a[: n_segments // 5]  # zero length
    # Along a row of cell edges.
    k = slice(n_segments // 5, 2 * n_segments // 5)
    a[k, 1] = b[k, 1] = origin[1] + resolution * rng.integers(0, rows + 1, len(a[k]))
    assert kernel("pointnav_core._sight_kernel", "misses_full") is not None
    got = tangent_edges._misses_full(planner, a, b, step)
    with numpy_paths():
        want = tangent_edges._misses_full(planner, a, b, step)
    np.testing.assert_array_equal(got, want)
    assert got.dtype == np.bool_ and got.shape == (n_segments,)
    # A segment with an end in a fully blocked cell (or off a closed map) is rejected.
    full = planner.fully_blocked_mask()
    col = np.floor((a[:, 0] - origin[0]) / resolution).astype(np.int64) + 1
    row = np.floor((a[:, 1] - origin[1]) / resolution).astype(np.int64) + 1
    on = (col >= 0) & (col < full.shape[1]) & (row >= 0) & (row < full.shape[0])
    end_bad = np.where(on, full[np.clip(row, 0, full.shape[0] - 1), np.clip(col, 0, full.shape[1] - 1)], outside)
    assert not (got & end_bad).any()
