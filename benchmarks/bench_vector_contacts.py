"""Cost of the batched contact resolvers, array and compiled paths, on the same robots.

4,096 robots of radius 0.18 m on a 20 x 15 m floor with 5 % random clutter (0.1 m cells),
each with a 0.05 m chord (a full-speed step at 10 Hz) in a random direction: once as 4,096
one-robot worlds through ``vector.contacts.advance`` (no robot-robot contacts), once as
1,024 worlds x 4 robots through ``vector.robots.advance_robots`` (walls and robots, one
event clock per world), and both again through the compiled path
(``vector.contacts_jit.advance_compiled``, numba, the ``fast`` extra) that the engines
take on the CPU. Numpy, one thread, best of 5 calls each (process time: the machines are
shared); the ratios are the figures.

Usage: ``python benchmarks/bench_vector_contacts.py``
"""

from __future__ import annotations

import math
import time

import numpy as np

from pointnav_core.scenes import Scene
from pointnav_core.vector.contacts import advance
from pointnav_core.vector.contacts_jit import advance_compiled
from pointnav_core.vector.floors import FloorTables
from pointnav_core.vector.robots import advance_robots, robot_walls
from pointnav_core.vector.xp import make_arrays


def main() -> None:
    rng = np.random.default_rng(0)
    grid = (rng.random((150, 200)) < 0.05).astype(np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = 1
    scene = Scene.from_array(grid, 0.1)
    n_worlds, n_robots, radius, travel = 1024, 4, 0.18, 0.05
    points: list[np.ndarray] = []
    while len(points) < n_worlds * n_robots:
        p = rng.uniform(0.5, [19.5, 14.5])
        if scene.is_usable(0, p, radius):
            points.append(p)
    pos = np.array(points).reshape(n_worlds, n_robots, 2)
    heading = rng.uniform(-math.pi, math.pi, (n_worlds, n_robots))
    mx, my = travel * np.cos(heading), travel * np.sin(heading)
    a = make_arrays("numpy")
    floors = FloorTables([scene], 0, radius, a)
    sc = np.zeros((n_worlds, n_robots), np.int64)
    limit = travel * (1 + 1e-9)

    def single() -> object:
        return advance(floors, sc.ravel(), pos[..., 0].ravel(), pos[..., 1].ravel(), mx.ravel(), my.ravel(), radius, limit)

    def multi() -> object:
        walls = robot_walls(floors, sc, pos[..., 0], pos[..., 1], mx, my, radius, limit)
        return advance_robots(a, pos[..., 0], pos[..., 1], mx, my, radius, walls=walls)

    every = np.ones((n_worlds, n_robots), bool)

    def single_compiled() -> object:
        return advance_compiled(floors, sc.reshape(-1, 1), pos[..., 0].reshape(-1, 1), pos[..., 1].reshape(-1, 1),
                                mx.reshape(-1, 1), my.reshape(-1, 1), every.reshape(-1, 1), radius, limit)

    def multi_compiled() -> object:
        return advance_compiled(floors, sc, pos[..., 0], pos[..., 1], mx, my, every, radius, limit)

    runs = {
        "one-robot, array path, 4,096 x 1": single,
        "multi-robot, array path, 1,024 x 4": multi,
        "one-robot, compiled, 4,096 x 1": single_compiled,
        "multi-robot, compiled, 1,024 x 4": multi_compiled,
    }
    best = {}
    with np.errstate(all="ignore"):
        for name, f in runs.items():
            f()
            times = []
            for _ in range(5):
                t0 = time.process_time()
                f()
                times.append(time.process_time() - t0)
            best[name] = min(times)
            print(f"{name}: {best[name] * 1e3:.2f} ms per call")
    one, multi_ = best["one-robot, array path, 4,096 x 1"], best["multi-robot, array path, 1,024 x 4"]
    print(f"multi / one-robot, array path: {multi_ / one:.1f} x")
    print(f"array / compiled: one-robot {one / best['one-robot, compiled, 4,096 x 1']:.1f} x, "
          f"multi-robot {multi_ / best['multi-robot, compiled, 1,024 x 4']:.1f} x")


if __name__ == "__main__":
    main()
