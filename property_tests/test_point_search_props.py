"""The point-to-point search on the whole graph (the fast path) against the lazy search that
builds edges tile by tile (the general path), and the batched arc drawing against arcs drawn
one by one."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pointnav_core.geodesic import Planner
from pointnav_core.geodesic.arcs import arc_points, draw_arcs
from tests.pairs_geodesic import PIECES, slit_floors, usable_points

SLOW = [HealthCheck.too_slow, HealthCheck.filter_too_much]


@settings(max_examples=40, deadline=None, suppress_health_check=SLOW)
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1), piece=PIECES)
def test_whole_graph_search_equals_the_lazy_search(floor, seed, piece) -> None:
    """Same reachability and lengths within 1e-9 m; both drawn paths join the same ends and
    are no shorter than the length (arcs are drawn outside their circles), nor longer than
    it over the cosine of half a ``piece`` (each drawn arc's factor)."""
    scene, radius = floor
    pts = usable_points(scene, radius, np.random.default_rng(seed), 10)
    fast = scene.planner(0, radius)
    # A planner of its own, that never searches the whole graph.
    lazy = Planner(fast.geo, radius)
    lazy.whole_graph_search = False
    for a, b in zip(pts[::2], pts[1::2]):
        got_path, got = fast.shortest_path(a, b, piece)
        want_path, want = lazy.shortest_path(a, b, piece)
        assert (got is None) == (want is None)
        if got is None:
            continue
        assert abs(got - want) <= 1e-9 * max(1.0, want)
        for path in (got_path, want_path):
            assert np.allclose(path[0], a) and np.allclose(path[-1], b)
            steps = np.diff(path, axis=0)
            drawn = np.hypot(steps[:, 0], steps[:, 1]).sum()
            assert got - 1e-9 <= drawn <= got / np.cos(piece / 2) + 1e-9


@settings(max_examples=40, deadline=None, suppress_health_check=SLOW)
@given(floor=slit_floors(), data=st.data(), piece=PIECES)
def test_arcs_drawn_together_equal_arcs_drawn_one_by_one(floor, data, piece) -> None:
    """One clearance test for a path's arcs gives the points of one test per arc, including
    the arcs split where a passage is as wide as the robot."""
    scene, radius = floor
    planner = scene.planner(0, radius)
    if not planner.n_nodes:
        return
    arcs = []
    for _ in range(data.draw(st.integers(1, 6))):
        node = data.draw(st.integers(0, planner.n_nodes - 1))
        span = float(planner.span[node])
        lo, hi = sorted(data.draw(st.floats(0.0, span)) for _ in range(2))
        arcs.append((node, data.draw(st.sampled_from((1, -1))), hi, lo))
    want = np.array([q for node, s, a, b in arcs for q in arc_points(planner, node, s, a, b, piece=piece)])
    assert np.array_equal(draw_arcs(planner, arcs, piece), want)
