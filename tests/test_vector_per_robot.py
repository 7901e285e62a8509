"""Per-robot ``task`` and ``robot`` lists in the batched engine (several robots per world):
each robot's own speed, tolerance, rewards and limits by hand, and bad lists named."""

from __future__ import annotations

import importlib.util
import math
from collections.abc import Iterator

import numpy as np
import pytest
from fleet_reference import compare_fleet, fleet_episodes

from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask
from pointnav_core.utils.compiled import numpy_paths
from pointnav_core.vector import VectorPointNavEnv

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])


def room(rows: int = 30, cols: int = 40) -> Scene:
    grid = np.zeros((rows, cols), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, 0.1)


# Three robots in a 4 x 3 m room, 1 m apart, each facing its goal along +x.
# robot 0: 0.5 m/s, goal 0.52 m ahead, tolerance 0.1 m -> 0.05 m a step, inside at step 9 (0.07 m).
# robot 1: 0.25 m/s, goal 0.52 m ahead, tolerance 0.2 m -> 0.025 m a step, inside at step 13 (0.195 m).
# robot 2: 0.5 m/s, far goal, max_steps 5 -> truncated at step 5.
EPISODE = [((0.5, 0.5), 0.0, (1.02, 0.5)), ((0.5, 1.5), 0.0, (1.02, 1.5)), ((0.5, 2.5), 0.0, (3.5, 2.5))]
ROBOTS = [{"max_linear_velocity": 0.5}, {"max_linear_velocity": 0.25}, {"max_linear_velocity": 0.5}]
TASKS = [
    {"goal_tolerance": 0.1, "reward_config": {"r_potential": 1.0, "r_pointgoal": 10.0}},
    {"goal_tolerance": 0.2, "reward_config": {"r_potential": 2.0, "r_pointgoal": 5.0}},
    {"goal_tolerance": 0.1, "termination_config": {"max_steps": 5}},
]


@pytest.mark.parametrize("device", DEVICES)
def test_each_robot_drives_and_scores_by_its_own_settings(device: str) -> None:
    env = VectorPointNavEnv(2, n_robots=3, scene=room(), robot=ROBOTS, task=TASKS, device=device, pool_size=1)
    obs, _ = env.reset(options={"episodes": [EPISODE, EPISODE]})
    np_ = env.arrays.numpy
    speed = [0.5, 0.25, 0.5]
    ends = {}
    for step in range(1, 15):
        obs, reward, terminated, truncated, info = env.step(np.tile([1.0, 0.0], (2, 3, 1)))
        obs, reward, terminated, truncated = np_(obs), np_(reward), np_(terminated), np_(truncated)
        active_before = [k not in ends for k in range(3)]
        for k in range(3):
            if not active_before[k]:
                assert reward[0, k] == 0.0 and not terminated[0, k] and not truncated[0, k]
                continue
            left = EPISODE[k][2][0] - EPISODE[k][0][0] - speed[k] * 0.1 * step
            # Forward speed (robot frame) and the goal ahead, by hand.
            np.testing.assert_allclose(obs[:, k, :3], [[left, 0.0, speed[k]]] * 2, atol=1e-6)
            progress = TASKS[k].get("reward_config", {}).get("r_potential", 1.0) * speed[k] * 0.1
            bonus = TASKS[k].get("reward_config", {}).get("r_pointgoal", 10.0) if terminated[0, k] else 0.0
            np.testing.assert_allclose(reward[:, k], progress + bonus, atol=1e-9)
            if terminated[0, k] or truncated[0, k]:
                ends[k] = (step, bool(terminated[0, k]), bool(truncated[0, k]), bool(np_(info["success"])[0, k]))
    assert ends == {0: (9, True, False, True), 1: (13, True, False, True), 2: (5, False, True, False)}


@pytest.mark.parametrize("device", DEVICES)
def test_goal_frame_and_lists_match_parallel_envs(device: str) -> None:
    # Robot 1 sees its goal in polar coordinates, robot 0 in Cartesian ones, by hand at reset.
    tasks = [{"goal_tolerance": 0.1}, {"goal_tolerance": 0.1, "goal_in_polar": True}]
    episode = [((0.5, 0.5), 0.0, (0.8, 0.9)), ((0.5, 1.5), 0.0, (0.8, 1.9))]
    env = VectorPointNavEnv(1, n_robots=2, scene=room(), task=tasks, device=device, pool_size=1)
    obs, _ = env.reset(options={"episodes": [episode]})
    np.testing.assert_allclose(env.arrays.numpy(obs)[0, :, :2], [[0.3, 0.4], [0.5, math.atan2(0.4, 0.3)]], atol=1e-6)
    # And step for step as the multi-robot env with the same lists (robots meet, too).
    rng = np.random.default_rng(3)
    actions = rng.uniform(-1.2, 1.2, (60, 1, 2, 2))
    actions[..., 0] = np.abs(actions[..., 0])
    compare_fleet(room(), [episode], actions, task=tasks, robot=[{"max_angular_velocity": 2.5}, None], device=device)


def test_a_list_of_equal_entries_is_the_shared_value() -> None:
    def run(task: object, robot: object) -> list[np.ndarray]:
        env = VectorPointNavEnv(3, n_robots=2, scene=room(), task=task, robot=robot, pool_size=2, seed=4)
        out = [env.reset()[0]]
        rng = np.random.default_rng(0)
        for _ in range(40):
            obs, reward, terminated, truncated, _ = env.step(rng.uniform(-1, 1, (3, 2, 2)))
            out += [obs, reward, terminated, truncated]
        return out

    task, robot = {"goal_tolerance": 0.3, "reward_type": "geodesic"}, {"max_linear_velocity": 0.4}
    for got, want in zip(run([task, task], [robot, robot]), run(task, robot), strict=True):
        np.testing.assert_array_equal(got, want)


def two_floors() -> Scene:
    return Scene([room().floors[0], room().floors[0]])


@pytest.mark.parametrize(("kwargs", "words"), [
    ({"task": [{}, {}, {}]}, r"^task must be one value for all robots or a list .*got a list of 3"),
    ({"task": [{}, 3]}, r"^task\[1\] must be None or a dict"),
    ({"task": [PointNavigationTask(), {}]}, r"^task\[0\] must be None or a dict"),
    ({"task": [{}, {"reward_functions": [object()]}]}, r"^task\[1\]: reward_functions"),
    ({"task": [{}, {"goal_tolerance": -1.0}]}, r"^task\[1\]"),
    ({"task": [{"floor": 0}, {"floor": 1}], "scene": two_floors()}, r"^task: .*same floor"),
    ({"robot": [{}]}, r"^robot must be one value for all robots or a list .*got a list of 1"),
    ({"robot": [{}, "fast"]}, r"^robot\[1\] must be a RobotSpec"),
    ({"robot": [{}, {"drive": "holonomic"}]}, r"^robot: every robot must have the same drive .*\['differential', 'holonomic'\]"),
])
def test_bad_lists_are_named(kwargs: dict, words: str) -> None:
    with pytest.raises(ValueError, match=words):
        VectorPointNavEnv(**{"num_envs": 1, "n_robots": 2, "scene": room(), "pool_size": 1, **kwargs})


def test_max_episode_steps_sets_every_listed_task() -> None:
    # Standing still, every robot is truncated at step 7, whatever its own task's max_steps.
    env = VectorPointNavEnv(1, n_robots=3, scene=room(), robot=ROBOTS, task=TASKS, pool_size=1, max_episode_steps=7)
    env.reset(options={"episodes": [EPISODE]})
    for step in range(1, 8):
        _, _, terminated, truncated, _ = env.step(np.zeros((1, 3, 2)))
        assert not terminated.any() and truncated.all() == (step == 7) and truncated.any() == (step == 7)


@pytest.mark.parametrize("device", DEVICES)
def test_discrete_actions_take_task_lists(device: str) -> None:
    # One plan of control steps: robots of one speed (a list of equal specs), tasks that differ.
    rng = np.random.default_rng(5)
    tasks = [{"goal_tolerance": 0.15, "reward_type": "geodesic", "reward_config": {"r_pointgoal": 3.0}},
             {"goal_tolerance": 0.3, "goal_in_polar": True, "termination_config": {"max_steps": 12, "max_collisions": 2}}]
    episodes = fleet_episodes(room(20, 16), 3, 2, rng, goal_gap=0.45, at_start=0.3)
    actions = rng.choice(4, size=(50, 3, 2), p=[0.5, 0.2, 0.2, 0.1])
    stats = compare_fleet(room(20, 16), episodes, actions, task=tasks, robot=[{"radius": 0.18}] * 2, device=device,
                          action_space="discrete", discrete_actions={"forward_step": 0.1, "stop": True})
    assert stats["ends"] > 3 and stats["successes"] > 0


# Two robots of radii 0.1 and 0.3 m face each other on y = 1 m, centres 0.72 m apart.
# Robot 0 drives +x at 0.05 m a step; robot 1 stands. They touch at 0.1 + 0.3 = 0.4 m:
# after 6 steps the gap is 0.42 m, and step 7 stops robot 0 at 0.4 m (less the backend's
# 1e-9 m placing margin), both robots flagged. Each scan ray ahead reads the other robot's
# centre distance less the other's radius: 0.72 - 0.3 = 0.42 and 0.72 - 0.1 = 0.62 m.
RADII_EPISODE = [((0.5, 1.0), 0.0, (3.0, 2.5)), ((1.22, 1.0), math.pi, (3.0, 0.5))]
RADII_ROBOTS = [{"radius": 0.1, "max_linear_velocity": 0.5}, {"radius": 0.3, "max_linear_velocity": 0.5}]
ONE_RAY = {"scan": {"n_rays": 1, "max_range": 2.0}}


@pytest.fixture
def array_paths() -> Iterator[None]:
    """Make the engine take its array paths (contacts and scan) instead of the compiled ones."""
    with numpy_paths():
        yield


@pytest.mark.parametrize("path", ["compiled", "array"])
@pytest.mark.parametrize("device", DEVICES)
def test_robots_of_radii_01_and_03_touch_at_04_m(device: str, path: str, request: pytest.FixtureRequest) -> None:
    if path == "array":
        request.getfixturevalue("array_paths")
    elif importlib.util.find_spec("numba") is None:
        pytest.skip("the compiled path needs numba")
    env = VectorPointNavEnv(1, n_robots=2, scene=room(), robot=RADII_ROBOTS, task={"goal_tolerance": 0.1},
                            sensors=ONE_RAY, device=device, pool_size=1)
    obs, _ = env.reset(options={"episodes": [RADII_EPISODE]})
    np_ = env.arrays.numpy
    np.testing.assert_allclose(np_(obs)[0, :, -1], [0.42, 0.62], atol=1e-9)
    drive = np.array([[[1.0, 0.0], [0.0, 0.0]]])
    for step in range(1, 8):
        obs, _, _, _, info = env.step(drive)
        x = np_(env.state.x)[0]
        contact = np_(info["in_contact"])[0].tolist()
        if step < 7:
            np.testing.assert_allclose(x, [0.5 + 0.05 * step, 1.22], atol=1e-12)
            assert contact == [False, False], step
    np.testing.assert_allclose(x, [1.22 - 0.4 - 1e-9, 1.22], atol=1e-12)
    assert contact == [True, True]
    np.testing.assert_array_equal(np_(info["collisions"])[0], [1, 1])
    np.testing.assert_allclose(np_(obs)[0, :, -1], [0.1, 0.3], atol=1e-8)


@pytest.mark.parametrize("device", DEVICES)
def test_robots_of_radii_01_and_03_match_parallel_envs(device: str) -> None:
    # The same meeting, and the robots driving on into each other, step for step as the
    # multi-robot env (scan and local map on).
    actions = np.tile([[1.0, 0.0], [0.3, 0.1]], (25, 1, 1, 1))
    sensors = {**ONE_RAY, "local_map": {"size": 1.2, "cells": 12}}
    stats = compare_fleet(room(), [RADII_EPISODE], actions, robot=RADII_ROBOTS, task={"goal_tolerance": 0.1},
                          sensors=sensors, device=device)
    assert stats["robot_contacts"] > 0


def test_discrete_actions_take_robots_of_different_radii() -> None:
    # One plan of control steps needs one speed, not one radius.
    env = VectorPointNavEnv(1, n_robots=2, scene=room(), pool_size=1, action_space="discrete",
                            robot=[{"radius": 0.1}, {"radius": 0.3}])
    env.reset(options={"episodes": [RADII_EPISODE]})
    env.step(np.zeros((1, 2), np.int64))


@pytest.mark.parametrize("device", DEVICES)
def test_discrete_actions_of_robots_of_different_speeds_by_hand(device: str) -> None:
    # 10 Hz, MOVE_FORWARD 0.25 m, turns 10 deg. Robot 0 (0.5 m/s, 1.5 rad/s): forward in
    # 0.25 / 0.05 = 5 control steps, a turn in ceil(0.1745 / 0.15) = 2. Robot 1 (0.25 m/s,
    # 0.5 rad/s): forward in 0.25 / 0.025 = 10, a turn in ceil(0.1745 / 0.05) = 4.
    robots = [{}, {"max_linear_velocity": 0.25, "max_angular_velocity": 0.5}]
    env = VectorPointNavEnv(1, n_robots=2, scene=room(), robot=robots, device=device, action_space="discrete")
    to_np = env.arrays.numpy
    env.reset(options={"episodes": [[((0.5, 0.5), 0.0, (3.5, 0.5)), ((0.5, 1.5), 0.0, (3.5, 1.5))]]})
    assert to_np(env._discrete.steps).tolist() == [[5, 2, 2, 1], [10, 4, 4, 1]]
    # Both forward: the world runs 10 control steps; robot 0 drives in the first 5 and then
    # stands (zero velocity at the end), robot 1 drives in all 10. Both end 0.25 m ahead.
    obs, _, _, _, info = env.step(np.array([[0, 0]]))
    np.testing.assert_allclose(to_np(env.state.x)[0], [0.75, 0.75], atol=1e-12)
    np.testing.assert_allclose(to_np(obs)[0, :, 2], [0.0, 0.25], atol=1e-6)  # forward speed (m/s)
    assert to_np(info["episode_length"]).tolist() == [[1, 1]]
    np.testing.assert_allclose(to_np(info["path_length"])[0], [0.25, 0.25], atol=1e-12)
    # Robot 0 forward (5 steps) while robot 1 turns left (4 steps): robot 0 drives to the end of
    # the world's 5 steps, robot 1 turns 10 deg at 0.436 rad/s and stands in the 5th.
    obs, _, _, _, _ = env.step(np.array([[0, 1]]))
    np.testing.assert_allclose(to_np(env.state.x)[0], [1.0, 0.75], atol=1e-12)
    np.testing.assert_allclose(to_np(env.state.yaw)[0], [0.0, math.radians(10.0)], atol=1e-12)
    np.testing.assert_allclose(to_np(obs)[0, :, 2], [0.5, 0.0], atol=1e-6)
    np.testing.assert_allclose(to_np(obs)[0, :, 7], [0.0, 0.0], atol=1e-6)  # yaw rate (rad/s)


@pytest.mark.parametrize("device", DEVICES)
def test_discrete_actions_of_robots_of_different_speeds_match_parallel_envs(device: str) -> None:
    # Each robot holds its action for its own number of control steps; the world runs its
    # longest. Crowded, so that robots of different speeds meet and the slow one is cut short.
    rng = np.random.default_rng(9)
    robots = [{"max_linear_velocity": 0.5}, {"max_linear_velocity": 0.2, "max_angular_velocity": 0.6},
              {"max_linear_velocity": 0.35, "max_angular_velocity": 2.0}]
    episodes = fleet_episodes(room(20, 16), 3, 3, rng, goal_gap=0.45, at_start=0.3)
    actions = rng.choice(4, size=(60, 3, 3), p=[0.55, 0.2, 0.15, 0.1])
    stats = compare_fleet(room(20, 16), episodes, actions, robot=robots, device=device, task={"goal_tolerance": 0.2},
                          action_space="discrete", discrete_actions={"forward_step": 0.3, "stop": True})
    assert stats["ends"] > 3 and stats["contacts"] > 0 and stats["robot_contacts"] > 0
