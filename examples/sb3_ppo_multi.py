"""Stable-Baselines3 PPO on several robots of ``pointnav_core/MultiPointNav-v0``.

``make_vec_env`` (``pointnav_core.integrations.sb3``) builds two worlds of three robots in a
small generated house: six slots of one ``VecEnv``, one shared policy. A robot that reaches
its goal first waits idle until its world's last robot finishes, then the world resets.
``VecMonitor`` adds SB3's episode returns, ``PointNavMetricsCallback`` the success rate,
SPL and SoftSPL of each robot's episode.

Run: ``python examples/sb3_ppo_multi.py`` (needs the ``rl`` extra). Expected output:

    PPO on MultiPointNav-v0, 2 worlds x 3 robots = 6 slots: 2724 robot-steps/s (updates included)
    last 100 of 136 robot-episodes: success rate 0.56, SPL 0.38, SoftSPL 0.36, collisions 12.8

(On a 2-core x86_64 CPU machine that other jobs shared, 12 s. The metrics repeat exactly
run after run (seeded); the rate depends on the machine.)
"""

from __future__ import annotations

import time

import torch
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import VecMonitor

from pointnav_core import scenes
from pointnav_core.integrations.sb3 import PointNavMetricsCallback, make_vec_env

TIMESTEPS = 24_576
torch.set_num_threads(1)  # tiny networks: one thread is fastest on a small CPU

venv = VecMonitor(
    make_vec_env(
        n_worlds=2,
        n_robots=3,
        seed=0,
        scene=scenes.rooms(seed=0, size=(8.0, 6.0)),
        max_cycles=200,
    )
)
model = PPO("MlpPolicy", venv, n_steps=256, batch_size=256, n_epochs=5, seed=0)
metrics = PointNavMetricsCallback()
start = time.perf_counter()
model.learn(TIMESTEPS, callback=metrics)
rate = model.num_timesteps / (time.perf_counter() - start)
print(
    f"PPO on MultiPointNav-v0, 2 worlds x 3 robots = {venv.num_envs} slots: "
    f"{rate:.0f} robot-steps/s (updates included)"
)
print(metrics.summary().replace("episodes", "robot-episodes", 1))
