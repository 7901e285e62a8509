"""Env speed: PointNav-v0 steps per second beside CartPole-v1, and the cost of a reset.

With sensors: the same env with a 64-ray 360 deg range scan (5.6 m), and with a 32 x 32
local map, in the same run; the extra time per step each sensor adds is printed in
microseconds, against a plain env measured beside them ("l2, warm"). The envs share one
scene and meet the same episodes, so the first PointNav row builds each episode's goal
field while the later rows find it in the scene's cache: compare the sensor rows with the
"warm" row, not with the first.

Both envs are built with ``gymnasium.make`` and stepped with random actions in the same
run, interleaved over several rounds (the best round of each is kept, since the machines
are shared); resets happen whenever an episode ends and are counted in the step rate.
The reset figure is the median time of ``env.reset`` on the default 20 x 15 m ``rooms``
house at 0.1 m with ``path_range=(1, 10)``: sampling a start and a goal and preparing the
goal's geodesic field (its first lookup builds the per-cell table).

Run: ``python benchmarks/bench_env.py [--steps 20000] [--rounds 5]``
"""

from __future__ import annotations

import argparse
import statistics
import time

import gymnasium as gym
import numpy as np

import pointnav_core  # noqa: F401  (registers pointnav_core/PointNav-v0)
from pointnav_core import scenes


def steps_per_second(env: gym.Env, steps: int, seed: int) -> float:
    env.reset(seed=seed)
    env.action_space.seed(seed)
    actions = [env.action_space.sample() for _ in range(steps)]
    start = time.perf_counter()
    for action in actions:
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset()
    return steps / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--resets", type=int, default=200)
    args = parser.parse_args()

    scene = scenes.rooms(seed=0)
    envs = {
        "CartPole-v1": gym.make("CartPole-v1"),
        "PointNav-v0 (l2)": gym.make("pointnav_core/PointNav-v0", scene=scene),
        "PointNav-v0 (geodesic)": gym.make(
            "pointnav_core/PointNav-v0", scene=scene, task={"reward_type": "geodesic"}
        ),
        "PointNav-v0 (l2, warm)": gym.make("pointnav_core/PointNav-v0", scene=scene),
        "PointNav-v0 (l2) + scan 64": gym.make(
            "pointnav_core/PointNav-v0", scene=scene, sensors={"scan": {"n_rays": 64}}
        ),
        "PointNav-v0 (l2) + map 32x32": gym.make(
            "pointnav_core/PointNav-v0", scene=scene, sensors={"local_map": {"cells": 32}}
        ),
    }
    best = {name: 0.0 for name in envs}
    for r in range(args.rounds):
        for name, env in envs.items():
            best[name] = max(best[name], steps_per_second(env, args.steps, seed=r))
    cart = best["CartPole-v1"]
    print(f"{'env':32} {'steps/s':>10} {'x CartPole':>11}")
    for name, rate in best.items():
        print(f"{name:32} {rate:10.0f} {rate / cart:11.3f}")
    plain = best["PointNav-v0 (l2, warm)"]
    for name in ("PointNav-v0 (l2) + scan 64", "PointNav-v0 (l2) + map 32x32"):
        added = (1.0 / best[name] - 1.0 / plain) * 1e6
        print(
            f"{name[len('PointNav-v0 (l2) + '):]} adds {added:.1f} us per step; "
            f"x CartPole {plain / cart:.3f} without it, {best[name] / cart:.3f} with it"
        )

    env = gym.make(
        "pointnav_core/PointNav-v0",
        scene=scenes.rooms(seed=0),
        task={"reward_type": "geodesic", "path_range": (1.0, 10.0)},
    )
    env.reset(seed=0)  # builds the per-floor planner once, as any first episode does
    times = []
    for i in range(args.resets):
        start = time.perf_counter()
        env.reset(seed=i + 1)
        times.append(time.perf_counter() - start)
    print(
        f"reset (rooms 20 x 15 m, 0.1 m, path_range=(1, 10), geodesic field ready): "
        f"median {statistics.median(times) * 1e3:.2f} ms, p90 {np.percentile(times, 90) * 1e3:.2f} ms"
    )


if __name__ == "__main__":
    main()
