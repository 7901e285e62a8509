"""Plain and compiled paths of the exact geodesics: the checks of
``property_tests/test_compiled_paths.py`` for ``geodesic._roots_kernel`` and
``geodesic._search_kernel``, with the random floors and goal fields they draw (shared with
``test_field_roots_props.py`` and ``test_geodesic_bounds_props.py``).

Each check takes ``plain_paths``, the context its plain side runs in (``numpy_paths()``).

- Goal fields of random scenes (cluttered rooms, walled rooms with blocks and a hole, and
  layouts mirrored left-right and/or top-bottom, with the goal on a mirror axis so that
  routes round mirrored corners tie), robot radii 0 and above, and random goals: the batched
  ``GoalField.settle`` makes the one-point decision (``GoalField._best``), and the compiled
  ``_way`` picks its root.
- Larger floors (20-60 cells a side, random boxes and long walls with slits, radius/cell from
  0.3 to 5, 0.05-0.5 m per cell): the compiled goal search equals scipy's, the compiled point
  links the numpy ones, the compiled exact query the one-point search, and the compiled
  point-to-point A* on the whole graph the plain one.
- ``ArcTables`` (the labels grouped by arc) equal, array for array, compiled and not.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable
from contextlib import AbstractContextManager

import numpy as np
from hypothesis import HealthCheck, assume, given, note, settings
from hypothesis import strategies as st

from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.testing.strategies import cluttered_rooms, nav_scenes

Plain = Callable[[], AbstractContextManager[None]]


def cluttered_scenes() -> st.SearchStrategy[Scene]:
    """Walled rooms with up to 20 % obstacle cells, maybe a hole, and a free patch."""
    return cluttered_rooms(max_clutter=0.2)


@st.composite
def mirrored_scenes(draw: st.DrawFn) -> Scene:
    """Random boxes in one half (or quarter) of a room, mirrored onto the rest; an odd side
    puts a row of cell centres on the mirror axis."""
    half_r, half_c = draw(st.integers(5, 13)), draw(st.integers(5, 13))
    rng = np.random.default_rng(draw(st.integers(0, 2**31 - 1)))
    part = np.zeros((half_r, half_c), np.uint8)
    for _ in range(draw(st.integers(1, 4))):
        r, c = rng.integers(1, half_r - 1), rng.integers(1, half_c - 1)
        part[r : r + rng.integers(1, 4), c : c + rng.integers(1, 4)] = OBSTACLE
    grid = part
    if draw(st.booleans()):  # left-right
        mid = np.zeros((half_r, draw(st.integers(0, 1))), np.uint8)
        grid = np.concatenate([grid, mid, grid[:, ::-1]], axis=1)
    if draw(st.booleans()):  # top-bottom
        mid = np.zeros((draw(st.integers(0, 1)), grid.shape[1]), np.uint8)
        grid = np.concatenate([grid, mid, grid[::-1]], axis=0)
    grid = np.pad(grid, 1, constant_values=OBSTACLE)
    return Scene.from_array(grid, 0.1)


def _goal(draw: st.DrawFn, scene: Scene, radius: float) -> np.ndarray:
    """A goal in a usable cell: its centre, a point inside it, or on the map's mirror axes."""
    tmap = scene.floors[0]
    usable = np.argwhere(tmap.usable(radius))
    if not len(usable):
        usable = np.argwhere(np.asarray(tmap.codes) == FREE)
    h, w = tmap.shape
    kind = draw(st.sampled_from(("axis", "centre", "inside")))
    if kind == "axis":
        point = tmap.origin + np.array([w, h]) * tmap.resolution / 2
        if tmap.is_usable(point, radius):
            return point
    r, c = usable[draw(st.integers(0, len(usable) - 1))]
    if kind == "inside":
        fr, fc = draw(st.floats(0.05, 0.95)), draw(st.floats(0.05, 0.95))
        return tmap.grid_to_world(np.array([r + fr, c + fc]))
    return tmap.cell_to_world(np.array([r, c]))


@st.composite
def fields(draw: st.DrawFn):
    """A goal field of a random scene, radius and goal, its table not settled yet."""
    scene = draw(st.one_of(cluttered_scenes(), mirrored_scenes(), nav_scenes()))
    radius = draw(st.one_of(st.just(0.0), st.floats(0.0, 0.2)))
    goal = _goal(draw, scene, radius)
    note(f"grid\n{np.asarray(scene.floors[0].codes)}\nradius {radius!r} goal {goal.tolist()!r}")
    return scene.planner(0, radius).goal_field(goal)


def _one_point(field, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    geo = field.planner.geo
    usable = field.planner.usable.ravel()
    kinds, labels = [], []
    for i in cells.tolist():
        r, c = divmod(i, geo.shape[1])
        _, lab, _ = field._best(geo.origin[0] + (c + 0.5) * geo.resolution, geo.origin[1] + (r + 0.5) * geo.resolution)
        kinds.append(0 if lab == -2 or not usable[i] else 1 if lab == -1 else 2)
        labels.append(max(lab, -1) if usable[i] else -1)
    return np.array(kinds, np.int8), np.array(labels, np.int32)


# 25 examples (53 s at 40 on CI's 2 cores, the suite's third longest).
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(field=fields(), data=st.data(), numpy_paths=st.booleans())
def check_settle(field, data, numpy_paths: bool, plain_paths: Plain) -> None:
    """The numpy path makes the one-point decision exactly, root for root. The compiled path
    rounds its scalar math apart from numpy's array loops in the last bit, so where two roots
    tie it may keep the other: it gives the same value at every centre (1e-9 m). (The
    compiled settle reads the floor's cell links: ``table_roots`` and ``cell_links``.)"""
    n = int(np.prod(field.planner.geo.shape))
    order = data.draw(st.permutations(range(n)))
    cells = np.array(order + order[: data.draw(st.integers(0, 5))], dtype=np.int64)
    with plain_paths() if numpy_paths else contextlib.nullcontext():
        for chunk in np.array_split(cells, data.draw(st.integers(1, 4))):
            kind, label = field.settle(chunk)
    with plain_paths():  # the reference: the one-point query on numpy arrays
        want_kind, want_label = _one_point(field, np.arange(n))
    if numpy_paths:
        assert np.array_equal(kind, want_kind)
        assert np.array_equal(label, want_label)
    assert np.array_equal(kind == 0, want_kind == 0)
    geo = field.planner.geo
    rows, cols = np.divmod(np.arange(n), geo.shape[1])
    xs = geo.origin[0] + (cols + 0.5) * geo.resolution
    ys = geo.origin[1] + (rows + 0.5) * geo.resolution
    for i in np.flatnonzero(kind > 0).tolist():
        got = field.distance(float(xs[i]), float(ys[i]))
        assert abs(got - field.point_distance((xs[i], ys[i]))) <= 1e-9
    note(f"kinds {np.bincount(want_kind, minlength=3).tolist()}")


# 15 examples of 30 points: the suite's longest check (about 2 minutes at 40, 91 s at 25, on
# CI's 2 cores).
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(field=fields(), seed=st.integers(0, 2**31 - 1))
def check_way(field, seed: int, plain_paths: Plain) -> None:
    """``GoalField.path`` starts from ``_way``: compiled, it picks the one-point query's root
    (the same label and departure) wherever two do not tie, and the same cost (1e-9 m)."""
    geo = field.planner.geo
    h, w = geo.shape
    rng = np.random.default_rng(seed)
    points = geo.origin + rng.uniform(0.0, 1.0, (30, 2)) * (w * geo.resolution, h * geo.resolution)
    for x, y in points.tolist():
        cost, label, dep = field._way(x, y)
        with plain_paths():
            want = field._best(x, y)
        assert (label == -2) == (want[1] == -2) and (label == -1) == (want[1] == -1)
        if label == -2:
            continue
        assert abs(cost - want[0]) <= 1e-9
        if label == want[1]:
            assert abs(dep - want[2]) <= 1e-9


@st.composite
def slit_floors(draw: st.DrawFn) -> tuple[Scene, float]:
    """A walled floor of 20-60 cells a side with random boxes and walls with slits, and a radius."""
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


def usable_points(scene: Scene, radius: float, rng: np.random.Generator, n: int) -> list[np.ndarray]:
    """``n`` points where the disc fits: in usable cells, at a random offset (or the centre)."""
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
def check_goal_search(floor, seed, plain_paths: Plain) -> None:
    """A goal field's Dijkstra: numba's seeded heap on the graph built once gives the costs of
    scipy's run on the graph with a source vertex added (the path without numba)."""
    scene, radius = floor
    pts = usable_points(scene, radius, np.random.default_rng(seed), 1)
    assume(len(pts) == 1)
    planner = scene.planner(0, radius)
    graph = planner.arc_graph()
    links = planner.point_links(*pts[0])
    fast = graph.solve(links)
    with plain_paths():
        plain = graph.solve(links)
    assert np.array_equal(np.isfinite(fast.cost), np.isfinite(plain.cost))
    ok = np.isfinite(fast.cost)
    np.testing.assert_allclose(fast.cost[ok], plain.cost[ok], rtol=1e-12, atol=1e-12)


#: Drawn arcs' largest pieces (rad): a robot's path's (2 deg), a pedestrian's (10 deg), and coarser.
PIECES = st.sampled_from([math.radians(2.0), math.radians(10.0), math.radians(30.0), math.pi / 2])


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1), piece=PIECES)
def check_point_search(floor, seed, piece, plain_paths: Plain) -> None:
    """A point-to-point search on the whole graph: the one compiled call
    (``_path_kernel.point_path``, with numba's A*) gives the plain path's reachability,
    lengths (1e-9 m) and drawn points (1e-9 m; where two routes tie and the two paths draw
    different ones, the drawn lengths agree instead)."""
    scene, radius = floor
    planner = scene.planner(0, radius)
    pts = usable_points(scene, radius, np.random.default_rng(seed), 8)
    # Ends where the disc does not fit, and a pair that sees itself.
    pts += [np.asarray(scene.floors[0].origin, dtype=np.float64), pts[0] if pts else np.zeros(2)]
    for a, b in zip(pts[::2], pts[1::2]):
        got_path, got = planner.shortest_path(a, b, piece)
        with plain_paths():
            want_path, want = planner.shortest_path(a, b, piece)
        same_drawn_path(got_path, got, want_path, want)


def same_drawn_path(got_path, got, want_path, want) -> None:
    """Two answers of a shortest-path query agree: reachability, length (1e-9 m), and the
    drawn points (1e-9 m), or where the drawings differ (a tie), their drawn lengths."""
    assert (got is None) == (want is None)
    assert (got_path is None) == (want_path is None)
    if got is None:
        return
    assert abs(got - want) <= 1e-9
    assert np.allclose(got_path[[0, -1]], want_path[[0, -1]], rtol=0, atol=1e-12)
    if got_path.shape == want_path.shape and np.allclose(got_path, want_path, rtol=0, atol=1e-9):
        return
    drawn = [np.hypot(*np.diff(path, axis=0).T).sum() for path in (got_path, want_path)]
    assert abs(drawn[0] - drawn[1]) <= 1e-9, (got_path, want_path)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(res=st.sampled_from([0.05, 0.1]), cells=st.integers(2, 5), seed=st.integers(0, 2**31 - 1), piece=PIECES)
def check_point_search_pinched(res, cells, seed, piece, plain_paths: Plain) -> None:
    """Round a block's corner A whose diagonal neighbour, a wall's corner B, is a hair more
    than one robot diameter away, the path's arc passes B's circle, and its drawn vertices
    there may overlap B. The compiled search hands a path's arcs back to be split where
    they pinch (``arcs.draw_arcs``) exactly when the plain path splits one, and the drawn
    paths are equal."""
    from unittest import mock

    from pointnav_core.geodesic import arc_search, arcs

    grid = np.full((40, 40), FREE, np.uint8)
    grid[11:15, 11:15] = OBSTACLE  # A: the block's top right corner, cell (15, 15)
    grid[15 + cells : 19 + cells, 15 + cells : 23 + cells] = OBSTACLE  # B: cells further on both axes
    radius = cells * res / np.sqrt(2) - 1e-10  # any narrower, and the arc is blocked there
    scene = Scene.from_array(grid, res)
    ax, ay = np.asarray(scene.floors[0].origin) + 15 * res
    planner = scene.planner(0, radius)
    rng = np.random.default_rng(seed)
    split = 0
    for _ in range(6):
        # From left of A, level with its circle's top, to below it, level with its right
        # side: the path wraps A's circle by about a quarter turn, through B's direction.
        a = (ax - rng.uniform(0.05, 0.15), ay + radius * rng.uniform(1.0, 1.2))
        b = (ax + radius * rng.uniform(1.0, 1.2), ay - rng.uniform(0.05, 0.15))
        with mock.patch.object(arc_search, "draw_arcs", wraps=arc_search.draw_arcs) as handed_back:
            got_path, got = planner.shortest_path(a, b, piece)
        with plain_paths(), mock.patch.object(arcs, "_split_pinched", wraps=arcs._split_pinched) as pinched:
            want_path, want = planner.shortest_path(a, b, piece)
        assert handed_back.called == pinched.called
        split += pinched.called
        same_drawn_path(got_path, got, want_path, want)
    note(f"{split} of 6 paths split")


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1))
def check_arc_tables(floor, seed, plain_paths: Plain) -> None:
    """``ArcTables``: the compiled counting sort gives the numpy path's arrays, dtype and all,
    for goal fields that reach all, some or none of the floor."""
    from pointnav_core.geodesic.roots import ArcTables

    scene, radius = floor
    planner = scene.planner(0, radius)
    for p in usable_points(scene, radius, np.random.default_rng(seed), 3):
        search = planner.goal_field(p).labels
        fast = ArcTables(planner, search)
        with plain_paths():
            plain = ArcTables(planner, search)
        for name in ("labels", "start", "graph_end", "cheapest", "by_cheap"):
            got, want = getattr(fast, name), getattr(plain, name)
            assert got.dtype == want.dtype, name
            np.testing.assert_array_equal(got, want, err_msg=name)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1))
def check_point_links(floor, seed, plain_paths: Plain) -> None:
    """``Planner.point_links``: the compiled tangents (after the sight profile's cut) are the
    numpy path's, node for node, in order."""
    scene, radius = floor
    planner = scene.planner(0, radius)
    for p in usable_points(scene, radius, np.random.default_rng(seed), 5):
        fast = planner.point_links(*p)
        with plain_paths():
            plain = planner.point_links(*p)
        assert [(n, s) for n, s, _, _ in fast] == [(n, s) for n, s, _, _ in plain]
        np.testing.assert_allclose([v[2:] for v in fast], [v[2:] for v in plain], rtol=0, atol=1e-12)


# 20 examples (36 s at 30 on CI's 2 cores).
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(floor=slit_floors(), seed=st.integers(0, 2**31 - 1))
def check_exact_query(floor, seed, plain_paths: Plain) -> None:
    """``GoalField.point_distance`` (compiled with numba) gives ``_best``'s value (the one-point
    query on numpy arrays) within 1e-9 m, at random points, reachable or not."""
    scene, radius = floor
    pts = usable_points(scene, radius, np.random.default_rng(seed), 12)
    assume(len(pts) > 1)
    field = scene.goal_field(0, pts[0], robot=radius).field
    for p in pts[1:]:
        fast = field.point_distance(p)
        with plain_paths():
            plain = field.point_distance(p)
        assert fast == plain or abs(fast - plain) <= 1e-9
