"""Time ``backend.step()`` on every installed backend: 1 and 8 robots in a generated house.

Each robot starts at a random valid pose of a 20 m x 20 m house (``scenes.rooms``, built
from polygons, 0.1 m grid) and drives random actions: uniform in [-1, 1], each held for
``--hold`` steps (1 s at 10 Hz) so that robots travel and run into walls and each other,
the same sequence for every backend. After a short warm-up, steps are timed for at least
``--seconds`` seconds per configuration; the table gives control steps per second (one
call advances all robots), the share of robot-steps with the contact flag set (from an
untimed replay), and each backend's speed relative to the first one.

Run::

    python benchmarks/bench_backends.py
    python benchmarks/bench_backends.py --seconds 5 --robots 1 8 16 --backends kinematic pymunk
"""

from __future__ import annotations

import argparse
import math
import platform
import time
from collections.abc import Sequence

import numpy as np

from pointnav_core.backend import RobotSpec, available_backends, make_backend
from pointnav_core.scenes import Scene, rooms


def house(seed: int) -> Scene:
    """A generated 20 m x 20 m house at 0.1 m per cell."""
    return rooms(seed=seed, size=(20.0, 20.0))


def start_poses(scene: Scene, specs: Sequence[RobotSpec], seed: int) -> list[np.ndarray]:
    """Non-overlapping start positions (x, y, z) for the robots, in order."""
    rng = np.random.default_rng(seed)
    probe = make_backend("kinematic")
    probe.load(scene, list(specs))
    out = []
    for idn, spec in enumerate(specs):
        for _ in range(10_000):
            _, xyz = scene.get_random_point(0, robot=spec.radius, rng=rng)
            if probe.is_valid_pose(idn, xyz):
                probe.land(idn, 0, xyz, (0.0, 0.0, 0.0, 1.0))
                out.append(xyz)
                break
        else:
            raise RuntimeError(f"no free start pose for robot {idn}")
    return out


def time_backend(
    name: str,
    scene: Scene,
    specs: Sequence[RobotSpec],
    starts: Sequence[np.ndarray],
    actions: Sequence[dict[int, np.ndarray]],
    seconds: float,
    warmup: int = 50,
) -> tuple[float, float]:
    """Return (steps per second, share of robot-steps in contact) for one backend."""

    def placed() -> object:
        backend = make_backend(name)
        backend.load(scene, list(specs))
        rng = np.random.default_rng(1)
        for idn, xyz in enumerate(starts):
            yaw = rng.uniform(-math.pi, math.pi)
            backend.land(idn, 0, xyz, (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))
        return backend

    n, total = len(specs), len(actions)
    backend = placed()
    for k in range(warmup):
        backend.step(actions[k % total])
    steps = 0
    start = time.perf_counter()
    elapsed = 0.0
    while elapsed < seconds:
        for k in range(steps, steps + 200):
            backend.step(actions[k % total])
        steps += 200
        elapsed = time.perf_counter() - start
    backend = placed()
    contacts = 0
    for step in actions:
        backend.step(step)
        contacts += sum(bool(backend.in_contact(i)) for i in range(n))
    return steps / elapsed, contacts / (n * total)


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="timing per configuration (s)")
    parser.add_argument("--robots", type=int, nargs="+", default=[1, 8], help="robot counts")
    parser.add_argument(
        "--backends", nargs="+", default=None, help="backends (default: every installed one)"
    )
    parser.add_argument("--seed", type=int, default=0, help="house, start-pose and action seed")
    parser.add_argument("--hold", type=int, default=10, help="steps each random action is held")
    args = parser.parse_args(argv)
    names = args.backends or available_backends()
    scene = house(args.seed)
    print(
        f"backend.step() calls per second: rooms(seed={args.seed}, size=(20, 20)) house, "
        f"0.1 m grid, 10 Hz, random actions held {args.hold} steps; "
        f"python {platform.python_version()}, {platform.machine()}"
    )
    header = f"{'robots':>6}" + "".join(f"  {n + ' steps/s':>18}  {'contact':>7}" for n in names)
    ratios = [f"{n}/{names[0]}" for n in names[1:]]
    print(header + "".join(f"  {r:>18}" for r in ratios))
    for count in args.robots:
        specs = [
            RobotSpec(drive="differential" if i % 2 == 0 else "holonomic") for i in range(count)
        ]
        starts = start_poses(scene, specs, args.seed)
        rng = np.random.default_rng(args.seed)
        held = rng.uniform(-1.0, 1.0, size=(-(-2000 // args.hold), count, 3))
        actions = [
            {i: held[k // args.hold, i, : spec.action_dim] for i, spec in enumerate(specs)}
            for k in range(2000)
        ]
        rates = []
        row = f"{count:>6}"
        for name in names:
            rate, contact = time_backend(name, scene, specs, starts, actions, args.seconds)
            rates.append(rate)
            row += f"  {rate:>18,.0f}  {contact:>7.0%}"
        row += "".join(f"  {r / rates[0]:>18.2f}" for r in rates[1:])
        print(row)


if __name__ == "__main__":
    main()
