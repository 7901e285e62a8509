"""A three-robot episode whose robots end in different ways, for the RL-library adapters.

In an open 4 x 3 m room, each robot starts facing +x (0.05 m per step at full forward speed,
0.5 m/s for 0.1 s) with a goal tolerance of 0.5 m:

- ``robot_0`` drives forward towards a goal 0.72 m ahead: 0.72 - 0.05 n < 0.5 first at
  n = 5, so it *terminates* (success) on step 5, having driven L = 0.25 m, 0.47 m short;
- ``robot_1`` stands still 2.2 m from its goal and its task has ``max_steps=5``: it is
  *truncated* (timeout) on step 5, on the same step as robot_0;
- ``robot_2``'s goal is 0.1 m ahead, inside the tolerance already: it *terminates*
  (success) on step 1 after 0.05 m, 0.05 m short, and waits idle until step 5.

Its metrics by hand (SPL = S d0 / max(d0, L), SoftSPL = (1 - dT / d0) d0 / max(d0, L)):

| robot   | success | SPL | SoftSPL          | collisions |
|---------|---------|-----|------------------|------------|
| robot_0 | 1       | 1   | 1 - 0.47 / 0.72  | 0          |
| robot_1 | 0       | 0   | 0                | 0          |
| robot_2 | 1       | 1   | 1 - 0.05 / 0.1   | 0          |
"""

from __future__ import annotations

import numpy as np

from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene

FACING_X = (0.0, 0.0, 0.0, 1.0)
TASKS = [
    {"initial_pos": (0.8, 0.5, 0.0), "initial_quat": FACING_X, "goal_pos": (1.52, 0.5, 0.0)},
    {
        "initial_pos": (0.8, 1.5, 0.0),
        "initial_quat": FACING_X,
        "goal_pos": (3.0, 1.5, 0.0),
        "termination_config": {"max_steps": 5},
    },
    {"initial_pos": (0.8, 2.5, 0.0), "initial_quat": FACING_X, "goal_pos": (0.9, 2.5, 0.0)},
]
AGENTS = ["robot_0", "robot_1", "robot_2"]
#: Each robot's action on every step: forward, still, forward.
ACTIONS = {
    "robot_0": np.array([1.0, 0.0], dtype=np.float32),
    "robot_1": np.array([0.0, 0.0], dtype=np.float32),
    "robot_2": np.array([1.0, 0.0], dtype=np.float32),
}
#: The step each robot's episode ends on, and how.
END_STEP = {"robot_0": 5, "robot_1": 5, "robot_2": 1}
TERMINATED = {"robot_0": True, "robot_1": False, "robot_2": True}
TRUNCATED = {"robot_0": False, "robot_1": True, "robot_2": False}
#: The final metrics, from the table in the module docstring.
EXPECTED = {
    "robot_0": {"success": 1.0, "spl": 1.0, "soft_spl": 1 - 0.47 / 0.72, "collisions": 0.0},
    "robot_1": {"success": 0.0, "spl": 0.0, "soft_spl": 0.0, "collisions": 0.0},
    "robot_2": {"success": 1.0, "spl": 1.0, "soft_spl": 1 - 0.05 / 0.1, "collisions": 0.0},
}
#: Their means over the three robot-episodes: what a success rate logger must show.
EXPECTED_MEANS = {
    key: sum(metrics[key] for metrics in EXPECTED.values()) / 3 for key in EXPECTED["robot_0"]
}


def open_room() -> Scene:
    """A 4 x 3 m room of free floor inside a one-cell wall, 0.1 m cells."""
    grid = np.full((30, 40), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, 0.1)


def mixed_end_world(**kwargs) -> MultiPointNavEnv:
    """The three-robot world of the module docstring (flat observations unless told)."""
    return MultiPointNavEnv(
        scene=open_room(), n_robots=3, task=TASKS, **{"flatten_obs": True, **kwargs}
    )
