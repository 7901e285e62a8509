"""The batched engine on real maps at their own resolution, at the default 10 Hz.

Two jobs, each in its own child process (``benchkit.measure``), with the geometry cache on
disk off (cold builds, as a new user's first run):

- ``bookstore``: ``VectorPointNavEnv(64)`` on the AWS RoboMaker bookstore map
  (``tests/data/bookstore``, read by ``tests/map_data.py``: a ROS map_server map, 384 x 384
  cells at 0.05 m; free below 0.196, occupied above 0.65, unknown as VOID), default robot, task and pool, 10 Hz. A
  0.5 m/s robot drives a whole cell a step: near walls each step is two sub-steps. Prints
  the build plus first reset against the geometry issue's target (at most 10 x the pool's
  episodes times one scipy 8-connected grid Dijkstra on the same grid), then ``--steps``
  steps of forward-biased random actions (full speed ahead 60 % of the time, seed 1): the
  first step with a contact, the median and the largest step, and the largest over the
  median (target: at most 10), in wall time and in process time.
- ``large``: ``VectorPointNavEnv(64)`` on a 1024 x 1024 map, built, reset and stepped
  ``--steps`` times: the map of ``--map`` (a MovingAI ``.map`` through
  ``Scene.from_movingai`` at 0.5 m) or, without it, a generated one of the same size
  (irregular blobs: smoothed noise over its 72nd percentile, 28 % blocked, seed 0; at
  0.5 m, 512 m a side). Prints the process's peak resident memory (``ru_maxrss``, imports
  included) against the 1 GB target.

Run: ``python benchmarks/bench_vector_maps.py [--jobs bookstore large] [--steps 300] [--map FILE]``
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import time
from pathlib import Path
from typing import Any

os.environ["POINTNAV_CACHE_DIR"] = "off"  # cold builds (before the children start)

from benchkit import machine, measure, start_children

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # map_data: the test data's readers

from map_data import bookstore

WORLDS = 64
#: Largest step over the median step, and peak memory (MiB) of the large job: the targets.
STEP_RATIO, PEAK_MIB = 10.0, 1024.0


def _peak_mib() -> float:
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 2**20 if sys.platform == "darwin" else peak / 1024


def blobs(side: int = 1024, seed: int = 0) -> Any:
    """A generated ``side`` x ``side`` map of irregular obstacles (28 % blocked), framed."""
    import numpy as np
    from scipy import ndimage

    field = ndimage.gaussian_filter(np.random.default_rng(seed).standard_normal((side, side)), 6)
    grid = (field > np.quantile(field, 0.72)).astype(np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = 1
    return grid


def setup(job: str, map_path: str | None) -> dict[str, Any]:
    from pointnav_core.scenes import Scene
    from pointnav_core.vector import VectorPointNavEnv  # noqa: F401  (imports are not timed)

    if job == "bookstore":
        return {"scene": bookstore(), "job": job}
    if map_path:
        return {"scene": Scene.from_movingai(map_path, resolution=0.5), "job": job}
    return {"scene": Scene.from_array(blobs(), 0.5), "job": job}


def grid_dijkstra(scene: Any) -> float:
    """Seconds of one scipy 8-connected Dijkstra over the scene's free cells (graph included),
    from the free cell nearest the map's centre (bench_geodesic's grid graph); best of 3."""
    import numpy as np
    from bench_geodesic import grid_graph
    from scipy.sparse import csgraph

    free = np.asarray(scene.floors[0].codes) == 0
    cells = np.argwhere(free)
    h, w = free.shape
    r, c = cells[np.argmin(((cells - (h / 2, w / 2)) ** 2).sum(1))]
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        csgraph.dijkstra(grid_graph(free), directed=True, indices=int(r * w + c))
        best = min(best, time.perf_counter() - start)
    return best


def run(state: dict[str, Any], lap: Any) -> dict[str, Any]:
    import numpy as np

    from pointnav_core.vector import VectorPointNavEnv

    env = VectorPointNavEnv(WORLDS, scene=state["scene"], seed=0)
    env.reset(seed=0)
    lap("reset")
    rng = np.random.default_rng(1)
    times, cpu, first = [], [], None
    for i in range(state["steps"]):
        act = rng.uniform(-1.0, 1.0, (WORLDS, 2))
        act[rng.random(WORLDS) < 0.6, 0] = 1.0
        start, start_cpu = time.perf_counter(), time.process_time()
        info = env.step(act)[4]
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
        if first is None and info["in_contact"].any():
            first = (i, times[-1])
    return {"times": times, "cpu": cpu, "first": first, "pool": env.pool_size, "peak": _peak_mib()}


def job_short(state: dict[str, Any], lap: Any) -> dict[str, Any]:
    return run({**state, "steps": int(os.environ.get("BENCH_STEPS", "300"))}, lap)


def report(name: str, m: Any, dijkstra: float | None) -> None:
    import numpy as np

    if m.error or m.timed_out:
        print(f"{name}: {'timed out' if m.timed_out else m.error}")
        return
    r = m.result
    times = np.array(r["times"])
    med, top = float(np.median(times)), float(times.max())
    print(f"{name}: build + first reset {m.laps['reset']:.2f} s", end="")
    if dijkstra is not None:
        ratio = m.laps["reset"] / (r["pool"] * dijkstra)
        print(f" = {ratio:.1f} x (pool {r['pool']} x grid Dijkstra {dijkstra * 1e3:.0f} ms; target <= 10)", end="")
    print()
    if r["first"] is not None:
        print(f"  first contact at step {r['first'][0]}: {r['first'][1] * 1e3:.2f} ms")
    else:
        print("  no contact in the steps run")
    print(f"  {len(times)} steps: median {med * 1e3:.2f} ms, max {top * 1e3:.2f} ms (step {int(times.argmax())}), "
          f"max / median {top / med:.1f} (target <= {STEP_RATIO:.0f})")
    cpu = np.array(r["cpu"])
    print(f"  in process time (what a shared machine's other jobs do not add): median {np.median(cpu) * 1e3:.2f} ms, "
          f"max {cpu.max() * 1e3:.2f} ms, max / median {cpu.max() / np.median(cpu):.1f}")
    verdict = "under" if r["peak"] <= PEAK_MIB else "OVER"
    print(f"  peak resident memory {r['peak']:.0f} MiB, imports included ({verdict} {PEAK_MIB:.0f} MiB)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", nargs="+", choices=("bookstore", "large"), default=["bookstore", "large"])
    parser.add_argument("--steps", type=int, default=300, help="steps timed after the reset")
    parser.add_argument("--map", default=None, help="a 1024 x 1024 MovingAI .map for the large job")
    parser.add_argument("--limit", type=float, default=600.0, help="seconds a job may run")
    args = parser.parse_args()
    os.environ["BENCH_STEPS"] = str(args.steps)
    start_children()
    print(machine())
    for name in args.jobs:
        dijkstra = None
        if name == "bookstore":
            sys.path.insert(0, str(Path(__file__).parent))
            dijkstra = grid_dijkstra(bookstore())
        m = measure(setup, job_short, (name, args.map), limit=args.limit)
        report(name if name == "bookstore" else f"large ({args.map or 'generated blobs, 1024 x 1024 at 0.5 m'})",
               m, dijkstra)


if __name__ == "__main__":
    main()
