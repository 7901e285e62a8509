"""Independent references for the crowd tests: a walled room of grid cells, distances to its
wall cells by brute force over every cell square, and the no-overlap rule of a crowd's start."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pointnav_core import scenes
from pointnav_core.datasets.format import PointNavEpisode
from pointnav_core.envs.pointnav import PointNavEnv

RES = 0.1


def room(width: int = 60, height: int = 40, boxes: int = 6, seed: int = 0) -> np.ndarray:
    """A walled room of ``width x height`` cells (0.1 m) with a few square boxes: True = free."""
    grid = np.ones((height, width), dtype=bool)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = False
    rng = np.random.default_rng(seed)
    for _ in range(boxes):
        r, c = rng.integers(5, height - 8), rng.integers(5, width - 8)
        grid[r: r + 3, c: c + 3] = False
    return grid


def wall_clearance(grid: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Distance (m) from each point to the nearest blocked cell square or the map's edge,
    by brute force over every blocked cell (the grid's origin is (0, 0))."""
    rows, cols = np.nonzero(~grid)
    cx, cy = (cols + 0.5) * RES, (rows + 0.5) * RES
    dx = np.maximum(np.abs(xy[:, 0, None] - cx[None]) - RES / 2, 0.0)
    dy = np.maximum(np.abs(xy[:, 1, None] - cy[None]) - RES / 2, 0.0)
    to_cells = np.hypot(dx, dy).min(axis=1)
    h, w = grid.shape
    to_edge = np.minimum.reduce([xy[:, 0], xy[:, 1], w * RES - xy[:, 0], h * RES - xy[:, 1]])
    return np.minimum(to_cells, to_edge)


def env_in(grid: np.ndarray, **kwargs: Any) -> PointNavEnv:
    return PointNavEnv(scene=scenes.Scene.from_array(grid, RES), **kwargs)


def spawn_is_clear(grid: np.ndarray, env: PointNavEnv) -> None:
    """Assert that no pedestrian of ``env`` (just reset in ``grid``) overlaps a wall cell, the
    robot or another pedestrian, and that radii are in the configured range."""
    crowd = env.crowd
    assert (wall_clearance(grid, crowd.positions) >= crowd.radius).all()
    robot = env.backend.get_pose(0)[0][:2]
    assert (np.hypot(*(crowd.positions - robot).T) >= crowd.radius + env.robot.radius).all()
    gaps = np.hypot(*(crowd.positions[:, None] - crowd.positions[None]).transpose(2, 0, 1))
    need = crowd.radius[:, None] + crowd.radius[None]
    off_diagonal = ~np.eye(crowd.n, dtype=bool)
    assert (gaps[off_diagonal] >= need[off_diagonal]).all()
    lo, hi = crowd.config.radius
    assert ((crowd.radius >= lo) & (crowd.radius <= hi)).all()


def world_episode(venv: Any, w: int, k: int | None = None) -> PointNavEpisode:
    """World ``w`` of a batched engine with pedestrians (robot ``k`` of it, with several
    robots a world): its current episode as a dataset episode, carrying the world's crowd
    (for the first robot only, whose recorded crowd the multi-robot env places), which a
    single env's (a multi-robot env's) reset plays exactly."""
    st = venv.state
    at = (w,) if k is None else (w, k)
    yaw = float(st.yaw[at])
    return PointNavEpisode(
        episode_id=str(w) if k is None else f"{w}_{k}", scene_id="here", floor=0,
        start_position=(float(st.x[at]), float(st.y[at]), 0.0),
        start_rotation=(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)),
        goal_position=(float(st.goal_x[at]), float(st.goal_y[at]), 0.0), goal_radius=None,
        geodesic_distance=float(st.start_distance[at]),
        robot_radius=(venv.robot if k is None else venv.robots[k]).radius,
        pedestrians=venv.crowd.record(w) if not k else None,
    )
