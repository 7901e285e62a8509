"""Observation terms, and terms added to a task: spaces, order, bounds, docs, copies, errors."""

from __future__ import annotations

import inspect
import math

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask
from pointnav_core.task.observations import (
    GoalVector,
    ObservationTerm,
    default_observation_terms,
    markdown_table,
)
from pointnav_core.task.rewards import RewardFunction
from pointnav_core.task.terminations import Falling, TerminationCondition


def small_scene() -> Scene:
    grid = np.full((30, 40), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[10:20, 15:18] = OBSTACLE
    return Scene.from_array(grid, 0.1)


class Heading(ObservationTerm):
    """cos and sin of the robot's yaw: a term written the way a user would."""

    name = "heading"
    size = 2
    doc_rows = (("cos yaw", "-1", "1"), ("sin yaw", "-1", "1"))

    def __init__(self) -> None:
        self.resets = 0

    def bounds(self, task, env):
        return (-1.0, -1.0), (1.0, 1.0)

    def reset(self, task, env):
        self.resets += 1

    def values(self, frame):
        return frame.cos_yaw, frame.sin_yaw


def yaw_of(quat) -> float:
    """Yaw of a planar unit quaternion (x, y, z, w), from first principles."""
    x, y, z, w = quat
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def test_the_env_docs_table_is_the_default_terms_table():
    doc = inspect.cleandoc(PointNavEnv.__doc__)
    assert markdown_table(default_observation_terms()) in doc


def test_an_added_term_is_observed_after_the_built_in_ones():
    env = PointNavEnv(scene=small_scene(), task={"observation_terms": [Heading()]})
    assert list(env.observation_space.spaces) == ["xy_pos_to_goal", "robot_lin_vel", "robot_ang_vel", "heading"]
    check_env(env, skip_render_check=True)
    before = env.task.observation_terms["heading"].resets
    obs, _ = env.reset(seed=3)
    for _ in range(5):
        obs, *_ = env.step(np.array([0.6, 0.4], dtype=np.float32))
        _, quat = env.backend.get_pose(0)
        yaw = yaw_of(quat.tolist())
        assert obs["heading"].dtype == np.float32
        assert obs["heading"] == pytest.approx([math.cos(yaw), math.sin(yaw)], abs=1e-6)
        assert env.observation_space.contains(obs)
    assert env.task.observation_terms["heading"].resets == before + 1  # once per reset


def test_flat_observation_is_the_terms_end_to_end():
    terms = [Heading()]
    flat_env = PointNavEnv(scene=small_scene(), task={"observation_terms": terms}, flatten_obs=True)
    dict_env = PointNavEnv(scene=small_scene(), task={"observation_terms": terms})
    assert flat_env.observation_space.shape == (10,)
    assert flat_env.observation_space.low[8:].tolist() == [-1.0, -1.0]
    flat, _ = flat_env.reset(seed=1)
    obs, _ = dict_env.reset(seed=1)
    assert np.array_equal(flat, np.concatenate([obs[k] for k in dict_env.observation_space.spaces]))


def test_a_term_named_like_a_built_in_one_replaces_it():
    replaced = PointNavEnv(scene=small_scene(), task={"observation_terms": [GoalVector(polar=True)]})
    polar = PointNavEnv(scene=small_scene(), task={"goal_in_polar": True})
    a, _ = replaced.reset(seed=5)
    b, _ = polar.reset(seed=5)
    assert list(a) == list(b)
    assert all(np.array_equal(a[k], b[k]) for k in a)
    assert a["xy_pos_to_goal"][0] == pytest.approx(math.dist(replaced.task.get_goal_pos()[:2],
                                                             replaced.backend.get_pose(0)[0][:2]), rel=1e-6)


def test_added_reward_and_termination_take_part_in_every_step():
    class Alive(RewardFunction):
        name = "alive"

        def compute(self, task, env, action):
            return -0.25

    class ThreeSteps(TerminationCondition):
        name = "three_steps"

        def terminate(self, task, env, action):
            return task.episode_length >= 3

    env = PointNavEnv(
        scene=small_scene(),
        task={"reward_functions": [Alive()], "termination_conditions": [ThreeSteps()]},
    )
    env.reset(seed=0)
    for step in range(3):
        _, reward, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))
        parts = info["reward_breakdown"]
        assert list(parts) == ["potential", "collision", "pointgoal", "alive"]
        assert parts["alive"] == -0.25
        assert reward == pytest.approx(sum(parts.values()))
    assert terminated and not truncated
    assert info["termination_conditions"]["three_steps"]["done"]


def test_every_robot_gets_its_own_copy_of_the_terms():
    env = MultiPointNavEnv(
        scene=small_scene(), n_robots=2, task={"observation_terms": [Heading()]}, flatten_obs=False
    )
    env.reset(seed=0)
    a, b = (t.observation_terms["heading"] for t in env.tasks)
    assert a is not b and a.resets == b.resets == 1
    assert env.observation_space("robot_1")["heading"].shape == (2,)


def test_a_condition_flagged_removes_robot_takes_its_robot_out():
    assert Falling.removes_robot and not TerminationCondition.removes_robot

    class Vanish(TerminationCondition):
        name = "vanish"
        removes_robot = True

        def terminate(self, task, env, action):
            return task.robot_idn == 0

    env = MultiPointNavEnv(scene=small_scene(), n_robots=2, task=[{"termination_conditions": [Vanish()]}, None])
    env.reset(seed=0)
    env.step({a: np.zeros(2, dtype=np.float32) for a in env.agents})
    assert env.agents == ["robot_1"]
    assert not env.backend.is_present(0) and env.backend.is_present(1)


@pytest.mark.parametrize(
    ("terms", "match"),
    [
        ("heading", "observation_terms must be None or a sequence"),
        ([object()], "observation_terms must hold ObservationTerm objects"),
        ([Heading(), Heading()], "two terms named 'heading'"),
    ],
)
def test_bad_terms_are_refused_by_name(terms, match):
    with pytest.raises(ValueError, match=match):
        PointNavigationTask(observation_terms=terms)


@pytest.mark.parametrize(
    ("bounds", "match"),
    [
        (((-1.0,), (1.0,)), "must give 2 low and high bounds"),
        (((-1.0, math.nan), (1.0, 1.0)), "bounds must be finite with low <= high"),
        (((1.0, 0.0), (-1.0, 1.0)), "bounds must be finite with low <= high"),
    ],
)
def test_bad_term_bounds_fail_when_the_task_meets_its_env(bounds, match):
    class Bad(Heading):
        def bounds(self, task, env):
            return bounds

    with pytest.raises(ValueError, match=f"'heading' {match}"):
        PointNavEnv(scene=small_scene(), task={"observation_terms": [Bad()]})
