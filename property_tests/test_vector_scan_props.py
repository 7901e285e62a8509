"""The batched range scan against PointNavEnv's.

``VectorPointNavEnv(sensors={"scan": ...})`` matches ``PointNavEnv`` with the same scan step
for step (observations within 1e-4) on numpy and torch on the CPU, and a hand-calculated
case reads its ranges on every path. (The two paths equal, and both against shapely:
``property_tests/test_compiled_paths.py``, checks in ``tests/pairs_vector.py``.)
"""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pairs_vector import random_grid
from vector_reference import compare, random_episodes

from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.vector.scan import ScanTables, cast_batch, compiled_available
from pointnav_core.vector.xp import make_arrays

HAS_TORCH = importlib.util.find_spec("torch") is not None
DEVICES = ["numpy"] + (["cpu"] if HAS_TORCH else [])
ATOL = 1e-4


@pytest.mark.parametrize("device", DEVICES)
@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(1, 4),
    steps=st.integers(1, 80),
    n_rays=st.integers(1, 32),
    max_range=st.floats(0.5, 5.6),
    min_range=st.floats(0.0, 0.3),
    noise_std=st.sampled_from([0.0, 0.01, 0.2]),
    dropout=st.sampled_from([0.0, 0.1, 0.5]),
)
def test_env_scan_matches_single_env(device, seed, n, steps, n_rays, max_range, min_range, noise_std, dropout) -> None:
    """Step for step against single envs, autoresets included; with noise and dropout the
    engine seeded with 0 reads in world w the counter-based draws of the env reset with seed w."""
    rng = np.random.default_rng(seed)
    rows, cols = rng.integers(12, 30, 2)
    grid = random_grid(rng, rows, cols, rng.uniform(0.0, 0.12))
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    r, c = rng.integers(1, rows - 7), rng.integers(1, cols - 7)
    grid[r : r + 6, c : c + 6] = FREE  # the robot always fits somewhere
    scene = Scene.from_array(grid, 0.1)
    episodes = random_episodes(scene, n, rng)
    actions = rng.uniform(-1.2, 1.2, (steps, n, 2)).astype(np.float32)
    actions[rng.random((steps, n)) < 0.4, 0] = 1.0
    sensors = {"scan": {"n_rays": n_rays, "max_range": max_range, "min_range": min(min_range, max_range / 2),
                        "fov": float(rng.uniform(0.5, 2 * math.pi)), "noise_std": noise_std, "dropout": dropout}}
    task = {"reward_type": "geodesic", "termination_config": {"max_steps": 40, "max_collisions": 20}}
    compare(scene, episodes, actions, task=task, device=device, sensors=sensors)


def test_hand_calculated_ranges() -> None:
    """A wall 0.25 m ahead of robot 0; robot 1 (radius 0.02 m) 0.1 m behind it; the map's edge."""
    grid = np.zeros((5, 8), np.uint8)
    grid[:, 5] = OBSTACLE  # a wall from x = 0.5 m to 0.6 m
    tables = ScanTables([Scene.from_array(grid, 0.1)], 0, make_arrays("numpy"))
    x, y = np.array([[0.25, 0.15]]), np.array([[0.25, 0.25]])
    yaw = np.zeros((1, 2))
    present = np.array([[True, True]])
    for method in ["array"] + (["numba"] if compiled_available() else []):
        d = cast_batch(tables, np.zeros(1, np.int64), x, y, yaw, present, 0.02, np.array([0.0, math.pi]), 2.0, method)
        # ahead: the wall at x = 0.5; behind: robot 1's disc, its near side at x = 0.17
        assert d[0, 0].tolist() == pytest.approx([0.25, 0.08], abs=1e-12)
        # ahead: robot 0's disc, its near side at x = 0.23; behind: the map's edge at x = 0
        assert d[0, 1].tolist() == pytest.approx([0.08, 0.15], abs=1e-12)
        present[0, 1] = False  # absent: robot 0 sees past it, robot 1 reads max_range
        d = cast_batch(tables, np.zeros(1, np.int64), x, y, yaw, present, 0.02, np.array([0.0, math.pi]), 2.0, method)
        np.testing.assert_allclose(d[0], [[0.25, 0.25], [2.0, 2.0]], rtol=0, atol=1e-12)
        present[0, 1] = True
