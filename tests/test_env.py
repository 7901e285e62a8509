"""PointNavEnv against Gymnasium's contracts: the checker, registration, spaces, seeding."""

from __future__ import annotations

import math
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.wrappers import FlattenObservation

from pointnav_core.backends.protocol import available_backends
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.envs.registration import ENV_IDS, register_envs
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask

ENV_ID = "pointnav_core/PointNav-v0"
INFO_KEYS = {
    "success", "done", "path_length", "spl", "soft_spl", "geodesic_dist", "distance_to_goal",
    "collisions", "reward_breakdown", "termination_conditions", "episode_length",
    "potential_metric",
}
# The Gymnasium contract and seeding hold on every registered backend.
BACKENDS = available_backends()


def small_scene() -> Scene:
    grid = np.full((30, 40), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[10:20, 15:18] = OBSTACLE
    return Scene.from_array(grid, 0.1)


# ------------------------------------------------------------------------------ checkers


@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"task": {"reward_type": "geodesic", "goal_in_polar": True}},
        {"flatten_obs": True, "robot": {"drive": "holonomic", "radius": 0.15}},
    ],
    ids=["default", "geodesic-polar", "flat-holonomic"],
)
@pytest.mark.parametrize("backend", BACKENDS)
def test_gymnasium_check_env_passes(kwargs, backend):
    check_env(PointNavEnv(scene=small_scene(), backend=backend, **kwargs), skip_render_check=True)


@pytest.mark.parametrize("backend", BACKENDS)
def test_gymnasium_check_env_passes_on_the_default_house(backend):
    check_env(PointNavEnv(backend=backend), skip_render_check=True)


def test_gymnasium_make_finds_the_registered_env_and_it_passes_check_env():
    register_envs()
    env = gym.make(ENV_ID, scene=small_scene())
    assert isinstance(env.unwrapped, PointNavEnv)
    assert env.spec.max_episode_steps is None  # the task's timeout owns truncation
    check_env(env.unwrapped, skip_render_check=True)


def test_gymnasium_make_finds_the_env_after_importing_the_package_only():
    # A fresh interpreter: nothing but the package import may register the id.
    code = (
        "import gymnasium as gym\n"
        f"env = gym.make({'pointnav_core:' + ENV_ID!r})\n"
        "print(type(env.unwrapped).__name__)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "PointNavEnv"


def test_register_envs_is_idempotent():
    register_envs()
    spec = gym.spec(ENV_ID)
    register_envs()  # no "overriding" warning (warnings are errors here)
    assert gym.spec(ENV_ID) is spec
    assert ENV_IDS[ENV_ID] == "pointnav_core.envs.pointnav:PointNavEnv"


def test_gymnasium_check_env_render_modes():
    register_envs()
    env = gym.make(ENV_ID, scene=small_scene(), render_mode="rgb_array")
    check_env(env.unwrapped)
    env.reset(seed=0)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3


def test_render_without_render_mode_warns_and_returns_none():
    env = PointNavEnv(scene=small_scene())
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="render_mode"):
        assert env.render() is None


def test_close_can_be_called_twice():
    env = PointNavEnv(scene=small_scene())
    env.close()
    env.close()


# ------------------------------------------------------------------------------ spaces and types


@pytest.mark.parametrize("backend", BACKENDS)
def test_spaces_are_built_once_and_hold_every_observation(backend):
    env = PointNavEnv(scene=small_scene(), backend=backend)
    obs_space, act_space = env.observation_space, env.action_space
    assert list(obs_space.spaces) == ["xy_pos_to_goal", "robot_lin_vel", "robot_ang_vel"]
    assert act_space == gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
    obs, _ = env.reset(seed=0)
    assert obs in obs_space
    rng = np.random.default_rng(0)
    for _ in range(200):
        action = rng.uniform(-1, 1, 2).astype(np.float32)
        obs, reward, terminated, truncated, info = env.step(action)
        assert obs in obs_space
        if terminated or truncated:
            env.reset()
    assert env.observation_space is obs_space and env.action_space is act_space


def test_polar_observation_space_bounds():
    env = PointNavEnv(scene=small_scene(), task={"goal_in_polar": True})
    box = env.observation_space["xy_pos_to_goal"]
    assert box.low[0] == 0.0
    assert box.low[1] <= -math.pi and box.high[1] >= math.pi


def test_flat_observation_is_omnigibson_low_dim_and_matches_flatten_observation():
    flat = PointNavEnv(scene=small_scene(), flatten_obs=True)
    wrapped = FlattenObservation(PointNavEnv(scene=small_scene()))
    assert flat.observation_space == wrapped.observation_space
    assert flat.observation_space.shape == (8,)
    a, _ = flat.reset(seed=3)
    b, _ = wrapped.reset(seed=3)
    np.testing.assert_array_equal(a, b)
    action = np.array([0.7, -0.3], dtype=np.float32)
    a, *_ = flat.step(action)
    b, *_ = wrapped.step(action)
    np.testing.assert_array_equal(a, b)
    dict_obs = flat.task.get_obs(flat)
    keys = ("xy_pos_to_goal", "robot_lin_vel", "robot_ang_vel")
    np.testing.assert_array_equal(a, np.concatenate([dict_obs[k] for k in keys]))


@pytest.mark.parametrize("backend", BACKENDS)
def test_rewards_are_python_floats_and_flags_python_bools(backend):
    env = PointNavEnv(
        scene=small_scene(), task={"termination_config": {"max_steps": 30}}, backend=backend
    )
    _, info = env.reset(seed=1)
    assert set(info) == INFO_KEYS
    rng = np.random.default_rng(1)
    for _ in range(30):
        _, reward, terminated, truncated, info = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
        assert type(reward) is float
        assert type(terminated) is bool and type(truncated) is bool
        assert set(info) == INFO_KEYS
        for key in ("success", "done"):
            assert type(info[key]) is bool
        for key in ("path_length", "spl", "soft_spl", "geodesic_dist", "distance_to_goal"):
            assert type(info[key]) is float
        assert all(type(v) is float for v in info["reward_breakdown"].values())
        for result in info["termination_conditions"].values():
            assert type(result["done"]) is bool and type(result["success"]) is bool
        if terminated or truncated:
            break
    assert truncated


def test_reset_info_describes_step_zero():
    env = PointNavEnv(scene=small_scene())
    _, info = env.reset(seed=2)
    assert info["episode_length"] == 0 and info["path_length"] == 0.0
    assert info["done"] is False and info["success"] is False
    assert info["distance_to_goal"] == pytest.approx(info["geodesic_dist"], abs=1e-9)
    assert all(v == 0.0 for v in info["reward_breakdown"].values())


def test_reset_accepts_options():
    env = PointNavEnv(scene=small_scene())
    obs, info = env.reset(seed=0, options={})
    assert obs in env.observation_space


# ------------------------------------------------------------------------------ seeding


def run(env: PointNavEnv, seed: int, n: int) -> list:
    trajectory = []
    obs, info = env.reset(seed=seed)
    trajectory.append((obs, info))
    rng = np.random.default_rng(seed)
    for _ in range(n):
        step = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
        trajectory.append(step)
        if step[2] or step[3]:
            obs, info = env.reset()
            trajectory.append((obs, info))
    return trajectory


def assert_same(a, b):
    if isinstance(a, dict):
        assert a.keys() == b.keys()
        for k in a:
            assert_same(a[k], b[k])
    elif isinstance(a, (tuple, list)):
        assert len(a) == len(b)
        for x, y in zip(a, b):
            assert_same(x, y)
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype
        np.testing.assert_array_equal(a, b)
    else:
        assert type(a) is type(b) and a == b


@pytest.mark.parametrize("reward_type", ["l2", "geodesic"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_same_seed_gives_identical_trajectories_in_two_envs(reward_type, backend):
    kwargs = {"reward_type": reward_type, "termination_config": {"max_steps": 40}}
    a = run(PointNavEnv(scene=small_scene(), task=kwargs, backend=backend), seed=11, n=120)
    b = run(PointNavEnv(scene=small_scene(), task=kwargs, backend=backend), seed=11, n=120)
    assert_same(a, b)
    c = run(PointNavEnv(scene=small_scene(), task=kwargs, backend=backend), seed=12, n=5)
    assert not np.array_equal(a[0][0]["xy_pos_to_goal"], c[0][0]["xy_pos_to_goal"])


def test_env_accepts_a_task_instance_and_a_robot_spec():
    # Kinematic only: collision_mode is that backend's argument (pymunk has no such mode).
    task = PointNavigationTask(goal_tolerance=0.2)
    robot = RobotSpec(radius=0.12, drive="holonomic")
    env = PointNavEnv(
        scene=small_scene(), robot=robot, task=task, backend_kwargs={"collision_mode": "stop"}
    )
    assert env.task is task and env.robot is robot and env.robots == (robot,)
    assert env.action_space.shape == (3,)
    assert env.backend.collision_mode == "stop"
    env.reset(seed=0)
    env.step(np.array([1.0, 1.0, 0.0], dtype=np.float32))


@pytest.mark.parametrize("backend", BACKENDS)
def test_out_of_range_actions_are_clipped(backend):
    scene = small_scene()
    task = {"initial_pos": (1, 1, 0), "initial_quat": (0, 0, 0, 1), "goal_pos": (3, 2.5, 0)}
    big = PointNavEnv(scene=scene, task=task, backend=backend)
    one = PointNavEnv(scene=scene, task=task, backend=backend)
    big.reset(seed=0)
    one.reset(seed=0)
    a, *_ = big.step(np.array([5.0, -7.0], dtype=np.float32))
    b, *_ = one.step(np.array([1.0, -1.0], dtype=np.float32))
    assert_same(a, b)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("kind", ["float32 array", "list"])
def test_a_non_finite_action_raises_and_changes_nothing(backend, bad, kind):
    # The env checks an action's type and shape, the backend its values: the refusal
    # must still come before anything moves, on every backend.
    env = PointNavEnv(scene=small_scene(), backend=backend)
    env.reset(seed=0)
    env.step(np.array([0.5, 0.3], dtype=np.float32))
    pose = [a.tolist() for a in env.backend.get_pose(0)]
    velocity = [a.tolist() for a in env.backend.get_velocity(0)]
    task = env.unwrapped.task
    steps, length, contact = task.episode_length, task.path_length, env.backend.in_contact(0)
    action = [0.2, bad] if kind == "list" else np.array([0.2, bad], dtype=np.float32)
    with pytest.raises(ValueError, match=r"^action must be finite, got \[0\.2"):
        env.step(action)
    assert [a.tolist() for a in env.backend.get_pose(0)] == pose
    assert [a.tolist() for a in env.backend.get_velocity(0)] == velocity
    assert env.backend.in_contact(0) == contact
    assert (task.episode_length, task.path_length) == (steps, length)
    env.step(np.array([0.5, 0.0], dtype=np.float32))  # the env still works
    assert task.episode_length == steps + 1


@pytest.mark.parametrize("backend", BACKENDS)
def test_two_envs_sharing_one_scene_agree_on_the_same_seed(backend):
    grid = np.full((16, 20), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[2:4, 2:4] = grid[2:4, 15:17] = grid[5:7, 12:14] = OBSTACLE
    scene = Scene.from_array(grid, 0.1)
    task = {"initial_pos": (1.35, 0.35, 0.0), "goal_pos": (1.05, 1.25, 0.0)}
    first = PointNavEnv(scene=scene, robot=RobotSpec(radius=0.0), task=task, backend=backend)
    second = PointNavEnv(scene=scene, robot=RobotSpec(radius=0.0), task=task, backend=backend)
    _, info_first = first.reset(seed=0)
    _, info_second = second.reset(seed=0)
    # Around the block's near corner (1.2, 0.5): 0.212 + 0.765 m.
    assert info_first["geodesic_dist"] == pytest.approx(0.97699, abs=1e-4)
    assert info_second["geodesic_dist"] == info_first["geodesic_dist"]
    # distance_to_goal is the per-step lookup: the length of a real path from the start cell.
    assert info_first["distance_to_goal"] >= info_first["geodesic_dist"] - 1e-9
    assert info_second["distance_to_goal"] == info_first["distance_to_goal"]
