"""The tangent graph's sight bounds are strict.

No clear tangent edge between two nodes is longer than either node's sight, nor than its
sight profile in the edge's direction, checked by brute force over every pair of nodes with
the exact clearance test and no sight filter at all. (The compiled sight rays and the
compiled rejection of candidate segments equal their plain paths:
``property_tests/test_compiled_paths.py``, checks in ``tests/pairs_floor.py``.)
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pairs_floor import floor_collision

from pointnav_core.geodesic import sight
from pointnav_core.geodesic.planner import Planner

pytest.importorskip("numba")


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
    geo = floor_collision(seed, rows, cols, density, resolution, True)
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
