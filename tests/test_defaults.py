"""Default episodes can be solved, and the step limit is the user's (issue 11).

The reach of a robot is worked out by hand here: ``max_steps`` steps of
``1 / action_frequency`` s at ``max_linear_velocity`` m/s, 500 * 0.5 / 10 = 25 m by default.
"""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pettingzoo
import pytest

import pointnav_core  # noqa: F401  (registers the ids)
from pointnav_core import scenes
from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.envs.pointnav import PointNavEnv, TaskStepLimit
from pointnav_core.errors import SamplingError
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask

ENV_ID = "pointnav_core/PointNav-v0"
MULTI_ID = "pointnav_core/MultiPointNav-v0"
STILL = np.zeros(2, dtype=np.float32)


def small_scene() -> Scene:
    grid = np.full((30, 40), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, 0.1)


def steps_until_end(env: gym.Env, seed: int = 0) -> tuple[int, dict]:
    env.reset(seed=seed)
    steps = 0
    while True:
        _, _, terminated, truncated, info = env.step(STILL)
        steps += 1
        if terminated or truncated:
            return steps, info


# ------------------------------------------------------------------------ the derived range


def test_the_registered_ids_keep_episodes_within_two_fifths_of_the_reach():
    single = gym.make(ENV_ID).unwrapped
    assert single.task.path_range == (1.0, 0.4 * 500 * 0.5 / 10)
    multi = pettingzoo.make("parallel", MULTI_ID)
    assert all(t.path_range == (1.0, 10.0) for t in multi.tasks)


@pytest.mark.parametrize(
    ("kwargs", "expected_max"),
    [
        ({"robot": {"max_linear_velocity": 1.0}}, 0.4 * 500 * 1.0 / 10),
        ({"action_frequency": 20.0}, 0.4 * 500 * 0.5 / 20),
        ({"task": {"termination_config": {"max_steps": 2000}}}, 0.4 * 2000 * 0.5 / 10),
        ({"task": {"termination_config": {"max_steps": 20}}}, 2.0),  # never under 1 m wide
    ],
)
def test_the_range_follows_speed_rate_and_step_limit(kwargs, expected_max):
    env = PointNavEnv(**kwargs)
    assert env.task.path_range == pytest.approx((1.0, expected_max))


def test_sampled_default_episodes_lie_in_the_range():
    env = gym.make(ENV_ID)
    for seed in range(15):
        _, info = env.reset(seed=seed)
        assert 1.0 < info["geodesic_dist"] < 10.0


def test_a_multi_robot_range_uses_the_shorter_of_max_steps_and_max_cycles():
    env = MultiPointNavEnv(max_cycles=100)
    assert all(t.path_range == pytest.approx((1.0, 0.4 * 100 * 0.5 / 10)) for t in env.tasks)
    mixed = MultiPointNavEnv(task=[{}, {"path_range": (2.0, 3.0)}])
    assert mixed.tasks[0].path_range == (1.0, 10.0) and mixed.tasks[1].path_range == (2.0, 3.0)


def test_explicit_ranges_and_task_objects_are_kept():
    assert PointNavEnv(task={"path_range": None}).task.path_range is None
    assert PointNavEnv(task={"path_range": (3.0, 4.0)}).task.path_range == (3.0, 4.0)
    assert PointNavEnv(task=PointNavigationTask()).task.path_range is None


def test_a_range_beyond_the_reach_warns_at_the_callers_line():
    with pytest.warns(
        UserWarning, match=r"path_range=\(0.0, 30.0\).*max_steps=500.*25 m"
    ) as record:
        PointNavEnv(task={"path_range": (0.0, 30.0)})
    assert record[0].filename == __file__
    with pytest.warns(UserWarning, match="cannot be solved") as record:
        gym.make(ENV_ID, task={"path_range": (0.0, 30.0)})
    assert record[0].filename == __file__
    with pytest.warns(UserWarning, match=r"task\[1\]: path_range"):
        MultiPointNavEnv(task=[{}, {"path_range": (0.0, 30.0)}])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        PointNavEnv(task={"path_range": (0.0, 25.0)})  # exactly the reach: no warning


def test_a_short_range_in_a_large_house_samples_without_failing():
    # Goals are drawn within the range's maximum of the start (a geodesic is never
    # shorter), so a 1.5 m range no longer fails by rejecting far goals.
    env = PointNavEnv(task={"path_range": (0.6, 1.5)})
    for seed in range(20):
        _, info = env.reset(seed=seed)
        assert 0.6 < info["geodesic_dist"] < 1.5


def test_get_random_point_with_max_distance_stays_within_it():
    scene = scenes.rooms(seed=0)
    _, anchor = scene.get_random_point(0, robot=0.18, rng=0)
    for seed in range(50):
        _, p = scene.get_random_point(
            0, reference_point=anchor, robot=0.18, rng=seed, max_distance=1.2
        )
        assert math.hypot(p[0] - anchor[0], p[1] - anchor[1]) <= 1.2
    with pytest.raises(ValueError, match="max_distance must be None or a number >= 0"):
        scene.get_random_point(0, reference_point=anchor, robot=0.18, max_distance=True)
    with pytest.raises(ValueError, match="max_distance needs a reference_point"):
        scene.get_random_point(0, robot=0.18, max_distance=1.0)


# ------------------------------------------------------------------------ the step limit


def test_max_episode_steps_in_make_sets_the_tasks_step_limit():
    env = gym.make(ENV_ID, max_episode_steps=700, task={"path_range": None})
    assert env.unwrapped.task.max_steps == 700
    steps, info = steps_until_end(env)
    assert steps == 700 and info["termination_conditions"]["timeout"]["done"]
    again = gym.make(env.spec)  # the spec keeps the limit
    assert again.unwrapped.task.max_steps == 700
    short = gym.make(ENV_ID, max_episode_steps=30)
    assert steps_until_end(short)[0] == 30
    assert short.unwrapped.task.path_range == (1.0, 2.0)  # the range follows the limit
    assert gym.make(ENV_ID).unwrapped.task.max_steps == 500


def test_task_step_limit_without_a_time_limit_changes_nothing():
    env = TaskStepLimit(PointNavEnv())
    assert env.unwrapped.task.max_steps == 500


def test_max_episode_steps_property_checks_and_refits():
    env = PointNavEnv()
    env.max_episode_steps = 1000
    assert env.task.max_steps == 1000 and env.task.path_range == (1.0, 0.4 * 1000 * 0.5 / 10)
    assert env.task.termination_config["max_steps"] == 1000
    for bad in (0, True, 2.5, "100"):
        with pytest.raises(ValueError, match="max_steps must be an integer >= 1"):
            env.max_episode_steps = bad
    fixed = PointNavEnv(task={"path_range": (2.0, 3.0)})
    fixed.max_episode_steps = 1000
    assert fixed.task.path_range == (2.0, 3.0)


def test_path_range_setter_refuses_what_is_not_two_numbers():
    task = PointNavigationTask()
    for bad in ("12", (True, 3.0), (0.0, "5"), (3.0, 2.0), (math.nan, 1.0)):
        with pytest.raises(ValueError, match="path_range"):
            task.path_range = bad
    task.path_range = (0, np.float32(2.5))
    assert task.path_range == (0.0, 2.5)


def test_a_small_scene_that_cannot_hold_the_default_range_says_so():
    tiny = np.full((12, 12), FREE, dtype=np.uint8)
    tiny[0, :] = tiny[-1, :] = tiny[:, 0] = tiny[:, -1] = OBSTACLE
    env = PointNavEnv(scene=Scene.from_array(tiny, 0.1), task={"goal_tolerance": 0.1})
    with pytest.raises(SamplingError, match=r"path_range \(1.0, 10.0\)"):
        env.reset(seed=0)
    ok = PointNavEnv(scene=small_scene(), task={"goal_tolerance": 0.1})
    ok.reset(seed=0)
