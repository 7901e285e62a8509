"""Batched engine: a pool over many generated houses, built in worker processes and here.

Times ``VectorPointNavEnv(worlds, scene=[scenes.rooms(seed=s) for s in range(houses)])``
plus its first ``reset()`` (the pool: each house's episodes sampled and their goal fields
settled) for each ``--workers`` value, each with an empty geometry cache of its own (a
first build, nothing reloaded), and prints the times against the target: at most 120 s
for 100 houses on 2 cores. The CPU seconds of this process and of the workers tell what
the build costs when other jobs share the cores.

Run: ``python benchmarks/bench_vector_pool.py [--houses 100] [--worlds 256] [--workers 2 1]``
"""

from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time

from benchkit import machine

from pointnav_core import scenes
from pointnav_core.geodesic import cache
from pointnav_core.utils.workers import usable_cores
from pointnav_core.vector import VectorPointNavEnv

TARGET_S = 120.0


def build(houses: list[scenes.Scene], worlds: int, workers: int) -> tuple[float, float, float]:
    """Wall seconds of the env's construction plus its first reset, with a fresh cache
    folder, and the CPU seconds of this process and of its (ended) workers meanwhile."""
    with tempfile.TemporaryDirectory() as folder:
        os.environ[cache.ENV_VAR] = folder  # read by this process and the spawned workers
        children = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu, start = time.process_time(), time.perf_counter()
        env = VectorPointNavEnv(worlds, scene=houses, seed=0, workers=workers)
        env.reset()
        took, cpu = time.perf_counter() - start, time.process_time() - cpu
        env.close()
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return took, cpu, (after.ru_utime + after.ru_stime) - (children.ru_utime + children.ru_stime)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--houses", type=int, default=100)
    parser.add_argument("--worlds", type=int, default=256)
    parser.add_argument("--workers", type=int, nargs="+", default=[2, 1])
    args = parser.parse_args()
    print(machine(), f"({usable_cores()} usable cores)")
    start = time.perf_counter()
    houses = [scenes.rooms(seed=s) for s in range(args.houses)]
    print(f"{args.houses} houses generated in {time.perf_counter() - start:.1f} s (not counted below)")
    # Compile the kernels once (numba's own disk cache) so that no figure pays for it.
    VectorPointNavEnv(1, scene=houses[0], seed=0, pool_size=1, workers=1).reset()
    for workers in args.workers:
        took, cpu, worker_cpu = build(houses, args.worlds, workers)
        verdict = "" if args.houses != 100 else (" (target <= 120 s: met)" if took <= TARGET_S else " (target <= 120 s: NOT met)")
        print(f"  workers={workers}: build + first reset of {args.worlds} worlds over {args.houses} houses: {took:.1f} s{verdict}",
              flush=True)
        print(f"    CPU: this process {cpu:.1f} s, its workers {worker_cpu:.1f} s (load average now {os.getloadavg()[0]:.1f})",
              flush=True)


if __name__ == "__main__":
    main()
