"""The batched range scan: its two paths equal, both against shapely, and the env against PointNavEnv.

For random grid scenes (obstacle cells, VOID, the map's edge) and random poses of up to
four robots per world, some absent, at robot radius / cell size ratios from 0.3 to 5
(one radius for all robots, or each robot its own):

- the compiled path (numba) and the array path (numpy, and torch on the CPU) give the
  same ranges;
- every range lies within 1e-4 m of an independent reference (``scan_reference``: shapely
  rays against the blocked squares, a frame round the map and the other robots' discs),
  so no ray passes a blocked cell; one case is a 2000 x 2000 floor;
- ``VectorPointNavEnv(sensors={"scan": ...})`` matches ``PointNavEnv`` with the same scan
  step for step (observations within 1e-4) on numpy and torch on the CPU.
"""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scan_reference import assert_within, blocked_shapes, reference_ranges
from vector_reference import compare, random_episodes

from pointnav_core.floor.maps import FREE, OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.sensors import scan_angles
from pointnav_core.vector.scan import ScanTables, cast_batch, compiled_available
from pointnav_core.vector.xp import make_arrays

HAS_TORCH = importlib.util.find_spec("torch") is not None
DEVICES = ["numpy"] + (["cpu"] if HAS_TORCH else [])
ATOL = 1e-4


def _grid(rng: np.random.Generator, rows: int, cols: int, density: float) -> np.ndarray:
    grid = np.zeros((rows, cols), np.uint8)
    grid[rng.random((rows, cols)) < density] = OBSTACLE
    grid[rng.random((rows, cols)) < 0.05] = VOID
    return grid


def _paths(scenes, tables_np, scene, x, y, yaw, present, radius, angles, max_range):
    """Ranges by every available path: array (numpy), numba, torch array, torch numba."""
    out = {"array": cast_batch(tables_np, scene, x, y, yaw, present, radius, angles, max_range, "array")}
    if compiled_available():
        out["numba"] = cast_batch(tables_np, scene, x, y, yaw, present, radius, angles, max_range, "numba")
    if HAS_TORCH:
        import torch

        tables_t = ScanTables(scenes, 0, make_arrays("cpu"))
        rad = radius if isinstance(radius, float) else torch.as_tensor(radius)
        args = (torch.as_tensor(scene), *(torch.as_tensor(v) for v in (x, y, yaw, present)), rad, angles, max_range)
        out["torch"] = cast_batch(tables_t, *args, "array").numpy()
        if compiled_available():  # torch on the CPU goes through the kernel, on views
            out["torch numba"] = cast_batch(tables_t, *args, "numba").numpy()
    return out


def _check_scenes(scenes, x, y, yaw, present, scene, radius, angles, max_range):
    tables = ScanTables(scenes, 0, make_arrays("numpy"))
    results = _paths(scenes, tables, scene, x, y, yaw, present, radius, angles, max_range)
    ref = results["array"]
    for name, got in results.items():
        assert got.shape == x.shape + (len(angles),)
        # The compiled path decides every crossing on the same numbers: equal to the ulp.
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9, err_msg=f"{name} vs array")
    shapes = {}
    w_n, r_n = x.shape
    for w in range(w_n):
        k = int(scene[w])
        if k not in shapes:
            tmap = scenes[k].floors[0]
            shapes[k] = blocked_shapes(np.asarray(tmap.codes), float(tmap.resolution), tuple(tmap.origin))
        for i in range(r_n):
            if not present[w, i]:
                assert (ref[w, i] == max_range).all()
                continue
            rad = np.broadcast_to(radius, x.shape)  # one radius, or each robot's own
            discs = [(x[w, m], y[w, m], rad[w, m]) for m in range(r_n) if m != i and present[w, m]]
            loose, strict = reference_ranges(shapes[k], (x[w, i], y[w, i]), yaw[w, i] + angles, max_range, discs)
            for got in results.values():
                assert_within(got[w, i], loose, strict, ATOL)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**31 - 1),
    n_worlds=st.integers(1, 3),
    n_robots=st.integers(1, 4),
    ratio=st.floats(0.3, 5.0),
    res=st.sampled_from([0.05, 0.1, 0.25]),
    n_rays=st.integers(1, 24),
    max_range=st.floats(0.3, 4.0),
    own_radii=st.booleans(),
)
def test_paths_agree_with_each_other_and_shapely(seed, n_worlds, n_robots, ratio, res, n_rays, max_range, own_radii) -> None:
    rng = np.random.default_rng(seed)
    scenes = []
    for cell in (res, float(rng.choice([0.05, 0.1, 0.25]))):  # worlds on floors of different cell sizes
        rows, cols = rng.integers(4, 30, 2)
        scenes.append(Scene.from_array(_grid(rng, rows, cols, rng.uniform(0.0, 0.3)), cell, origin=tuple(rng.uniform(-2, 2, 2))))
    scene = rng.integers(0, 2, n_worlds)
    x = np.empty((n_worlds, n_robots))
    y = np.empty((n_worlds, n_robots))
    for w in range(n_worlds):
        tmap = scenes[scene[w]].floors[0]
        h, wd = np.asarray(tmap.codes).shape
        res = float(tmap.resolution)
        # Anywhere on the map, obstacles and VOID included; some on grid lines.
        x[w] = tmap.origin[0] + rng.uniform(0, wd, n_robots) * res
        y[w] = tmap.origin[1] + rng.uniform(0, h, n_robots) * res
        snap = rng.random(n_robots) < 0.2
        x[w, snap] = tmap.origin[0] + np.round(rng.uniform(0, wd, snap.sum())) * res
    yaw = rng.uniform(-2 * np.pi, 2 * np.pi, (n_worlds, n_robots))
    present = rng.random((n_worlds, n_robots)) < 0.8
    angles = scan_angles(n_rays, rng.uniform(0.5, 2 * np.pi))
    radius = ratio * float(scenes[0].floors[0].resolution)
    if own_radii:  # each robot its own radius, down to a fifth of the drawn one
        radius = radius * rng.uniform(0.2, 1.0, (n_worlds, n_robots))
    _check_scenes(scenes, x, y, yaw, present, scene, radius, angles, max_range)


@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), ratio=st.floats(0.3, 5.0))
def test_large_floor(seed, ratio) -> None:
    """A 2000 x 2000 floor of 0.05 m cells, sparse clutter, rays up to 5.6 m."""
    rng = np.random.default_rng(seed)
    grid = _grid(rng, 2000, 2000, 0.002)
    res = 0.05
    scene = Scene.from_array(grid, res)
    n = 3
    x = rng.uniform(0, 2000 * res, (1, n))
    y = rng.uniform(0, 2000 * res, (1, n))
    x[0, 1], y[0, 1] = x[0, 0] + 0.8, y[0, 0] - 0.3  # a neighbour in sight
    x[0, 2], y[0, 2] = rng.uniform(0, 0.5), rng.uniform(0, 0.5)  # near the map's corner
    yaw = rng.uniform(-np.pi, np.pi, (1, n))
    present = np.ones((1, n), bool)
    _check_scenes([scene], x, y, yaw, present, np.zeros(1, np.int64), ratio * res, scan_angles(32, 2 * np.pi), 5.6)


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
    grid = _grid(rng, rows, cols, rng.uniform(0.0, 0.12))
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
