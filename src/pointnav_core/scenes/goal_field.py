"""Geodesic distance to one goal on one floor: the per-goal view a task keeps for an episode."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import TraversableMap
from pointnav_core.geodesic import GoalField
from pointnav_core.utils import validation

__all__ = ["FloorGoalField", "as_xy"]


def as_xy(value: ArrayLike, name: str) -> NDArray[np.float64]:
    """The (x, y) of a finite 2- or 3-vector in metres; ``name`` is named when it is not one."""
    try:
        return validation.vector(name, value, sizes=(2, 3))[:2]
    except ValueError:
        raise ArgumentError(f"{name} must be a finite (x, y) or (x, y, z) point in metres, got {value!r}") from None


class FloorGoalField:
    """Geodesic distance to one goal on one floor, in metres (a cached view of a GoalField).

    ``distance(x, y)`` is the per-step query: a table lookup plus one tangent (the table is
    built on the first call). ``exact_distance`` and ``path`` are exact for the given point.
    """

    def __init__(self, tmap: TraversableMap, field: GoalField) -> None:
        self.tmap = tmap
        self.field = field

    def distance(self, x: float, y: float) -> float:
        """Geodesic distance (m) from world point (x, y) to the goal; ``inf`` if unreachable."""
        return float(self.field.distance(x, y))

    @property
    def goal_usable(self) -> bool:
        """Whether the robot fits at the goal (if not, nothing reaches it)."""
        return self.field.reachable_from_anywhere

    def exact_distance(self, source_xy: ArrayLike) -> float:
        """Geodesic distance (m) from the exact point ``source_xy`` (``inf`` if none)."""
        return float(self.field.point_distance(as_xy(source_xy, "source_xy")))

    def path(
        self, source_xy: ArrayLike, exact: bool = True, max_length: float = math.inf
    ) -> tuple[NDArray[np.float64] | None, float]:
        """Shortest path (N, 2) in world metres from ``source_xy`` to the goal, and its length
        (``(None, inf)`` when unreachable). ``exact`` is accepted for compatibility: every path
        is exact. A finite ``max_length`` (m) draws only the path's beginning, to its first
        vertex at least that far along; the length is still the whole path's."""
        points, length = self.field.path(as_xy(source_xy, "source_xy"), max_length=max_length)
        if points is None:
            return None, math.inf
        return points, float(length)
