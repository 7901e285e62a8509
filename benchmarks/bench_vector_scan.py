"""Batched range scan cost: microseconds per robot-scan, beside the single env's compiled scan.

The default house (``scenes.rooms(seed=0)`` as grid cells, 0.1 m cells), ``--worlds`` worlds
of ``--robots`` robots at random usable poses, ``--rays`` rays over a full turn up to 5.6 m.
In the same run, interleaved over ``--rounds`` rounds (the best round of each kept, in
process time, since the machines are shared), on one thread:

- ``batched numba``: :func:`pointnav_core.vector.scan.cast_batch`, compiled path, every
  robot of every world in one call (each sees the other robots of its world);
- ``batched array``: the same call on the array path (numpy), the GPU's code on the CPU;
- ``batched torch``: the array path on torch on the CPU (when torch is installed);
- ``single, one robot``: the single env's compiled scan of one robot without discs
  (``cast_pose_compiled``, what ``RangeScan`` runs for one robot), once per robot;
- ``single, per world``: the single env's compiled ``cast_rays`` of one world's robots in one
  call with their discs (what a multi-robot env's ``ScanShare`` runs), once per world;
- ``batched local map``, ``batched local map torch``: a ``--map-cells`` square local map of
  ``--map-size`` m (:class:`pointnav_core.vector.local_map.VectorLocalMap`, numpy and torch
  on the CPU) of every robot in one call, with the other robots' discs;
- ``single local map``: the single env's ``LocalMap.grid`` of one robot (no discs), once per robot.

Every row is in microseconds per robot-scan; the last column is that row over
``batched numba``. With ``--engine``, also ``VectorPointNavEnv`` steps (numpy, geodesic
reward, random actions, ``worlds x robots`` one-robot worlds) without and with a 32-ray
scan, and with the local map alone and after the scan, in microseconds of process time
per agent-step (process time, not wall time: the machines are shared).

Run: ``python benchmarks/bench_vector_scan.py [--worlds 1024] [--robots 4] [--rays 32] [--map-cells 32] [--map-size 5] [--rounds 5] [--engine]``
"""

from __future__ import annotations

import argparse
import importlib.util
import time
from collections.abc import Callable

import numpy as np

from pointnav_core import scenes
from pointnav_core.backends.kit.checks import planar_quat_floats
from pointnav_core.sensors import LocalMap, ScanGeometry, cast_rays, scan_angles
from pointnav_core.sensors.raycast import cast_pose_compiled
from pointnav_core.task.observations import Frame
from pointnav_core.vector.floors import FloorTables
from pointnav_core.vector.local_map import VectorLocalMap
from pointnav_core.vector.scan import ScanTables, cast_batch, compiled_available
from pointnav_core.vector.xp import make_arrays

MAX_RANGE = 5.6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--worlds", type=int, default=1024)
    parser.add_argument("--robots", type=int, default=4)
    parser.add_argument("--rays", type=int, default=32)
    parser.add_argument("--map-cells", type=int, default=32)
    parser.add_argument("--map-size", type=float, default=5.0)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--engine", action="store_true", help="also time the engine's step without and with the scan")
    args = parser.parse_args()
    if not compiled_available():
        raise SystemExit('numba is not installed: pip install "pointnav-core[fast]"')
    try:
        import torch

        torch.set_num_threads(1)
    except ImportError:
        torch = None
    import numba

    numba.set_num_threads(1)

    house = scenes.rooms(seed=0).floors[0]
    scene = scenes.Scene.from_array(np.asarray(house.codes), house.resolution, origin=tuple(house.origin))
    w, r = args.worlds, args.robots
    rng = np.random.default_rng(0)
    points = np.array([scene.get_random_point(0, robot=0.18, rng=rng)[1][:2] for _ in range(w * r)])
    x, y = points[:, 0].reshape(w, r).copy(), points[:, 1].reshape(w, r).copy()
    yaw = rng.uniform(-np.pi, np.pi, (w, r))
    present = np.ones((w, r), bool)
    angles = scan_angles(args.rays, 2 * np.pi)
    world_scene = np.zeros(w, np.int64)
    tables = ScanTables([scene], 0, make_arrays("numpy"))
    geo = ScanGeometry(scene.floors[0])

    rows: dict[str, Callable[[], object]] = {
        "batched numba": lambda: cast_batch(tables, world_scene, x, y, yaw, present, 0.18, angles, MAX_RANGE, "numba"),
        "batched array": lambda: cast_batch(tables, world_scene, x, y, yaw, present, 0.18, angles, MAX_RANGE, "array"),
    }
    if torch is not None and importlib.util.find_spec("torch"):
        ttables = ScanTables([scene], 0, make_arrays("cpu"))
        tx, ty, tyaw, tp, ts = (torch.as_tensor(v) for v in (x, y, yaw, present, world_scene))
        rows["batched torch"] = lambda: cast_batch(ttables, ts, tx, ty, tyaw, tp, 0.18, angles, MAX_RANGE)
    origin, one_yaw, heading = np.zeros((1, 2)), np.zeros(1), np.zeros(2)
    directions = (np.cos(angles), np.sin(angles))

    def single_one() -> None:  # RangeScan's own steps for one robot
        for i in range(w):
            for j in range(r):
                origin[0, 0], origin[0, 1] = x[i, j], y[i, j]
                one_yaw[0] = yaw[i, j]
                np.cos(one_yaw, out=heading[:1])
                np.sin(one_yaw, out=heading[1:])
                cast_pose_compiled(geo, origin, heading, directions, MAX_RANGE)

    def single_world() -> None:
        for i in range(w):
            xy = np.stack([x[i], y[i]], 1)
            cast_rays(geo, xy, yaw[i], angles, MAX_RANGE, discs=np.column_stack([xy, np.full(r, 0.18)]),
                      own_disc=np.arange(r), method="numba")

    rows["single, one robot"] = single_one
    rows["single, per world"] = single_world
    term = LocalMap(size=args.map_size, cells=args.map_cells)
    lmap = VectorLocalMap(term, FloorTables([scene], 0, 0.18, make_arrays("numpy")))
    rows["batched local map"] = lambda: lmap.values(world_scene, x, y, yaw, present, 0.18)
    if "batched torch" in rows:
        tmap = VectorLocalMap(term, FloorTables([scene], 0, 0.18, make_arrays("cpu")))
        rows["batched local map torch"] = lambda: tmap.values(ts, tx, ty, tyaw, tp, 0.18)
    frame, env = Frame(), type("OneRobot", (), {"scene": scene, "robots": [None], "backend": None})()
    frame.task, frame.env = type("Task", (), {"floor": 0, "robot_idn": 0})(), env
    quats = [[planar_quat_floats(float(v)) for v in row] for row in yaw]

    def single_map() -> None:  # LocalMap.grid of one robot, as PointNavEnv observes it
        for i in range(w):
            for j in range(r):
                frame.set_pose(float(x[i, j]), float(y[i, j]), 0.0, quats[i][j])
                term.grid(frame)

    rows["single local map"] = single_map
    # Both batched paths agree before anything is timed.
    np.testing.assert_allclose(rows["batched numba"](), rows["batched array"](), rtol=0, atol=1e-9)
    best = dict.fromkeys(rows, np.inf)
    for k in range(args.rounds):
        for name, fn in rows.items():
            t = time.process_time()  # process time: the machines are shared
            fn()
            best[name] = min(best[name], time.process_time() - t)
    base = best["batched numba"]
    print(f"{w} worlds x {r} robots x {args.rays} rays, max_range {MAX_RANGE} m, default house as grid; "
          f"best of {args.rounds} rounds, one thread, process time")
    print(f"{'':22s}{'us / robot-scan':>16s}{'x batched numba':>17s}")
    for name, sec in best.items():
        print(f"{name:22s}{sec / (w * r) * 1e6:16.3f}{sec / base:17.2f}")
    if args.engine:
        _engine(w * r, args.rays, args.rounds, {"size": args.map_size, "cells": args.map_cells})


def _engine(n: int, rays: int, rounds: int, local_map: dict) -> None:
    from pointnav_core.vector import VectorPointNavEnv

    scan, cells = {"n_rays": rays}, local_map["cells"]
    configs = (
        ("engine, no scan", None), (f"engine, {rays}-ray scan", {"scan": scan}),
        (f"engine, {cells}x{cells} map", {"local_map": local_map}),
        ("engine, scan + map", {"scan": scan, "local_map": local_map}),
    )
    envs = {
        label: VectorPointNavEnv(n, seed=0, pool_size=2, task={"reward_type": "geodesic"}, sensors=sensors)
        for label, sensors in configs
    }
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, (20, n, 2))
    for env in envs.values():
        env.reset(seed=0)
    best = dict.fromkeys(envs, np.inf)
    for _ in range(rounds):
        for label, env in envs.items():
            start = time.process_time()
            for act in actions:
                env.step(act)
            best[label] = min(best[label], (time.process_time() - start) / len(actions))
    print(f"{n} one-robot worlds, numpy, 20 steps a round, best of {rounds}, process time")
    for label, sec in best.items():
        print(f"{label:22s}{sec / n * 1e6:10.3f} us / agent-step{n / sec:14,.0f} agent-steps/s")


if __name__ == "__main__":
    main()
