"""Can the registered defaults be solved? The oracle on default ``PointNav-v0`` and
``MultiPointNav-v0`` episodes.

Both ids are built exactly as users get them (``gymnasium.make`` and ``pettingzoo.make``
with no arguments), so the episodes come from the default ``path_range`` the envs derive
from the robot's reach (``_envcommon.fit_path_range``). The privileged shortest-path
follower (:class:`pointnav_core.policies.oracle.ShortestPathFollower`) drives ``--episodes``
robot-episodes of each; the target is a success rate of at least 99 %. To show why the
range is what it is, each episode's *time ratio* is printed by geodesic band: the steps it
took times the robot's full-speed step length (``max_linear_velocity / action_frequency``)
over its geodesic, the share of the reach an episode of that length needs. With
``--unlimited`` the step limit is lifted (10,000 steps, same ``path_range``), so the
ratios of episodes that would time out are measured too.

Run::

    python benchmarks/bench_default_episodes.py
    python benchmarks/bench_default_episodes.py --episodes 400 --unlimited
"""

from __future__ import annotations

import argparse
import platform
import time
from collections.abc import Sequence

import gymnasium as gym
import numpy as np
import pettingzoo

import pointnav_core  # noqa: F401  (registers the ids)
from pointnav_core.policies.oracle import ShortestPathFollower

BANDS = (0.0, 2.5, 5.0, 10.0, 15.0, np.inf)
TARGET = 0.99


def _single(episodes: int, unlimited: bool) -> list[tuple[float, int, bool, float]]:
    """(geodesic, steps, success, spl) of each default PointNav-v0 episode."""
    env = gym.make("pointnav_core/PointNav-v0", max_episode_steps=10_000 if unlimited else None)
    base = env.unwrapped
    if unlimited:  # keep the default range the 500-step limit gave
        base.task.path_range = gym.make("pointnav_core/PointNav-v0").unwrapped.task.path_range
    oracle = ShortestPathFollower(base)
    out = []
    for seed in range(episodes):
        _, info = env.reset(seed=seed)
        geodesic, steps = info["geodesic_dist"], 0
        while True:
            _, _, terminated, truncated, info = env.step(oracle.act())
            steps += 1
            if terminated or truncated:
                break
        out.append((geodesic, steps, bool(info["success"]), info["spl"]))
    return out


def _multi(episodes: int) -> list[tuple[float, int, bool, float]]:
    """The same for the robots of default MultiPointNav-v0 worlds."""
    env = pettingzoo.make("parallel", "pointnav_core/MultiPointNav-v0")
    oracles = {f"robot_{i}": ShortestPathFollower(env, task=t) for i, t in enumerate(env.tasks)}
    out: list[tuple[float, int, bool, float]] = []
    seed = 0
    while len(out) < episodes:
        _, infos = env.reset(seed=seed)
        seed += 1
        start = {agent: infos[agent]["geodesic_dist"] for agent in env.agents}
        while env.agents:
            actions = {agent: oracles[agent].act() for agent in env.agents}
            _, _, terms, truncs, infos = env.step(actions)
            for agent in actions:
                if terms[agent] or truncs[agent]:
                    info = infos[agent]
                    out.append(
                        (start[agent], info["episode_length"], bool(info["success"]), info["spl"])
                    )
    return out[:episodes]


def _report(
    name: str, runs: list[tuple[float, int, bool, float]], step_m: float, wall: float
) -> bool:
    geo = np.array([r[0] for r in runs])
    steps = np.array([r[1] for r in runs], dtype=float)
    success = np.array([r[2] for r in runs])
    spl = np.array([r[3] for r in runs])
    rate = success.mean()
    print(
        f"\n{name}: {len(runs)} episodes, success {rate:.1%} (target >= {TARGET:.0%}: "
        f"{'met' if rate >= TARGET else 'MISSED'}), SPL {spl.mean():.3f}, geodesic "
        f"{geo.min():.2f}-{geo.max():.2f} m, {wall:.0f} s"
    )
    print(
        f"  {'geodesic m':<12} {'episodes':>8} {'success':>8} {'ratio median':>13} {'p95':>6} {'max':>6}"
    )
    ratio = steps * step_m / np.maximum(geo, 1e-9)
    for lo, hi in zip(BANDS[:-1], BANDS[1:]):
        band = (geo >= lo) & (geo < hi)
        if band.any():
            r = ratio[band]
            print(
                f"  [{lo:g}, {hi:g}){'':<{8 - len(f'{lo:g}{hi:g}')}} {band.sum():>8} "
                f"{success[band].mean():>8.1%} {np.median(r):>13.2f} "
                f"{np.percentile(r, 95):>6.2f} {r.max():>6.2f}"
            )
    for g, s, ok, _ in runs:
        if not ok:
            print(f"  failed: geodesic {g:.2f} m after {s} steps")
    return rate >= TARGET


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--unlimited", action="store_true", help="lift the step limit")
    parser.add_argument("--which", choices=("single", "multi", "both"), default="both")
    args = parser.parse_args(argv)
    env = gym.make("pointnav_core/PointNav-v0").unwrapped
    step_m = env.robot.max_linear_velocity / env.action_frequency
    print(
        f"oracle on the registered defaults: path_range {env.task.path_range} m, max_steps "
        f"{env.task.max_steps}, {step_m:g} m per full-speed step; python "
        f"{platform.python_version()}, {platform.machine()}"
    )
    met = True
    if args.which in ("single", "both"):
        start = time.perf_counter()
        runs = _single(args.episodes, args.unlimited)
        met &= _report("PointNav-v0", runs, step_m, time.perf_counter() - start)
    if args.which in ("multi", "both"):
        start = time.perf_counter()
        runs = _multi(args.episodes)
        met &= _report("MultiPointNav-v0", runs, step_m, time.perf_counter() - start)
    return 0 if met else 1


if __name__ == "__main__":
    raise SystemExit(main())
