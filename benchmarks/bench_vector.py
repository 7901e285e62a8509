"""Batched engine speed: VectorPointNavEnv agent-steps per second beside VMAS navigation.

One run prints one table per size. Every runner is stepped with random actions drawn
before the clock starts, on one CPU thread (``torch.set_num_threads(1)``; numba and numpy
single-threaded as well, see ``main``), in the same run, interleaved over several rounds,
keeping each one's best round (the machines are shared). An agent-step is one robot acting
for one step; resets are counted in the time (next-step autoreset for ours, VMAS's own
``done`` resets for VMAS).

- ours: ``VectorPointNavEnv`` on the default house (``scenes.rooms(seed=0)`` as grid
  cells), ``reward_type="geodesic"`` (a goal-field gather every step), with a 32-ray scan
  (``sensors={"scan": {"n_rays": 32}}``: 360 deg, 5.6 m) and without, on numpy (the scan
  compiled with numba when the ``fast`` extra is installed) and on torch. The issue's row is
  1,024 worlds x 4 robots with the scan; the same engine without the scan and the one-robot
  engine on the same agents (4,096 worlds x 1 robot), with and without the scan, show what
  each part costs.
- VMAS: ``vmas.make_env("navigation", num_envs=W, n_agents=4)``, continuous actions
  (``pip install vmas``, in the ``bench`` extra), on the same device.

When CUDA is present the multi-robot engine (with and without the scan) and VMAS also run
at 8,192, 32,768 and 131,072 worlds x 4 on the GPU; without it the script says so.

Run: ``python benchmarks/bench_vector.py [--steps 30] [--rounds 3] [--pool-size 1]``
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from benchkit import steps_per_second, vmas_navigation

from pointnav_core.vector import VectorPointNavEnv

SCAN = {"scan": {"n_rays": 32}}


def _ours(scene: Any, worlds: int, robots: int, device: str, scan: bool, pool_size: int) -> tuple[Callable[[], None], float]:
    start = time.perf_counter()
    env = VectorPointNavEnv(worlds, n_robots=robots, scene=scene, device=device, seed=0, pool_size=pool_size,
                            task={"reward_type": "geodesic"}, sensors=SCAN if scan else None)
    env.reset(seed=0)
    built = time.perf_counter() - start
    shape = (16, worlds, robots, 2) if robots > 1 else (16, worlds, 2)
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, shape)
    if device != "numpy":
        import torch

        actions = torch.as_tensor(actions, device=device)
    state = {"i": 0}

    def step() -> None:
        env.step(actions[state["i"] % len(actions)])
        state["i"] += 1

    return step, built


def _table(scene: Any, worlds: int, robots: int, device: str, steps: int, rounds: int, pool_size: int) -> dict[str, float]:
    """One size: our runners and VMAS at ``worlds x robots`` agents, best of ``rounds``."""
    import torch

    agents = worlds * robots
    sync = torch.cuda.synchronize if device.startswith("cuda") else (lambda: None)
    engines = ["numpy", "cpu"] if device == "cpu" else [device]
    shapes = [(worlds, robots), (agents, 1)] if device == "cpu" else [(worlds, robots)]
    runners: dict[tuple[str, str, str], Any] = {}
    builds: dict[tuple[str, str, str], float] = {}
    for w, r in shapes:
        for scan in (True, False):
            for engine in engines:
                key = ("pointnav-core " + ("numpy" if engine == "numpy" else f"torch {engine}"), f"{w:,} x {r}",
                       "32 rays" if scan else "none")
                runners[key], builds[key] = _ours(scene, w, r, engine, scan, pool_size)
    vmas_step = vmas_navigation(worlds, robots, device)
    vmas_key = (f"VMAS navigation (torch {device})", f"{worlds:,} x {robots}", "none")
    if vmas_step is not None:
        runners[vmas_key] = vmas_step
    best = dict.fromkeys(runners, 0.0)
    for _ in range(rounds):
        for key, step in runners.items():
            best[key] = max(best[key], steps_per_second(step, steps, agents, sync))
    print(f"\n{agents:,} agent-steps a step on {device}, best of {rounds} rounds of {steps} steps:\n")
    print("| engine                          | worlds x robots | scan    | agent-steps/s | / VMAS | built (s) |")
    print("|---------------------------------|----------------:|---------|--------------:|-------:|----------:|")
    for key, rate in best.items():
        ratio = f"{rate / best[vmas_key]:.2f}" if vmas_step is not None else "-"
        built = f"{builds[key]:.1f}" if key in builds else "-"
        print(f"| {key[0]:<31} | {key[1]:>15} | {key[2]:<7} | {rate:>13,.0f} | {ratio:>6} | {built:>9} |")
    if vmas_step is None:
        print("\nVMAS is not installed (pip install vmas): no comparison")
    return {" ".join(k): v for k, v in best.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=30, help="steps per round")
    parser.add_argument("--rounds", type=int, default=3, help="rounds; the best of each is kept")
    parser.add_argument("--pool-size", type=int, default=1, help="episodes prepared per scene")
    args = parser.parse_args()
    import torch

    from pointnav_core.vector.arguments import default_scene

    torch.set_num_threads(1)
    try:  # the compiled scan: one thread as well (it does not use more today)
        import numba

        numba.set_num_threads(1)
    except ImportError:
        pass
    threads = os.environ.get("OMP_NUM_THREADS", "unset")
    print(f"machine: {platform.machine()}, {platform.processor() or 'cpu'}, {os.cpu_count()} cores; torch "
          f"{torch.__version__}; one torch thread; OMP_NUM_THREADS={threads}")
    # One scene object for every engine: the goal fields it caches are settled once.
    scene = default_scene()
    _table(scene, 1024, 4, "cpu", args.steps, args.rounds, args.pool_size)
    if torch.cuda.is_available():
        for worlds in (8192, 32768, 131072):
            _table(scene, worlds, 4, "cuda", args.steps, args.rounds, args.pool_size)
    else:
        print("\nno GPU present (torch.cuda.is_available() is False): the 8,192 / 32,768 / 131,072-world runs are skipped")


if __name__ == "__main__":
    main()
