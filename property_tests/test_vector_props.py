"""The batched engine against one single env per world, for random scenes and actions.

For random grid scenes (clutter, walls, a hole to fall into), fixed random episodes and
random action sequences, ``VectorPointNavEnv`` matches separate ``PointNavEnv``s on the
kinematic backend step for step (observations within 1e-4, rewards within 1e-5, the same
flags, success, SPL and SoftSPL) over whole episodes and their autoresets, on numpy and
on torch on the CPU, with differential and holonomic robots; with a local map, its codes equal the single env's except at a cell
centre on a cell edge (``local_map_reference``).
"""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from vector_reference import compare, random_actions, random_episodes

from pointnav_core.scenes import Scene
from pointnav_core.testing.strategies import cluttered_rooms

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])


def cluttered_scenes() -> st.SearchStrategy[Scene]:
    """Walled rooms with up to 12 % obstacle cells, maybe a hole, and a free patch."""
    return cluttered_rooms(max_clutter=0.12)


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    scene=cluttered_scenes(),
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(1, 5),
    steps=st.integers(1, 160),
    reward_type=st.sampled_from(["l2", "geodesic"]),
    max_steps=st.integers(5, 80),
    drive=st.sampled_from(["differential", "holonomic"]),
)
def test_vector_matches_single_envs(
    device: str, scene: Scene, seed: int, n: int, steps: int, reward_type: str, max_steps: int, drive: str
) -> None:
    rng = np.random.default_rng(seed)
    episodes = random_episodes(scene, n, rng)
    # Overshoot [-1, 1] (clipping), and drive straight ahead (and diagonally) often, into walls.
    actions = random_actions(rng, (steps, n), drive)
    task = {"reward_type": reward_type, "termination_config": {"max_steps": max_steps, "max_collisions": 20}}
    compare(scene, episodes, actions, task=task, device=device, robot={"drive": drive})


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    scene=cluttered_scenes(),
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(1, 4),
    steps=st.integers(1, 100),
    max_steps=st.integers(5, 60),
    size=st.floats(0.2, 4.0),
    cells=st.integers(1, 12),
    dtype=st.sampled_from(["uint8", "float32"]),
    scan=st.booleans(),
)
def test_vector_local_map_matches_single_envs(
    device: str, scene: Scene, seed: int, n: int, steps: int, max_steps: int, size: float, cells: int, dtype: str,
    scan: bool,
) -> None:
    """With a local map (after a scan or alone) the codes are the single env's, exactly but at ties."""
    rng = np.random.default_rng(seed)
    episodes = random_episodes(scene, n, rng)
    actions = rng.uniform(-1.2, 1.2, (steps, n, 2)).astype(np.float32)
    actions[rng.random((steps, n)) < 0.4, 0] = 1.0
    task = {"termination_config": {"max_steps": max_steps, "max_collisions": 20}}
    sensors = {"local_map": {"size": size, "cells": cells, "dtype": dtype}}
    if scan:
        sensors["scan"] = {"n_rays": 7, "max_range": 2.0}
    compare(scene, episodes, actions, task=task, device=device, sensors=sensors)


@settings(max_examples=30, deadline=None)
@given(scene=cluttered_scenes(), seed=st.integers(0, 2**31 - 1))
def test_fast_path_equals_contact_path(scene: Scene, seed: int) -> None:
    """Where the clearance table vouches for a step, sweeping it for contacts changes nothing."""
    from pointnav_core.vector.contacts import advance
    from pointnav_core.vector.floors import FloorTables
    from pointnav_core.vector.xp import make_arrays

    rng = np.random.default_rng(seed)
    radius = 0.18
    floors = FloorTables([scene], 0, radius, make_arrays("numpy"))
    points = np.array([scene.get_random_point(0, robot=radius, rng=rng)[1][:2] for _ in range(64)])
    x, y = points[:, 0], points[:, 1]
    heading = rng.uniform(-np.pi, np.pi, 64)
    length = rng.uniform(0.0, 0.05, 64)
    mx, my = length * np.cos(heading), length * np.sin(heading)
    zeros = np.zeros(64, dtype=np.int64)
    row, col, inside = floors.cells(zeros, x, y)
    fast = inside & (floors.fast[floors.flat_index(zeros, row, col, inside)] > length)
    nx, ny, contact = advance(floors, zeros, x, y, mx, my, radius, max_travel=0.05)
    np.testing.assert_allclose(nx[fast], (x + mx)[fast], rtol=0, atol=1e-12)
    np.testing.assert_allclose(ny[fast], (y + my)[fast], rtol=0, atol=1e-12)
    assert not contact[fast].any()


@settings(max_examples=30, deadline=None)
@given(scene=cluttered_scenes(), seed=st.integers(0, 2**31 - 1), reach=st.floats(0.0, 0.35))
def test_wall_table_holds_every_wall_within_reach(scene: Scene, seed: int, reach: float) -> None:
    """Every edge obstacle square within ``reach`` of a point (shapely's distance) is in its window."""
    from shapely.geometry import Point, box

    from pointnav_core.vector.contacts import window
    from pointnav_core.vector.floors import FloorTables
    from pointnav_core.vector.xp import make_arrays

    rng = np.random.default_rng(seed)
    floors = FloorTables([scene], 0, 0.0, make_arrays("numpy"))
    codes = np.asarray(scene.floors[0].codes)
    rows, cols = codes.shape
    x, y = rng.uniform(0.0, cols * 0.1, 16), rng.uniform(0.0, rows * 0.1, 16)
    x0, y0, _, _, valid = window(floors, np.zeros(16, dtype=np.int64), x, y, reach)
    edge = np.frombuffer(floors.geometries[0].edge, dtype=np.uint8).reshape(rows, cols).astype(bool)
    for i in range(16):
        got = {(round(a, 9), round(b, 9)) for a, b in zip(x0[i][valid[i]], y0[i][valid[i]])}
        for r, c in zip(*np.nonzero(edge)):
            square = box(c * 0.1, r * 0.1, (c + 1) * 0.1, (r + 1) * 0.1)
            if square.distance(Point(x[i], y[i])) <= reach:
                assert (round(c * 0.1, 9), round(r * 0.1, 9)) in got


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    scene=cluttered_scenes(),
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(1, 5),
    steps=st.integers(1, 120),
    reward_type=st.sampled_from(["l2", "geodesic"]),
    max_steps=st.integers(3, 60),
    forward_step=st.floats(0.02, 0.6),
    turn_angle=st.floats(0.05, 1.5),
    stop=st.booleans(),
    drive=st.sampled_from(["differential", "holonomic"]),
)
def test_vector_discrete_matches_single_envs(
    device: str, scene: Scene, seed: int, n: int, steps: int, reward_type: str, max_steps: int,
    forward_step: float, turn_angle: float, stop: bool, drive: str,
) -> None:
    """Discrete actions (several control steps each, cut short by contacts; STOP) as the single env runs them."""
    rng = np.random.default_rng(seed)
    episodes = random_episodes(scene, n, rng)
    # Some goals at the start, so that STOP (or reaching the goal without STOP) succeeds.
    episodes = [(s, yaw, s if rng.random() < 0.4 else g) for s, yaw, g in episodes]
    n_actions = 4 if stop else 3
    weights = np.array([0.5, 0.2, 0.2, 0.1][:n_actions])
    actions = rng.choice(n_actions, size=(steps, n), p=weights / weights.sum())
    task = {"reward_type": reward_type, "termination_config": {"max_steps": max_steps, "max_collisions": 20}}
    discrete = {"forward_step": forward_step, "turn_angle": turn_angle, "stop": stop}
    compare(scene, episodes, actions, task=task, device=device, action_space="discrete", discrete_actions=discrete,
            robot={"drive": drive})
