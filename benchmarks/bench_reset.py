"""The cost of a reset as a multiple of the same env's median step, for one and three robots.

``PointNav-v0`` (one robot) and ``MultiPointNav-v0`` (three robots, ``parallel_env``), each
with its default settings on the default 20 x 15 m ``rooms`` house, are stepped with random
actions; every ``env.step`` and every ``env.reset`` (a new start and goal per robot: the
sampling, the goal's exact geodesic and the first lookup of its field) is timed alone with
``time.perf_counter``. A reset comes whenever an episode ends (for the multi-robot env,
when ``agents`` is empty), and also every ``--every`` steps, so that enough resets are
measured. Each env gets a scene of its own, built before the clock starts; the goals are new
ones, so their fields are not cached. Printed: the median step, the median reset and their
ratio (the geometry issue's target is 50 x), and the 90th percentile reset.

Run: ``python benchmarks/bench_reset.py [--steps 4000] [--every 100] [--seed 0]``
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

import gymnasium as gym
import numpy as np

import pointnav_core  # noqa: F401  (registers the envs)
from pointnav_core import scenes
from pointnav_core.envs.multi_pointnav import parallel_env


def _timed(fn: Any, *args: Any, **kwargs: Any) -> tuple[float, Any]:
    start = time.perf_counter()
    out = fn(*args, **kwargs)
    return time.perf_counter() - start, out


def single(steps: int, every: int, seed: int) -> tuple[list[float], list[float]]:
    """Step and reset times (s) of PointNav-v0."""
    env = gym.make("pointnav_core/PointNav-v0", scene=scenes.rooms(seed=0))
    env.action_space.seed(seed)
    actions = [env.action_space.sample() for _ in range(steps)]
    env.reset(seed=seed)
    step_t, reset_t = [], []
    since = 0
    for action in actions:
        dt, (_, _, terminated, truncated, _) = _timed(env.step, action)
        step_t.append(dt)
        since += 1
        if terminated or truncated or since >= every:
            reset_t.append(_timed(env.reset)[0])
            since = 0
    return step_t, reset_t


def multi(steps: int, every: int, seed: int) -> tuple[list[float], list[float]]:
    """Step and reset times (s) of MultiPointNav-v0 with three robots."""
    env = parallel_env(n_robots=3, scene=scenes.rooms(seed=0))
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    spaces = {a: env.action_space(a) for a in env.possible_agents}
    plans = [{a: rng.uniform(s.low, s.high).astype(s.dtype) for a, s in spaces.items()} for _ in range(steps)]
    step_t, reset_t = [], []
    since = 0
    for plan in plans:
        dt, _ = _timed(env.step, {a: plan[a] for a in env.agents})
        step_t.append(dt)
        since += 1
        if not env.agents or since >= every:
            reset_t.append(_timed(env.reset)[0])
            since = 0
    return step_t, reset_t


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, default=4000)
    parser.add_argument("--every", type=int, default=100, help="reset at least this often (steps)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    print(f"{'env':24} {'median step':>12} {'median reset':>13} {'reset / step':>13} {'p90 reset':>10} {'resets':>7}")
    for name, run in (("PointNav-v0", single), ("MultiPointNav-v0 (3)", multi)):
        step_t, reset_t = run(args.steps, args.every, args.seed)
        step, reset = statistics.median(step_t), statistics.median(reset_t)
        p90 = float(np.percentile(reset_t, 90))
        print(f"{name:24} {step * 1e6:9.1f} us {reset * 1e3:10.2f} ms {reset / step:12.0f}x {p90 * 1e3:7.2f} ms {len(reset_t):7d}")


if __name__ == "__main__":
    main()
