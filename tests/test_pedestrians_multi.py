"""Pedestrians in the PettingZoo env (``parallel_env(pedestrians={...})``): one crowd beside
every robot, each robot's contacts and metrics its own (issue 33, point 1)."""

from __future__ import annotations

import math
import pickle
import warnings

import numpy as np
import pytest
from crowd_reference import room, wall_clearance

from pointnav_core import scenes
from pointnav_core.envs.multi_pointnav import parallel_env

RES = 0.1


def fleet(boxes: int = 4, **kwargs: object):
    return parallel_env(scene=scenes.Scene.from_array(room(80, 60, boxes=boxes), RES), **kwargs)


@pytest.mark.parametrize("seed", range(4))
def test_the_crowd_starts_clear_of_every_robot_and_the_walls(seed: int) -> None:
    grid = room(80, 60, boxes=4)
    env = parallel_env(scene=scenes.Scene.from_array(grid, RES), n_robots=3, pedestrians={"count": 10})
    env.reset(seed=seed)
    crowd = env.crowd
    assert (wall_clearance(grid, crowd.positions) >= crowd.radius).all()
    for i, spec in enumerate(env.robots):
        robot = env.backend.get_pose(i)[0][:2]
        assert (np.hypot(*(crowd.positions - robot).T) >= crowd.radius + spec.radius).all()


def test_a_contact_is_the_touching_robots_own_and_ends_only_its_episode() -> None:
    env = fleet(boxes=0, n_robots=2, pedestrians={"count": 1, "behaviour": "static", "end_on_collision": True},
                task=[{"initial_pos": [1.0, 2.0], "initial_quat": [0, 0, 0, 1.0], "goal_pos": [6.0, 2.0]},
                      {"initial_pos": [1.0, 4.5], "initial_quat": [0, 0, 0, 1.0], "goal_pos": [6.0, 4.5]}])
    _, infos = env.reset(seed=0)
    assert infos["robot_0"]["pedestrian_collisions"] == infos["robot_1"]["pedestrian_collisions"] == 0
    env.crowd.positions = np.array([[1.6, 2.0]])  # 0.6 m ahead of robot 0 only
    env.crowd.radius = np.array([0.2])
    touch = 0.2 + env.robots[0].radius
    for _ in range(30):
        _, _, terminations, _, infos = env.step({a: np.array([1.0, 0.0]) for a in env.agents})
        x = env.backend.get_pose(0)[0][0]
        if abs(1.6 - x) < touch:
            break
        assert not terminations["robot_0"]
    assert terminations["robot_0"] and not terminations["robot_1"]
    assert infos["robot_0"]["pedestrian_collisions"] == 1 and infos["robot_1"]["pedestrian_collisions"] == 0
    assert infos["robot_0"]["termination_conditions"]["pedestrian_collision"]["done"]
    assert "social" in infos["robot_0"] and "social" not in infos["robot_1"]
    assert env.agents == ["robot_1"]


@pytest.mark.parametrize("action_space", ["continuous", "discrete"])
def test_same_seed_same_crowd_and_a_pickled_copy_walks_the_same(action_space: str) -> None:
    def rollout(env, steps):
        out = []
        for i in range(steps):
            if not env.agents:
                env.reset()
            acts = {a: (np.array([0.6, math.sin(i / 5)]) if action_space == "continuous" else i % 3) for a in env.agents}
            env.step(acts)
            out.append(env.crowd.positions.copy())
        return np.array(out)

    a, b = (fleet(n_robots=2, pedestrians={"count": 5}, action_space=action_space) for _ in range(2))
    a.reset(seed=3)
    b.reset(seed=3)
    np.testing.assert_array_equal(rollout(a, 30), rollout(b, 30))
    copy = pickle.loads(pickle.dumps(a))
    np.testing.assert_array_equal(rollout(a, 40), rollout(copy, 40))


def test_pettingzoo_parallel_api_with_pedestrians() -> None:
    with warnings.catch_warnings():
        # pettingzoo.test imports the classic envs through their deprecated creation API.
        warnings.simplefilter("ignore", DeprecationWarning)
        from pettingzoo.test import parallel_api_test
    parallel_api_test(fleet(n_robots=2, pedestrians={"count": 4}, sensors={"scan": {"n_rays": 8}}), num_cycles=50)
