"""Falls over several control steps in the batched engines, against the single envs.

For random grid scenes with a pit of VOID cells, robots started near the pit (half of them
facing it), actions that drive ahead often, and a ``fall_height`` drawn between 0.2 and
2 m (above a fall's first drop, 0.149 m at 10 Hz, so that a fall lasts 2 to 6 steps),
``VectorPointNavEnv`` matches one ``PointNavEnv`` per world and ``VectorPointNavEnv(W,
n_robots=R)`` one ``parallel_env`` per world step for step: observations (the fall's
vertical speed among them), rewards, flags, info and every robot's height z within 1e-9 m
(``vector_reference``, ``fleet_reference``), with continuous and discrete actions, parked
and removed robots, on numpy and on torch on the CPU.
"""

from __future__ import annotations

import importlib.util
import math
from typing import Any

import numpy as np
import pytest
from fleet_reference import compare_fleet
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from vector_reference import compare

from pointnav_core.floor.maps import FREE, OBSTACLE, VOID
from pointnav_core.scenes import Scene

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])
RADIUS = 0.18


@st.composite
def pitted_scenes(draw: st.DrawFn) -> tuple[Scene, tuple[float, float]]:
    """A walled room, 18 to 30 cells a side, random clutter, a free 12 x 12 patch and a pit
    of VOID, 2 to 6 cells a side, somewhere in it; with the pit's centre (m)."""
    rows, cols = draw(st.integers(18, 30)), draw(st.integers(18, 30))
    rng = np.random.default_rng(draw(st.integers(0, 2**31 - 1)))
    grid = np.zeros((rows, cols), np.uint8)
    grid[rng.random((rows, cols)) < draw(st.floats(0.0, 0.08))] = OBSTACLE
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    r, c = draw(st.integers(1, rows - 13)), draw(st.integers(1, cols - 13))
    grid[r : r + 12, c : c + 12] = FREE
    h, w = draw(st.integers(2, 6)), draw(st.integers(2, 6))
    pr, pc = draw(st.integers(r, r + 12 - h)), draw(st.integers(c, c + 12 - w))  # inside the patch
    grid[pr : pr + h, pc : pc + w] = VOID
    return Scene.from_array(grid, 0.1), ((pc + w / 2) * 0.1, (pr + h / 2) * 0.1)


def near_pit(scene: Scene, pit: tuple[float, float], n: int, rng: np.random.Generator, gap: float) -> list[Any]:
    """``n`` usable points ``gap`` m apart, each the nearest to the pit of a few draws."""
    points: list[Any] = []
    for _ in range(2_000):
        draws = [scene.get_random_point(0, robot=RADIUS, rng=rng)[1][:2] for _ in range(4)]
        p = min(draws, key=lambda q: math.dist(q, pit))
        if all(math.dist(p, q) >= gap for q in points):
            points.append(p)
            if len(points) == n:
                return points
    raise AssertionError(f"no room for {n} points {gap} m apart")


def episodes_at_the_pit(scene: Scene, pit: tuple[float, float], n_robots: int, rng: np.random.Generator) -> list[Any]:
    """One world's episodes: starts near the pit, half of them facing it, goals apart."""
    starts, goals = near_pit(scene, pit, n_robots, rng, 2 * RADIUS), near_pit(scene, pit, n_robots, rng, 0.4)
    out = []
    for s, g in zip(starts, goals):
        facing = math.atan2(pit[1] - s[1], pit[0] - s[0])
        yaw = facing + rng.uniform(-0.3, 0.3) if rng.random() < 0.5 else rng.uniform(-math.pi, math.pi)
        out.append((s, float(yaw), g))
    return out


def drive_ahead(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    """Continuous actions in and beyond ``[-1, 1]``, full speed ahead with little turning often."""
    actions = rng.uniform(-1.2, 1.2, (*shape, 2)).astype(np.float32)
    ahead = rng.random(shape) < 0.6
    actions[ahead, 0] = 1.0
    actions[ahead, 1] *= 0.2
    return actions


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    pitted=pitted_scenes(),
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(1, 4),
    steps=st.integers(1, 80),
    fall_height=st.floats(0.2, 2.0),
    reward_type=st.sampled_from(["l2", "geodesic"]),
    discrete=st.one_of(st.none(), st.fixed_dictionaries({
        "forward_step": st.floats(0.05, 0.4), "turn_angle": st.floats(0.05, 1.0), "stop": st.booleans()})),
)
def test_long_falls_match_single_envs(
    device: str, pitted: tuple, seed: int, n: int, steps: int, fall_height: float, reward_type: str,
    discrete: dict | None,
) -> None:
    scene, pit = pitted
    rng = np.random.default_rng(seed)
    episodes = [episodes_at_the_pit(scene, pit, 1, rng)[0] for _ in range(n)]
    task = {"reward_type": reward_type, "termination_config": {"max_steps": 60, "fall_height": fall_height}}
    if discrete is None:
        stats = compare(scene, episodes, drive_ahead(rng, (steps, n)), task=task, device=device)
    else:
        k = 4 if discrete["stop"] else 3
        p = np.array([0.7, 0.1, 0.1, 0.1][:k])
        actions = rng.choice(k, size=(steps, n), p=p / p.sum())
        stats = compare(scene, episodes, actions, task=task, device=device, action_space="discrete",
                        discrete_actions=discrete)
    event(f"robot-steps mid-fall: {'some' if stats['falling_steps'] else 'none'}")


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    pitted=pitted_scenes(),
    seed=st.integers(0, 2**31 - 1),
    n_worlds=st.integers(1, 3),
    n_robots=st.integers(2, 3),
    steps=st.integers(1, 80),
    fall_heights=st.lists(st.floats(0.2, 2.0), min_size=3, max_size=3),
    per_robot=st.booleans(),
    max_cycles=st.integers(3, 60),
    finished=st.sampled_from(["park", "remove"]),
    discrete=st.one_of(st.none(), st.fixed_dictionaries({
        "forward_step": st.floats(0.05, 0.4), "turn_angle": st.floats(0.05, 1.0), "stop": st.booleans()})),
)
def test_long_falls_match_parallel_envs(
    device: str, pitted: tuple, seed: int, n_worlds: int, n_robots: int, steps: int, fall_heights: list,
    per_robot: bool, max_cycles: int, finished: str, discrete: dict | None,
) -> None:
    """Robots of a world fall over several steps while the others drive on; a robot that is
    truncated mid-fall (``max_cycles``, ``max_steps``) and parked falls on, unseen by the
    contacts, as in the multi-robot env."""
    scene, pit = pitted
    rng = np.random.default_rng(seed)
    episodes = [episodes_at_the_pit(scene, pit, n_robots, rng) for _ in range(n_worlds)]
    tasks = [{"goal_tolerance": 0.2, "termination_config": {"max_steps": 40, "fall_height": h}} for h in fall_heights]
    task: Any = tasks[:n_robots] if per_robot else tasks[0]
    if discrete is None:
        stats = compare_fleet(scene, episodes, drive_ahead(rng, (steps, n_worlds, n_robots)), task=task,
                              device=device, finished=finished, max_cycles=max_cycles)
    else:
        k = 4 if discrete["stop"] else 3
        p = np.array([0.7, 0.1, 0.1, 0.1][:k])
        actions = rng.choice(k, size=(steps, n_worlds, n_robots), p=p / p.sum())
        stats = compare_fleet(scene, episodes, actions, task=task, device=device, finished=finished,
                              max_cycles=max_cycles, action_space="discrete", discrete_actions=discrete)
    event(f"robot-steps mid-fall: {'some' if stats['falling_steps'] else 'none'}")
