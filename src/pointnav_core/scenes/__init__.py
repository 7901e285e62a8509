"""Scenes: one or more floors, with episode sampling and exact geodesic shortest paths, and
the generated scenes (``rooms``, ``maze``, ``clutter``) datasets name.
"""

from pointnav_core.scenes.generated import clutter, maze, rooms
from pointnav_core.scenes.goal_field import FloorGoalField
from pointnav_core.scenes.scene import Scene, robot_radius

__all__ = ["FloorGoalField", "Scene", "clutter", "maze", "robot_radius", "rooms"]
