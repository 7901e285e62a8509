"""Crowds' speed (issue 33, must-show 3): the batched engine against VMAS, and the single env with pedestrians.

One run, one CPU thread (torch, numba and BLAS), interleaved rounds, each row's best round
(the machines are shared, so only ratios from the same run mean much), random continuous
actions drawn before the clock starts, resets counted in the time as they happen. An
agent-step is one robot acting for one step; a pedestrian's step is not counted.

- ``VMAS navigation``: ``vmas.make_env("navigation", num_envs=W, n_agents=R)`` on torch's
  CPU (``benchkit.vmas_navigation``, as ``bench_vector.py`` runs it), whose agents carry
  navigation's lidar (it is on whenever ``collisions`` is, the default) with its default
  12 rays (``n_lidar_rays``): the reference, in agent-steps per second.
- ``batched engine, 12-ray scan``: ``VectorPointNavEnv(W, n_robots=R)`` on numpy, every robot
  with a 12-ray scan (360 deg, 5.6 m), the default house as grid cells, geodesic reward:
  the like-for-like form of the engine's CPU target, over the row above (issue 33: >= 3 x).
- ``batched engine, 12-ray scan to 0.35 m``: the same with the scan's ``max_range`` at
  navigation's lidar range (``lidar_range``, 0.35 m), the work VMAS's row does: the rows
  above cast 5.6 m rays through a house's walls against VMAS's 0.35 m rays in a world
  without walls. Still in the house, with the geodesic reward (VMAS's is Euclidean).
- ``VMAS navigation + P pedestrians``: the same counts in VMAS, which has no pedestrians.
  Its fairest form, chosen here: navigation with ``P`` more agents per world
  (``benchkit.vmas_navigation(..., pedestrians=P)``) that are discs with goals in VMAS's physics, driven by random
  actions, colliding with the robots and each other and seen by the robots' lidars, but
  carrying no lidar of their own; only the ``R`` robots' agent-steps are counted. Plain
  navigation with ``R + P`` agents would also give every pedestrian a 12-ray lidar that
  our pedestrians lack, and runs 2.6 x slower still (10,700 against 28,100 robots'
  agent-steps/s at 1,024 x 4, 2026-11-28): a reference that easy would say little. Most
  of this row's cost is the robots' lidars, which cast against every other agent (13
  discs instead of 3), as our scan will have to see the pedestrians. VMAS moves its
  pedestrians by physics and random actions, ours by ORCA or social force: the
  comparison is of the worlds' sizes, not of the crowds' models.
- ``batched engine, 12-ray scan, P pedestrians``: the same engine with
  ``pedestrians={"count": P}`` (ORCA, seeing the robots; :mod:`pointnav_core.vector.crowd`),
  whose scans see the pedestrians: over the VMAS row above (issue 33: >= 1.0 x). Its
  pedestrians plan a new exact path at each arrival, as the single env's do.
- Every batched row, VMAS's too, steps 1,000 times before the clock starts, into its steady
  state: at a reset every pedestrian has just planned (arrivals come after tens of steps),
  and our goal fields' blocks are settled as robots first reach them (the pool's build,
  spread over its first thousands of steps). ``its first 1,000 steps after a reset``
  times that once, apart: a fresh engine with the 0.35 m scan, from its reset.
- ``single env``: ``PointNavEnv`` (default house, 12-ray scan) without pedestrians, with
  ``P`` ORCA pedestrians (``pedestrians={"count": P}``, the compiled crowd step where numba
  is installed) and with ``P`` social-force ones (``"behaviour": "social_force"``, numpy),
  in steps per second, each crowd's rate over the rate without (issue 33: ORCA >= 0.5 x),
  and the mean cost of one ``reset()`` timed apart (the crowd is placed and planned there).

Run: ``python benchmarks/bench_crowd.py [--worlds 1024] [--robots 4] [--rays 12] [--pedestrians 10] [--rounds 3] [--quick]``
(``--quick``: a smoke run of a few seconds, 16 worlds, 1 round, a few steps.)
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from typing import Any

for _name in ("OMP_NUM_THREADS", "NUMBA_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import numpy as np
from benchkit import VMAS_LIDAR_RANGE, machine, steps_per_second, vmas_navigation

from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.vector import VectorPointNavEnv


def _no_sync() -> None:
    """Nothing to wait for on the CPU."""


def _batched(worlds: int, robots: int, rays: int, walkers: int = 0, max_range: float = 5.6) -> Callable[[], None]:
    """One step of ``worlds x robots`` robots in the batched engine, each with a ``rays``-ray
    scan to ``max_range`` m, and ``walkers`` ORCA pedestrians a world."""
    env = VectorPointNavEnv(worlds, n_robots=robots, seed=0, task={"reward_type": "geodesic"},
                            sensors={"scan": {"n_rays": rays, "max_range": max_range}},
                            pedestrians={"count": walkers} if walkers else None)
    env.reset(seed=0)
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, (16, worlds, robots, 2))
    state = {"i": 0}

    def step() -> None:
        env.step(actions[state["i"] % len(actions)])
        state["i"] += 1

    return step


def _single(rays: int, pedestrians: dict[str, Any] | None) -> tuple[Callable[[], None], Callable[[], None]]:
    """One step (a reset when the episode ends) and one reset of a single env with a ``rays``-ray scan."""
    env = PointNavEnv(sensors={"scan": {"n_rays": rays}}, pedestrians=pedestrians)
    env.reset(seed=0)
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, (64, 2)).astype(np.float32)
    state = {"i": 0}

    def step() -> None:
        _, _, terminated, truncated, _ = env.step(actions[state["i"] % len(actions)])
        if terminated or truncated:
            env.reset()
        state["i"] += 1

    def reset() -> None:
        env.reset()

    return step, reset


def _reset_ms(reset: Callable[[], None], resets: int) -> float:
    """Mean milliseconds of ``resets`` calls of ``reset``."""
    start = time.perf_counter()
    for _ in range(resets):
        reset()
    return (time.perf_counter() - start) / resets * 1e3


def _first_steps(step: Callable[[], None], steps: int, agents: int) -> float:
    """Agent-steps per second of a fresh engine's first ``steps`` steps after its reset
    (its goal fields' blocks settled as robots first reach them, :mod:`pointnav_core.vector.fields`)."""
    start = time.perf_counter()
    for _ in range(steps):
        step()
    return steps * agents / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--worlds", type=int, default=1024)
    parser.add_argument("--robots", type=int, default=4)
    parser.add_argument("--rays", type=int, default=12)
    parser.add_argument("--pedestrians", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=3, help="rounds; each row keeps its best")
    parser.add_argument("--quick", action="store_true", help="a smoke run: 16 worlds, 1 round, a few steps")
    args = parser.parse_args()
    import torch

    torch.set_num_threads(1)
    worlds, rounds = (16, 1) if args.quick else (args.worlds, args.rounds)
    batch_steps, single_steps, resets = (3, 50, 2) if args.quick else (30, 2000, 20)
    robots, rays, walkers = args.robots, args.rays, args.pedestrians
    agents = worlds * robots
    vmas_key, ours_key = "VMAS navigation", f"batched engine, {rays}-ray scan"
    vmas_crowd_key = f"VMAS navigation + {walkers} pedestrians"
    ours_crowd_key = f"{ours_key}, {walkers} pedestrians per world"
    short_key = f"{ours_key} to {VMAS_LIDAR_RANGE} m"
    batched: dict[str, Callable[[], None]] = {ours_key: _batched(worlds, robots, rays),
                                              short_key: _batched(worlds, robots, rays, max_range=VMAS_LIDAR_RANGE)}
    vmas = vmas_navigation(worlds, robots, "cpu")
    if vmas is not None:
        if rays != 12:
            print(f"note: VMAS's navigation lidar keeps its default 12 rays; ours has {rays}")
        crowd = vmas_navigation(worlds, robots, "cpu", pedestrians=walkers)
        batched = {vmas_key: vmas, **batched, vmas_crowd_key: crowd}
    else:
        print("VMAS is not installed (pip install vmas, in the bench extra): no comparison")
    batched[ours_crowd_key] = _batched(worlds, robots, rays, walkers)
    # Every row walks the same steps before the clock starts, into its steady state: at a
    # reset every pedestrian has just planned (arrivals, a new exact plan each, come after
    # tens of steps), and the goal fields' blocks are settled as robots first reach them.
    # A fresh engine's first steps are timed apart, below.
    warm = 5 if args.quick else 1000
    for step in batched.values():
        for _ in range(warm):
            step()
    fresh_key = f"{short_key}, its first {warm} steps after a reset"
    fresh = _first_steps(_batched(worlds, robots, rays, max_range=VMAS_LIDAR_RANGE), warm, agents)
    alone = "single env, no pedestrians"
    single = {
        alone: _single(rays, None),
        f"single env, {walkers} ORCA pedestrians": _single(rays, {"count": walkers}),
        f"single env, {walkers} social-force pedestrians": _single(rays, {"count": walkers, "behaviour": "social_force"}),
    }
    best = dict.fromkeys([*batched, *single], 0.0)
    reset_ms = dict.fromkeys(single, float("inf"))
    start = time.perf_counter()
    for _ in range(rounds):
        for key, step in batched.items():
            best[key] = max(best[key], steps_per_second(step, batch_steps, agents, _no_sync))
        for key, (step, reset) in single.items():
            best[key] = max(best[key], steps_per_second(step, single_steps, 1, _no_sync))
            reset_ms[key] = min(reset_ms[key], _reset_ms(reset, resets))
    print(f"{machine()}; torch {torch.__version__}, one thread")
    print(f"best of {rounds} rounds ({time.perf_counter() - start:.0f} s); {worlds:,} worlds x {robots} robots, "
          f"{batch_steps} steps a round; single env {single_steps} steps and {resets} resets a round\n")
    print("| row | rate | ratio | target | reset |")
    print("|---|---:|---:|---:|---:|")
    size = f"({worlds:,} x {robots})"
    ref = best.get(vmas_key)
    if ref:
        print(f"| {vmas_key}, 12-ray lidar {size} | {ref:,.0f} agent-steps/s | 1.00 x | reference | - |")
    ratio = f"{best[ours_key] / ref:.2f} x VMAS" if ref else "-"
    print(f"| {ours_key} {size} | {best[ours_key]:,.0f} agent-steps/s | {ratio} | >= 3 x | - |")
    short = f"{best[short_key] / ref:.2f} x VMAS" if ref else "-"
    print(f"| {short_key}, VMAS's lidar range {size} | {best[short_key]:,.0f} agent-steps/s | {short} | >= 3 x (fair form) | - |")
    first = f"{fresh / ref:.2f} x VMAS" if ref else "-"
    print(f"| {fresh_key} (one pass, fields settling) {size} | {fresh:,.0f} agent-steps/s | {first} | - | - |")
    crowd_ref = best.get(vmas_crowd_key)
    if crowd_ref:
        print(f"| {vmas_crowd_key} (no lidar), robots counted {size} | {crowd_ref:,.0f} agent-steps/s | "
              f"{crowd_ref / ref:.2f} x VMAS | reference | - |")
    crowd_ratio = f"{best[ours_crowd_key] / crowd_ref:.2f} x VMAS + pedestrians" if crowd_ref else "-"
    print(f"| {ours_crowd_key} {size} | {best[ours_crowd_key]:,.0f} agent-steps/s | {crowd_ratio} | >= 1.0 x | - |")
    for key in single:
        target = "reference" if key == alone else (">= 0.5 x" if "ORCA" in key else "-")
        print(f"| {key} | {best[key]:,.0f} steps/s | {best[key] / best[alone]:.2f} x alone | {target} | "
              f"{reset_ms[key]:.1f} ms |")


if __name__ == "__main__":
    main()
