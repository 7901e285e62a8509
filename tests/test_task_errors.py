"""Every invalid argument, action or call fails at once with an error that names the culprit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pointnav_core.backends.protocol import UnknownBackendError
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.errors import PointNavError, SamplingError
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask, TaskState, TaskStateError

NAN = float("nan")
INF = float("inf")


def small_scene(n_floors: int = 1) -> Scene:
    grid = np.full((20, 40), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[5:15, 20] = OBSTACLE  # a wall segment from (2.0, 0.5) to (2.1, 1.5)
    return Scene.from_array([grid] * n_floors, 0.1)


ROBOT = RobotSpec(radius=0.1)


# ------------------------------------------------------------------------------ task arguments


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"robot_idn": -1}, "robot_idn"),
        ({"robot_idn": 1.5}, "robot_idn"),
        ({"robot_idn": True}, "robot_idn"),
        ({"floor": -1}, "floor"),
        ({"floor": "0"}, "floor"),
        ({"initial_pos": (NAN, 0.0, 0.0)}, "initial_pos"),
        ({"initial_pos": (1.0, 2.0, 3.0, 4.0)}, "initial_pos"),
        ({"initial_pos": "here"}, "initial_pos"),
        ({"initial_quat": (0.0, 0.0, 0.0, 0.0)}, "initial_quat"),
        ({"initial_quat": (0.0, 0.0, 0.0, 2.0)}, "initial_quat"),
        ({"initial_quat": (0.0, 0.0, NAN, 1.0)}, "initial_quat"),
        ({"initial_quat": (0.0, 0.0, 1.0)}, "initial_quat"),
        ({"goal_pos": (INF, 0.0, 0.0)}, "goal_pos"),
        ({"goal_pos": [[1.0, 2.0]]}, "goal_pos"),
        ({"goal_tolerance": -0.1}, "goal_tolerance"),
        ({"goal_tolerance": NAN}, "goal_tolerance"),
        ({"goal_tolerance": "big"}, "goal_tolerance"),
        ({"goal_in_polar": "yes"}, "goal_in_polar"),
        ({"path_range": (2.0, 1.0)}, "path_range"),
        ({"path_range": (1.0, 1.0)}, "path_range"),
        ({"path_range": (-1.0, 2.0)}, "path_range"),
        ({"path_range": (NAN, 2.0)}, "path_range"),
        ({"path_range": (1.0, NAN)}, "path_range"),
        ({"path_range": (1.0, 2.0, 3.0)}, "path_range"),
        ({"path_range": 3.0}, "path_range"),
        ({"visualize_goal": 1}, "visualize_goal"),
        ({"visualize_path": None}, "visualize_path"),
        ({"goal_height": -1.0}, "goal_height"),
        ({"waypoint_height": INF}, "waypoint_height"),
        ({"waypoint_width": 0.0}, "waypoint_width"),
        ({"n_vis_waypoints": 0}, "n_vis_waypoints"),
        ({"n_vis_waypoints": 2.5}, "n_vis_waypoints"),
        ({"reward_type": "L2"}, "reward_type"),
        ({"reward_type": None}, "reward_type"),
        ({"termination_config": {"max_stepz": 3}}, "max_stepz"),
        ({"termination_config": {"max_steps": 0}}, "max_steps"),
        ({"termination_config": {"max_steps": 2.5}}, "max_steps"),
        ({"termination_config": {"max_collisions": -1}}, "max_collisions"),
        ({"termination_config": {"fall_height": -0.01}}, "fall_height"),
        ({"termination_config": {"fall_height": NAN}}, "fall_height"),
        ({"termination_config": [("max_steps", 3)]}, "termination_config"),
        ({"reward_config": {"r_potential": -1.0}}, "r_potential"),
        ({"reward_config": {"r_collision": NAN}}, "r_collision"),
        ({"reward_config": {"r_pointgoal": INF}}, "r_pointgoal"),
        ({"reward_config": {"r_goal": 1.0}}, "r_goal"),
        ({"reward_config": "dense"}, "reward_config"),
    ],
)
def test_invalid_task_argument_is_a_value_error_naming_it(kwargs, name):
    with pytest.raises(ValueError, match=name):
        PointNavigationTask(**kwargs)


def test_unknown_config_key_lists_the_valid_keys():
    with pytest.raises(ValueError, match="max_stepz") as excinfo:
        PointNavigationTask(termination_config={"max_stepz": 3})
    message = str(excinfo.value)
    assert "termination_config" in message
    for key in ("max_collisions", "max_steps", "fall_height"):
        assert key in message


def test_bad_reward_type_lists_the_choices():
    with pytest.raises(ValueError, match=r"reward_type must be one of \['l2', 'geodesic'\]"):
        PointNavigationTask(reward_type="euclid")


def test_a_slightly_unnormalised_quaternion_is_accepted_and_normalised():
    task = PointNavigationTask(initial_quat=(0.0, 0.0, 0.7071, 0.7071))
    assert np.linalg.norm(task.initial_quat) == pytest.approx(1.0, abs=1e-12)


# ------------------------------------------------------------------------------ meeting the env


@pytest.mark.parametrize(
    ("task", "name"),
    [
        ({"robot_idn": 1}, "robot_idn"),
        ({"floor": 1}, "floor"),
        ({"goal_pos": (2.05, 1.0, 0.0)}, "goal_pos"),  # on the wall segment
        ({"goal_pos": (9.0, 1.0, 0.0)}, "goal_pos"),  # off the map
        ({"goal_pos": (-0.5, -0.5, 0.0)}, "goal_pos"),  # off the map, negative side
        ({"initial_pos": (0.15, 1.0, 0.0)}, "initial_pos"),  # closer to the wall than 0.1 m
        ({"initial_pos": (2.0, 1.0, 0.0)}, "initial_pos"),  # touching the wall segment
    ],
)
def test_task_that_does_not_fit_the_env_fails_at_env_construction(task, name):
    with pytest.raises(ValueError, match=name):
        PointNavEnv(scene=small_scene(), robot=ROBOT, task=task)


def test_floor_out_of_range_is_checked_against_the_scene():
    PointNavEnv(scene=small_scene(n_floors=2), robot=ROBOT, task={"floor": 1})
    with pytest.raises(ValueError, match=r"floor must be in \[0, 2\)"):
        PointNavEnv(scene=small_scene(n_floors=2), robot=ROBOT, task={"floor": 2})


def test_task_reset_in_a_new_env_checks_it_first():
    task = PointNavigationTask(robot_idn=0, goal_pos=(9.0, 1.0, 0.0))  # off this 4 m map
    env = PointNavEnv(scene=small_scene(), robot=ROBOT, task={})
    with pytest.raises(ValueError, match="goal_pos"):
        task.reset(env)
    assert task.state is TaskState.ERROR


# ------------------------------------------------------------------------------ env arguments


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"render_mode": "human"}, "render_mode"),
        ({"flatten_obs": "yes"}, "flatten_obs"),
        ({"action_frequency": 0.0}, "action_frequency"),
        ({"action_frequency": -10.0}, "action_frequency"),
        ({"action_frequency": NAN}, "action_frequency"),
        ({"action_frequency": "fast"}, "action_frequency"),
        ({"scene": "rooms"}, "scene"),
        ({"robot": {"radius": -1.0}}, "radius"),
        ({"robot": {"size": 1.0}}, "size"),
        ({"robot": 0.2}, "robot"),
        ({"task": {"goal_tol": 1.0}}, "goal_tol"),
        ({"task": 3}, "task"),
        ({"backend_kwargs": 3}, "backend_kwargs"),
        ({"backend_kwargs": {"collision_mode": "bounce"}}, "collision_mode"),
    ],
)
def test_invalid_env_argument_is_a_value_error_naming_it(kwargs, name):
    kwargs.setdefault("scene", small_scene())
    with pytest.raises(ValueError, match=name):
        PointNavEnv(**kwargs)


def test_unknown_backend_name_lists_the_installed_ones():
    with pytest.raises(UnknownBackendError, match="backend must be one of .*'kinematic'.*'bullet'"):
        PointNavEnv(scene=small_scene(), backend="bullet")
    with pytest.raises(ValueError):  # it is a ValueError too
        PointNavEnv(scene=small_scene(), backend="bullet")


# ------------------------------------------------------------------------------ actions


@pytest.mark.parametrize(
    "action",
    [
        np.array([NAN, 0.0], np.float32),
        np.array([0.0, INF], np.float32),
        np.array([1.0, 0.0, 0.0], np.float32),
        np.zeros((2, 2), np.float32),
        np.float32(1.0),
        [1.0],
        ["a", "b"],
        None,
    ],
    ids=["nan", "inf", "too-long", "2d", "scalar", "too-short", "strings", "none"],
)
def test_invalid_action_is_a_value_error_naming_it_and_moves_nothing(action):
    env = PointNavEnv(scene=small_scene(), robot=ROBOT)
    env.reset(seed=0)
    env.step(np.array([1.0, 0.5], np.float32))
    pose = env.backend.get_pose(0)
    info_before = (env.task.episode_length, env.task.path_length)
    with pytest.raises(ValueError, match="action"):
        env.step(action)
    np.testing.assert_array_equal(env.backend.get_pose(0)[0], pose[0])
    assert (env.task.episode_length, env.task.path_length) == info_before
    assert env.task.state is TaskState.RUNNING


def test_actions_may_be_lists_of_python_floats():
    env = PointNavEnv(scene=small_scene(), robot=ROBOT)
    env.reset(seed=0)
    obs, reward, *_ = env.step([0.5, -0.25])
    assert type(reward) is float


# ------------------------------------------------------------------------------ lifecycle


def test_step_before_reset_raises_and_changes_nothing():
    env = PointNavEnv(scene=small_scene(), robot=ROBOT)
    pose = env.backend.get_pose(0)
    with pytest.raises(TaskStateError, match="reset"):
        env.step(np.zeros(2, np.float32))
    with pytest.raises(TaskStateError):
        env.task.step(env, np.zeros(2))
    assert env.task.state is TaskState.IDLE
    np.testing.assert_array_equal(env.backend.get_pose(0)[0], pose[0])
    assert issubclass(TaskStateError, PointNavError)


def test_observations_and_potential_before_reset_raise():
    env = PointNavEnv(scene=small_scene(), robot=ROBOT)
    for call in (env.task.get_obs, env.task.get_low_dim_obs, env.task.get_potential,
                 env.task.get_shortest_path_to_goal):
        with pytest.raises(TaskStateError):
            call(env)
    assert env.task.get_goal_pos() is None
    assert env.task.get_start_pos() is None


def test_observation_bounds_need_an_env():
    with pytest.raises(TaskStateError, match="load"):
        PointNavigationTask().observation_bounds


def test_impossible_path_range_is_a_sampling_error_naming_it():
    with pytest.warns(UserWarning, match=r"path_range=\(50.0, 60.0\).*cannot be solved"):
        env = PointNavEnv(scene=small_scene(), robot=ROBOT, task={"path_range": (50.0, 60.0)})
    with pytest.raises(SamplingError, match="path_range") as excinfo:
        env.reset(seed=0)
    assert "100 trials" in str(excinfo.value)
    assert isinstance(excinfo.value, RuntimeError)
    assert env.task.state is TaskState.ERROR
    with pytest.raises(TaskStateError, match="failed"):
        env.step(np.zeros(2, np.float32))
    assert env.task.state is TaskState.ERROR


def test_goal_that_cannot_be_far_enough_from_the_start_is_a_sampling_error():
    grid = np.full((7, 7), OBSTACLE, dtype=np.uint8)
    grid[2:5, 2:5] = FREE  # a 0.3 m box: every goal is within goal_tolerance of the start
    env = PointNavEnv(scene=Scene.from_array(grid, 0.1), robot=RobotSpec(radius=0.0))
    with pytest.raises(SamplingError, match="goal_tolerance"):
        env.reset(seed=0)


def test_fixed_start_occupied_by_another_robot_names_initial_pos():
    # Two tasks on one two-robot world: robot 0 stands where robot 1 must start.
    env = PointNavEnv(scene=small_scene(), robot=ROBOT)
    env.robots = (ROBOT, ROBOT)  # a stand-in for a two-robot env
    env.backend.load(env.scene, env.robots, 10.0)
    first = PointNavigationTask(robot_idn=0, initial_pos=(1.0, 1.0, 0.0), goal_pos=(3.0, 1.0, 0.0))
    second = PointNavigationTask(
        robot_idn=1, initial_pos=(1.05, 1.0, 0.0), goal_pos=(3.0, 1.0, 0.0)
    )
    env.backend.reset()
    first.reset(env)
    with pytest.raises(ValueError, match="initial_pos .* another robot"):
        second.reset(env)
    assert second.state is TaskState.ERROR
    assert first.state is TaskState.RUNNING


def test_sampled_start_avoids_other_robots():
    env = PointNavEnv(scene=small_scene(), robot=ROBOT)
    env.robots = (ROBOT, ROBOT)
    env.backend.load(env.scene, env.robots, 10.0)
    first = PointNavigationTask(robot_idn=0)
    second = PointNavigationTask(robot_idn=1)
    for seed in range(10):
        env.np_random = np.random.default_rng(seed)
        env.backend.reset()
        first.reset(env)
        second.reset(env)
        a, b = env.backend.get_pose(0)[0], env.backend.get_pose(1)[0]
        assert math.dist(a[:2], b[:2]) >= 0.2 - 1e-9
