"""The ``pointnav`` command line: ``pointnav demo`` runs the main job."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

import numpy as np

from pointnav_core import scenes

__all__ = ["main"]


def _demo(args: argparse.Namespace) -> int:
    scene = scenes.rooms(seed=args.seed)
    rng = np.random.default_rng(args.seed)
    floor, start = scene.get_random_point(robot=0.18, rng=rng)
    _, goal = scene.get_random_point(floor, reference_point=start, robot=0.18, rng=rng)
    path, dist = scene.get_shortest_path(floor, start, goal, entire_path=True, robot=0.18)
    print(f"house {scene.floors[floor].extent}, start {start[:2]}, goal {goal[:2]}")
    print(f"geodesic distance {dist:.3f} m through {len(path)} waypoints:")
    for x, y in path:
        print(f"  ({x:7.3f}, {y:7.3f})")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``pointnav`` console script."""
    parser = argparse.ArgumentParser(prog="pointnav", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="drive robots to goals in a generated house")
    demo.add_argument("--seed", type=int, default=0)
    demo.set_defaults(func=_demo)
    args = parser.parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())
