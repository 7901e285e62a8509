"""A few PPO updates run on every observation layout, continuous and discrete (seconds)."""

from __future__ import annotations

import numpy as np
import pytest
from stable_baselines3 import PPO

from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.integrations.sb3 import make_vec_env
from pointnav_core.scenes import Scene

LAYOUTS = [None, {"scan": {"n_rays": 8}}, {"local_map": {"cells": 6}}, {"scan": {"n_rays": 8}, "local_map": {"cells": 6}}]


def room() -> Scene:
    grid = np.full((20, 30), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[5:15, 12:14] = OBSTACLE
    return Scene.from_array(grid, 0.1)


@pytest.mark.parametrize("sensors", LAYOUTS)
@pytest.mark.parametrize("flatten_obs", [False, True])
@pytest.mark.parametrize("action_space", ["continuous", "discrete"])
def test_ppo_updates_run(sensors, flatten_obs, action_space):
    env = PointNavEnv(scene=room(), sensors=sensors, flatten_obs=flatten_obs, action_space=action_space)
    policy = "MlpPolicy" if flatten_obs else "MultiInputPolicy"
    model = PPO(policy, env, n_steps=32, batch_size=16, n_epochs=1, seed=0, device="cpu")
    model.learn(total_timesteps=64)
    assert model.num_timesteps == 64
    obs, _ = env.reset(seed=0)
    action, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(action if action_space == "continuous" else int(action))


@pytest.mark.parametrize("action_space", ["continuous", "discrete"])
def test_ppo_updates_run_on_the_multi_robot_vec_env_with_a_scan(action_space):
    venv = make_vec_env(n_worlds=1, n_robots=2, seed=0, scene=room(), sensors={"scan": {"n_rays": 8}}, action_space=action_space)
    assert venv.observation_space.shape == (16,)
    model = PPO("MlpPolicy", venv, n_steps=16, batch_size=16, n_epochs=1, seed=0, device="cpu")
    model.learn(total_timesteps=32)
    assert model.num_timesteps == 32
