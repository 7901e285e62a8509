"""Crowds' speed (issue 33): the batched engine against VMAS, and the single env with pedestrians.

One run, one CPU thread (torch, numba and BLAS), interleaved rounds, each row's best round
(the machines are shared), resets counted in the time:

- ``VMAS navigation``: ``vmas.make_env("navigation", num_envs=W, n_agents=R)`` on torch's
  CPU, whose agents carry VMAS's default lidar of 12 rays (``n_lidar_rays``): the reference,
  in agent-steps per second;
- ``batched engine, 12-ray scan``: ``VectorPointNavEnv(W, n_robots=R)`` on numpy, every robot
  with a 12-ray scan (360 deg, 5.6 m), the default house as grid cells, geodesic reward: the
  like-for-like form of the engine's CPU target (issue 33: at least 3 x VMAS);
- ``batched engine, 12-ray scan, P pedestrians``: not built (the batched engine has no
  pedestrians yet), printed as such;
- ``single env``: ``PointNavEnv`` (default house, 12-ray scan, random continuous actions)
  without pedestrians, with ``P`` ORCA pedestrians and with ``P`` social-force ones, in steps
  per second, and each crowd's rate over the rate without (issue 33: at least 0.5 x).

Run: ``python benchmarks/bench_crowd.py [--worlds 1024] [--robots 4] [--rays 12] [--pedestrians 10] [--rounds 3] [--quick]``
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

for _name in ("OMP_NUM_THREADS", "NUMBA_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import numpy as np
from bench_vector import _rate, _vmas

from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.vector import VectorPointNavEnv


def _batched(worlds: int, robots: int, rays: int) -> Callable[[], None]:
    env = VectorPointNavEnv(worlds, n_robots=robots, seed=0, task={"reward_type": "geodesic"},
                            sensors={"scan": {"n_rays": rays}})
    env.reset(seed=0)
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, (16, worlds, robots, 2))
    state = {"i": 0}

    def step() -> None:
        env.step(actions[state["i"] % len(actions)])
        state["i"] += 1

    return step


def _single(rays: int, pedestrians: dict | None) -> Callable[[], None]:
    env = PointNavEnv(sensors={"scan": {"n_rays": rays}}, pedestrians=pedestrians)
    env.reset(seed=0)
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, (64, 2)).astype(np.float32)
    state = {"i": 0}

    def step() -> None:
        _, _, terminated, truncated, _ = env.step(actions[state["i"] % len(actions)])
        if terminated or truncated:
            env.reset()
        state["i"] += 1

    return step


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--worlds", type=int, default=1024)
    parser.add_argument("--robots", type=int, default=4)
    parser.add_argument("--rays", type=int, default=12)
    parser.add_argument("--pedestrians", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="a smoke run: 16 worlds, 1 round, few steps")
    args = parser.parse_args()
    import torch

    torch.set_num_threads(1)
    worlds, rounds = (16, 1) if args.quick else (args.worlds, args.rounds)
    batch_steps, single_steps = (3, 50) if args.quick else (30, 2000)
    agents = worlds * args.robots
    none = lambda: None
    batched = {"batched engine, 12-ray scan".replace("12", str(args.rays)): _batched(worlds, args.robots, args.rays)}
    vmas = _vmas(worlds, args.robots, "cpu")
    if vmas is not None:
        batched = {"VMAS navigation (its 12-ray lidar)": vmas, **batched}
    crowd = {"count": args.pedestrians}
    single = {
        "single env, no pedestrians": _single(args.rays, None),
        f"single env, {args.pedestrians} ORCA pedestrians": _single(args.rays, crowd),
        f"single env, {args.pedestrians} social-force pedestrians": _single(args.rays, {**crowd, "behaviour": "social_force"}),
    }
    best = dict.fromkeys([*batched, *single], 0.0)
    start = time.perf_counter()
    for _ in range(rounds):
        for key, step in batched.items():
            best[key] = max(best[key], _rate(step, batch_steps, agents, none))
        for key, step in single.items():
            best[key] = max(best[key], _rate(step, single_steps, 1, none))
    print(f"best of {rounds} rounds, one CPU thread ({time.perf_counter() - start:.0f} s)\n")
    print("| row | rate | ratio | target |")
    print("|---|---:|---:|---:|")
    vmas_rate = best.get("VMAS navigation (its 12-ray lidar)")
    for key in batched:
        ratio = f"{best[key] / vmas_rate:.2f} x VMAS" if vmas_rate else "-"
        target = "3 x" if key.startswith("batched") else "1"
        print(f"| {key} ({worlds:,} x {args.robots}) | {best[key]:,.0f} agent-steps/s | {ratio} | {target} |")
    print(f"| batched engine, {args.rays}-ray scan, {args.pedestrians} pedestrians per world | not built | - | 1.0 x |")
    alone = best["single env, no pedestrians"]
    for key in single:
        print(f"| {key} | {best[key]:,.0f} steps/s | {best[key] / alone:.2f} x alone | {'-' if key.endswith('no pedestrians') else '0.5 x'} |")


if __name__ == "__main__":
    main()
