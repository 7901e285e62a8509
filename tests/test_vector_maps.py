"""The batched engine on maps at their own resolution, at the default 10 Hz.

A 0.5 m/s robot drives 0.05 m a control step: a whole cell of a 0.05 m map and nearly two of
a 0.03 m one. Near a wall the kinematic backend cuts such a step into sub-steps (the travel
over half a cell: two and four), and so does the batched engine; these tests play it
against one ``PointNavEnv`` per world (:mod:`vector_reference`) on a crop of a real ROS
map at 0.05 m (``tests/data/bookstore``) and on a cluttered 0.03 m floor, on the compiled
contacts and on the array path that runs on a GPU; and on polygon floors (the generated
house, a floor plan whose thin wall covers no cell centre), which the compiled contacts
take as the backend's capsule walls.
"""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest
import shapely
from fleet_reference import compare_fleet, fleet_episodes
from map_data import bookstore
from shapely import affinity
from vector_reference import (
    OBS_TOL,
    REWARD_TOL,
    compare,
    random_actions,
    random_episodes,
)

from pointnav_core import scenes
from pointnav_core.floor.maps import OBSTACLE, VOID
from pointnav_core.scenes import Scene
from pointnav_core.utils import compiled as _compiled

ARRAY_DEVICE = "cpu" if importlib.util.find_spec("torch") else "numpy"
TASK = {"reward_type": "geodesic", "termination_config": {"max_steps": 80, "max_collisions": 30}}


def fine_clutter() -> Scene:
    """A 3.6 x 3 m room at 0.03 m: boxes of 2 to 8 cells, one-cell walls and a VOID hole."""
    rng = np.random.default_rng(3)
    grid = np.zeros((100, 120), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    for _ in range(40):
        r, c = rng.integers(2, 95), rng.integers(2, 115)
        h, w = rng.integers(2, 9, size=2)
        grid[r:r + h, c:c + w] = OBSTACLE
    grid[50, 20:60] = OBSTACLE  # a wall one cell (0.03 m) thick
    grid[70:80, 90:100] = VOID
    return Scene.from_array(grid, 0.03)


@pytest.mark.parametrize(("resolution", "paths", "device"), [
    (0.05, "compiled", "numpy"), (0.05, "arrays", ARRAY_DEVICE), (0.03, "compiled", "numpy"), (0.03, "arrays", "numpy"),
])
def test_native_resolution_matches_single_envs(resolution: float, paths: str, device: str) -> None:
    # A crop of the bookstore (shelves, walls, unknown space as VOID) or the 0.03 m room.
    scene = bookstore(slice(40, 140), slice(44, 184)) if resolution == 0.05 else fine_clutter()
    rng = np.random.default_rng(11)
    episodes = random_episodes(scene, 6, rng)
    actions = random_actions(rng, (160 if paths == "compiled" else 80, 6))
    if paths == "arrays":  # the array path, the one a GPU runs (on torch where it is installed)
        with _compiled.numpy_paths():
            stats = compare(scene, episodes, actions, task=TASK, device=device)
    else:
        stats = compare(scene, episodes, actions, task=TASK)
    assert stats["obs_diff"] <= OBS_TOL and stats["reward_diff"] <= REWARD_TOL
    # The play reached walls (sub-stepped contacts) and ended episodes.
    assert stats["contacts"] >= 10 and stats["ends"] >= 3, stats


def test_robots_of_several_speeds_match_parallel_envs_at_005() -> None:
    # Three robots a world, the fastest at 0.8 m/s (0.08 m a step: two sub-steps near a wall,
    # once refused as "too low a control rate"), on the bookstore crop.
    scene = bookstore(slice(40, 140), slice(44, 184))
    rng = np.random.default_rng(5)
    robots = [{}, {"max_linear_velocity": 0.8}, {"max_linear_velocity": 0.3, "radius": 0.12}]
    task = {"reward_type": "geodesic", "goal_tolerance": 0.2, "termination_config": {"max_steps": 60}}
    stats = compare_fleet(scene, fleet_episodes(scene, 3, 3, rng), random_actions(rng, (100, 3, 3)), task=task,
                          robot=robots)
    assert stats["contacts"] > 5 and stats["ends"] > 0, stats


def floor_plan() -> Scene:
    """A 4 x 3 m floor plan at 0.1 m: a wall 2 cm thick (no cell centre under it), a box
    turned 30 degrees and a 24-gon pillar; only their edges block where no cell does."""
    thin = shapely.box(2.01, 0.0, 2.03, 2.1)
    turned = affinity.rotate(shapely.box(0.8, 1.8, 1.4, 2.2), 30.0)
    pillar = shapely.Point(3.2, 1.0).buffer(0.25, quad_segs=6)
    return Scene.from_polygons(shapely.box(0.0, 0.0, 4.0, 3.0), [thin, turned, pillar], resolution=0.1)


@pytest.mark.parametrize("which", ["house", "plan"])
def test_polygon_floors_match_single_envs(which: str) -> None:
    scene = scenes.rooms(seed=0) if which == "house" else floor_plan()
    rng = np.random.default_rng(2)
    stats = compare(scene, random_episodes(scene, 6, rng), random_actions(rng, (150, 6)), task=TASK)
    assert stats["obs_diff"] <= OBS_TOL and stats["reward_diff"] <= REWARD_TOL
    assert stats["contacts"] >= 20 and stats["ends"] >= 2, stats


def test_robots_meet_polygon_edges_and_each_other() -> None:
    scene = floor_plan()
    rng = np.random.default_rng(4)
    task = {"reward_type": "geodesic", "goal_tolerance": 0.2, "termination_config": {"max_steps": 60}}
    stats = compare_fleet(scene, fleet_episodes(scene, 3, 3, rng), random_actions(rng, (100, 3, 3)), task=task)
    assert stats["contacts"] > 10 and stats["robot_contacts"] > 0, stats


def test_polygon_floors_need_the_compiled_contacts() -> None:
    # The array contacts (a GPU, or no numba) know grid squares only: refused, naming the scene.
    from pointnav_core.vector import VectorPointNavEnv

    with _compiled.numpy_paths(), pytest.raises(ValueError, match="scene 0 has obstacle polygons on floor 0"):
        VectorPointNavEnv(1, scene=floor_plan())
