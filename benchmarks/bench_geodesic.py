"""Geodesic speed and accuracy against the planners robot-learning code uses today.

Three modes; each prints the figures of one run, so that ratios are meaningful on a shared
machine.

Speed (default): for generated houses on 200x200, 400x400 and 1000x1000 grids, the time to
build the per-floor planner of :mod:`pointnav_core.geodesic.planner` (erosion, corners and
their arcs), to build one goal field, to query a cached field (a distance lookup and a whole
any-angle path), to find the same pair's path without a field (``Planner.shortest_path``,
the point-to-point search a crowd's plans run), and, for the same start/goal pairs, one query of pyastar2d's C++ A* and of
networkx A* on an 8-connected grid graph (how iGibson planned).

Accuracy (``--accuracy``, with the speed mode): relative error of ``get_shortest_path``
against the exact continuous geodesic on polygon floor plans at 0.05 m, beside an
8-connected grid search.

Scale (``--scale``, alone): wall time and peak memory of three jobs per case, each alone in
a child process (``benchkit.measure``; peak = the child's ``ru_maxrss`` minus its resident
memory after imports and loading the case, so C allocations count):

- ``scipy Dijkstra``: the 8-connected graph of the free cells, a diagonal move only where
  both cells beside it are free (no corner cutting), built with numpy and ``scipy.sparse``
  (the ``build`` lap), then one single-source ``csgraph.dijkstra`` from the start cell;
- ``pyastar2d``: its C++ A* from the start cell to the goal cell on the same grid (weight 1
  free, infinite blocked, ``allow_diagonal=True``). Its diagonal moves may cut blocked
  corners and cost as much as straight ones, so its length, measured in metres along its
  cells, can be longer or shorter than Dijkstra's;
- ``tangent``: ``geodesic.Planner(FloorCollision(blocked, res, origin), r)`` (the
  ``build`` lap), then its first ``shortest_path(start, goal)``;
- ``tangent, cached``: the same in a process whose floor's geometry is in the disk cache
  (``geodesic.cache``; a child process, not timed, built every edge into a fresh cache
  folder first, as ``pointnav scene build`` does): the form Habitat users know, whose
  navmesh is built once per scene and loaded from its file. The ``build`` lap is the
  planner's load.

The grid searches plan a point on the cell grid (no erosion for the radius), the cheapest
thing a grid planner does; the tangent planner plans the disc exactly, so lengths differ.
The ratio tangent / Dijkstra (whole jobs) is printed against the target 3.0. A job still
running after ``--limit`` seconds (default 600) is killed and shown as ``> limit``. Cases
(r = 0.18 m; start and goal nudged to the nearest cell centre the disc fits at):

- ``A``: 1000 x 1000 cells at 0.1 m, 2 % random single-cell clutter
  (``np.random.default_rng(0).random((1000, 1000)) < 0.02``), start near (5, 5) m, goal near
  (95, 95) m;
- ``B``: a 2000 x 2000 perfect maze at 0.5 m (randomized depth-first search, iterative,
  seed 0; corridors and walls one cell wide, like MovingAI's ``maze-*-1`` maps), start and
  goal near opposite corners;
- ``movingai``: ``den312d.map`` and ``maze-128-128-1.map`` from ``--movingai DIR`` (default
  ``$POINTNAV_MOVINGAI`` or ``/work/shared/data/movingai``) through
  ``Scene.from_movingai`` at 0.5 m, start and goal near opposite corners of the largest
  free region; skipped with a note when the files are absent (they are optional).

Breakdown (``--breakdown``, alone): where the tangent planner's time goes on smaller
versions of cases A and B (``--sizes``, default 500 and 1000 cells a side), in one
process: the 8-connected scipy Dijkstra as above (graph and search, from the goal cell),
then the planner's nodes, every tangent edge (``build_all_edges``), the arc-split graph,
the goal field's ``csgraph.dijkstra`` over it and one exact query; each as a multiple of
the grid Dijkstra.

Run::

    python benchmarks/bench_geodesic.py [--pairs 30] [--accuracy]
    python benchmarks/bench_geodesic.py --scale [--cases A B movingai] [--limit 600]
    python benchmarks/bench_geodesic.py --breakdown [--sizes 500 1000]

(needs the ``bench`` extra: ``pip install -e ".[bench]"``).
"""

from __future__ import annotations

import os

# Cold builds: the geometry cache on disk would reload a floor built by an earlier run.
os.environ.setdefault("POINTNAV_CACHE_DIR", "off")

import argparse
import math
import random
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from benchkit import (
    MOVINGAI_DIR,
    Measurement,
    machine,
    measure,
    movingai_maps,
    start_children,
)
from scipy import ndimage

from pointnav_core import scenes
from pointnav_core.floor.collision import FloorCollision

RADIUS = 0.18


def timed(fn, repeat=1):
    best = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best.append(time.perf_counter() - t0)
    return out, statistics.median(best)


def grid_pairs(scene, n, rng):
    tmap = scene.floors[0]
    pairs = []
    while len(pairs) < n:
        _, a = scene.get_random_point(0, robot=RADIUS, rng=rng)
        _, b = scene.get_random_point(0, reference_point=a, robot=RADIUS, rng=rng)
        pairs.append((a[:2], b[:2], tmap.world_to_cell(a[:2]), tmap.world_to_cell(b[:2])))
    return pairs


def networkx_graph(usable):
    import networkx as nx

    graph = nx.Graph()
    h, w = usable.shape
    for r, c in zip(*np.nonzero(usable)):
        for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
            rr, cc = r + dr, c + dc
            if 0 <= rr < h and 0 <= cc < w and usable[rr, cc]:
                if dr and dc and not (usable[r + dr, c] and usable[r, c + dc]):
                    continue
                graph.add_edge((r, c), (rr, cc), weight=math.hypot(dr, dc))
    return graph


def speed(args):
    import networkx as nx
    import pyastar2d

    cases = [
        ("200x200 (20 m, 0.10 m)", dict(size=(20.0, 20.0), resolution=0.1)),
        ("400x400 (20 m, 0.05 m)", dict(size=(20.0, 20.0), resolution=0.05)),
        ("1000x1000 (50 m, 0.05 m)", dict(size=(50.0, 50.0), resolution=0.05)),
    ]
    rows = []
    for name, kw in cases:
        scene = scenes.rooms(seed=args.seed, **kw)
        tmap = scene.floors[0]
        rng = np.random.default_rng(args.seed)
        _, t_planner = timed(lambda: scene.planner(0, RADIUS))  # built on first use, then cached
        pairs = grid_pairs(scene, args.pairs, rng)
        fields = []
        t_field = []
        for a, b, _, _ in pairs:
            # A new goal: corner distances, then the per-cell root table (first lookup).
            def build():
                field = scene.goal_field(0, b, robot=RADIUS)
                field.distance(*a)
                return field

            f, t = timed(build)
            fields.append(f)
            t_field.append(t)
        t_lookup = []
        t_path = []
        t_point = []
        planner = scene.planner(0, RADIUS)
        for (a, b, _, _), f in zip(pairs, fields):
            _, t = timed(lambda: f.distance(a[0], a[1]), repeat=50)
            t_lookup.append(t)
            _, t = timed(lambda: scene.get_shortest_path(0, a, b, entire_path=True, robot=RADIUS), repeat=5)
            t_path.append(t)
            # The same pair without the goal's field: the point-to-point search a crowd's plans run.
            _, t = timed(lambda: planner.shortest_path(a, b), repeat=5)
            t_point.append(t)
        usable = tmap.usable(RADIUS)
        weights = np.where(usable, 1.0, np.inf).astype(np.float32)
        t_astar = []
        for _, _, ca, cb in pairs:
            _, t = timed(lambda: pyastar2d.astar_path(weights, tuple(ca), tuple(cb), allow_diagonal=True), repeat=3)
            t_astar.append(t)
        t_nx = []
        if tmap.shape[0] * tmap.shape[1] <= args.max_nx_cells:
            graph = networkx_graph(usable)
            heuristic = lambda u, v: math.hypot(u[0] - v[0], u[1] - v[1])  # noqa: E731
            for _, _, ca, cb in pairs[: max(3, args.pairs // 5)]:
                _, t = timed(lambda: nx.astar_path(graph, tuple(ca), tuple(cb), heuristic=heuristic, weight="weight"))
                t_nx.append(t)
        med = statistics.median
        rows.append((name, t_planner, med(t_field), med(t_lookup), med(t_path), med(t_point), med(t_astar),
                     med(t_nx) if t_nx else math.nan))
    print(f"{'grid':26} {'planner':>9} {'field':>9} {'lookup':>9} {'path':>9} {'point':>9} {'pyastar2d':>10} "
          f"{'networkx':>10} {'astar/lookup':>13} {'astar/path':>11} {'astar/point':>12} {'nx/path':>9}")
    for name, tp, tf, tl, tq, tpt, ta, tn in rows:
        print(f"{name:26} {tp*1e3:8.1f}ms {tf*1e3:8.2f}ms {tl*1e6:8.2f}us {tq*1e6:8.1f}us {tpt*1e6:8.1f}us "
              f"{ta*1e3:9.2f}ms {tn*1e3:9.1f}ms {ta/tl:13.0f} {ta/tq:11.1f} {ta/tpt:12.1f} {tn/tq:9.0f}")
    print("planner: per floor and radius (erosion, corners, arcs), cached;"
          " field: per goal (arc-vertex distances + root table), cached; lookup:"
          " FloorGoalField.distance (the per-step query); path: get_shortest_path to a cached"
          " goal (checked, entire any-angle path); point: Planner.shortest_path of the same pair"
          " without a field (A* on the whole graph, one compiled call with numba); medians over pairs.")


def accuracy(args):
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from geodesic_reference import ContinuousGeodesic, house_plan
    from scipy.sparse import csgraph
    from test_geodesic_accuracy import RADIUS as R
    from test_geodesic_accuracy import relative_errors

    errors = relative_errors(seeds=tuple(range(args.plans)), pairs_per_plan=args.acc_pairs)
    print(f"pointnav-core any-angle: n={len(errors)} median {np.median(errors)*100:.3f}% "
          f"p95 {np.percentile(errors, 95)*100:.3f}% max {errors.max()*100:.3f}%")
    # 8-connected grid search on the same eroded grid, for scale.
    grid_err = []
    for seed in range(args.plans):
        outline, obstacles = house_plan(seed)
        reference = ContinuousGeodesic(outline, obstacles, R)
        scene = scenes.Scene.from_polygons(outline, obstacles, resolution=0.05)
        planner = scene.planner(0, R)
        g = planner.cell_graph()
        # Keep only king moves (weights 1 and sqrt 2).
        g = g.copy()
        g.data[g.data > 1.5] = 0
        g.eliminate_zeros()
        rng = np.random.default_rng(seed)
        tmap = scene.floors[0]
        for _ in range(args.acc_pairs // 2):
            _, a = scene.get_random_point(0, robot=R, rng=rng)
            _, b = scene.get_random_point(0, reference_point=a, robot=R, rng=rng)
            exact = reference.distance(a[:2], b[:2])
            if exact < 0.5 or not np.isfinite(exact):
                continue
            ca, cb = tmap.world_to_cell(a[:2]), tmap.world_to_cell(b[:2])
            w = tmap.shape[1]
            d = csgraph.dijkstra(g, indices=int(ca[0] * w + ca[1]))[int(cb[0] * w + cb[1])]
            grid_err.append(abs(d * 0.05 - exact) / exact)
    grid_err = np.array(grid_err)
    print(f"8-connected grid search:  n={len(grid_err)} median {np.median(grid_err)*100:.3f}% "
          f"p95 {np.percentile(grid_err, 95)*100:.3f}%")


# --------------------------------------------------------------------------- scale: cases
#: Largest acceptable tangent-planner time (build + first path) over one grid Dijkstra.
TARGET_RATIO = 3.0
#: MovingAI maps used as extra cases when present.
MOVINGAI_NAMES = ("den312d.map", "maze-128-128-1.map")


@dataclass
class Case:
    """One scale case: a blocked grid, its geometry and a start/goal pair (world metres)."""

    name: str
    blocked: np.ndarray
    resolution: float
    origin: tuple[float, float]
    start: np.ndarray
    goal: np.ndarray


def nearest_fitting_centre(
    geo: FloorCollision, allowed: np.ndarray, target: tuple[float, float], radius: float
) -> np.ndarray:
    """Centre (m) of the ``allowed`` cell nearest ``target`` where a disc of ``radius`` fits."""
    rows, cols = np.nonzero(allowed)
    res, (ox, oy) = geo.resolution, geo.origin
    centres = np.stack([ox + (cols + 0.5) * res, oy + (rows + 0.5) * res], axis=1)
    order = np.argsort(np.hypot(centres[:, 0] - target[0], centres[:, 1] - target[1]), kind="stable")
    for lo in range(0, len(order), 1024):  # nearest first, a batch at a time
        batch = centres[order[lo : lo + 1024]]
        ok = np.flatnonzero(geo.points_clear(batch, radius))
        if len(ok):
            return batch[ok[0]]
    raise ValueError(f"no allowed cell fits a disc of radius {radius} m")


def clutter_case(size: int = 1000, resolution: float = 0.1) -> Case:
    """Case A: ``size`` squared cells with 2 % random single-cell clutter (seed 0)."""
    rng = np.random.default_rng(0)
    blocked = rng.random((size, size)) < 0.02
    geo = FloorCollision(blocked, resolution, (0.0, 0.0))
    extent = size * resolution
    start = nearest_fitting_centre(geo, ~blocked, (0.05 * extent, 0.05 * extent), RADIUS)
    goal = nearest_fitting_centre(geo, ~blocked, (0.95 * extent, 0.95 * extent), RADIUS)
    name = f"A clutter {size}x{size} {resolution:g} m"
    return Case(name, blocked, resolution, (0.0, 0.0), start, goal)


def maze_grid(size: int, seed: int = 0) -> np.ndarray:
    """A perfect maze of ``size`` x ``size`` cells (True = wall), by randomized depth-first search.

    Rooms are the cells with both indices even, corridors and walls one cell wide (the
    layout of MovingAI's ``maze-*-1`` maps); the odd last row and column, if any, are wall.
    The search is iterative and seeded, so the maze depends on ``seed`` only.
    """
    if size < 1:
        raise ValueError(f"size must be >= 1, got {size}")
    n = (size + 1) // 2  # rooms per side
    rnd = random.Random(seed)
    visited = bytearray(n * n)
    visited[0] = 1
    stack = [0]
    came, went = [], []
    while stack:
        cur = stack[-1]
        i, j = divmod(cur, n)
        options = []
        if i > 0 and not visited[cur - n]:
            options.append(cur - n)
        if i < n - 1 and not visited[cur + n]:
            options.append(cur + n)
        if j > 0 and not visited[cur - 1]:
            options.append(cur - 1)
        if j < n - 1 and not visited[cur + 1]:
            options.append(cur + 1)
        if not options:
            stack.pop()
            continue
        nxt = options[rnd.randrange(len(options))]
        visited[nxt] = 1
        came.append(cur)
        went.append(nxt)
        stack.append(nxt)
    blocked = np.ones((size, size), dtype=bool)
    blocked[0 : 2 * n : 2, 0 : 2 * n : 2] = False
    a, b = np.asarray(came, dtype=np.int64), np.asarray(went, dtype=np.int64)
    blocked[a // n + b // n, a % n + b % n] = False  # the wall between two rooms
    return blocked


def maze_case(size: int = 2000, resolution: float = 0.5, seed: int = 0) -> Case:
    """Case B: a ``size`` squared perfect maze, start and goal near opposite corners."""
    blocked = maze_grid(size, seed)
    geo = FloorCollision(blocked, resolution, (0.0, 0.0))
    extent = size * resolution
    start = nearest_fitting_centre(geo, ~blocked, (0.0, 0.0), RADIUS)
    goal = nearest_fitting_centre(geo, ~blocked, (extent, extent), RADIUS)
    name = f"B maze {size}x{size} {resolution:g} m"
    return Case(name, blocked, resolution, (0.0, 0.0), start, goal)


def movingai_case(path: Path, resolution: float = 0.5) -> Case:
    """A MovingAI map through ``Scene.from_movingai``: start and goal near opposite corners
    of its largest 4-connected free region (where they are sure to be joined)."""
    from pointnav_core.scenes import Scene

    tmap = Scene.from_movingai(path, resolution=resolution).floors[0]
    geo = tmap.collision
    blocked = np.asarray(geo.blocked)
    labels, count = ndimage.label(~blocked)
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    sizes[0] = 0
    region = labels == int(np.argmax(sizes))
    (ox, oy), (h, w) = geo.origin, blocked.shape
    far = (ox + w * resolution, oy + h * resolution)
    start = nearest_fitting_centre(geo, region, (ox, oy), RADIUS)
    goal = nearest_fitting_centre(geo, region, far, RADIUS)
    return Case(f"{path.name} {w}x{h} {resolution:g} m", blocked, resolution, geo.origin, start, goal)


# --------------------------------------------------------------------------- scale: jobs (children)
def load_case(path: str) -> dict[str, Any]:
    """Child setup: import every planner and read the case file."""
    import pyastar2d  # noqa: F401
    from scipy.sparse import csgraph  # noqa: F401

    import pointnav_core.geodesic.planner  # noqa: F401

    with np.load(path) as f:
        case = {key: f[key] for key in f.files}
    res = float(case["resolution"])
    ox, oy = case["origin"]
    for key in ("start", "goal"):
        x, y = case[key]
        case[key + "_cell"] = (int((y - oy) // res), int((x - ox) // res))
    return case


def grid_graph(free: np.ndarray) -> Any:
    """8-connected graph (CSR, both directions) of the ``free`` cells, weights in cells.

    A diagonal move needs all four cells of its 2x2 block free (no corner cutting).
    """
    from scipy import sparse

    h, w = free.shape
    idx = np.arange(h * w, dtype=np.int32).reshape(h, w)
    block = free[:-1, :-1] & free[1:, 1:] & free[1:, :-1] & free[:-1, 1:]
    moves = (
        (free[:, :-1] & free[:, 1:], idx[:, :-1], idx[:, 1:], 1.0),
        (free[:-1, :] & free[1:, :], idx[:-1, :], idx[1:, :], 1.0),
        (block, idx[:-1, :-1], idx[1:, 1:], math.sqrt(2.0)),
        (block, idx[:-1, 1:], idx[1:, :-1], math.sqrt(2.0)),
    )
    src = np.concatenate([a[m] for m, a, _, _ in moves])
    dst = np.concatenate([b[m] for m, _, b, _ in moves])
    wts = np.concatenate([np.full(int(m.sum()), c) for m, _, _, c in moves])
    return sparse.csr_matrix(
        (np.concatenate([wts, wts]), (np.concatenate([src, dst]), np.concatenate([dst, src]))),
        shape=(h * w, h * w),
    )


def job_dijkstra(case: dict[str, Any], lap: Any) -> float:
    """Graph of the free cells and one single-source Dijkstra; the goal's distance (m)."""
    from scipy.sparse import csgraph

    blocked = case["blocked"]
    graph = grid_graph(~blocked)
    lap("build")
    w = blocked.shape[1]
    (sr, sc), (gr, gc) = case["start_cell"], case["goal_cell"]
    dist = csgraph.dijkstra(graph, directed=True, indices=sr * w + sc)
    return float(dist[gr * w + gc]) * float(case["resolution"])


def job_astar(case: dict[str, Any], lap: Any) -> float:
    """pyastar2d from the start cell to the goal cell; the path's length (m)."""
    import pyastar2d

    weights = np.where(case["blocked"], np.inf, 1.0).astype(np.float32)
    path = pyastar2d.astar_path(weights, case["start_cell"], case["goal_cell"], allow_diagonal=True)
    if path is None:
        return math.inf
    steps = np.diff(path, axis=0)
    return float(np.hypot(steps[:, 0], steps[:, 1]).sum()) * float(case["resolution"])


def job_tangent(case: dict[str, Any], lap: Any) -> float:
    """Tangent planner build, then its first exact shortest path; the length (m)."""
    from pointnav_core.geodesic.planner import Planner

    geo = FloorCollision(case["blocked"], float(case["resolution"]), tuple(case["origin"]))
    planner = Planner(geo, float(case["radius"]))
    lap("build")
    _, length = planner.shortest_path(case["start"], case["goal"])
    return math.inf if length is None else float(length)


def job_fill_cache(case: dict[str, Any], lap: Any) -> float:
    """Untimed set-up of ``tangent, cached``: every edge of the floor, kept in the disk cache."""
    from pointnav_core.geodesic import cache
    from pointnav_core.geodesic.planner import Planner

    os.environ["POINTNAV_CACHE_DIR"] = str(case["cache"])
    cache.MIN_SECONDS = 0.0  # keep it however quick
    geo = FloorCollision(case["blocked"], float(case["resolution"]), tuple(case["origin"]))
    planner = Planner(geo, float(case["radius"]))
    planner.build_all_edges()
    return float(planner.cached)


def job_tangent_cached(case: dict[str, Any], lap: Any) -> float:
    """``tangent`` with the floor's geometry in the disk cache folder ``case["cache"]``."""
    os.environ["POINTNAV_CACHE_DIR"] = str(case["cache"])
    return job_tangent(case, lap)


JOBS = (("scipy Dijkstra", job_dijkstra), ("pyastar2d", job_astar), ("tangent", job_tangent))


# --------------------------------------------------------------------------- breakdown
def breakdown(sizes: list[int]) -> None:
    """Time each stage of a goal field on cases A and B beside one grid Dijkstra."""
    from scipy.sparse import csgraph

    from pointnav_core.geodesic.planner import Planner

    print(f"machine: {machine()}")
    print(f"radius {RADIUS} m; times in s, and as multiples of the grid Dijkstra (x)")
    print(f"{'case':28} {'grid':>7} {'nodes':>14} {'edges':>14} {'arc graph':>14} {'field':>13} {'query':>7} {'all':>8}")
    for size in sizes:
        for case in (clutter_case(size), maze_case(size)):
            h, w = case.blocked.shape
            gr = int((case.goal[1] - case.origin[1]) // case.resolution)
            gc = int((case.goal[0] - case.origin[0]) // case.resolution)
            t0 = time.perf_counter()
            csgraph.dijkstra(grid_graph(~case.blocked), directed=True, indices=gr * w + gc)
            grid = time.perf_counter() - t0
            laps = [time.perf_counter()]
            planner = Planner(FloorCollision(case.blocked, case.resolution, case.origin), RADIUS)
            laps.append(time.perf_counter())
            planner.build_all_edges()
            laps.append(time.perf_counter())
            graph = planner.arc_graph()
            laps.append(time.perf_counter())
            field = planner.goal_field(case.goal)
            laps.append(time.perf_counter())
            field.point_distance(case.start)
            laps.append(time.perf_counter())
            cells = [f"{b - a:6.2f} {(b - a) / grid:5.0f}x" for a, b in zip(laps, laps[1:])]
            cells[3] = f"{laps[4] - laps[3]:5.3f} {(laps[4] - laps[3]) / grid:5.1f}x"
            cells[4] = f"{laps[5] - laps[4]:7.3f}"
            print(f"{case.name:28} {grid:7.3f} {cells[0]:>14} {cells[1]:>14} {cells[2]:>14} {cells[3]:>13} "
                  f"{cells[4]:>7} {(laps[-1] - laps[0]) / grid:7.0f}x   ({planner.n_nodes:,} nodes, "
                  f"{graph.n_vertices:,} arc vertices)", flush=True)


# --------------------------------------------------------------------------- scale: driver
def _fmt_time(m: Measurement, key: str, limit: float) -> str:
    if key in m.laps:
        t = m.laps[key]
        return f"{t:.3f}" if t < 10 else f"{t:.1f}"
    return f"> {limit:g}" if m.timed_out else "-"


def scale(case_names: list[str], limit: float, movingai_dir: Path) -> None:
    """Build the chosen cases, measure every job on each, print the table."""
    start_children()  # before the big arrays exist
    print(f"machine: {machine()}")
    print(f"radius {RADIUS} m, limit {limit:g} s per job; times in s, peak in MiB above setup")
    builders: list[tuple[str, Any]] = []
    if "A" in case_names:
        builders.append(("A", clutter_case))
    if "B" in case_names:
        builders.append(("B", maze_case))
    if "movingai" in case_names:
        for path in movingai_maps(movingai_dir, MOVINGAI_NAMES):
            builders.append((path.name, lambda p=path: movingai_case(p)))
    header = f"{'case':34} {'job':15} {'build':>8} {'total':>8} {'peak':>8} {'length m':>10}"
    with tempfile.TemporaryDirectory() as tmp:
        for index, (_, build) in enumerate(builders):
            t0 = time.perf_counter()
            case = build()
            file = str(Path(tmp) / f"case{index}.npz")
            np.savez(file, blocked=case.blocked, resolution=case.resolution, origin=np.array(case.origin),
                     start=case.start, goal=case.goal, radius=RADIUS)
            h, w = case.blocked.shape
            print(f"\n{case.name}: {h * w:,} cells, {case.blocked.mean():.1%} blocked, start "
                  f"({case.start[0]:.2f}, {case.start[1]:.2f}), goal ({case.goal[0]:.2f}, "
                  f"{case.goal[1]:.2f}) m; case built in {time.perf_counter() - t0:.1f} s")
            print(header)
            got = {}
            for label, job in JOBS:
                m = measure(load_case, job, (file,), limit=limit)
                got[label] = m
                peak = "-" if math.isnan(m.peak_mib) else f"{m.peak_mib:.0f}"
                if m.timed_out and peak != "-":
                    peak = ">= " + peak  # the peak until it was stopped
                length = "-" if m.result is None else f"{m.result:.3f}"
                print(f"{case.name:34} {label:15} {_fmt_time(m, 'build', limit):>8} "
                      f"{_fmt_time(m, 'total', limit):>8} {peak:>8} {length:>10}", flush=True)
                if m.error:
                    print(f"  failed:\n{m.error}")
            got["tangent, cached"] = _cached_job(case.name, file, Path(tmp) / f"cache{index}", limit)
            base = got["scipy Dijkstra"].laps.get("total")
            for label in ("tangent", "tangent, cached"):
                tan = got[label]
                if base and "total" in tan.laps:
                    ratio = tan.laps["total"] / base
                    verdict = "met" if ratio <= TARGET_RATIO else "MISSED"
                    print(f"  {label} / Dijkstra = {ratio:.1f} (target <= {TARGET_RATIO:g}): {verdict}")
                elif base and tan.timed_out:
                    print(f"  {label} / Dijkstra > {limit / base:.0f} (target <= {TARGET_RATIO:g}): MISSED")


def _cached_job(name: str, file: str, folder: Path, limit: float) -> Any:
    """``tangent, cached``: fill a fresh cache ``folder`` in one child (not timed), then time
    the planner's load and first path in another; prints its row."""
    with np.load(file) as f:
        arrays = {key: f[key] for key in f.files}
    file = file.replace(".npz", "_cached.npz")
    np.savez(file, **arrays, cache=str(folder))  # the children set the folder themselves
    filled = measure(load_case, job_fill_cache, (file,), limit=limit)
    m = measure(load_case, job_tangent_cached, (file,), limit=limit)
    if not filled.result:
        print(f"  (the cache was not filled: {filled.error or 'timed out' if filled.timed_out else 'not kept'})")
    peak = "-" if math.isnan(m.peak_mib) else f"{m.peak_mib:.0f}"
    length = "-" if m.result is None else f"{m.result:.3f}"
    print(f"{name:34} {'tangent, cached':15} {_fmt_time(m, 'build', limit):>8} "
          f"{_fmt_time(m, 'total', limit):>8} {peak:>8} {length:>10}", flush=True)
    return m


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--pairs", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--max-nx-cells", type=int, default=200_000)
    parser.add_argument("--accuracy", action="store_true")
    parser.add_argument("--plans", type=int, default=3)
    parser.add_argument("--acc-pairs", type=int, default=70)
    parser.add_argument("--scale", action="store_true", help="run the scale benchmark only")
    parser.add_argument("--breakdown", action="store_true", help="time the planner's stages only")
    parser.add_argument("--sizes", nargs="+", type=int, default=[500, 1000], help="cells a side (--breakdown)")
    parser.add_argument("--cases", nargs="+", choices=("A", "B", "movingai"), default=["A", "B", "movingai"])
    parser.add_argument("--limit", type=float, default=600.0, help="seconds per scale job (default 600)")
    parser.add_argument("--movingai", type=Path, default=MOVINGAI_DIR, help="folder of the MovingAI maps")
    args = parser.parse_args()
    if not args.limit > 0:
        parser.error(f"--limit must be > 0 seconds, got {args.limit}")
    if args.scale:
        scale(args.cases, args.limit, args.movingai)
        return
    if args.breakdown:
        breakdown(args.sizes)
        return
    speed(args)
    if args.accuracy:
        accuracy(args)


if __name__ == "__main__":
    main()
