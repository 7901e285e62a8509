"""The global state of :class:`~pointnav_core.envs.multi_pointnav.MultiPointNavEnv`: its space and values.

``state()`` holds :data:`STATE_FIELDS` for each robot, robot by robot. :func:`state_space`
bounds them by the scene's floors (their extents plus a margin, their heights with room
below for a falling robot); :func:`global_state` reads them from the backend and the tasks
and clips them to those bounds.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from pointnav_core import scenes
from pointnav_core.backends.protocol import Backend
from pointnav_core.task import PointNavigationTask

__all__ = ["STATE_FIELDS", "global_state", "state_space"]

#: The values ``state()`` holds for each robot, in order.
STATE_FIELDS = ("x", "y", "z", "yaw", "goal_x", "goal_y", "goal_z", "active")

# State bounds: margin (m) around the floors' extents (a robot falling off an edge), and
# how far below the lowest floor a falling robot's z is still shown (it is clipped there).
_XY_MARGIN = 1.0
_Z_BELOW = 10.0
_Z_ABOVE = 1.0


def state_space(scene: scenes.Scene, n_robots: int) -> spaces.Box:
    """The float32 ``Box`` of ``len(STATE_FIELDS) * n_robots`` state values.

    Parameters
    ----------
    scene : Scene
        The floors the robots share: x and y are bounded by the union of their extents
        plus 1 m, z by their heights minus 10 m and plus 1 m (metres).
    n_robots : int
        Number of robots.

    Returns
    -------
    gymnasium.spaces.Box
        Bounds per robot, in :data:`STATE_FIELDS` order; yaw in ``[-pi, pi]`` (radians),
        ``active`` in ``[0, 1]``.
    """
    extents = [scene.floors[f].extent for f in range(scene.n_floors)]
    heights = [float(scene.get_floor_height(f)) for f in range(scene.n_floors)]
    xmin = min(e[0] for e in extents) - _XY_MARGIN
    xmax = max(e[1] for e in extents) + _XY_MARGIN
    ymin = min(e[2] for e in extents) - _XY_MARGIN
    ymax = max(e[3] for e in extents) + _XY_MARGIN
    zmin, zmax = min(heights) - _Z_BELOW, max(heights) + _Z_ABOVE
    low = [xmin, ymin, zmin, -math.pi, xmin, ymin, zmin, 0.0]
    high = [xmax, ymax, zmax, math.pi, xmax, ymax, zmax, 1.0]
    return spaces.Box(
        np.array(low * n_robots, dtype=np.float32),
        np.array(high * n_robots, dtype=np.float32),
        dtype=np.float32,
    )


def global_state(
    backend: Backend,
    tasks: Sequence[PointNavigationTask],
    active: Sequence[bool],
    low: NDArray[np.float64],
    high: NDArray[np.float64],
) -> NDArray[np.float32]:
    """Every robot's :data:`STATE_FIELDS`, as a fresh float32 array clipped to ``[low, high]``.

    Parameters
    ----------
    backend : Backend
        Gives robot ``i``'s pose (position in metres, orientation as a quaternion).
    tasks : sequence of PointNavigationTask
        Task ``i`` gives robot ``i``'s goal (metres) and floor height (metres).
    active : sequence of bool
        Whether robot ``i``'s agent is alive (1.0) or not (0.0).
    low, high : ndarray of float64
        The state space's bounds, ``(len(STATE_FIELDS) * len(tasks),)``.

    Returns
    -------
    ndarray of float32
        ``(len(STATE_FIELDS) * len(tasks),)``: x, y, z, yaw (radians), goal x, y, z, active.
    """
    values: list[float] = []
    for i, task in enumerate(tasks):
        pos, quat = backend.get_pose(i)
        x, y, z = pos.tolist()
        qx, qy, qz, qw = quat.tolist()
        yaw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
        gx, gy = task.goal_xy  # type: ignore[misc]
        values += (x, y, z, yaw, gx, gy, task.floor_height, 1.0 if active[i] else 0.0)
    state = np.clip(np.array(values), low, high)
    return state.astype(np.float32)
