"""The batched engine from construction to its N-th step: build, first reset and the steps after.

A pool's goal fields settle as robots arrive (``vector.fields.FieldTables``), so the work
the build no longer does is done by the first steps instead. This benchmark times what a
user waits for: ``VectorPointNavEnv(--worlds, n_robots=--robots)`` on the default house,
constructed, reset (seed 0) and stepped with uniform random actions (seed 1), printing the
seconds from construction to the end of the reset and to steps 100, 400, 1,000, 2,000 ...

Each run is a fresh process that first builds and steps a small env on another floor, so
that numba's kernels are loaded (once per process) before the clock starts. With ``--old``
(another checkout's root) the two trees run alternately, ``--rounds`` times each, so that
both see the same machine.

Run: ``python benchmarks/bench_vector_first_steps.py [--worlds 1024] [--robots 4] [--steps 2000] [--old PATH]``
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

MARKS = (100, 400, 1000, 2000, 4000, 8000)


def child(worlds: int, robots: int, steps: int) -> None:
    """One run in this process (its ``sys.path`` set by the parent): prints the marks as JSON."""
    import numpy as np

    from pointnav_core.floor.maps import OBSTACLE
    from pointnav_core.scenes import Scene
    from pointnav_core.vector import VectorPointNavEnv

    grid = np.zeros((24, 30), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    small = VectorPointNavEnv(4, scene=Scene.from_array(grid, 0.1), seed=1, pool_size=2)
    small.reset()
    for _ in range(3):
        small.step(small.action_space.sample())
    start = time.perf_counter()
    env = VectorPointNavEnv(worlds, seed=0, **({"n_robots": robots} if robots > 1 else {}))
    env.reset(seed=0)
    marks = {"reset": time.perf_counter() - start}
    rng = np.random.default_rng(1)
    for i in range(1, steps + 1):
        env.step(rng.uniform(-1.0, 1.0, env.action_space.shape))
        if i in MARKS:
            marks[str(i)] = time.perf_counter() - start
    print(json.dumps(marks))


def run(tree: str, args: argparse.Namespace) -> dict[str, float]:
    """One fresh process of ``tree`` (a checkout's root); its marks."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([f"{tree}/src", f"{tree}/src/backends"]))
    out = subprocess.run(
        [sys.executable, os.path.abspath(__file__), "--child", str(args.worlds), str(args.robots), str(args.steps)],
        env=env, capture_output=True, text=True, check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--worlds", type=int, default=1024)
    parser.add_argument("--robots", type=int, default=4)
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--old", help="another checkout's root, run alternately with this one")
    parser.add_argument("--child", nargs=3, type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(*args.child)
        return
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    trees = [("new", here)] + ([("old", args.old)] if args.old else [])
    for r in range(args.rounds):
        for name, tree in trees if r % 2 == 0 else trees[::-1]:
            marks = run(tree, args)
            shown = ", ".join(f"{k} {v:.2f} s" for k, v in marks.items())
            print(f"{name:3s} {args.worlds} worlds x {args.robots}: from construction to {shown}", flush=True)


if __name__ == "__main__":
    main()
