"""The batched engine's range scan: reading rules, seeding, the observation layout and bad input."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.sensors import RangeScan
from pointnav_core.vector import VectorPointNavEnv
from pointnav_core.vector.scan import ScanTables, VectorScan, cast_batch
from pointnav_core.vector.xp import make_arrays


def _room(rows: int = 20, cols: int = 30) -> Scene:
    grid = np.zeros((rows, cols), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    return Scene.from_array(grid, 0.1)


def _scan(**kwargs) -> tuple[VectorScan, tuple]:
    scene = _room()
    scan = VectorScan(RangeScan(**kwargs), ScanTables([scene], 0, make_arrays("numpy")))
    rng = np.random.default_rng(0)
    w = 64
    pose = (np.zeros(w, np.int64), rng.uniform(0.3, 2.7, (w, 1)), rng.uniform(0.3, 1.7, (w, 1)),
            rng.uniform(-3, 3, (w, 1)), np.ones((w, 1), bool), 0.18)
    return scan, pose


def test_min_range_reads_max_range() -> None:
    # In a 3 x 2 m room (walls 0.1 m thick) nothing is farther than 2.9 m: with
    # min_range 0.5, the returns nearer than 0.5 read max_range and no others change.
    scan, pose = _scan(n_rays=16, min_range=0.5, max_range=4.0)
    exact = cast_batch(scan.tables, *pose, scan.angles, 4.0)
    got = scan.readings(*pose)
    near = exact < 0.5
    assert near.any() and (~near).any()
    assert (got[near] == 4.0).all()
    np.testing.assert_array_equal(got[~near], exact[~near])


def test_noise_and_dropout_follow_the_rules_and_the_seed() -> None:
    scan, pose = _scan(n_rays=32, min_range=0.0, max_range=1.0, noise_std=0.01, dropout=0.25)
    exact = cast_batch(scan.tables, *pose, scan.angles, 1.0)
    steps = np.zeros((len(pose[0]), 1), np.int64)
    every = np.ones(len(pose[0]), bool)
    scan.seed(np.random.default_rng(7))
    scan.begin(every, len(every))
    a = scan.readings(*pose, steps)
    scan.seed(np.random.default_rng(7))
    scan.begin(every, len(every))
    b = scan.readings(*pose, steps)
    np.testing.assert_array_equal(a, b)  # the same seed, the same scans
    assert ((a >= 0.0) & (a <= 1.0)).all()
    lost = a == 1.0
    seen = exact < 1.0
    # Dropout: about a quarter of the readings that saw something read max_range.
    assert 0.18 < lost[seen].mean() < 0.32
    # Noise moves the kept readings below max_range by a few standard deviations at most.
    kept = seen & ~lost
    diff = a[kept] - exact[kept]
    assert 0.005 < diff.std() < 0.015 and np.abs(diff).max() < 0.06
    scan.seed(np.random.default_rng(8))
    scan.begin(every, len(every))
    assert not np.array_equal(scan.readings(*pose, steps), a)
    with pytest.raises(ValueError, match="steps"):
        scan.readings(*pose)


def test_observation_layout_and_bounds_match_the_single_env() -> None:
    sensors = {"scan": {"n_rays": 12, "max_range": 3.0, "fov": 4.0}}
    venv = VectorPointNavEnv(3, scene=_room(), sensors=sensors, seed=0, pool_size=2, task={"path_range": (0.5, 1.5)})
    single = PointNavEnv(scene=_room(), sensors=sensors, flatten_obs=True)
    assert venv.single_observation_space == single.observation_space
    obs, _ = venv.reset()
    assert obs.shape == (3, 20) and obs.dtype == np.float32
    assert ((obs[:, 8:] >= 0.0) & (obs[:, 8:] <= 3.0)).all()


@pytest.mark.skipif(importlib.util.find_spec("torch") is None, reason="torch not installed (the vector extra)")
def test_torch_observation_is_float32_on_the_device() -> None:
    venv = VectorPointNavEnv(2, scene=_room(), sensors={"scan": {"n_rays": 5}}, device="cpu", seed=0, pool_size=2,
                             task={"path_range": (0.5, 1.5)})
    obs, _ = venv.reset()
    obs, *_ = venv.step(np.zeros((2, 2)))
    assert tuple(obs.shape) == (2, 13) and str(obs.dtype) == "torch.float32"


@pytest.mark.parametrize(
    ("sensors", "message"),
    [
        ({"local_map": {"cells": 0}}, "cells must be an integer"),
        ({"scan": {}, "local_map": {"size": -1.0}}, "size"),
        ({"lidar": {}}, "unknown sensor 'lidar'"),
        ({"scan": {"rays": 8}}, "unknown key 'rays'"),
        ({"scan": {"n_rays": 0}}, "n_rays"),
        ("scan", "sensors must be None or a dict"),
    ],
)
def test_bad_sensors_raise_naming_them(sensors, message) -> None:
    with pytest.raises(ValueError, match=message):
        VectorPointNavEnv(2, scene=_room(), sensors=sensors)


def test_bad_method_raises() -> None:
    scan, pose = _scan()
    with pytest.raises(ValueError, match="method must be one of"):
        cast_batch(scan.tables, *pose, scan.angles, 1.0, method="gpu")
    # The single scan's old name of the plain path is refused here too, naming the new one.
    with pytest.raises(ValueError, match=r"got 'numpy' \(the plain path is 'array'\)"):
        VectorScan(scan.term, scan.tables, method="numpy")


def test_a_sensor_the_batched_engines_do_not_cast_is_refused_by_name(monkeypatch) -> None:
    # Every sensor the single envs know today is cast by the batched engines; one added to
    # the single envs only must be refused, not silently left out of the observation.
    import pointnav_core.sensors as sensors_module

    class Depth:
        name = "depth"

    monkeypatch.setattr(sensors_module, "make_sensors", lambda sensors: [Depth()])
    with pytest.raises(ValueError, match="'depth' is not supported by the batched engine"):
        VectorPointNavEnv(2, scene=_room(), sensors={"depth": {}})
