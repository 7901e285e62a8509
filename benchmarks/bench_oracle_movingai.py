"""Oracle quality on real grid maps: the MovingAI ``den312d`` and ``maze-128-128-1`` maps.

The privileged shortest-path follower (:class:`pointnav_core.policies.oracle.ShortestPathFollower`)
drives ``--episodes`` episodes per map and per backend (kinematic and pymunk by default),
the way :func:`pointnav_core.cli.run_demo` drives generated houses. Each map becomes a
scene through ``Scene.from_movingai`` (``--resolution`` metres per character, default 0.5,
so that a corridor one character wide fits the robot of radius ``--radius``, default
0.18 m), passed to :class:`~pointnav_core.envs.pointnav.PointNavEnv` as its ``scene``. The task's
own sampler picks start and goal (any two points of one connected region); the episode
seeds are the same on every backend, so only the motion differs. ``max_steps`` is 10,000
(5,000 s at 10 Hz), so the timeout does not bind: an episode the oracle does not finish
failed for another reason (the collision limit, or a stall the column ``ended by``
names).

Printed per map and backend: success rate, mean SPL, mean collisions per episode, mean
geodesic and path lengths, steps per second, beside the targets: success >= 99 % and at
most 1 collision per episode on average.

The maps are not shipped: the script looks in ``--movingai DIR`` (default
``$POINTNAV_MOVINGAI`` or ``/work/shared/data/movingai``) and skips, with a note, a map
it does not find.

Run::

    python benchmarks/bench_oracle_movingai.py
    python benchmarks/bench_oracle_movingai.py --episodes 5 --backends kinematic
"""

from __future__ import annotations

import argparse
import time
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from benchkit import MOVINGAI_DIR, machine, movingai_maps

from pointnav_core.backends.protocol import available_backends
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.policies.oracle import ShortestPathFollower
from pointnav_core.scenes import Scene

#: The maps, as named in the MovingAI benchmark sets.
MAPS = ("den312d.map", "maze-128-128-1.map")
#: Minimum success rate and maximum mean collisions per episode.
TARGET_SUCCESS = 0.99
TARGET_COLLISIONS = 1.0


def run_map(
    path: Path,
    backend: str,
    episodes: int,
    seed: int,
    resolution: float,
    radius: float,
    max_steps: int,
    drive: str,
) -> dict[str, float | Counter]:
    """Drive the oracle for ``episodes`` episodes on one map with one backend.

    Returns
    -------
    dict
        Means of ``success``, ``spl``, ``collisions`` (per episode), ``geodesic`` and
        ``path_length`` (m), plus ``steps_per_second``, ``wall`` (s) and ``ended_by``
        (a Counter of the conditions that ended the failed episodes).
    """
    env = PointNavEnv(
        scene=Scene.from_movingai(path, resolution=resolution),
        robot={"radius": radius, "drive": drive},
        task={"termination_config": {"max_steps": max_steps}},
        backend=backend,
    )
    keys = ("success", "spl", "collisions", "geodesic_dist", "path_length")
    results: dict[str, list[float]] = {k: [] for k in keys}
    ended_by: Counter = Counter()
    steps = 0
    stepping = 0.0
    start_wall = time.perf_counter()
    try:
        for episode in range(episodes):
            _, info = env.reset(seed=seed * 100_003 + episode)
            oracle = ShortestPathFollower(env)
            geodesic = float(info["geodesic_dist"])
            done = False
            t0 = time.perf_counter()
            while not done:
                _, _, terminated, truncated, info = env.step(oracle.act())
                steps += 1
                done = terminated or truncated
            stepping += time.perf_counter() - t0
            info = dict(info, geodesic_dist=geodesic)
            for key in keys:
                results[key].append(float(info[key]))
            if not info["success"]:
                fired = [n for n, c in info["termination_conditions"].items() if c["done"]]
                ended_by.update(fired or ["?"])
    finally:
        env.close()
    out: dict[str, float | Counter] = {k: float(np.mean(v)) for k, v in results.items()}
    out.update(
        steps_per_second=steps / stepping if stepping else float("nan"),
        wall=time.perf_counter() - start_wall,
        ended_by=ended_by,
    )
    return out


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=100, help="episodes per map and backend")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--resolution", type=float, default=0.5, help="metres per map character")
    parser.add_argument("--radius", type=float, default=0.18, help="robot radius (m)")
    parser.add_argument("--max-steps", type=int, default=10_000)
    parser.add_argument("--drive", choices=("differential", "holonomic"), default="differential")
    parser.add_argument("--backends", nargs="+", default=None, help="default: kinematic and pymunk")
    parser.add_argument("--movingai", type=Path, default=MOVINGAI_DIR, help="folder of the MovingAI maps")
    parser.add_argument("--maps", nargs="+", default=None, help=f"map files (default: {' '.join(MAPS)})")
    args = parser.parse_args(argv)
    if args.episodes < 1:
        parser.error(f"--episodes must be >= 1, got {args.episodes}")
    if args.max_steps < 1:
        parser.error(f"--max-steps must be >= 1, got {args.max_steps}")
    installed = available_backends()
    names = args.backends or [b for b in ("kinematic", "pymunk") if b in installed]
    unknown = sorted(set(args.maps or ()) - set(MAPS))
    if unknown:
        parser.error(f"--maps: unknown map {unknown[0]!r}; known maps are {list(MAPS)}")
    maps = movingai_maps(args.movingai, args.maps or MAPS)
    if not maps:
        print(f"no MovingAI maps in {args.movingai}: nothing to run")
        return 0
    print(f"machine: {machine()}")
    print(
        f"oracle, {args.episodes} episodes per map and backend (seed {args.seed}), "
        f"{args.resolution:g} m per cell, radius {args.radius:g} m, {args.drive} drive, "
        f"max_steps {args.max_steps}"
    )
    print(
        f"{'map':20} {'backend':10} {'success':>8} {'SPL':>6} {'coll/ep':>8} {'geod m':>7} "
        f"{'path m':>7} {'steps/s':>8} {'wall s':>7}  target (success >= {TARGET_SUCCESS:.0%}, "
        f"coll/ep <= {TARGET_COLLISIONS:g}); ended by"
    )
    missed = False
    for path in maps:
        for backend in names:
            s = run_map(path, backend, args.episodes, args.seed, args.resolution, args.radius,
                        args.max_steps, args.drive)
            met = s["success"] >= TARGET_SUCCESS and s["collisions"] <= TARGET_COLLISIONS
            missed |= not met
            ended = ", ".join(f"{k} {v}" for k, v in sorted(s["ended_by"].items())) or "-"
            print(
                f"{path.stem:20} {backend:10} {s['success']:>8.1%} {s['spl']:>6.3f} "
                f"{s['collisions']:>8.2f} {s['geodesic_dist']:>7.2f} {s['path_length']:>7.2f} "
                f"{s['steps_per_second']:>8,.0f} {s['wall']:>7.1f}  {'met' if met else 'MISSED'}; {ended}",
                flush=True,
            )
    return 1 if missed else 0


if __name__ == "__main__":
    raise SystemExit(main())
