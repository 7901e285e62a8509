"""The oracle (ShortestPathFollower) reaches its goals on every backend.

A quick version of ``benchmarks/bench_oracle.py`` (200 episodes per backend, where the
targets are success >= 97 % and mean SPL >= 0.85 on pymunk): a few episodes in generated
``rooms`` houses through ``pointnav_core.cli.run_demo``, the code behind ``pointnav demo``.
"""

from __future__ import annotations

import numpy as np
import pytest

from pointnav_core import scenes
from pointnav_core.backends.protocol import available_backends
from pointnav_core.cli import run_demo
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.policies.oracle import ShortestPathFollower
from pointnav_core.scenes import Scene

BACKENDS = available_backends()


@pytest.mark.parametrize("drive", ["differential", "holonomic"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_oracle_reaches_most_goals_in_generated_houses(backend, drive):
    summary = run_demo(episodes=10, seed=1, houses=2, backend=backend, drive=drive, progress=False)
    assert summary["episodes"] == 10
    assert summary["success"] >= 0.9
    assert summary["spl"] >= 0.8
    assert 0.0 <= summary["soft_spl"] <= 1.0


@pytest.mark.parametrize("backend", BACKENDS)
def test_holonomic_oracle_does_not_cycle_between_two_cheap_paths(backend):
    # From neighbouring points near (-0.77, -0.9) the goal field's cheap paths (each cell's
    # root) lead in opposite directions, and a holonomic robot, which moves at once, used to
    # step back and forth between them until the timeout.
    env = PointNavEnv(
        scene=scenes.rooms(seed=2),
        robot={"drive": "holonomic"},
        task={"termination_config": {"max_steps": 1000}},
        backend=backend,
    )
    _, info = env.reset(seed=100_006)
    d0 = info["geodesic_dist"]
    oracle = ShortestPathFollower(env)
    done = False
    while not done:
        _, _, terminated, truncated, info = env.step(oracle.act())
        done = terminated or truncated
    assert info["success"] is True
    assert info["path_length"] < d0 + 1.0


def _grid(text):
    """Cell codes from rows of digits (first row: y from 0 to one cell)."""
    return np.array([[int(c) for c in row] for row in text.split()], dtype=np.uint8)


PINNED_ROOM = """
1111111111111111111
1000000000000000001
1000000000000000001
1001100000000000001
1001100000000000001
1000001100000000001
1000001100000000001
1000000000000000001
1000000000000000001
1000000000000000001
1000000110000000001
1000000110000000001
1000000000000000001
1222222222222222221
1222222222222222221
1111111111111111111
"""


def test_holonomic_oracle_rounds_the_block_between_two_near_blocks():
    # Found by property_tests/test_geometry_agreement.py: the planner finds a 1.29 m way
    # from (0.25, 0.65) to (1.35, 0.45) for a 0.15 m robot through the gap, exactly 0.3 m
    # wide, between the blocks at x 0.6-0.8, y 0.5-0.7 and x 0.7-0.9, y 1.0-1.2. The
    # holonomic oracle used to pin itself on the second block's corner there: float32
    # actions strayed ~1e-9 m sideways, into one side or the other.
    env = PointNavEnv(
        scene=Scene.from_array(_grid(PINNED_ROOM), 0.1),
        robot={"radius": 0.15, "drive": "holonomic"},
        task={
            "initial_pos": (0.25, 0.65, 0.0),
            "goal_pos": (1.35, 0.45, 0.0),
            "initial_quat": (0.0, 0.0, -0.906252546923065, 0.4227367043390695),
            "termination_config": {"max_steps": 1000, "max_collisions": 1000},
        },
    )
    _, info = env.reset(seed=0)
    assert info["geodesic_dist"] < 1.3
    oracle = ShortestPathFollower(env)
    done = False
    while not done:
        _, _, terminated, truncated, info = env.step(oracle.act())
        done = terminated or truncated
    assert info["success"] and info["collisions"] == 0


def _walled(shape, blocks, resolution=0.1):
    """A scene of ``shape`` cells, walled round, with ``blocks`` (row and column slices) set."""
    grid = np.zeros(shape, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = 1
    for rows, cols in blocks:
        grid[rows, cols] = 1
    return Scene.from_array(grid, resolution)


def _drive(env, seed=0):
    _, info = env.reset(seed=seed)
    oracle = ShortestPathFollower(env)
    done = False
    while not done:
        _, _, terminated, truncated, info = env.step(oracle.act())
        done = terminated or truncated
    return info


@pytest.mark.parametrize("drive", ["differential", "holonomic"])
def test_oracle_leaves_a_pocket_it_touches_on_two_sides(drive):
    # The start (0.25, 0.55) touches two blocks, and a 0.05 m robot's shortest way runs up
    # a corridor exactly 0.1 m wide (x 0.1-0.2) that float32 actions cannot thread without
    # grazing a side; the way down and round, 0.12 m longer, has room.
    env = PointNavEnv(
        scene=_walled((16, 17), [(slice(4, 6), slice(3, 5)), (slice(6, 8), slice(2, 4))]),
        robot={"radius": 0.05, "drive": drive},
        task={
            "initial_pos": (0.25, 0.55, 0.0),
            "goal_pos": (0.85, 1.35, 0.0),
            "termination_config": {"max_steps": 300, "max_collisions": 300},
        },
    )
    info = _drive(env)
    assert info["success"] and info["collisions"] == 0
    assert info["episode_length"] < 60


GOAL_AGAINST_A_WALL = """
1111111111111111
1222222222222221
1222222222222221
1000110000000001
1001110000000001
1001100000000001
1000000000000001
1000000000000001
1000000000000001
1000000000000001
1000000011000001
1000000011000001
1000000000000001
1000000000000001
1000000000000001
1111111111111111
"""


@pytest.mark.parametrize("drive", ["differential", "holonomic"])
def test_oracle_keeps_clear_of_corners_on_its_way_to_a_goal_against_a_wall(drive):
    # The goal (1.45, 1.05) touches the east wall, so no wider robot fits there and the
    # follower used to take the true robot's way, whose chords graze the corner of the
    # block at (1.0, 1.2) within a differential drive's heading error.
    env = PointNavEnv(
        scene=Scene.from_array(_grid(GOAL_AGAINST_A_WALL), 0.1),
        robot={"radius": 0.05, "drive": drive},
        task={
            "initial_pos": (0.25, 1.45, 0.0),
            "initial_quat": (0.0, 0.0, -0.9642275703570744, 0.26507582417733444),
            "goal_pos": (1.45, 1.05, 0.0),
            "termination_config": {"max_steps": 300, "max_collisions": 300},
        },
    )
    info = _drive(env)
    assert info["success"] and info["collisions"] == 0
