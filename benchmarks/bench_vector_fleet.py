"""Several robots per world: agent-steps per second of the batched engine beside its peers.

In one run, on one CPU thread, interleaved over rounds (best round kept): the multi-robot
engine at 1,024 worlds x 4 robots (numpy), the one-robot engine on the same 4,096 agents
as 4,096 worlds x 1 robot, and VMAS navigation at 1,024 worlds x 4 agents when installed.
The same scene for ours (the default house as grid cells), ``reward_type="geodesic"``,
random actions drawn before the clock starts, autoresets counted in the time.

Run: ``python benchmarks/bench_vector_fleet.py [--worlds 1024] [--robots 4] [--steps 50] [--rounds 3]``
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
from bench_vector import _rate, _vmas

from pointnav_core.vector import VectorPointNavEnv


def _ours(worlds: int, robots: int, pool_size: int) -> tuple[Callable[[], None], float]:
    start = time.perf_counter()
    env = VectorPointNavEnv(worlds, n_robots=robots, seed=0, pool_size=pool_size, task={"reward_type": "geodesic"})
    env.reset(seed=0)
    built = time.perf_counter() - start
    shape = (64, worlds, robots, 2) if robots > 1 else (64, worlds, 2)
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, shape)
    state = {"i": 0}

    def step() -> None:
        env.step(actions[state["i"] % len(actions)])
        state["i"] += 1

    return step, built


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=1024)
    parser.add_argument("--robots", type=int, default=4)
    parser.add_argument("--steps", type=int, default=50, help="steps per round")
    parser.add_argument("--rounds", type=int, default=3, help="rounds; the best of each is kept")
    parser.add_argument("--pool-size", type=int, default=1, help="episodes prepared per scene")
    args = parser.parse_args()
    import torch

    torch.set_num_threads(1)
    w, r = args.worlds, args.robots
    agents = w * r
    runners, builds = {}, {}
    for name, (worlds, robots) in {f"ours, {w:,} x {r} robots (numpy)": (w, r),
                                    f"ours, {agents:,} x 1 robot (numpy)": (agents, 1)}.items():
        runners[name], builds[name] = _ours(worlds, robots, args.pool_size)
    vmas_step = _vmas(w, r, "cpu")
    if vmas_step is not None:
        runners[f"VMAS navigation, {w:,} x {r} (torch cpu)"] = vmas_step
    best = dict.fromkeys(runners, 0.0)
    for _ in range(args.rounds):
        for name, step in runners.items():
            best[name] = max(best[name], _rate(step, args.steps, agents, lambda: None))
    print(f"{agents:,} agent-steps a step, one thread, best of {args.rounds} rounds of {args.steps} steps:")
    first = next(iter(best))
    for name, rate in best.items():
        built = f"  (built in {builds[name]:.1f} s)" if name in builds else ""
        print(f"  {name:<40} {rate:>12,.0f} agent-steps/s  ratio to the first {rate / best[first]:.2f}{built}")


if __name__ == "__main__":
    main()
