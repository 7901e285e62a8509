"""Geodesic speed and accuracy against the planners robot-learning code uses today.

Speed (one run, so the ratios are meaningful on a shared machine): for generated houses on
200x200, 400x400 and 1000x1000 grids, the time to build the per-floor planner (erosion,
corners, corner graph), to build one goal field, to query a cached field (a distance lookup
and a whole any-angle path), and, for the same start/goal pairs, one query of pyastar2d's
C++ A* and of networkx A* on an 8-connected grid graph (how iGibson planned).

Accuracy (``--accuracy``): relative error of ``get_shortest_path`` against the exact
continuous geodesic on polygon floor plans at 0.05 m, beside an 8-connected grid search.

Run: ``python benchmarks/bench_geodesic.py [--pairs 30] [--accuracy]``
(needs the ``bench`` extra: ``pip install -e ".[bench]"``).
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from pointnav_core import scenes

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
        _, t_planner = timed(lambda: scene.planner(0, RADIUS).component_graph(1) and scene.planner(0, RADIUS).cell_graph())
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
        for (a, b, _, _), f in zip(pairs, fields):
            _, t = timed(lambda: f.distance(a[0], a[1]), repeat=50)
            t_lookup.append(t)
            _, t = timed(lambda: scene.get_shortest_path(0, a, b, entire_path=True, robot=RADIUS), repeat=5)
            t_path.append(t)
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
        rows.append((name, t_planner, med(t_field), med(t_lookup), med(t_path), med(t_astar),
                     med(t_nx) if t_nx else math.nan))
    print(f"{'grid':26} {'planner':>9} {'field':>9} {'lookup':>9} {'path':>9} {'pyastar2d':>10} "
          f"{'networkx':>10} {'astar/lookup':>13} {'astar/path':>11} {'nx/path':>9}")
    for name, tp, tf, tl, tq, ta, tn in rows:
        print(f"{name:26} {tp*1e3:8.1f}ms {tf*1e3:8.2f}ms {tl*1e6:8.2f}us {tq*1e6:8.1f}us "
              f"{ta*1e3:9.2f}ms {tn*1e3:9.1f}ms {ta/tl:13.0f} {ta/tq:11.1f} {tn/tq:9.0f}")
    print("planner: per floor and radius (erosion, corners, corner graph, cell graph), cached;"
          " field: per goal (corner distances + root table), cached; lookup:"
          " FloorGoalField.distance (the per-step query); path: get_shortest_path to a cached"
          " goal (checked, entire any-angle path); medians over pairs.")


def accuracy(args):
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from test_geodesic_accuracy import RADIUS as R, relative_errors

    from geodesic_reference import ContinuousGeodesic, house_plan
    from scipy.sparse import csgraph

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


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--pairs", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--max-nx-cells", type=int, default=200_000)
    parser.add_argument("--accuracy", action="store_true")
    parser.add_argument("--plans", type=int, default=3)
    parser.add_argument("--acc-pairs", type=int, default=70)
    args = parser.parse_args()
    speed(args)
    if args.accuracy:
        accuracy(args)


if __name__ == "__main__":
    main()
