"""Range scan cost: microseconds per 64-ray scan, the compiled path beside the numpy path.

A robot drives a random episode in the default 20 x 15 m ``rooms`` house (0.1 m cells,
53 obstacle polygons); its poses are recorded first. Then, in the same run and interleaved
over several rounds (the best round of each kept, since the machines are shared):

- ``scan term``: the ``"scan"`` observation term's whole per-step work
  (``RangeScan.values`` at each recorded pose: the pose in, the rays cast, the
  ``min_range`` rule), the figure a step pays for the scan;
- ``cast_rays``: the ray casting alone, one robot per call;
- ``cast_rays x8``: eight robots in one call, each seeing the others' discs, per robot.

each with ``method="numba"`` (the ``fast`` extra) and ``method="array"``; the last column
is the numpy time over the compiled one. The two paths give equal ranges
(``property_tests/test_compiled_paths.py``, checks in ``tests/pairs_scan.py``).

Run: ``python benchmarks/bench_scan.py [--poses 500] [--rounds 5]``
"""

from __future__ import annotations

import argparse
import math
import time
from typing import Any

import gymnasium as gym
import numpy as np

import pointnav_core  # noqa: F401  (registers pointnav_core/PointNav-v0)
from pointnav_core import scenes
from pointnav_core.sensors import RangeScan, ScanGeometry, cast_rays, raycast_jit
from pointnav_core.task.observations import Frame
from pointnav_core.utils.compiled import numpy_paths


def record_poses(scene: Any, n: int, seed: int) -> list[tuple[float, float, float]]:
    """``(x, y, yaw)`` of a robot driving random actions for ``n`` steps."""
    env = gym.make("pointnav_core/PointNav-v0", scene=scene)
    env.reset(seed=seed)
    env.action_space.seed(seed)
    poses = []
    for _ in range(n):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
        position, quat = env.unwrapped.backend.get_pose(0)
        poses.append((float(position[0]), float(position[1]), 2.0 * math.atan2(quat[2], quat[3])))
    return poses


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--poses", type=int, default=500)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    if not raycast_jit.available():
        raise SystemExit('numba is not installed: pip install "pointnav-core[fast]"')

    scene = scenes.rooms(seed=0)
    poses = record_poses(scene, args.poses, seed=0)
    env = gym.make("pointnav_core/PointNav-v0", scene=scene, sensors={"scan": {"n_rays": 64}})
    env.reset(seed=0)
    task = env.unwrapped.task
    term: RangeScan = task.observation_terms["scan"]
    geo = ScanGeometry(scene.floors[0])
    angles = term.angles
    frame = Frame()
    frame.task, frame.env = task, env.unwrapped
    xy = np.array([p[:2] for p in poses])
    yaw = np.array([p[2] for p in poses])
    groups = [slice(i, i + 8) for i in range(0, len(poses) - 7, 8)]
    discs = [np.column_stack([xy[g], np.full(8, 0.18)]) for g in groups]
    own = np.arange(8)

    def scan_term() -> float:
        start = time.perf_counter()
        for x, y, a in poses:
            frame.set_pose(x, y, 0.0, (0.0, 0.0, math.sin(a / 2.0), math.cos(a / 2.0)))
            term.values(frame)
        return (time.perf_counter() - start) / len(poses)

    def one(method: str) -> float:
        start = time.perf_counter()
        for i in range(len(poses)):
            cast_rays(geo, xy[i : i + 1], yaw[i : i + 1], angles, term.max_range, method=method)
        return (time.perf_counter() - start) / len(poses)

    def eight(method: str) -> float:
        start = time.perf_counter()
        for g, d in zip(groups, discs):
            cast_rays(geo, xy[g], yaw[g], angles, term.max_range, discs=d, own_disc=own, method=method)
        return (time.perf_counter() - start) / (8 * len(groups))

    def scan_term_numpy() -> float:
        # The same term on the array path: every compiled path off for this run.
        with numpy_paths():
            return scan_term()

    rows = {
        "scan term": (scan_term, scan_term_numpy),
        "cast_rays, 1 robot": (lambda: one("numba"), lambda: one("array")),
        "cast_rays x8, per robot": (lambda: eight("numba"), lambda: eight("array")),
    }
    for fast, general in rows.values():  # compile / warm up
        fast()
        general()
    best = {name: [math.inf, math.inf] for name in rows}
    for _ in range(args.rounds):
        for name, fns in rows.items():
            for k, fn in enumerate(fns):
                best[name][k] = min(best[name][k], fn())
    print(f"64 rays, 360 deg, 5.6 m, rooms(seed=0), {len(poses)} poses of a random episode")
    print(f"{'':26} {'numba (us)':>11} {'numpy (us)':>11} {'numpy / numba':>14}")
    for name, (f, g) in best.items():
        print(f"{name:26} {f * 1e6:11.1f} {g * 1e6:11.1f} {g / f:14.1f}")


if __name__ == "__main__":
    main()
