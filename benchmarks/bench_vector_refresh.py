"""Batched engine: what a pool refresh costs, built in place and in the background.

Steps ``VectorPointNavEnv`` (the default house as a grid, ``reward_type="geodesic"``,
random actions) and prints its agent-steps/s before a refresh, the time of
``refresh_pool(wait=True)``, and the time of a background ``refresh_pool()`` with the
agent-steps/s the engine keeps while the worker builds.

Run: ``python benchmarks/bench_vector_refresh.py [--worlds 4096] [--pool-size 4]``
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from pointnav_core.vector import VectorPointNavEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=4096)
    parser.add_argument("--pool-size", type=int, default=4, help="episodes per scene")
    parser.add_argument("--device", default="numpy")
    args = parser.parse_args()
    n = args.worlds
    env = VectorPointNavEnv(n, seed=0, pool_size=args.pool_size, device=args.device, task={"reward_type": "geodesic"})
    env.reset(seed=0)
    actions = [env.arrays.asarray(a) for a in np.random.default_rng(0).uniform(-1.0, 1.0, (20, n, 2))]

    def rate(steps: int = 40) -> float:
        start = time.perf_counter()
        for i in range(steps):
            env.step(actions[i % len(actions)])
        return steps * n / (time.perf_counter() - start)

    print(f"{n:,} worlds, pool_size {args.pool_size}, {args.device}")
    print(f"  stepping, no refresh:           {rate():>12,.0f} agent-steps/s")
    start = time.perf_counter()
    env.refresh_pool(wait=True)
    print(f"  refresh_pool(wait=True):        {time.perf_counter() - start:>12.1f} s")
    env.refresh_pool()
    steps, start = 0, time.perf_counter()
    while env.refresh_pending:
        env.step(actions[steps % len(actions)])
        steps += 1
    took = time.perf_counter() - start
    print(f"  refresh_pool() in the background: {took:>10.1f} s, {steps} steps meanwhile")
    print(f"  stepping meanwhile:             {steps * n / took:>12,.0f} agent-steps/s")
    env.close()


if __name__ == "__main__":
    main()
