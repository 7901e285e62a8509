"""Hypothesis strategies for pointnav-core values, exported for users' own property tests.

Strategies build valid values directly (rather than filtering) and put the simplest choice
first, so that failures shrink to something readable.

The strategies live in one module per subject (:mod:`.geometry`, :mod:`.robots`,
:mod:`.maps`, :mod:`.navigation`); this package is their API.
"""

from pointnav_core.testing.strategies.geometry import (
    euler_angles,
    finite_vectors,
    unit_quaternions,
    yaws,
)
from pointnav_core.testing.strategies.maps import (
    code_grids,
    floor_plans,
    maps_with_points,
    traversable_maps,
)
from pointnav_core.testing.strategies.navigation import (
    action_sequences,
    cluttered_rooms,
    nav_robot_specs,
    nav_scenes,
    nav_task_kwargs,
    robot_placements,
    scenes,
    valid_poses,
)
from pointnav_core.testing.strategies.robots import (
    robot_actions,
    robot_specs,
)

__all__ = [
    "unit_quaternions",
    "yaws",
    "euler_angles",
    "finite_vectors",
    "robot_specs",
    "robot_actions",
    "floor_plans",
    "code_grids",
    "traversable_maps",
    "maps_with_points",
    "nav_scenes",
    "nav_robot_specs",
    "nav_task_kwargs",
    "scenes",
    "valid_poses",
    "robot_placements",
    "action_sequences",
    "cluttered_rooms",
]
