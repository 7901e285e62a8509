"""Building the batched engine on a large map: the wait before the first step.

A square map of ``--side`` cells (0.1 m) holds ``--boxes`` random boxes of 2-9 cells a side
(seed 0). ``VectorPointNavEnv(--worlds, n_robots=--robots, pool_size=--pool-size)`` with
geodesic rewards and a ``--rays``-ray scan is built on it and reset (seed 0): sampling the
episodes (each goal's field, the first one building the planner's tangent graph), settling
the fields within each episode's reach, and the engine's tables. Prints the seconds that
took, the fields' windows and the process's peak memory; then, unless ``--steps 0``, the
seconds of that many steps of fixed uniform actions in [-1, 1].

Run: ``python benchmarks/bench_build.py [--side 1000] [--boxes 760] [--robots 4] [--steps 0]``
"""

from __future__ import annotations

import argparse
import os
import resource
import time

import numpy as np

# Cold builds: the geometry cache on disk would reload a floor built by an earlier run
# (run with POINTNAV_CACHE_DIR set to a folder to measure a warm one).
os.environ.setdefault("POINTNAV_CACHE_DIR", "off")

from pointnav_core import scenes
from pointnav_core.vector import VectorPointNavEnv


def grid(side: int, boxes: int) -> np.ndarray:
    """The map: ``boxes`` random boxes (code 1) of 2-9 cells a side on a free square."""
    rng = np.random.default_rng(0)
    g = np.zeros((side, side), np.uint8)
    for _ in range(boxes):
        r, c = rng.integers(0, side - 10, 2)
        h, w = rng.integers(2, 10, 2)
        g[r : r + h, c : c + w] = 1
    return g


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=1000, help="cells per side (0.1 m each)")
    parser.add_argument("--boxes", type=int, default=760, help="random boxes")
    parser.add_argument("--robots", type=int, default=4, help="robots per world")
    parser.add_argument("--worlds", type=int, default=64, help="worlds")
    parser.add_argument("--pool-size", type=int, default=2, help="episodes sampled per scene")
    parser.add_argument("--rays", type=int, default=32, help="scan rays")
    parser.add_argument("--steps", type=int, default=0, help="steps timed after the reset")
    args = parser.parse_args()
    scene = scenes.Scene.from_array(grid(args.side, args.boxes), 0.1)
    start = time.perf_counter()
    env = VectorPointNavEnv(
        args.worlds, n_robots=args.robots, scene=scene, seed=0, pool_size=args.pool_size,
        task={"reward_type": "geodesic"}, sensors={"scan": {"n_rays": args.rays}},
    )
    obs, _ = env.reset(seed=0)
    built = time.perf_counter() - start
    f = env.pool.fields
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"{args.side} x {args.side} cells, {args.boxes} boxes: built and reset in {built:.1f} s, "
          f"observations {tuple(obs.shape)}, field cells {int(f.kind.shape[0])}, "
          f"windows {f.rows.tolist()} x {f.width.tolist()}, peak memory {peak:.0f} MB")
    if args.steps:
        shape = (args.steps, args.worlds, args.robots, 2) if args.robots > 1 else (args.steps, args.worlds, 2)
        actions = np.random.default_rng(1).uniform(-1, 1, shape)
        start = time.perf_counter()
        for a in actions:
            env.step(a)
        print(f"{args.steps} steps in {time.perf_counter() - start:.2f} s")


if __name__ == "__main__":
    main()
