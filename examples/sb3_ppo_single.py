"""Stable-Baselines3 PPO on ``pointnav_core/PointNav-v0``: one robot, a short budget.

Four copies of the env (SB3's ``make_vec_env``) in a small generated house, flat
observations for ``MlpPolicy``; ``PointNavMetricsCallback`` logs success rate, SPL and
SoftSPL of the finished episodes to SB3's logger, printed here at the end.

Run: ``python examples/sb3_ppo_single.py`` (needs the ``rl`` extra). Expected output:

    PPO on PointNav-v0, 4 envs: 2395 steps/s (updates included)
    last 100 of 141 episodes: success rate 0.53, SPL 0.31, SoftSPL 0.33, collisions 12.6

(On a 2-core x86_64 CPU machine that other jobs shared, 14 s. The metrics repeat exactly
run after run (seeded); the rate depends on the machine.)
"""

from __future__ import annotations

import time

import torch
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env

import pointnav_core  # noqa: F401  (registers pointnav_core/PointNav-v0)
from pointnav_core import scenes
from pointnav_core.integrations.sb3 import PointNavMetricsCallback

TIMESTEPS = 24_576
torch.set_num_threads(1)  # tiny networks: one thread is fastest on a small CPU

venv = make_vec_env(
    "pointnav_core/PointNav-v0",
    n_envs=4,
    seed=0,
    env_kwargs={
        "scene": scenes.rooms(seed=0, size=(8.0, 6.0)),
        "flatten_obs": True,
        "task": {"termination_config": {"max_steps": 200}},
    },
)
model = PPO("MlpPolicy", venv, n_steps=512, batch_size=256, n_epochs=5, seed=0)
metrics = PointNavMetricsCallback()
start = time.perf_counter()
model.learn(TIMESTEPS, callback=metrics)
rate = model.num_timesteps / (time.perf_counter() - start)
print(f"PPO on PointNav-v0, {venv.num_envs} envs: {rate:.0f} steps/s (updates included)")
print(metrics.summary())
