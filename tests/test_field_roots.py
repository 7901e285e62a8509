"""Settling goal-field cells in batches: a hand-made room, a cluttered map, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.utils import compiled as _compiled

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


def _one_point(field, cell: int) -> tuple[int, int]:
    """The kind and label the one-point exact query picks at a cell's centre."""
    geo = field.planner.geo
    r, c = divmod(cell, geo.shape[1])
    _, lab, _ = field._best(geo.origin[0] + (c + 0.5) * geo.resolution, geo.origin[1] + (r + 0.5) * geo.resolution)
    return (0 if lab == -2 else 1 if lab == -1 else 2), max(lab, -1)


def test_hand_made_room_by_hand_and_cell_by_cell() -> None:
    goal = _centre(10, 3)  # (0.35, 1.05), left of the block on its mirror axis
    field = _room().planner(0, 0.0).goal_field(goal)
    behind, seen, block, pocket = _cell(10, 17), _cell(10, 1), _cell(10, 10), _cell(2, 18)
    cells = np.array([behind, seen, block, pocket])
    kind, label = field.settle(cells)
    assert kind[cells].tolist() == [2, 1, 0, 0]
    assert label[cells].tolist()[1:] == [-1, -1, -1]
    # Behind the block: round one of its near corners, along its 0.3 m side, to the goal;
    # both ways tie by symmetry (a point robot plans as a 1e-6 m disc).
    node = int(field.labels.node[label[behind]])
    corner = (float(field.planner.cx[node]), float(field.planner.cy[node]))
    assert min(math.dist(corner, c) for c in ((1.2, 1.2), (1.2, 0.9))) < 1e-9
    x, y = _centre(10, 17)
    by_hand = 2 * math.hypot(1.75 - 1.2, 1.2 - 1.05) + 0.3
    assert field.distance(x, y) == pytest.approx(by_hand, abs=1e-5)
    # The same decisions, one cell at a time (on numpy arrays both: numba's scalar math may
    # break the symmetric tie the other way, check_settle in tests/pairs_geodesic.py).
    with _compiled.numpy_paths():
        fresh = _room().planner(0, 0.0).goal_field(goal)
        kind, label = fresh.settle(cells)
        assert [_one_point(fresh, i) for i in cells.tolist()] == list(zip(kind[cells].tolist(), label[cells].tolist()))


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
    h, w = grid.shape
    for r, c in np.argwhere(lazy.planner.usable):  # each lookup settles its cell's block
        lazy.distance((c + 0.5) * RES, (r + 0.5) * RES)
    assert lazy._table["done"].sum() > 1
    kind, label = scene.planner(0, 0.18).goal_field(goal).settle()
    assert not np.isin(kind, (3, 4)).any()
    assert np.array_equal(kind, lazy._table["kind"])
    assert np.array_equal(label, lazy._table["label"])
    assert (kind == 2).sum() > 100  # much of the map goes round a corner


@pytest.mark.parametrize(
    "cells, match",
    [
        (np.zeros((2, 2), np.int64), "cells must be a 1D array"),
        (np.array([1.0, 2.0]), "cells must be a 1D array of integer"),
        (np.array([0, 21 * 21]), r"cells must lie in \[0, 441\)"),
        (np.array([-1]), r"cells must lie in \[0, 441\)"),
    ],
)
def test_settle_rejects_bad_cells_and_leaves_the_table(cells: np.ndarray, match: str) -> None:
    field = _room().planner(0, 0.0).goal_field(_centre(10, 3))
    kind, label = (a.copy() for a in field.settle(np.zeros(0, np.int64)))
    with pytest.raises(ValueError, match=match):
        field.settle(cells)
    got = field.settle(np.zeros(0, np.int64))
    assert np.array_equal(got[0], kind) and np.array_equal(got[1], label)


def test_the_node_balls_answer_many_points_as_they_answer_one() -> None:
    """The batch takes each centre's candidates from one many-point query; the one-point code
    keeps the first of equal totals in its query's order, so the answers must be the same."""
    rng = np.random.default_rng(3)
    grid = (rng.random((40, 40)) < 0.15).astype(np.uint8)
    planner = Scene.from_array(grid, RES).planner(0, 0.1)
    pts = rng.uniform(0.0, 4.0, (200, 2))
    owner, node = planner.nodes_seeing(pts[:, 0], pts[:, 1])
    for i, (x, y) in enumerate(pts):
        assert node[owner == i].tolist() == planner.nodes_seeing(np.array([x]), np.array([y]))[1].tolist()
    # Brute force: a node is a candidate exactly when the point lies in its sight ball.
    inside = np.hypot(pts[:, None, 0] - planner.cx[None], pts[:, None, 1] - planner.cy[None]) <= planner.sights + planner.radius
    assert sorted(zip(owner.tolist(), node.tolist())) == sorted(map(tuple, np.argwhere(inside).tolist()))


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


@pytest.mark.parametrize("shape", [(10, 7), (4, 4), (9, 13), (1, 5)])
def test_block_cells_are_the_cells_of_their_blocks_by_brute_force(shape: tuple[int, int]) -> None:
    # Every cell's block by hand (4 cells square, row-major over the blocks), block by block.
    from pointnav_core.geodesic.field import block_cells

    h, w = shape
    blocks_w = -(-w // 4)
    of = {(r, c): r // 4 * blocks_w + c // 4 for r in range(h) for c in range(w)}
    n_blocks = -(-h // 4) * blocks_w
    rng = np.random.default_rng(h * 100 + w)
    for chosen in [[k] for k in range(n_blocks)] + [sorted(rng.choice(n_blocks, min(3, n_blocks), replace=False))]:
        want = [r * w + c for k in chosen for (r, c) in sorted(of) if of[r, c] == k]
        assert block_cells(np.array(chosen, dtype=np.int64), h, w).tolist() == want
