"""The crowd baselines (``pointnav eval --policy orca_robot`` and ``dwa``) give way where the
oracle, which ignores people, drives into a pedestrian; without pedestrians all reach the goal.

The scene is a 6 x 4 m room; the robot starts at (1, 2) facing its goal at (5, 2), and one
pedestrian walks the same line the other way without avoiding anyone (``sees_robots=False``),
so any avoiding is the robot's. Contacts are judged here from the two centres.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from crowd_reference import env_in, room

from pointnav_core.evaluation.policy_specs import make_policy

START = {"initial_pos": [1.0, 2.0], "initial_quat": [0.0, 0.0, 0.0, 1.0], "goal_pos": [5.0, 2.0]}


def play(policy: str, pedestrian: bool) -> tuple[bool, float]:
    """Success, and the least centre distance (m) between the robot and the pedestrian."""
    env = env_in(room(60, 40, boxes=0), task=START,
                 pedestrians={"count": 1 if pedestrian else 0, "speed": 0.5, "radius": 0.25, "sees_robots": False})
    env.reset(seed=0)
    if pedestrian:
        crowd = env.crowd
        crowd.positions = np.array([[4.5, 2.0]])
        crowd.set_route(0, [[4.5, 2.0], [0.5, 2.0]])
    act = make_policy(policy)(env)
    closest = math.inf
    obs, info = None, {}
    for _ in range(200):
        obs, _, terminated, truncated, info = env.step(act(obs))
        if pedestrian:
            closest = min(closest, math.dist(env.backend.get_pose(0)[0][:2], env.crowd.positions[0]))
        if terminated or truncated:
            break
    return bool(info["success"]), closest


@pytest.mark.parametrize("policy", ["oracle", "orca_robot", "dwa"])
def test_without_pedestrians_every_baseline_reaches_the_goal(policy: str) -> None:
    success, _ = play(policy, pedestrian=False)
    assert success


def test_the_baselines_give_way_where_the_oracle_does_not() -> None:
    touch = 0.25 + 0.18  # pedestrian radius + the default robot's
    _, oracle = play("oracle", pedestrian=True)
    assert oracle < touch  # straight through: the test's scene does test avoiding
    for policy in ("orca_robot", "dwa"):
        success, closest = play(policy, pedestrian=True)
        assert closest >= touch, (policy, closest)
        assert success, policy
