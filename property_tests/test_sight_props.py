"""The tangent graph's sight bounds: strict, and the compiled rays equal the plain ones.

- For random floors (random blocked cells, sometimes an open outside), robot radii and cell
  sizes, :func:`pointnav_core.geodesic.sight.node_sights` gives the same bounds, bit for
  bit, with numba and as plain Python (the ``fast`` extra's path and the path without it).
- The bounds are strict: no clear tangent edge between two nodes is longer than either
  node's sight, nor than its sight profile in the edge's direction, checked by brute force
  over every pair of nodes with the exact clearance test and no sight filter at all.
- ``_misses_full`` (the cheap rejection of candidate tangent segments) gives the same answer
  with its numba kernel and with its numpy samples.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pointnav_core.floor.collision import FloorCollision
from pointnav_core.geodesic import edges, sight
from pointnav_core.geodesic.planner import Planner
from pointnav_core.utils.compiled import kernel, numpy_paths

pytest.importorskip("numba")


def _floor(seed: int, rows: int, cols: int, density: float, resolution: float, outside: bool) -> FloorCollision:
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
def test_compiled_sights_equal_the_plain_rays(seed, rows, cols, density, radius, resolution, outside) -> None:
    geo = _floor(seed, rows, cols, density, resolution, outside)
    planner = Planner(geo, radius)
    assert kernel("pointnav_core.geodesic._sight_kernel", "sight_rays") is not None
    got, got_profile = sight.node_sights(geo, planner.radius, planner.cx, planner.cy, planner.phi0, planner.span)
    with numpy_paths():
        assert kernel("pointnav_core.geodesic._sight_kernel", "sight_rays") is None
        want, want_profile = sight.node_sights(geo, planner.radius, planner.cx, planner.cy, planner.phi0, planner.span)
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(got_profile, want_profile)
    assert (got > 0).all() and (got_profile.max(axis=1) >= got * (1 - 1e-6)).all()


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    rows=st.integers(3, 24),
    cols=st.integers(3, 24),
    density=st.floats(0.02, 0.3),
    ratio=st.floats(0.3, 5.0),
    resolution=st.sampled_from([0.05, 0.1, 0.5]),
)
def test_no_clear_edge_is_longer_than_either_nodes_sight(seed, rows, cols, density, ratio, resolution) -> None:
    """Brute force: every common tangent of every pair of nodes whose segment the exact test
    finds clear is no longer than both nodes' sights (the bound the edge search relies on)."""
    geo = _floor(seed, rows, cols, density, resolution, True)
    radius = ratio * resolution
    p = Planner(geo, radius)
    if p.n_nodes < 2:
        return
    a, b = np.meshgrid(np.arange(p.n_nodes), np.arange(p.n_nodes), indexing="ij")
    a, b = a.ravel(), b.ravel()
    keep = a != b
    a, b = a[keep], b[keep]
    dx, dy = p.cx[b] - p.cx[a], p.cy[b] - p.cy[a]
    dist = np.hypot(dx, dy)
    base = np.arctan2(dy, dx)
    r = p.radius
    for s in (1, -1):
        for sb in (s, -s):
            if sb == s:
                heading, ok, length = base, dist > 0, dist
            else:
                ok = dist > 2 * r
                heading = base + s * np.arcsin(np.clip(2 * r / np.where(ok, dist, 1.0), -1, 1))
                length = np.sqrt(np.maximum(dist**2 - 4 * r * r, 0))
            dep, arr = heading - s * math.pi / 2, heading - sb * math.pi / 2
            on_a = np.mod(dep - p.phi0[a], 2 * math.pi) <= p.span[a] + 1e-9
            on_b = np.mod(arr - p.phi0[b], 2 * math.pi) <= p.span[b] + 1e-9
            k = np.flatnonzero(ok & on_a & on_b)
            pa = np.stack([p.cx[a[k]] + r * np.cos(dep[k]), p.cy[a[k]] + r * np.sin(dep[k])], 1)
            pb = np.stack([p.cx[b[k]] + r * np.cos(arr[k]), p.cy[b[k]] + r * np.sin(arr[k])], 1)
            clear = geo.segments_clear(pa, pb, r)
            k, pa, pb = k[clear], pa[clear], pb[clear]
            assert (length[k] <= p.sights[a[k]] + 1e-9).all()
            assert (length[k] <= p.sights[b[k]] + 1e-9).all()
            # ... and no longer than either node's profile in its direction of departure.
            assert not sight.blocked_by_profile(p.sight_profile, a[k], *(pb - pa).T).any()
            assert not sight.blocked_by_profile(p.sight_profile, b[k], *(pa - pb).T).any()


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
    rng = np.random.default_rng(seed)
    geo = _floor(seed, rows, cols, density, resolution, outside)
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
    with numpy_paths():
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
