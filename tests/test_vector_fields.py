"""Goal fields kept to the window of cells an episode's robot can reach (``reach_window``)."""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.vector import VectorPointNavEnv
from pointnav_core.vector.fields import FieldTables, reach_window
from pointnav_core.vector.xp import make_arrays

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])


def long_hall() -> Scene:
    # 12 x 3 m at 0.1 m cells, pillars every metre: a field's blocks are many, a window few.
    grid = np.zeros((30, 120), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    for c in range(10, 120, 10):
        grid[12:16, c : c + 2] = OBSTACLE
    return Scene.from_array(grid, 0.1)


def test_reach_window_by_hand() -> None:
    field = long_hall().goal_field(0, (1.0, 1.0), robot=RobotSpec()).field
    # From (1, 1) m, 0.5 m each way is x, y in [0.5, 1.5] m: columns and rows 5 to 15, and a
    # cell to spare each side, 4 to 16 (half-open: to 17).
    assert reach_window(field, [(1.0, 1.0)], 0.5) == (4, 17, 4, 17)
    # Two starts: the box round both; clipped to the grid (30 rows, 120 columns).
    assert reach_window(field, [(1.0, 1.0), (11.5, 2.5)], 0.5) == (4, 30, 4, 120)
    assert reach_window(field, [(1.0, 1.0)], math.inf) == (0, 30, 0, 120)


@pytest.mark.parametrize("device", DEVICES)
def test_a_windowed_field_reads_its_own_lookup_inside_and_inf_outside(device: str) -> None:
    spec = RobotSpec()
    scene = long_hall()
    start, goal, reach = np.array([3.0, 1.5]), (4.6, 0.6), 1.2
    field = scene.goal_field(0, goal, robot=spec).field
    a = make_arrays(device)
    tables = FieldTables([field], a, [start[None]], reach)
    t = field._table
    # Only the blocks the window reads were checked: 2 of 8 block rows x 8 columns, at most.
    assert int(np.sum(t["done"])) < len(t["done"]) // 2
    r0, r1, c0, c1 = reach_window(field, [start], reach)
    assert (int(a.numpy(tables.rows)[0]), int(a.numpy(tables.width)[0])) == (r1 - r0, c1 - c0)
    assert (r1 - r0) * (c1 - c0) < 30 * 120 // 3
    rng = np.random.default_rng(0)
    xy = start + rng.uniform(-reach, reach, (400, 2))
    xy = xy[[scene.is_usable(0, p, spec) for p in xy]]
    got = a.numpy(tables.distance(a.zeros(len(xy), a.i64), a.asarray(xy[:, 0]), a.asarray(xy[:, 1])))
    # The single env's lookup of the same field (the same settled cells).
    want = np.array([field.distance(float(x), float(y)) for x, y in xy])
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    assert np.isfinite(got).all()
    # Far from the start, outside the window: no cell, inf.
    far = a.numpy(tables.distance(a.zeros(1, a.i64), a.asarray([10.0]), a.asarray([1.5])))
    assert math.isinf(far[0])


def test_the_engines_reach_is_steps_times_the_longest_chord() -> None:
    grid = np.zeros((20, 20), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    scene = Scene.from_array(grid, 0.1)
    env = VectorPointNavEnv(2, scene=scene, seed=0, pool_size=1, task={"termination_config": {"max_steps": 40}})
    assert env._reach == pytest.approx(40 * 0.5 * 0.1, rel=1e-8)  # 40 steps of 0.05 m
    holo = VectorPointNavEnv(2, scene=scene, seed=0, pool_size=1, robot={"drive": "holonomic"},
                             task={"termination_config": {"max_steps": 40}})
    assert holo._reach == pytest.approx(40 * math.sqrt(2) * 0.05, rel=1e-8)  # the diagonal
    # A discrete MOVE_FORWARD of 0.25 m takes 5 control steps of 0.05 m: 40 actions, 10 m.
    disc = VectorPointNavEnv(2, scene=scene, seed=0, pool_size=1, action_space="discrete",
                             task={"termination_config": {"max_steps": 40}})
    assert disc._reach == pytest.approx(40 * 5 * 0.05, rel=1e-8)
    fleet = VectorPointNavEnv(2, n_robots=2, scene=scene, seed=0, pool_size=1, max_cycles=10,
                              task={"termination_config": {"max_steps": 40}})
    assert fleet._reach == pytest.approx(10 * 0.05, rel=1e-8)  # max_cycles comes first


def test_tables_keep_only_the_labels_their_window_names() -> None:
    # A goal's search labels every arc node of the floor's graph; a window of 13 x 13 cells
    # names a few of them, and its tables keep those (plus the one spare row).
    field = long_hall().goal_field(0, (1.0, 1.0), robot=RobotSpec()).field
    tables = FieldTables([field], make_arrays("numpy"), [np.array([[1.0, 1.0]])], 0.5)
    kind, label = tables.kind, tables.label
    named = len(set(label[kind == 2].tolist()))
    assert tables.cost.shape[0] == named + 1 < len(field.labels.node)


def test_field_tables_fit_their_byte_budget(monkeypatch: pytest.MonkeyPatch) -> None:
    # The window of (1, 1) m within 0.5 m is 13 x 13 cells (test_reach_window_by_hand): 16
    # bytes each is 2,704 bytes. One byte less is refused before any settling.
    from pointnav_core.vector import fields

    field = long_hall().goal_field(0, (1.0, 1.0), robot=RobotSpec()).field
    monkeypatch.setattr(fields, "FIELD_TABLE_BYTES", 13 * 13 * 16)
    FieldTables([field], make_arrays("numpy"), [np.array([[1.0, 1.0]])], 0.5)
    monkeypatch.setattr(fields, "FIELD_TABLE_BYTES", 13 * 13 * 16 - 1)
    with pytest.raises(ValueError, match=r"169 cells .* FIELD_TABLE_BYTES .* lower pool_size or max_episode_steps"):
        FieldTables([field], make_arrays("numpy"), [np.array([[1.0, 1.0]])], 0.5)
