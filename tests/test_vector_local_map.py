"""The batched local map: a hand-drawn case, ties on cell edges, spaces and bad input."""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest

from pointnav_core.backends.kit.checks import planar_quat_floats
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.sensors import LocalMap
from pointnav_core.task.observations import Frame
from pointnav_core.vector import VectorPointNavEnv
from pointnav_core.vector.floors import FloorTables
from pointnav_core.vector.local_map import VectorLocalMap
from pointnav_core.vector.xp import make_arrays

DEVICES = ["numpy"] + (["cpu"] if importlib.util.find_spec("torch") else [])


def _tiny_scene() -> Scene:
    """0.8 x 0.5 m, 0.1 m cells: a wall at x in [0.5, 0.6), one VOID cell at x in [0.3, 0.4), y in [0.1, 0.2)."""
    grid = np.zeros((5, 8), np.uint8)
    grid[:, 5] = OBSTACLE
    grid[1, 3] = VOID
    return Scene.from_array(grid, 0.1)


def _maps(device: str, x: list[float], y: list[float], yaw: list[float], present: list[bool], radius: float) -> np.ndarray:
    a = make_arrays(device)
    lm = VectorLocalMap(LocalMap(size=0.8, cells=4), FloorTables([_tiny_scene()], 0, radius, a))
    args = [a.asarray(np.array([v])) for v in (x, y, yaw)]
    out = lm.values(a.asarray(np.zeros(1), a.i64), *args, a.asarray(np.array([present]), a.boolean), radius)
    return a.numpy(out)[0].reshape(len(x), 4, 4)


@pytest.mark.parametrize("device", DEVICES)
def test_hand_drawn_maps_of_a_robot_before_a_wall(device: str) -> None:
    # Cell centres 0.1 m and 0.3 m from the robot at (0.25, 0.25) m; 2 is VOID or off the map.
    facing_x = np.array([
        [2, 1, 1, 2],  # 0.3 m ahead, x = 0.55: the wall; y = 0.55 (left) and -0.05 (right) off the map
        [2, 0, 2, 2],  # x = 0.35: the VOID cell at y = 0.15
        [2, 0, 0, 2],  # x = 0.15
        [2, 2, 2, 2],  # x = -0.05: behind the map's edge
    ])
    facing_y = np.array([
        [2, 2, 2, 2],  # y = 0.55: off the map ahead
        [2, 0, 0, 1],  # y = 0.35; left is -x: x = -0.05, 0.15, 0.35, 0.55 (the wall, on the right)
        [2, 0, 2, 1],  # y = 0.15: the VOID cell at x = 0.35
        [2, 2, 2, 2],  # y = -0.05
    ])
    got = _maps(device, [0.25, 0.25], [0.25, 0.25], [0.0, math.pi / 2], [True, False], 0.05)
    np.testing.assert_array_equal(got[0], facing_x)
    np.testing.assert_array_equal(got[1], facing_y)


@pytest.mark.parametrize("device", DEVICES)
def test_other_present_robot_is_drawn_as_code_3(device: str) -> None:
    # Robot B at (0.35, 0.38), radius 0.05: A's cell centre (0.35, 0.35) is 0.03 m from it,
    # and B's centre (0.25, 0.28) is 0.03 m from A; every other centre is at least 0.13 m away.
    a_with_b = np.array([[2, 1, 1, 2], [2, 3, 2, 2], [2, 0, 0, 2], [2, 2, 2, 2]])
    b_with_a = np.array([[2, 0, 0, 0], [2, 0, 0, 0], [2, 0, 3, 0], [2, 0, 0, 0]])
    got = _maps(device, [0.25, 0.35], [0.25, 0.38], [0.0, 0.0], [True, True], 0.05)
    np.testing.assert_array_equal(got[0], a_with_b)
    np.testing.assert_array_equal(got[1], b_with_a)
    # An absent robot is not drawn on the others' maps.
    got = _maps(device, [0.25, 0.35], [0.25, 0.38], [0.0, 0.0], [True, False], 0.05)
    a_alone = a_with_b.copy()
    a_alone[1, 1] = 0
    np.testing.assert_array_equal(got[0], a_alone)


@pytest.mark.parametrize("device", DEVICES)
def test_cell_centres_on_cell_edges_read_as_the_single_term(device: str) -> None:
    """Poses on the floor's lattice, headings a multiple of 90 degrees, 0.2 m map cells: every
    centre lies on a cell edge (a tie), and the batched map still equals the single term's,
    because both run the same operations on the same heading."""
    rng = np.random.default_rng(0)
    scene = Scene.from_array((rng.random((12, 12)) < 0.4).astype(np.uint8), 0.1)
    term = LocalMap(size=0.4, cells=2)
    xs = np.arange(2, 11) * 0.1
    x, y = (v.ravel() for v in np.meshgrid(xs, xs))
    yaw = np.repeat(np.arange(-4, 5) * (math.pi / 2), x.size)
    x, y = np.tile(x, 9), np.tile(y, 9)
    a = make_arrays(device)
    lm = VectorLocalMap(term, FloorTables([scene], 0, 0.1, a))
    one = a.asarray(np.ones((x.size, 1)), a.boolean)
    got = a.numpy(lm.values(a.asarray(np.zeros(x.size), a.i64), *(a.asarray(v[:, None]) for v in (x, y, yaw)), one, 0.1))

    class _Env:
        robots, backend = [None], None  # one robot: no discs

    class _Task:
        floor, robot_idn = 0, 0

    env = _Env()
    env.scene = scene  # type: ignore[attr-defined]
    frame = Frame()
    frame.task, frame.env = _Task(), env
    for i in range(x.size):
        frame.set_pose(float(x[i]), float(y[i]), 0.0, planar_quat_floats(float(yaw[i])))
        np.testing.assert_array_equal(got[i, 0], term.grid(frame).ravel(), err_msg=f"pose {x[i], y[i], yaw[i]}")


@pytest.mark.parametrize("n_robots", [1, 2])
def test_observation_space_is_the_single_envs(n_robots: int) -> None:
    grid = np.zeros((30, 30), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    scene = Scene.from_array(grid, 0.1)
    sensors = {"local_map": {"size": 2.0, "cells": 5, "dtype": "float32"}, "scan": {"n_rays": 6}}
    venv = VectorPointNavEnv(3, n_robots=n_robots, scene=scene, sensors=sensors, seed=0)
    single = PointNavEnv(scene=scene, sensors=sensors, flatten_obs=True)
    assert venv.single_observation_space == single.observation_space
    low, high = venv.single_observation_space.low, venv.single_observation_space.high
    assert low.shape == (8 + 6 + 25,) and (low[-25:] == 0.0).all() and (high[-25:] == 3.0).all()
    obs, _ = venv.reset(seed=0)
    obs = venv.arrays.numpy(obs)
    assert obs.dtype == np.float32 and obs.shape == (3, *(() if n_robots == 1 else (n_robots,)), 39)
    assert np.isin(obs[..., -25:], [0.0, 1.0, 2.0, 3.0]).all()


@pytest.mark.parametrize("n_robots", [1, 2])
@pytest.mark.parametrize(
    ("args", "name"),
    [({"cells": 0}, "cells"), ({"cells": 2.5}, "cells"), ({"size": 0.0}, "size"), ({"size": "big"}, "size"),
     ({"dtype": "int8"}, "dtype"), ({"radius": 1.0}, "radius")],
)
def test_bad_local_map_arguments_name_the_parameter(n_robots: int, args: dict, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        PointNavEnv(sensors={"local_map": args})
    with pytest.raises(ValueError, match=name):
        VectorPointNavEnv(2, n_robots=n_robots, sensors={"local_map": args})


def test_vector_local_map_refuses_another_term() -> None:
    a = make_arrays("numpy")
    floors = FloorTables([_tiny_scene()], 0, 0.1, a)
    with pytest.raises(ValueError, match="term must be a LocalMap"):
        VectorLocalMap({"cells": 4}, floors)  # type: ignore[arg-type]
