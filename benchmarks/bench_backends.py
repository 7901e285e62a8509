"""Time every installed backend with 1 and 8 robots in a house: ``backend.step()`` and envs.

Each robot starts at a random valid pose of a 20 m x 20 m house (``scenes.rooms``, built
from polygons, 0.1 m grid) and drives random actions: uniform in [-1, 1], each held for
``--hold`` steps (1 s at 10 Hz) so that robots travel and run into walls and each other,
the same sequence for every backend. After a short warm-up, steps are timed for at least
``--seconds`` seconds per configuration; the first table gives control steps per second (one
call advances all robots), the share of robot-steps with the contact flag set (from an
untimed replay), and each backend's speed relative to the first one.

The second table, from the same run and house, times whole environments on each backend,
with the task's bookkeeping (rewards, terminations, metrics, observations) on top of the
backend: ``PointNavEnv`` for one robot (env steps per second) and, for more robots, the
PettingZoo env ``pointnav_core.envs.multi_pointnav.parallel_env(n_robots=n)`` (agent-steps per second:
one agent acting for one step; finished agents leave ``agents``). Robots use the default
``RobotSpec`` (differential drive) and random actions held ``--hold`` steps; episodes are
sampled by the tasks, and resets are counted in the time.

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
from typing import Any

import numpy as np

from pointnav_core.backends.protocol import available_backends, make_backend
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs.pointnav import PointNavEnv
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


def held_actions(count: int, dim: int, hold: int, seed: int, total: int = 2000) -> np.ndarray:
    """Random actions in [-1, 1], shape (total, count, dim) float32, each held ``hold`` steps."""
    rng = np.random.default_rng(seed)
    held = rng.uniform(-1.0, 1.0, size=(-(-total // hold), count, dim)).astype(np.float32)
    return np.repeat(held, hold, axis=0)[:total]


def time_single_env(
    name: str, scene: Scene, actions: np.ndarray, seconds: float, seed: int, warmup: int = 50
) -> float:
    """PointNavEnv steps per second on backend ``name``, resets included."""
    env = PointNavEnv(scene=scene, backend=name)
    env.reset(seed=seed)
    total = len(actions)

    def run(first: int, n: int) -> None:
        for k in range(first, first + n):
            _, _, terminated, truncated, _ = env.step(actions[k % total, 0])
            if terminated or truncated:
                env.reset()

    run(0, warmup)
    steps = 0
    start = time.perf_counter()
    elapsed = 0.0
    while elapsed < seconds:
        run(warmup + steps, 200)
        steps += 200
        elapsed = time.perf_counter() - start
    env.close()
    return steps / elapsed


def time_parallel_env(
    make: Any, name: str, scene: Scene, actions: np.ndarray, seconds: float, seed: int,
    warmup: int = 50,
) -> float:
    """Agent-steps per second of ``make(n_robots=..., backend=name)``, resets included."""
    count = actions.shape[1]
    env = make(scene=scene, n_robots=count, backend=name)
    env.reset(seed=seed)
    index = {agent: i for i, agent in enumerate(env.possible_agents)}
    total = len(actions)

    def run(first: int, n: int) -> int:
        agent_steps = 0
        for k in range(first, first + n):
            row = actions[k % total]
            agent_steps += len(env.agents)
            env.step({agent: row[index[agent]] for agent in env.agents})
            if not env.agents:
                env.reset()
        return agent_steps

    run(0, warmup)
    steps = agent_steps = 0
    start = time.perf_counter()
    elapsed = 0.0
    while elapsed < seconds:
        agent_steps += run(warmup + steps, 200)
        steps += 200
        elapsed = time.perf_counter() - start
    env.close()
    return agent_steps / elapsed


def parallel_env_factory() -> tuple[Any, str]:
    """``pointnav_core.envs.multi_pointnav.parallel_env``, or None and the reason it is unavailable."""
    try:
        from pointnav_core.envs.multi_pointnav import parallel_env
    except ImportError as err:
        return None, f"pointnav_core.envs.multi_pointnav is not available ({err})"
    return parallel_env, ""


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

    print()
    print(
        "env steps per second, same house, default robots, random actions held "
        f"{args.hold} steps, resets counted (1 robot: PointNavEnv, steps/s; more: "
        "parallel_env, agent-steps/s)"
    )
    header = f"{'robots':>6}  {'env':<12}" + "".join(f"  {n + ' /s':>18}" for n in names)
    print(header + "".join(f"  {r:>18}" for r in ratios))
    make_parallel, why_not = parallel_env_factory()
    for count in args.robots:
        actions = held_actions(count, RobotSpec().action_dim, args.hold, args.seed)
        label = "PointNavEnv" if count == 1 else "parallel_env"
        if count > 1 and make_parallel is None:
            print(f"{count:>6}  {label:<12}  {why_not}")
            continue
        rates = []
        for name in names:
            if count == 1:
                rate = time_single_env(name, scene, actions, args.seconds, args.seed)
            else:
                rate = time_parallel_env(
                    make_parallel, name, scene, actions, args.seconds, args.seed
                )
            rates.append(rate)
        row = f"{count:>6}  {label:<12}" + "".join(f"  {r:>18,.0f}" for r in rates)
        row += "".join(f"  {r / rates[0]:>18.2f}" for r in rates[1:])
        print(row)


if __name__ == "__main__":
    main()
