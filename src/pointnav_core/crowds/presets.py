"""Standard crowd scenarios, so that papers compare on the same ones.

Each preset is a :class:`Scenario`: a scene, the robot's task (fixed start, heading and goal)
and a ``pedestrians`` dict with fixed starts and goal lists (plain lists: an
:class:`~pointnav_core.envs.config.EnvConfig` saves them, so a results file records the
scenario it was run on). ``PointNavEnv(**scenario.env_arguments())`` builds it.

==========================  =================================================================
preset                      what
==========================  =================================================================
:func:`circle_crossing`     CrowdNav's: 5 humans on a 4 m circle, each walking to the point
                            opposite and back, radius 0.3 m at 1 m/s, in an open 12 x 12 m
                            room; the robot crosses the circle from (0, -4) to (0, 4)
:func:`corridor`            a 2.4 m wide, 14 m long corridor: the robot walks its length while
                            4 people come the other way in two lanes 0.3 m off its line
:func:`doorway`             two 6 x 6 m rooms joined by a 1.2 m door: the robot goes through
                            the door while 4 people come through it the other way
:func:`igibson_density`     iGibson's social navigation density, 1 pedestrian per 8 m² of
                            free floor (a ``pedestrians`` dict for any scene: the houses)
==========================  =================================================================

The robot's radius is the default ``RobotSpec``'s (0.18 m); the pedestrians walk by ORCA
and see the robot unless the arguments say otherwise.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from pointnav_core import scenes

__all__ = ["Scenario", "circle_crossing", "corridor", "doorway", "igibson_density"]

RESOLUTION = 0.1  # m per cell of the preset scenes


@dataclasses.dataclass(frozen=True)
class Scenario:
    """A scene, the robot's task and the crowd: ``PointNavEnv(**scenario.env_arguments())``."""

    name: str
    scene: Any
    task: dict[str, Any]
    pedestrians: dict[str, Any]

    def env_arguments(self) -> dict[str, Any]:
        """``scene``, ``task`` and ``pedestrians`` for an env."""
        return {"scene": self.scene, "task": dict(self.task), "pedestrians": dict(self.pedestrians)}


def _walled(grid: np.ndarray, origin: tuple[float, float]) -> Any:
    """A one-floor scene of ``grid`` (True free) with a wall around it."""
    grid = grid.copy()
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = False
    return scenes.Scene.from_array(grid, RESOLUTION, origin=origin)


def _facing(yaw: float) -> list[float]:
    return [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)]


def circle_crossing(humans: int = 5, circle_radius: float = 4.0, seed: int = 0, **pedestrians: Any) -> Scenario:
    """CrowdNav's circle crossing (Chen et al. 2019): ``humans`` on a ``circle_radius`` m
    circle at equal angles (CrowdNav draws them at random; fixed here, none on the robot's
    line), each start moved by CrowdNav's noise, up to half the preferred speed's worth of
    metres in x and y (drawn from ``seed``), and each walking to the point opposite its
    start and back. Without the noise the humans meet at the centre in perfect symmetry,
    where ORCA stops them all (its known deadlock). Extra keyword arguments override the
    ``pedestrians`` dict."""
    side = 2 * circle_radius + 4.0
    cells = round(side / RESOLUTION)
    scene = _walled(np.ones((cells, cells), dtype=bool), (-side / 2, -side / 2))
    # Equal steps, none on the robot's line x = 0 (its start and goal are on the circle).
    turn = math.pi / (2 * humans) if humans % 4 == 2 else 0.0
    angles = [2 * math.pi * (k + 0.5) / humans + turn for k in range(humans)]
    noise = np.random.default_rng(seed).uniform(-0.5, 0.5, (humans, 2))  # CrowdNav's, at 1 m/s
    starts = [[circle_radius * math.cos(a) + dx, circle_radius * math.sin(a) + dy] for a, (dx, dy) in zip(angles, noise.tolist())]
    goals = [[[-x, -y], [x, y]] for x, y in starts]
    task = {"initial_pos": [0.0, -circle_radius], "initial_quat": _facing(math.pi / 2), "goal_pos": [0.0, circle_radius]}
    crowd = {"starts": starts, "goals": goals, "radius": 0.3, "speed": 1.0, **pedestrians}
    return Scenario("circle_crossing", scene, task, crowd)


def corridor(humans: int = 4, width: float = 2.4, length: float = 14.0, **pedestrians: Any) -> Scenario:
    """A corridor ``width`` x ``length`` m along x: the robot from one end to the other along
    its middle, and ``humans`` coming the other way in two lanes a quarter of the width
    apart about the middle, 1.5 m apart along it, then walking back."""
    rows, cols = round((width + 0.2) / RESOLUTION), round((length + 0.2) / RESOLUTION)
    scene = _walled(np.ones((rows, cols), dtype=bool), (-(length + 0.2) / 2, -(width + 0.2) / 2))
    end = length / 2 - 1.0
    lanes = (-width / 8, width / 8)  # near the robot's line: they must give way
    starts = [[end - 1.5 * (k // 2), lanes[k % 2]] for k in range(humans)]
    goals = [[[-end, y], [x, y]] for x, y in starts]
    task = {"initial_pos": [-end, 0.0], "initial_quat": _facing(0.0), "goal_pos": [end, 0.0]}
    crowd = {"starts": starts, "goals": goals, "radius": 0.25, "speed": (0.8, 1.0), **pedestrians}
    return Scenario("corridor", scene, task, crowd)


def doorway(humans: int = 4, door: float = 1.2, room: float = 6.0, **pedestrians: Any) -> Scenario:
    """Two ``room`` x ``room`` m rooms side by side, joined by a ``door`` m gap in the wall
    between them: the robot goes from the left room's middle to the right room's, and
    ``humans`` start in the right room and walk to the left one and back."""
    cells = round(room / RESOLUTION)
    grid = np.ones((cells + 2, 2 * cells + 3), dtype=bool)
    wall = cells + 1
    grid[:, wall] = False
    half = round(door / RESOLUTION / 2)
    mid = (cells + 2) // 2
    grid[mid - half: mid + half, wall] = True
    width, height = grid.shape[1] * RESOLUTION, grid.shape[0] * RESOLUTION
    scene = _walled(grid, (-width / 2, -height / 2))
    centre = room / 2 + 0.1
    spots = [(centre + dx, dy) for dx, dy in ((0.0, 1.5), (0.0, -1.5), (1.5, 0.0), (-1.2, 0.0), (1.5, 2.0), (1.5, -2.0))]
    starts = [list(spots[k % len(spots)]) for k in range(humans)]
    goals = [[[-x, y], [x, y]] for x, y in starts]
    task = {"initial_pos": [-centre, 0.0], "initial_quat": _facing(0.0), "goal_pos": [centre, 0.0]}
    crowd = {"starts": starts, "goals": goals, "radius": 0.25, "speed": (0.6, 0.9), **pedestrians}
    return Scenario("doorway", scene, task, crowd)


def igibson_density(**pedestrians: Any) -> dict[str, Any]:
    """iGibson's social navigation density, 1 pedestrian per 8 m² (``SocialNavRandomTask``:
    ``num_pedestrians`` from the floor area), as a ``pedestrians`` dict for any scene."""
    return {"density": 1.0 / 8.0, **pedestrians}
