"""Settling goal-field cells in batches: a hand-made room, a cluttered map, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pointnav_core.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.tangent_field import _BLOCK
from pointnav_core.vector.fields import settle

RES = 0.1


def _room() -> Scene:
    """A walled 21 x 21 room of 0.1 m cells: a 3 x 3 block in the middle (x, y in [0.9, 1.2]
    m) and a sealed pocket of cells (rows 1-3, columns 17-19) in a corner."""
    grid = np.zeros((21, 21), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[9:12, 9:12] = OBSTACLE
    grid[4, 16:] = OBSTACLE
    grid[:5, 16] = OBSTACLE
    return Scene.from_array(grid, RES)


def _cell(row: int, col: int) -> int:
    return row * 21 + col


def _centre(row: int, col: int) -> tuple[float, float]:
    return ((col + 0.5) * RES, (row + 0.5) * RES)


def test_hand_made_room_by_hand_and_cell_by_cell() -> None:
    goal = _centre(10, 3)  # (0.35, 1.05), left of the block on its mirror axis
    field = _room().planner(0, 0.0).goal_field(goal)
    t = field._build_table()
    behind, seen, block, pocket = _cell(10, 17), _cell(10, 1), _cell(10, 10), _cell(2, 18)
    cells = np.array([behind, seen, block, pocket])
    kinds = field._settle_cells(cells)
    assert kinds.tolist() == [2, 1, 0, 0]
    assert t["label"][cells].tolist()[1:] == [-1, -1, -1]
    # Behind the block: round one of its near corners, along its 0.3 m side, to the goal;
    # both ways tie by symmetry (a point robot plans as a 1e-6 m disc).
    node = int(field._search.node[t["label"][behind]])
    corner = (float(field.planner.cx[node]), float(field.planner.cy[node]))
    assert min(math.dist(corner, c) for c in ((1.2, 1.2), (1.2, 0.9))) < 1e-9
    x, y = _centre(10, 17)
    by_hand = 2 * math.hypot(1.75 - 1.2, 1.2 - 1.05) + 0.3
    assert field.distance(x, y) == pytest.approx(by_hand, abs=1e-5)
    # The same decisions, one cell at a time.
    batched = t["kind"].copy(), t["label"].copy()
    for i in cells.tolist():
        field._settle_cell(i)
    assert np.array_equal(batched[0], t["kind"]) and np.array_equal(batched[1], t["label"])


def test_settle_of_a_cluttered_map_equals_the_lazy_lookup() -> None:
    rng = np.random.default_rng(1)
    grid = np.zeros((60, 60), np.uint8)
    for _ in range(10):
        r, c = rng.integers(0, 50, 2)
        h, w = rng.integers(2, 10, 2)
        grid[r : r + h, c : c + w] = OBSTACLE
    scene = Scene.from_array(grid, RES)
    goal = scene.get_random_point(0, robot=0.18, rng=np.random.default_rng(1))[1][:2]
    lazy = Scene.from_array(grid, RES).planner(0, 0.18).goal_field(goal)
    t = lazy._build_table()
    h, w = grid.shape
    for r0 in range(0, h, _BLOCK):
        for c0 in range(0, w, _BLOCK):
            lazy._check_block(r0 * w + c0)
    left = np.flatnonzero(t["kind"] == 3)
    assert len(left) > 50  # the map leaves cells to settle exactly
    for i in left.tolist():
        lazy._settle_cell(i)
    settled = settle(scene.planner(0, 0.18).goal_field(goal))
    assert not np.isin(settled["kind"], (3, 4)).any()
    assert np.array_equal(settled["kind"], t["kind"])
    assert np.array_equal(settled["label"], t["label"])


@pytest.mark.parametrize(
    "cells, match",
    [
        (np.zeros((2, 2), np.int64), "cells must be a 1D array"),
        (np.array([1.0, 2.0]), "cells must be a 1D array of integer"),
        (np.array([0, 21 * 21]), r"cells must lie in \[0, 441\)"),
        (np.array([-1]), r"cells must lie in \[0, 441\)"),
    ],
)
def test_settle_cells_rejects_bad_cells_and_leaves_the_table(cells: np.ndarray, match: str) -> None:
    field = _room().planner(0, 0.0).goal_field(_centre(10, 3))
    t = field._build_table()
    kind, label = t["kind"].copy(), t["label"].copy()
    with pytest.raises(ValueError, match=match):
        field._settle_cells(cells)
    assert np.array_equal(t["kind"], kind) and np.array_equal(t["label"], label)


def test_the_ball_query_orders_many_points_as_it_orders_one() -> None:
    """The batch takes each centre's candidates from one many-point query; the one-point code
    keeps the first of equal totals in its query's order, so the orders must be the same."""
    rng = np.random.default_rng(3)
    grid = (rng.random((40, 40)) < 0.15).astype(np.uint8)
    planner = Scene.from_array(grid, RES).planner(0, 0.1)
    pts = rng.uniform(0.0, 4.0, (200, 2))
    radii = rng.uniform(0.0, 3.0, 200)
    many = planner._tree.query_ball_point(pts, radii, return_sorted=False)
    for p, r, got in zip(pts, radii, many):
        assert list(got) == list(planner._tree.query_ball_point((float(p[0]), float(p[1])), float(r)))


def _mod_two_pi(a: np.ndarray) -> np.ndarray:
    return np.mod(a, 2.0 * math.pi)


@pytest.mark.parametrize("fn", [np.arcsin, np.sin, np.cos, np.hypot, np.arctan2, np.sqrt, _mod_two_pi])
def test_array_math_gives_the_same_bits_for_any_length(fn) -> None:
    """The batch evaluates the one-point code's tangents on longer arrays than it does: numpy's
    vectorised loops must round each element alike whatever the length or the stride."""
    rng = np.random.default_rng(4)
    args = [rng.uniform(-1.0, 1.0, 1001)] if fn is np.arcsin else [rng.uniform(-9.0, 9.0, 1001)]
    if fn in (np.hypot, np.arctan2):
        args.append(rng.uniform(-9.0, 9.0, 1001))
    if fn is np.sqrt:
        args = [np.abs(args[0])]
    whole = fn(*args)
    one = np.array([fn(*(a[i : i + 1] for a in args))[0] for i in range(len(whole))])
    strided = fn(*(np.repeat(a, 2)[::2] for a in args))
    assert np.array_equal(whole, one) and np.array_equal(whole, strided)
