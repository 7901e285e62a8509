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

from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene


@st.composite
def slit_floors(draw: st.DrawFn) -> tuple[Scene, float]:
    h, w = draw(st.integers(20, 60)), draw(st.integers(20, 60))
    res = draw(st.sampled_from([0.05, 0.1, 0.25, 0.5]))
    radius = draw(st.floats(0.3, 5.0)) * res
    rng = np.random.default_rng(draw(st.integers(0, 2**31 - 1)))
    grid = np.zeros((h, w), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    for _ in range(draw(st.integers(0, 12))):
        r, c = rng.integers(1, h - 2), rng.integers(1, w - 2)
        grid[r : r + rng.integers(1, 4), c : c + rng.integers(1, 4)] = OBSTACLE
    for _ in range(draw(st.integers(0, 3))):  # a wall with slits one to four cells wide
        if rng.random() < 0.5:
            at = rng.integers(2, h - 2)
            grid[at, :] = OBSTACLE
            for _ in range(rng.integers(1, 3)):
                c = rng.integers(1, w - 5)
                grid[at, c : c + rng.integers(1, 5)] = 0
        else:
            at = rng.integers(2, w - 2)
            grid[:, at] = OBSTACLE
            for _ in range(rng.integers(1, 3)):
                r = rng.integers(1, h - 5)
                grid[r : r + rng.integers(1, 5), at] = 0
    return Scene.from_array(grid, res), radius


def _points(scene: Scene, radius: float, rng: np.random.Generator, n: int) -> list[np.ndarray]:
    planner = scene.planner(0, radius)
    cells = np.argwhere(planner.usable)
    if not len(cells):
        return []
    res, origin = scene.floors[0].resolution, np.asarray(scene.floors[0].origin)
    out = []
    for r, c in cells[rng.integers(len(cells), size=n)]:
        p = origin + (np.array([c, r]) + rng.uniform(0.02, 0.98, 2)) * res
        out.append(p if planner.is_clear(*p) else origin + (np.array([c, r]) + 0.5) * res)
    return out


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1))
def test_the_triangle_inequality_over_three_legs(floor, seed) -> None:
    scene, radius = floor
    pts = _points(scene, radius, np.random.default_rng(seed), 4)
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
    pts = _points(scene, radius, rng, 25)
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


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1))
def test_the_compiled_goal_search_equals_scipys(floor, seed) -> None:
    """A goal field's Dijkstra: numba's seeded heap on the graph built once gives the costs of
    scipy's run on the graph with a source vertex added (the path without numba)."""
    import pytest

    from pointnav_core.utils import compiled as _compiled

    pytest.importorskip("numba")
    scene, radius = floor
    pts = _points(scene, radius, np.random.default_rng(seed), 1)
    assume(len(pts) == 1)
    planner = scene.planner(0, radius)
    graph = planner.arc_graph()
    links = planner.point_links(*pts[0])
    fast = graph.solve(links)
    with _compiled.numpy_paths():
        plain = graph.solve(links)
    assert np.array_equal(np.isfinite(fast.cost), np.isfinite(plain.cost))
    ok = np.isfinite(fast.cost)
    np.testing.assert_allclose(fast.cost[ok], plain.cost[ok], rtol=1e-12, atol=1e-12)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1))
def test_the_compiled_point_links_equal_the_numpy_ones(floor, seed) -> None:
    """``Planner.point_links``: the compiled tangents (after the sight profile's cut) are the
    numpy path's, node for node, in order."""
    import pytest

    from pointnav_core.utils import compiled as _compiled

    pytest.importorskip("numba")
    scene, radius = floor
    planner = scene.planner(0, radius)
    for p in _points(scene, radius, np.random.default_rng(seed), 5):
        fast = planner.point_links(*p)
        with _compiled.numpy_paths():
            plain = planner.point_links(*p)
        assert [(n, s) for n, s, _, _ in fast] == [(n, s) for n, s, _, _ in plain]
        np.testing.assert_allclose([v[2:] for v in fast], [v[2:] for v in plain], rtol=0, atol=1e-12)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1))
def test_the_compiled_exact_query_equals_the_one_point_search(floor, seed) -> None:
    """``GoalField.point_distance`` (compiled with numba) gives ``_best``'s value (the one-point
    query on numpy arrays) within 1e-9 m, at random points, reachable or not."""
    import pytest

    from pointnav_core.utils import compiled as _compiled

    pytest.importorskip("numba")
    scene, radius = floor
    pts = _points(scene, radius, np.random.default_rng(seed), 12)
    assume(len(pts) > 1)
    field = scene.goal_field(0, pts[0], robot=radius).field
    for p in pts[1:]:
        fast = field.point_distance(p)
        with _compiled.numpy_paths():
            plain = field.point_distance(p)
        assert fast == plain or abs(fast - plain) <= 1e-9


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1))
def test_the_landmark_bounds_hold_the_exact_geodesic(floor, seed) -> None:
    """``Scene.geodesic_bounds`` (ALT landmarks): ``lower <= d(a, b) <= upper`` for the exact
    A* geodesic, at cell centres and off them, reachable or not."""
    scene, radius = floor
    pts = _points(scene, radius, np.random.default_rng(seed), 10)
    assume(len(pts) > 1)
    planner = scene.planner(0, radius)
    for a, b in zip(pts[:-1], pts[1:]):
        lower, upper = scene.geodesic_bounds(0, a, b, robot=radius)
        _, exact = planner.shortest_path(a, b)  # one A* search, no goal field and no landmark
        exact = math.inf if exact is None else exact
        assert lower <= exact <= upper or (math.isinf(exact) and math.isinf(upper))


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(
    floor=slit_floors(),
    seed=st.integers(0, 2**31 - 1),
    low=st.floats(0.0, 3.0),
    span=st.floats(0.5, 6.0),
)
def test_sampling_draws_the_same_episodes_with_and_without_landmark_bounds(floor, seed, low, span) -> None:
    """The sampler's landmark rejection is a fast path: with the bounds answering ``(0, inf)``
    (no rejection before the exact geodesic) the same seed draws the same episodes, or
    fails with the same error."""
    import gymnasium as gym

    from pointnav_core.errors import SamplingError

    scene, radius = floor
    plain = Scene(scene.floors)
    plain.geodesic_bounds = lambda *args, **kwargs: (0.0, math.inf)  # type: ignore[method-assign]
    task = {"path_range": (low, low + span)}
    runs = []
    for sc in (scene, plain):
        env = gym.make("pointnav_core/PointNav-v0", scene=sc, task=task, robot={"radius": radius})
        out = []
        try:
            env.reset(seed=seed)
            for _ in range(5):
                t = env.unwrapped.task
                out.append((tuple(t.get_start_pos()[:2].tolist()), tuple(t.goal_xy), t.geodesic_dist))
                env.reset()
        except SamplingError as err:
            out.append(str(err))
        runs.append(out)
    assert runs[0] == runs[1]
