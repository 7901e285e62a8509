"""Batched engine on one house: the pool's build and first reset against grid Dijkstras.

The geometry issue's point 3: ``VectorPointNavEnv(256)`` on the default house's grid
(``Scene.from_array`` of ``scenes.rooms(seed=0)``'s codes), constructed and reset once, in
a fresh process (numba's kernels load from its cache inside the clock), against its pool's
episodes times one scipy 8-connected Dijkstra on the same grid (``csgraph.dijkstra`` from
one free cell, the graph built before the clock). Target: at most 10 x.

Two geometry caches are measured, each in processes of their own:

- ``cold``: an empty cache folder, as on a new machine: the floor's tangent graph is built
  and every goal's roots are settled link by link;
- ``warm``: the folder after ``pointnav scene build`` of the same floor (its tangent graph
  and every cell's clear links), as in every later process: a goal's roots cost one segment
  test per cell.

And a third form, ``warm, kernels loaded``: the warm cache, in a process that has already
built and stepped a small env on another floor, before the clock. numba itself is imported
before the clock in every form, as scipy is; but scipy's Dijkstra is compiled code loaded
at import, while numba's kernels load from their cache on first call (about 0.4 s per
process, once), inside our clock. This form compares the two with their compiled code
loaded alike; the library's caches hold nothing of the house.

The batched engine settles goal fields lazily (``FieldTables``): the build samples the
pool's episodes and runs each goal's search, and the cells are settled as robots arrive.

Run: ``python benchmarks/bench_pool_cost.py [--worlds 256] [--rounds 3]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
from typing import Any

import numpy as np
from benchkit import machine, measure, start_children

TARGET = 10.0


def _scene() -> Any:
    from pointnav_core import scenes
    from pointnav_core.scenes import Scene

    return Scene.from_array(np.asarray(scenes.rooms(seed=0).floors[0].codes), scenes.rooms(seed=0).floors[0].resolution)


def _env_setup(folder: str, worlds: int) -> tuple[Any, int]:
    os.environ["POINTNAV_CACHE_DIR"] = folder
    import numba  # noqa: F401  (imports outside the clock, as scipy's are; kernels load inside)

    import pointnav_core.vector  # noqa: F401

    return _scene(), worlds


def _loaded_setup(folder: str, worlds: int) -> tuple[Any, int]:
    state = _env_setup(folder, worlds)
    from pointnav_core.floor.maps import OBSTACLE
    from pointnav_core.scenes import Scene
    from pointnav_core.vector import VectorPointNavEnv

    grid = np.zeros((24, 30), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[12, :18] = OBSTACLE
    small = VectorPointNavEnv(4, scene=Scene.from_array(grid, 0.1), seed=1, pool_size=2)
    small.reset()
    for _ in range(3):
        small.step(np.zeros((4, 2)))
    return state


def _env_job(state: tuple[Any, int], lap: Any) -> int:
    from pointnav_core.vector import VectorPointNavEnv

    scene, worlds = state
    env = VectorPointNavEnv(worlds, scene=scene, seed=0)
    env.reset()
    return int(env.pool_size)


def _fill_setup(folder: str) -> Any:
    os.environ["POINTNAV_CACHE_DIR"] = folder
    return _scene()


def _fill_job(scene: Any, lap: Any) -> bool:
    from pointnav_core.backends.robot_spec import RobotSpec
    from pointnav_core.geodesic import planner_for

    planner = planner_for(scene.floors[0], RobotSpec().radius)
    planner.build_all_edges()
    return planner.cell_links() is not None and planner.cached


def _dijkstra_setup(episodes: int) -> tuple[Any, list[int], int]:
    from scipy.sparse import coo_matrix

    free = np.asarray(_scene().floors[0].codes) == 0
    h, w = free.shape
    ids = np.arange(h * w).reshape(h, w)
    src, dst, cost = [], [], []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        c0, c1 = max(0, -dc), w - max(0, dc)
        both = free[: h - dr, c0:c1] & free[dr:, c0 + dc : c1 + dc]
        src.append(ids[: h - dr, c0:c1][both])
        dst.append(ids[dr:, c0 + dc : c1 + dc][both])
        cost.append(np.full(int(both.sum()), float(np.hypot(dr, dc))))
    s, d, c = (np.concatenate(v) for v in (src, dst, cost))
    graph = coo_matrix((c, (s, d)), shape=(h * w, h * w)).tocsr()
    rng = np.random.default_rng(0)
    sources = rng.choice(np.flatnonzero(free.ravel()), episodes, replace=False).tolist()
    return graph, sources, episodes


def _dijkstra_job(state: tuple[Any, list[int], int], lap: Any) -> int:
    from scipy.sparse.csgraph import dijkstra

    graph, sources, _ = state
    for s in sources:
        dijkstra(graph, directed=False, indices=s)
    return len(sources)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--worlds", type=int, default=256)
    parser.add_argument("--episodes", type=int, default=8, help="the pool's episodes (the engine's default)")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    start_children()
    print(machine())
    with tempfile.TemporaryDirectory() as warm:
        fill = measure(_fill_setup, _fill_job, (warm,))
        if fill.error or not fill.result:
            raise SystemExit(f"could not fill the warm cache: {fill.error or 'no links kept'}")
        print(f"pointnav scene build of the floor (tangent graph and cell links): {fill.laps['total']:.2f} s")
        rows: dict[str, list[float]] = {"cold": [], "warm": [], "warm, kernels loaded": [], "dijkstra": []}
        for _ in range(args.rounds):  # alternating, so that both see the same machine
            with tempfile.TemporaryDirectory() as cold:
                for name, folder, setup in (("cold", cold, _env_setup), ("warm", warm, _env_setup),
                                            ("warm, kernels loaded", warm, _loaded_setup)):
                    m = measure(setup, _env_job, (folder, args.worlds))
                    if m.error:
                        raise SystemExit(m.error)
                    rows[name].append(m.laps["total"])
            d = measure(_dijkstra_setup, _dijkstra_job, (args.episodes,))
            rows["dijkstra"].append(d.laps["total"])
    dij = statistics.median(rows["dijkstra"])
    print(f"{args.episodes} scipy 8-connected Dijkstras: median {dij * 1e3:.1f} ms over {args.rounds} rounds")
    for name in ("cold", "warm", "warm, kernels loaded"):
        t = statistics.median(rows[name])
        print(f"VectorPointNavEnv({args.worlds}) build + first reset, {name} cache: median {t:.3f} s "
              f"= {t / dij:.0f} x (target <= {TARGET:.0f} x); rounds {', '.join(f'{v:.3f}' for v in rows[name])} s")


if __name__ == "__main__":
    main()
