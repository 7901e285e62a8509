"""Batched engine speed: VectorPointNavEnv agent-steps per second beside VMAS navigation.

Both are stepped with random actions drawn before the clock starts, on one CPU thread
(``torch.set_num_threads(1)``), in the same run, interleaved over several rounds, keeping
each one's best round (the machines are shared). An agent-step is one robot acting for one
step; resets are counted in the time (next-step autoreset for ours, VMAS's own ``done``
resets for VMAS).

- ours: ``VectorPointNavEnv`` on the default house (``scenes.rooms(seed=0)`` as grid cells),
  ``reward_type="geodesic"`` (a goal-field gather every step), on numpy and on torch (CPU).
  The engine has one robot per world so far, so the 4,096 agents of 1,024 worlds x 4
  robots run as 4,096 worlds x 1 robot. No scan: the sensors package casts scans per
  world, not as a batch, so the batched engine has no sensors yet.
- VMAS: ``vmas.make_env("navigation", num_envs=1024, n_agents=4, device="cpu")``,
  continuous actions (``pip install vmas``, in the ``bench`` extra).

When CUDA is present the same runs are made at 8,192, 32,768 and 131,072 worlds (x 4
agents) on the GPU; without it the script says so.

Run: ``python benchmarks/bench_vector.py [--steps 50] [--rounds 3]``
"""

from __future__ import annotations

import argparse
import platform
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from pointnav_core.vector import VectorPointNavEnv


def _ours(num_envs: int, device: str, pool_size: int) -> tuple[Callable[[], None], float]:
    start = time.perf_counter()
    env = VectorPointNavEnv(num_envs, device=device, seed=0, pool_size=pool_size, task={"reward_type": "geodesic"})
    env.reset(seed=0)
    built = time.perf_counter() - start
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, (64, num_envs, 2))
    if device != "numpy":
        import torch

        actions = torch.as_tensor(actions, device=device)
    state = {"i": 0}

    def step() -> None:
        env.step(actions[state["i"] % len(actions)])
        state["i"] += 1

    return step, built


def _vmas(num_envs: int, n_agents: int, device: str) -> Callable[[], None] | None:
    try:
        import vmas
    except ImportError:
        return None
    import torch

    env = vmas.make_env("navigation", num_envs=num_envs, device=device, continuous_actions=True, n_agents=n_agents, seed=0)
    env.reset()
    gen = torch.Generator(device=device).manual_seed(0)
    actions = [
        [2 * torch.rand((num_envs, env.get_agent_action_size(a)), generator=gen, device=device) - 1 for a in env.agents]
        for _ in range(8)
    ]
    state = {"i": 0}

    def step() -> None:
        _, _, dones, _ = env.step(actions[state["i"] % len(actions)])
        done = dones.nonzero().flatten()
        for index in done.tolist():  # VMAS resets finished worlds one by one
            env.reset_at(index)
        state["i"] += 1

    return step


def _rate(step: Callable[[], None], steps: int, agents: int, sync: Callable[[], None]) -> float:
    step()  # warm up
    sync()
    start = time.perf_counter()
    for _ in range(steps):
        step()
    sync()
    return steps * agents / (time.perf_counter() - start)


def _table(worlds: int, robots: int, device: str, steps: int, rounds: int, pool_size: int) -> dict[str, float]:
    import torch

    agents = worlds * robots
    sync = torch.cuda.synchronize if device.startswith("cuda") else (lambda: None)
    runners: dict[str, Any] = {}
    builds = {}
    engines = ["numpy"] if device == "cpu" else []
    engines.append(device)
    for engine in engines:
        name = f"pointnav-core vector ({'numpy' if engine == 'numpy' else 'torch ' + engine})"
        runners[name], builds[name] = _ours(agents, engine, pool_size)
    vmas_step = _vmas(worlds, robots, device)
    vmas_name = f"VMAS navigation ({device})"
    if vmas_step is not None:
        runners[vmas_name] = vmas_step
    best = {name: 0.0 for name in runners}
    for _ in range(rounds):
        for name, step in runners.items():
            best[name] = max(best[name], _rate(step, steps, agents, sync))
    print(f"\n{worlds:,} worlds x {robots} agents ({agents:,} agent-steps a step) on {device}:")
    for name, rate in best.items():
        built = f"  (built in {builds[name]:.1f} s)" if name in builds else ""
        print(f"  {name:<42} {rate:>14,.0f} agent-steps/s{built}")
    if vmas_step is None:
        print("  VMAS is not installed (pip install vmas): no comparison")
    else:
        for name in builds:
            print(f"  ratio {name} / VMAS: {best[name] / best[vmas_name]:.2f}")
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=50, help="steps per round")
    parser.add_argument("--rounds", type=int, default=3, help="rounds; the best of each is kept")
    parser.add_argument("--pool-size", type=int, default=2, help="episodes prepared per scene")
    args = parser.parse_args()
    import torch

    torch.set_num_threads(1)
    print(f"machine: {platform.machine()}, {platform.processor() or 'cpu'}; torch {torch.__version__}; one torch thread")
    print("ours: one robot per world, so 4 agents per VMAS world count as 4 of our worlds")
    _table(1024, 4, "cpu", args.steps, args.rounds, args.pool_size)
    if torch.cuda.is_available():
        for worlds in (8192, 32768, 131072):
            _table(worlds, 4, "cuda", args.steps, args.rounds, args.pool_size)
    else:
        print("\nno GPU present (torch.cuda.is_available() is False): the 8,192 / 32,768 / 131,072-world runs are skipped")


if __name__ == "__main__":
    main()
