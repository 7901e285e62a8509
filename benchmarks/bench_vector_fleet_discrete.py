"""Discrete actions with several robots per world beside continuous ones, same worlds.

1,024 worlds x 4 robots on a 20 x 15 m floor with 5 % random clutter (0.1 m cells), L2
reward, no scan, numpy, one thread: the multi-robot engine stepped with random discrete
actions (MOVE_FORWARD 0.25 m = 5 control steps, turns of 10 deg = 2, STOP 1, drawn 0.55 /
0.2 / 0.2 / 0.05) and with random continuous actions, best of 3 interleaved rounds of
``--steps`` steps each. A discrete action is up to 5 batched control steps, so the figure
is agent-actions/s beside agent-steps/s, and their ratio.

Usage: ``python benchmarks/bench_vector_fleet_discrete.py [--steps 30] [--rounds 3]``
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

from pointnav_core.scenes import Scene
from pointnav_core.vector import VectorPointNavEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=30)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    grid = (rng.random((150, 200)) < 0.05).astype(np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = 1
    scene = Scene.from_array(grid, 0.1)
    worlds, robots = 1024, 4
    common = {"scene": scene, "seed": 0, "pool_size": 2, "task": {"reward_type": "l2"}}
    envs = {
        "discrete": VectorPointNavEnv(worlds, n_robots=robots, action_space="discrete", **common),
        "continuous": VectorPointNavEnv(worlds, n_robots=robots, **common),
    }
    for env in envs.values():
        env.reset(seed=0)
    p = np.array([0.55, 0.2, 0.2, 0.05])
    best = dict.fromkeys(envs, 0.0)
    for _ in range(args.rounds):
        for name, env in envs.items():
            if name == "discrete":
                actions = [rng.choice(4, size=(worlds, robots), p=p) for _ in range(args.steps)]
            else:
                actions = [rng.uniform(-1.0, 1.0, (worlds, robots, 2)) for _ in range(args.steps)]
            start = time.perf_counter()
            for act in actions:
                env.step(act)
            rate = args.steps * worlds * robots / (time.perf_counter() - start)
            best[name] = max(best[name], rate)
    print(f"{'engine (1,024 x 4, numpy)':34s} {'per second':>12s}")
    print(f"{'discrete, agent-actions':34s} {best['discrete']:12,.0f}")
    print(f"{'continuous, agent-steps':34s} {best['continuous']:12,.0f}")
    print(f"discrete / continuous: {best['discrete'] / best['continuous']:.3f}")


if __name__ == "__main__":
    main()
