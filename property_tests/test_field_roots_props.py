"""Settling a goal field's cells in batches makes exactly the one-point decision.

For random grid scenes (cluttered rooms, walled rooms with blocks and a hole, and layouts
mirrored left-right and/or top-bottom, with the goal on a mirror axis so that routes
round mirrored corners tie), robot radii 0 and above, and random goals,
``GoalField.settle`` gives every cell of the map (its blocks in a random order, some twice)
exactly the kind and label that the one-point exact query (``GoalField._best``) picks at
the cell's centre; with numba's kernels and on their numpy paths alike.

The floor's cell links (:class:`pointnav_core.geodesic.cell_links.CellLinks`: every usable
cell centre's clear links, found once per floor) give, through ``roots.table_roots``, exactly
the kinds, labels and distances of ``roots.compiled_roots``, which tests each candidate
link's segment itself; each cell's links are those the one-point query finds.
"""

from __future__ import annotations

import contextlib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st

from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.geodesic import roots
from pointnav_core.geodesic.cell_links import CellLinks, cell_centres
from pointnav_core.scenes import Scene
from pointnav_core.testing.strategies import cluttered_rooms, nav_scenes
from pointnav_core.utils import compiled as _compiled


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


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(field=fields(), data=st.data(), numpy_paths=st.booleans())
def test_batched_settle_equals_the_one_point_query(field, data, numpy_paths: bool) -> None:
    """The numpy path makes the one-point decision exactly, root for root. The compiled path
    rounds its scalar math apart from numpy's array loops in the last bit, so where two roots
    tie it may keep the other: it gives the same value at every centre (1e-9 m)."""
    n = int(np.prod(field.planner.geo.shape))
    order = data.draw(st.permutations(range(n)))
    cells = np.array(order + order[: data.draw(st.integers(0, 5))], dtype=np.int64)
    with _compiled.numpy_paths() if numpy_paths else contextlib.nullcontext():
        for chunk in np.array_split(cells, data.draw(st.integers(1, 4))):
            kind, label = field.settle(chunk)
    with _compiled.numpy_paths():  # the reference: the one-point query on numpy arrays
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


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(field=fields())
def test_roots_from_cell_links_equal_the_roots_found_link_by_link(field) -> None:
    pytest.importorskip("numba")
    p = field.planner
    if not p.n_nodes or not field.goal_usable:
        return
    links = CellLinks.build(p)
    cells = np.flatnonzero(p.usable.ravel())
    xs, ys = cell_centres(p, cells)
    tables = field.arc_tables()
    got = roots.table_roots(field, tables, links, cells, xs, ys)
    want = roots.compiled_roots(field, tables, xs, ys)
    for a, b in zip(got, want):
        np.testing.assert_array_equal(a, b)
    # Every link is clear and lands on its node's arc: the same links the one-point query
    # finds (Planner.point_links), in a cell's order.
    for i in cells[:: max(1, len(cells) // 25)].tolist():
        x, y = cell_centres(p, np.array([i]))
        lo, n = links.first[i], links.count[i]
        mine = sorted(zip(links.node[lo : lo + n].tolist(), (1 - 2 * links.side[lo : lo + n]).tolist()))
        theirs = sorted((c, s) for c, s, _, _ in p.point_links(float(x[0]), float(y[0])))
        assert mine == theirs


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(field=fields(), seed=st.integers(0, 2**31 - 1))
def test_compiled_way_equals_the_one_point_query(field, seed: int) -> None:
    """``GoalField.path`` starts from ``_way``: compiled, it picks the one-point query's root
    (the same label and departure) wherever two do not tie, and the same cost (1e-9 m)."""
    pytest.importorskip("numba")
    geo = field.planner.geo
    h, w = geo.shape
    rng = np.random.default_rng(seed)
    points = geo.origin + rng.uniform(0.0, 1.0, (30, 2)) * (w * geo.resolution, h * geo.resolution)
    for x, y in points.tolist():
        cost, label, dep = field._way(x, y)
        with _compiled.numpy_paths():
            want = field._best(x, y)
        assert (label == -2) == (want[1] == -2) and (label == -1) == (want[1] == -1)
        if label == -2:
            continue
        assert abs(cost - want[0]) <= 1e-9
        if label == want[1]:
            assert abs(dep - want[2]) <= 1e-9
