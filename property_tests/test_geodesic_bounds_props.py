"""The geodesic layer's bounds on larger random floors: the triangle inequality over three
legs, and the per-step lookup against the exact query within its documented bound.

Floors are 20-60 cells a side with random boxes and long walls with slits (where a sight
bound that misses a slit makes an exact path too long), radius/cell from 0.3 to 5, at
0.05-0.5 m per cell. Points are drawn where the robot's disc fits (the planner's usable
cells, then a random offset inside the cell where the disc still fits).

- ``d(s, g) <= d(s, a) + d(a, b) + d(b, g)`` (1e-6 m), every leg exact;
- the lookup of ``p`` is within ``|p - c| + d(p, c)`` of the exact distance, ``c`` the
  centre of the cell the lookup reads (``geodesic.LOOKUP_BOUND``'s statement in general
  form); at a usable cell's centre the two are equal.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from pairs_geodesic import slit_floors, usable_points


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1))
def test_the_triangle_inequality_over_three_legs(floor, seed) -> None:
    scene, radius = floor
    pts = usable_points(scene, radius, np.random.default_rng(seed), 4)
    assume(len(pts) == 4)
    s, a, b, g = pts

    def d(u, v) -> float:
        return scene.geodesic_distance(0, u, v, robot=radius)

    whole = d(s, g)
    legs = d(s, a) + d(a, b) + d(b, g)
    assume(math.isfinite(legs))
    assert whole <= legs + 1e-6


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1))
def test_the_lookup_is_within_its_bound_of_the_exact_query(floor, seed) -> None:
    scene, radius = floor
    rng = np.random.default_rng(seed)
    pts = usable_points(scene, radius, rng, 25)
    assume(len(pts) > 1)
    tmap = scene.floors[0]
    planner = scene.planner(0, radius)
    field = scene.goal_field(0, pts[0], robot=radius)
    h, w = tmap.shape
    for p in pts[1:]:
        col, row = (int(v) for v in np.floor((p - np.asarray(tmap.origin)) / tmap.resolution))
        i = int(planner.near_usable[row * w + col])
        c = np.asarray(tmap.origin) + (np.array([i % w, i // w]) + 0.5) * tmap.resolution
        exact = field.exact_distance(p)
        lookup = field.distance(*p)
        assert field.distance(*c) == field.exact_distance(c) or math.isclose(field.distance(*c), field.exact_distance(c), abs_tol=1e-9)
        to_c = scene.geodesic_distance(0, p, c, robot=radius)
        if not math.isfinite(to_c):
            continue
        if math.isinf(exact):
            assert math.isinf(lookup)
            continue
        assert abs(lookup - exact) <= math.dist(p, c) + to_c + 1e-9
