"""Several robots per world in the batched engine against one PettingZoo env per world.

For random grid scenes (clutter, walls, maybe a hole to fall into), fixed random episodes
of 2 to 4 robots and random action sequences, ``VectorPointNavEnv(W, n_robots=R)``
matches ``W`` separate ``parallel_env(n_robots=R, backend="kinematic")`` step for step
(observations within 1e-4, rewards within 1e-5, the same terminated, truncated and active
flags, success, SPL and SoftSPL) over whole episodes and their autoresets, with parked or
removed finished robots, differential or holonomic, with or without a range scan and a local map (both see the other
robots of its world; the map's codes are equal, except at a cell centre on a cell edge or
a disc's rim, ``local_map_reference``), on numpy and on torch on the CPU; and the same with
discrete actions (``action_space="discrete"``, random ``forward_step``, ``turn_angle`` and
STOP, with or without a scan and a local map); and with per-robot
``task`` and ``robot`` lists, robots of different radii among them.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from fleet_reference import compare_fleet, fleet_episodes
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from vector_reference import random_actions

from pointnav_core.scenes import Scene
from pointnav_core.testing.strategies import cluttered_rooms

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])


def crowded_scenes() -> st.SearchStrategy[Scene]:
    """Walled rooms of 16 to 30 cells a side with a free 12 x 12 patch, so that four robots
    and their goals always fit."""
    return cluttered_rooms(max_clutter=0.1, min_side=16, patch=12)


def per_robot_lists(specs: Callable[[int], st.SearchStrategy[Any]]) -> st.SearchStrategy[tuple[Any, Any, int]]:
    """(task, robot, n_robots) for 2 to 4 robots: one task dict or one per robot, and ``specs(n_robots)``."""
    return st.integers(2, 4).flatmap(lambda r: st.tuples(
        st.one_of(robot_tasks(), st.lists(robot_tasks(), min_size=r, max_size=r)), specs(r), st.just(r)))


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    scene=crowded_scenes(),
    seed=st.integers(0, 2**31 - 1),
    n_worlds=st.integers(1, 3),
    n_robots=st.integers(2, 4),
    steps=st.integers(1, 120),
    reward_type=st.sampled_from(["l2", "geodesic"]),
    max_steps=st.integers(5, 60),
    max_cycles=st.integers(3, 70),
    finished=st.sampled_from(["park", "remove"]),
    scan=st.one_of(st.none(), st.fixed_dictionaries({
        "n_rays": st.integers(1, 32), "fov": st.floats(0.5, 2 * np.pi), "max_range": st.floats(0.3, 5.6),
        "min_range": st.sampled_from([0.0, 0.05, 0.2]),
        # Counter-based noise and dropout: the same draws as the parallel env reset with seed w.
        "noise_std": st.sampled_from([0.0, 0.05]), "dropout": st.sampled_from([0.0, 0.3]),
    })),
    local_map=st.one_of(st.none(), st.fixed_dictionaries({
        "size": st.floats(0.2, 4.0), "cells": st.integers(1, 12), "dtype": st.sampled_from(["uint8", "float32"]),
    })),
    drive=st.sampled_from(["differential", "holonomic"]),
)
def test_fleet_matches_parallel_envs(
    device: str, scene: Scene, seed: int, n_worlds: int, n_robots: int, steps: int, reward_type: str,
    max_steps: int, max_cycles: int, finished: str, scan: dict | None, local_map: dict | None, drive: str,
) -> None:
    rng = np.random.default_rng(seed)
    # goal_tolerance 0.2 m: the multi-robot env keeps goals max(0.4, 0.36, 0.1) m apart.
    episodes = fleet_episodes(scene, n_worlds, n_robots, rng, goal_gap=0.4)
    # Overshoot [-1, 1] (clipping), and drive straight ahead (and diagonally) often, into walls and robots.
    actions = random_actions(rng, (steps, n_worlds, n_robots), drive)
    task = {"reward_type": reward_type, "goal_tolerance": 0.2,
            "termination_config": {"max_steps": max_steps, "max_collisions": 15}}
    sensors = {k: v for k, v in (("scan", scan), ("local_map", local_map)) if v is not None}
    compare_fleet(scene, episodes, actions, task=task, device=device, finished=finished, max_cycles=max_cycles,
                  sensors=sensors or None, robot={"drive": drive})


@st.composite
def robot_tasks(draw: st.DrawFn) -> dict:
    """Task arguments for one robot: every number the engine takes per robot, drawn."""
    return {
        "reward_type": draw(st.sampled_from(["l2", "geodesic"])),
        "goal_tolerance": draw(st.floats(0.05, 0.2)),
        "goal_in_polar": draw(st.booleans()),
        "termination_config": {"max_steps": draw(st.integers(5, 60)), "max_collisions": draw(st.integers(0, 20)),
                               "fall_height": draw(st.sampled_from([0.01, 0.03, 0.1, 0.2, 0.7, 2.0]))},
        "reward_config": {"r_potential": draw(st.floats(0.0, 2.0)), "r_collision": draw(st.floats(0.0, 1.0)),
                          "r_pointgoal": draw(st.floats(0.0, 20.0))},
    }


# Speed limits the batched engine takes at 10 Hz: at most half a 0.1 m cell and 0.25 rad a
# step; radii up to 0.2 m (the episodes are placed for the largest, 0.2 m).
robot_specs = st.fixed_dictionaries({"radius": st.sampled_from([0.18, 0.05, 0.1, 0.2]),
                                     "max_linear_velocity": st.floats(0.05, 0.5),
                                     "max_angular_velocity": st.floats(0.2, 2.5)})


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    scene=crowded_scenes(),
    seed=st.integers(0, 2**31 - 1),
    n_worlds=st.integers(1, 3),
    lists=per_robot_lists(lambda r: st.one_of(st.none(), robot_specs, st.lists(robot_specs, min_size=r, max_size=r))),
    steps=st.integers(1, 120),
    max_cycles=st.integers(3, 70),
    finished=st.sampled_from(["park", "remove"]),
    scan=st.booleans(),
    local_map=st.booleans(),
    drive=st.sampled_from(["differential", "holonomic"]),
)
def test_fleet_with_per_robot_lists_matches_parallel_envs(
    device: str, scene: Scene, seed: int, n_worlds: int, lists: tuple, steps: int, max_cycles: int,
    finished: str, scan: bool, local_map: bool, drive: str,
) -> None:
    """Per-robot ``task`` and ``robot`` lists (or one shared value) give each robot its own
    rewards, tolerance, limits, goal frame, speed limits and radius (its contacts, and its
    disc in the others' scans and local maps), as in the multi-robot env (every robot of
    one drive)."""
    task, robot, n_robots = lists
    if drive == "holonomic":
        robot = [{**r, "drive": drive} for r in robot] if isinstance(robot, list) else {**(robot or {}), "drive": drive}
    rng = np.random.default_rng(seed)
    # The multi-robot env keeps goals max(tol_i + tol_j, r_i + r_j, cell) apart: 0.4 m at most here.
    episodes = fleet_episodes(scene, n_worlds, n_robots, rng, radius=0.2, goal_gap=0.4)
    actions = random_actions(rng, (steps, n_worlds, n_robots), drive)
    sensors = {"scan": {"n_rays": 8, "max_range": 2.0, "noise_std": 0.05, "dropout": 0.2}} if scan else {}
    if local_map:
        sensors["local_map"] = {"size": 1.6, "cells": 8}
    compare_fleet(scene, episodes, actions, task=task, robot=robot, device=device, finished=finished,
                  max_cycles=max_cycles, sensors=sensors or None)


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=30, deadline=None)
@given(scene=crowded_scenes(), seed=st.integers(0, 2**31 - 1), n_robots=st.integers(1, 4), own_radii=st.booleans())
def test_one_slow_robot_resolves_as_in_the_multi_robot_resolver(
    device: str, scene: Scene, seed: int, n_robots: int, own_radii: bool
) -> None:
    """The env's shortcut for a world with one slow robot (the one-robot resolver) equals
    the multi-robot resolver with that robot the only one present (one radius for all, or
    each robot its own)."""
    from pointnav_core.vector.contacts import advance
    from pointnav_core.vector.floors import FloorTables
    from pointnav_core.vector.robots import advance_robots, robot_walls
    from pointnav_core.vector.xp import make_arrays

    rng = np.random.default_rng(seed)
    a, radius, travel, worlds = make_arrays(device), 0.18, 0.05, 32
    floors = FloorTables([scene], 0, radius, a)
    xy = np.array([scene.get_random_point(0, robot=radius, rng=rng)[1][:2] for _ in range(worlds * n_robots)])
    x, y = xy[:, 0].reshape(worlds, n_robots), xy[:, 1].reshape(worlds, n_robots)
    heading = rng.uniform(-np.pi, np.pi, (worlds, n_robots))
    length = rng.uniform(0.0, travel, (worlds, n_robots))
    mx, my = length * np.cos(heading), length * np.sin(heading)
    mover = rng.integers(n_robots, size=worlds)
    present = np.arange(n_robots)[None, :] == mover[:, None]
    args = [a.asarray(v) for v in (x, y, mx, my)]
    scene_ids = a.zeros((worlds, n_robots), a.i64)
    rows = np.arange(worlds)
    # Placed for 0.18 m, so that smaller robots fit too.
    radii = rng.choice([0.05, 0.1, 0.18], (worlds, n_robots)) if own_radii else np.full((worlds, n_robots), radius)
    rad, one_rad = (a.asarray(radii), a.asarray(radii[rows, mover])) if own_radii else (radius, radius)
    walls = robot_walls(floors, scene_ids, *args, rad, travel)
    got = [a.numpy(v) for v in advance_robots(a, *args, rad, present=a.asarray(present, a.boolean), walls=walls)]
    one = [a.asarray(v[rows, mover]) for v in (x, y, mx, my)]
    want = [a.numpy(v) for v in advance(floors, a.zeros(worlds, a.i64), *one, one_rad, travel)]
    np.testing.assert_allclose(got[0][rows, mover], want[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(got[1][rows, mover], want[1], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(got[2][rows, mover], want[2])


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    scene=crowded_scenes(),
    seed=st.integers(0, 2**31 - 1),
    n_worlds=st.integers(1, 3),
    n_robots=st.integers(2, 4),
    steps=st.integers(1, 80),
    reward_type=st.sampled_from(["l2", "geodesic"]),
    max_steps=st.integers(5, 40),
    max_cycles=st.integers(3, 50),
    finished=st.sampled_from(["park", "remove"]),
    forward_step=st.floats(0.02, 0.4),
    turn_angle=st.floats(0.05, 1.5),
    stop=st.booleans(),
    scan=st.one_of(st.none(), st.fixed_dictionaries({"n_rays": st.integers(1, 16), "max_range": st.floats(0.3, 3.0)})),
    local_map=st.one_of(st.none(), st.fixed_dictionaries({"size": st.floats(0.2, 4.0), "cells": st.integers(1, 12)})),
    drive=st.sampled_from(["differential", "holonomic"]),
)
def test_fleet_discrete_matches_parallel_envs(
    device: str, scene: Scene, seed: int, n_worlds: int, n_robots: int, steps: int, reward_type: str,
    max_steps: int, max_cycles: int, finished: str, forward_step: float, turn_angle: float, stop: bool,
    scan: dict | None, local_map: dict | None, drive: str,
) -> None:
    """Discrete actions (each robot's for its control steps, all robots of a world together,
    cut short by contacts; STOP) as the multi-robot env runs them."""
    rng = np.random.default_rng(seed)
    # Some goals at the start, so that STOP (or reaching the goal without STOP) succeeds.
    episodes = fleet_episodes(scene, n_worlds, n_robots, rng, goal_gap=0.4, at_start=0.4)
    n_actions = 4 if stop else 3
    weights = np.array([0.5, 0.2, 0.2, 0.1][:n_actions])
    actions = rng.choice(n_actions, size=(steps, n_worlds, n_robots), p=weights / weights.sum())
    task = {"reward_type": reward_type, "goal_tolerance": 0.2,
            "termination_config": {"max_steps": max_steps, "max_collisions": 15}}
    discrete = {"forward_step": forward_step, "turn_angle": turn_angle, "stop": stop}
    sensors = {k: v for k, v in (("scan", scan), ("local_map", local_map)) if v is not None}
    compare_fleet(scene, episodes, actions, task=task, device=device, finished=finished, max_cycles=max_cycles,
                  sensors=sensors or None, action_space="discrete", discrete_actions=discrete, robot={"drive": drive})


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    scene=crowded_scenes(),
    seed=st.integers(0, 2**31 - 1),
    n_worlds=st.integers(1, 3),
    lists=per_robot_lists(lambda r: st.lists(robot_specs, min_size=r, max_size=r)),
    steps=st.integers(1, 60),
    max_cycles=st.integers(3, 50),
    finished=st.sampled_from(["park", "remove"]),
    forward_step=st.floats(0.02, 0.4),
    turn_angle=st.floats(0.05, 1.5),
    stop=st.booleans(),
)
def test_fleet_discrete_with_per_robot_speeds_matches_parallel_envs(
    device: str, scene: Scene, seed: int, n_worlds: int, lists: tuple, steps: int, max_cycles: int,
    finished: str, forward_step: float, turn_angle: float, stop: bool,
) -> None:
    """Discrete actions of robots whose speed limits differ: each robot holds its action for
    its own number of control steps, and a world runs as many as its longest action, as in
    the multi-robot env."""
    task, robot, n_robots = lists
    rng = np.random.default_rng(seed)
    # No goal at a start: after a straight MOVE_FORWARD from it the goal lies exactly behind,
    # where a polar goal's angle is +pi or -pi by the last bit of a cosine (torch's or math's).
    episodes = fleet_episodes(scene, n_worlds, n_robots, rng, radius=0.2, goal_gap=0.4)  # the largest radius drawn
    n_actions = 4 if stop else 3
    weights = np.array([0.5, 0.2, 0.2, 0.1][:n_actions])
    actions = rng.choice(n_actions, size=(steps, n_worlds, n_robots), p=weights / weights.sum())
    discrete = {"forward_step": forward_step, "turn_angle": turn_angle, "stop": stop}
    compare_fleet(scene, episodes, actions, task=task, robot=robot, device=device, finished=finished,
                  max_cycles=max_cycles, action_space="discrete", discrete_actions=discrete)
