"""Oracle quality on every installed backend: success, SPL, SoftSPL, collisions, speed.

The privileged shortest-path follower (:class:`pointnav_core.policies.oracle.ShortestPathFollower`)
drives ``--episodes`` episodes over ``--houses`` generated ``rooms`` houses through
:func:`pointnav_core.cli.run_demo`, the same code as ``pointnav demo``, once per backend.
Start and goal come from the core's sampler, so every backend gets the same episodes (one
seed, one start pose and goal); only the motion differs: the kinematic backend slides
along contacts, the pymunk backend resolves them with a rigid-body solver.

The targets the issue sets are printed beside the figures: success >= 97 % and mean
SPL >= 0.85 on pymunk, and the kinematic backend must keep >= 99 % and >= 0.90. Steps per
second count the whole env step with the oracle's action (its path lookup included), so
they are lower than ``bench_backends.py``'s figures.

Run::

    python benchmarks/bench_oracle.py
    python benchmarks/bench_oracle.py --episodes 50 --backends pymunk --drive holonomic
"""

from __future__ import annotations

import argparse
import platform
import time
from collections.abc import Sequence

from pointnav_core.backends.protocol import available_backends
from pointnav_core.cli import run_demo

#: Minimum success rate and mean SPL per backend (the issue's targets).
TARGETS = {"kinematic": (0.99, 0.90), "pymunk": (0.97, 0.85)}


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--houses", type=int, default=4)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--max-steps", type=int, default=1000)
    parser.add_argument("--drive", choices=("differential", "holonomic"), default="differential")
    parser.add_argument(
        "--backends", nargs="+", default=None, help="backends (default: every installed one)"
    )
    args = parser.parse_args(argv)
    names = args.backends or available_backends()
    print(
        f"oracle, {args.episodes} episodes over {args.houses} rooms houses (seed {args.seed}), "
        f"{args.drive} drive, max_steps {args.max_steps}; "
        f"python {platform.python_version()}, {platform.machine()}"
    )
    header = (
        f"{'backend':<10} {'success':>8} {'SPL':>6} {'SoftSPL':>8} {'path m':>7} "
        f"{'coll/ep':>8} {'steps/s':>8} {'wall s':>7}  target (success, SPL)"
    )
    print(header)
    missed = []
    for name in names:
        start = time.perf_counter()
        s = run_demo(
            episodes=args.episodes,
            seed=args.seed,
            houses=args.houses,
            max_steps=args.max_steps,
            backend=name,
            drive=args.drive,
            progress=False,
        )
        wall = time.perf_counter() - start
        target = TARGETS.get(name)
        verdict = "-"
        if target is not None:
            met = s["success"] >= target[0] and s["spl"] >= target[1]
            verdict = f">= {target[0]:.0%}, >= {target[1]:.2f}: {'met' if met else 'MISSED'}"
            if not met:
                missed.append(name)
        print(
            f"{name:<10} {s['success']:>8.1%} {s['spl']:>6.3f} {s['soft_spl']:>8.3f} "
            f"{s['path_length']:>7.2f} {s['collisions']:>8.2f} {s['steps_per_second']:>8,.0f} "
            f"{wall:>7.1f}  {verdict}"
        )
    return 1 if missed else 0


if __name__ == "__main__":
    raise SystemExit(main())
