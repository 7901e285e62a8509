"""What per-robot ``robot`` and ``task`` lists cost the batched multi-robot engine.

Two engines of 1,024 worlds x 4 robots on the default house (as grid cells), geodesic
reward, random actions, numpy, one thread, stepped in the same run, interleaved over
several rounds, each one's best round kept:

- ``shared``: one ``task`` dict and one ``robot`` for every robot;
- ``lists``: a list of four tasks whose tolerances, reward weights, step and collision
  limits and goal frames differ, and a list of four robots of the default speeds. Limits
  that end episodes early (robots that park) or slower robots (fewer walls reached) would
  change the work, not its bookkeeping, so the limits lie beyond the rounds.

Run it on two checkouts (``PYTHONPATH=<checkout>/src``, ``--shared-only`` where lists are
not supported) to compare a branch with another.

Run: ``python benchmarks/bench_vector_per_robot.py [--steps 30] [--rounds 3]``
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

import numpy as np

from pointnav_core.vector import VectorPointNavEnv

WORLDS, ROBOTS = 1024, 4
SHARED_TASK = {"reward_type": "geodesic"}
TASKS = [
    {"reward_type": "geodesic", "goal_tolerance": 0.5 - 0.05 * i, "goal_in_polar": i % 2 == 1,
     "termination_config": {"max_steps": 500 + i, "max_collisions": 500 + i},  # beyond a round: same work
     "reward_config": {"r_potential": 1.0 + i, "r_collision": 0.1 * i, "r_pointgoal": 10.0 - i}}
    for i in range(ROBOTS)
]
ROBOT_LIST = [{"max_linear_velocity": 0.5, "max_angular_velocity": 1.5} for _ in range(ROBOTS)]


def _runner(lists: bool, steps: int) -> Callable[[], float]:
    env = VectorPointNavEnv(WORLDS, n_robots=ROBOTS, seed=0, pool_size=1,
                            task=TASKS if lists else SHARED_TASK, robot=ROBOT_LIST if lists else None)
    env.reset(seed=0)
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, (16, WORLDS, ROBOTS, 2))

    def run() -> float:
        start = time.perf_counter()
        for i in range(steps):
            env.step(actions[i % len(actions)])
        return WORLDS * ROBOTS * steps / (time.perf_counter() - start)

    return run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=30, help="steps per round")
    parser.add_argument("--rounds", type=int, default=3, help="rounds; the best of each is kept")
    parser.add_argument("--shared-only", action="store_true", help="only the shared engine")
    args = parser.parse_args()
    runners = {"shared": _runner(False, args.steps)}
    if not args.shared_only:
        runners["lists"] = _runner(True, args.steps)
    best = dict.fromkeys(runners, 0.0)
    for _ in range(args.rounds):
        for name, run in runners.items():
            best[name] = max(best[name], run())
    print(f"{WORLDS} worlds x {ROBOTS} robots, numpy, {args.steps} steps x {args.rounds} rounds, "
          f"load average {os.getloadavg()[0]:.2f}")
    for name, rate in best.items():
        print(f"{name:>7}: {rate:>10,.0f} agent-steps/s  ({rate / best['shared']:.2f} x shared)")


if __name__ == "__main__":
    main()
