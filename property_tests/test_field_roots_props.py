"""Settling a goal field's cells in batches makes exactly the one-cell decision.

For random grid scenes (cluttered rooms, walled rooms with blocks and a hole, and layouts
mirrored left-right and/or top-bottom, with the goal on a mirror axis so that routes
round mirrored corners tie), robot radii 0 and above, and random goals,
``GoalField._settle_cells`` gives every cell of the map (in a random order, some twice)
exactly the kind and label that ``GoalField._settle_cell`` gives it one call at a time on
a copy of the same table; with numba's kernels and on their numpy paths alike. The
reference is the one-point code the lazy single-env lookup uses.
"""

from __future__ import annotations

import contextlib

import numpy as np
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st

from pointnav_core import _compiled
from pointnav_core.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.testing.strategies import cluttered_rooms, nav_scenes


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
    """A goal field of a random scene, radius and goal, with its proposed (unsettled) table."""
    scene = draw(st.one_of(cluttered_scenes(), mirrored_scenes(), nav_scenes()))
    radius = draw(st.one_of(st.just(0.0), st.floats(0.0, 0.2)))
    goal = _goal(draw, scene, radius)
    note(f"grid\n{np.asarray(scene.floors[0].codes)}\nradius {radius!r} goal {goal.tolist()!r}")
    field = scene.planner(0, radius).goal_field(goal)
    field._build_table()
    return field


def _one_by_one(field, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    t = field._table
    for i in cells.tolist():
        field._settle_cell(int(i))
    return t["kind"].copy(), t["label"].copy()


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(field=fields(), data=st.data(), numpy_paths=st.booleans())
def test_batched_settle_equals_one_cell_at_a_time(field, data, numpy_paths: bool) -> None:
    t = field._table
    n = len(t["kind"])
    order = data.draw(st.permutations(range(n)))
    cells = np.array(order + order[: data.draw(st.integers(0, 5))], dtype=np.int64)
    before = {k: v.copy() for k, v in t.items() if isinstance(v, np.ndarray)}
    with _compiled.numpy_paths() if numpy_paths else contextlib.nullcontext():
        kinds = field._settle_cells(cells)
        got_kind, got_label = t["kind"].copy(), t["label"].copy()
        t.update({k: v.copy() for k, v in before.items()})
        want_kind, want_label = _one_by_one(field, cells)
    assert np.array_equal(got_kind, want_kind)
    assert np.array_equal(got_label, want_label)
    assert np.array_equal(kinds, want_kind[cells])
    note(f"kinds {np.bincount(want_kind, minlength=3).tolist()}")


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(field=fields())
def test_batched_settle_of_the_left_over_cells_equals_the_lazy_lookup(field) -> None:
    """After every block is checked, the cells left without a root (kind 3) settle alike."""
    from pointnav_core.tangent_field import _BLOCK

    t = field._table
    h, w = field.planner.geo.shape
    for r0 in range(0, h, _BLOCK):
        for c0 in range(0, w, _BLOCK):
            field._check_block(r0 * w + c0)
    cells = np.flatnonzero(t["kind"] == 3)
    before = {k: v.copy() for k, v in t.items() if isinstance(v, np.ndarray)}
    field._settle_cells(cells)
    got_kind, got_label = t["kind"].copy(), t["label"].copy()
    t.update({k: v.copy() for k, v in before.items()})
    want_kind, want_label = _one_by_one(field, cells)
    assert np.array_equal(got_kind, want_kind)
    assert np.array_equal(got_label, want_label)
