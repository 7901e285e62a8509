"""Multi-robot speed: MultiPointNav-v0 agent-steps per second beside MPE2's simple_spread_v3.

Both are PettingZoo parallel envs with 3 agents and continuous actions, measured in the same
run: ``pointnav_core.envs.multi_pointnav.parallel_env(n_robots=3)`` (kinematic backend, the default
20 x 15 m ``rooms`` house) and ``mpe2.simple_spread_v3.parallel_env(N=3,
continuous_actions=True)``. Actions are uniform random in each agent's action space, drawn
before the clock starts; an agent-step is one agent acting for one env step. Resets happen
whenever ``agents`` is empty and are counted in the time. The envs are interleaved over
several rounds and the best round of each is kept (the machines are shared).

Episode lengths differ by default (MPE2: ``max_cycles=25``; ours: ``max_cycles=500``, and
each task's own 500-step timeout), so MultiPointNav is also measured with
``max_cycles=25``, where a reset (sampling three starts and goals) comes every 25 steps as
in MPE2. The ratio line compares each default configuration. The last two lines split
MultiPointNav's time: stepping alone (episodes that never end) and the median reset.

With sensors: 8 robots, each with a 64-ray 360 deg range scan (5.6 m; every robot sees the
others' discs), beside 8 robots without one and MPE2 with ``N=8``.

If ``mpe2`` is not installed (``pip install mpe2``, or ``pip install pointnav-core[bench]``),
the old ``pettingzoo.mpe`` module is tried; PettingZoo >= 1.25 no longer ships it.

Run: ``python benchmarks/bench_parallel.py [--steps 6000] [--rounds 5]``
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from typing import Any

from pointnav_core.envs import multi_pointnav as parallel


def _simple_spread() -> tuple[str, Callable[..., Any]]:
    try:
        from mpe2 import simple_spread_v3

        return "MPE2 simple_spread_v3", simple_spread_v3.parallel_env
    except ImportError:
        pass
    try:
        from pettingzoo.mpe import simple_spread_v3  # PettingZoo < 1.25

        return "pettingzoo.mpe simple_spread_v3", simple_spread_v3.parallel_env
    except ImportError:
        raise SystemExit(
            "simple_spread_v3 is not available: pip install mpe2 (the maintained MPE)"
        ) from None


def agent_steps_per_second(env: Any, steps: int, seed: int) -> float:
    """Step ``env`` ``steps`` times with random actions; return agent-steps per second."""
    env.reset(seed=seed)
    plans = []
    for k, agent in enumerate(env.possible_agents):
        space = env.action_space(agent)
        space.seed(seed * 1000 + k)
        plans.append([space.sample() for _ in range(steps)])
    table = dict(zip(env.possible_agents, plans))
    count = 0
    start = time.perf_counter()
    for t in range(steps):
        if not env.agents:
            env.reset()
        actions = {agent: table[agent][t] for agent in env.agents}
        env.step(actions)
        count += len(actions)
    return count / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--steps", type=int, default=6000, help="env steps per round")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()

    mpe_name, mpe_parallel_env = _simple_spread()
    envs = {
        f"{mpe_name} (N=3, max_cycles=25)": mpe_parallel_env(
            N=3, continuous_actions=True
        ),
        "MultiPointNav-v0 (3 robots, max_cycles=500)": parallel.parallel_env(n_robots=3),
        "MultiPointNav-v0 (3 robots, max_cycles=25)": parallel.parallel_env(
            n_robots=3, max_cycles=25
        ),
        f"{mpe_name} (N=8, max_cycles=25)": mpe_parallel_env(N=8, continuous_actions=True),
        "MultiPointNav-v0 (8 robots, max_cycles=500)": parallel.parallel_env(n_robots=8),
        "MultiPointNav-v0 (8 robots, 64-ray scans)": parallel.parallel_env(
            n_robots=8, sensors={"scan": {"n_rays": 64}}
        ),
    }
    best = dict.fromkeys(envs, 0.0)
    for r in range(args.rounds):
        for name, env in envs.items():
            best[name] = max(best[name], agent_steps_per_second(env, args.steps, seed=r))
    names = list(envs)
    base = best[names[0]]
    print(f"{'env':48} {'agent-steps/s':>14} {'x MPE2':>8}")
    for name in names:
        print(f"{name:48} {best[name]:14.0f} {best[name] / base:8.2f}")
    ratio = best[names[1]] / base
    print(f"ratio (defaults, MultiPointNav / {mpe_name}): {ratio:.2f} (target >= 3)")
    mpe8 = best[names[3]]
    for name in names[4:]:
        print(f"ratio ({name} / {mpe_name} N=8): {best[name] / mpe8:.2f}")
    added = (1.0 / best[names[5]] - 1.0 / best[names[4]]) * 1e6 * 8
    print(f"64-ray scans add {added:.0f} us per env step for 8 robots ({added / 8:.0f} us per robot)")

    # Where MultiPointNav's time goes: steps alone (no episode ends), and one reset.
    steady = parallel.parallel_env(
        n_robots=3,
        max_cycles=10**9,
        task={"termination_config": {"max_steps": 10**9, "max_collisions": 10**9}},
    )
    rate = max(agent_steps_per_second(steady, args.steps, seed=r) for r in range(args.rounds))
    print(f"MultiPointNav-v0 stepping only (no resets): {rate:.0f} agent-steps/s")
    times = []
    for seed in range(1, 31):
        start = time.perf_counter()
        steady.reset(seed=seed)
        times.append(time.perf_counter() - start)
    print(
        f"MultiPointNav-v0 reset, 3 robots (starts, distinct goals, geodesic fields): "
        f"median {statistics.median(times) * 1e3:.1f} ms"
    )
    for env in envs.values():
        env.close()


if __name__ == "__main__":
    main()
