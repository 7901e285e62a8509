"""The running record of one episode: what every term reads after each step.

A :class:`~pointnav_core.task.PointNavigationTask` keeps one :class:`EpisodeState`. Its
:meth:`~EpisodeState.begin` starts it from a sampled :class:`~pointnav_core.task.sampling.Episode`
at reset; :meth:`~EpisodeState.advance` does the bookkeeping of one control step (the
pose, the path length, the step and contact counts, the geodesic distance and the
potential) before any termination condition or reward runs, so every term of a step sees
the same snapshot through the task's read-only properties (``robot_xyz``, ``in_contact``,
``collisions``, ``episode_length``, ``distance_to_goal``, ``potential``...). It also builds
the step's ``info`` (:meth:`~EpisodeState.info`).

Plain attributes of Python floats, not arrays: the task reads and writes them on every
step.
"""

from __future__ import annotations

import math
from typing import Any

from pointnav_core.task.metrics import soft_spl_values, spl_values

__all__ = ["EpisodeState"]


class EpisodeState:
    """One episode's start, goal and running measurements (m, s counts, plain floats).

    Attributes
    ----------
    start_xy, goal_xy : tuple of 2 floats or None
        This episode's start and goal (m); None before the first reset (the goal: a fixed
        one is known from the start).
    start_quat : tuple of 4 floats or None
        The start orientation ``(x, y, z, w)``.
    field : FloorGoalField or None
        The goal's geodesic field; ``field_distance`` its per-step lookup.
    geodesic_dist : float
        Exact geodesic (m) from the start to the goal; ``inf`` if unreachable.
    metric : {"l2", "geodesic"}
        The potential's metric this episode (fixed at reset).
    robot_xyz : tuple of 3 floats
        Robot position (m) at the last reset or step; ``robot_quat`` its orientation.
    potential, distance_to_goal, path_length : float
        Metres, at the last reset or step.
    collisions, steps : int
        Steps with a contact, steps taken.
    in_contact, success : bool
        Contact during the last step; whether the episode has ended in success.
    results : dict
        Name -> ``(done, success)`` of every termination condition at the last step.
    """

    __slots__ = (
        "start_xy", "start_quat", "goal_xy", "field", "field_distance", "geodesic_dist",
        "metric", "robot_xyz", "robot_quat", "potential", "distance_to_goal", "path_length",
        "collisions", "in_contact", "steps", "success", "results",
    )

    def __init__(self, goal_xy: tuple[float, float] | None = None) -> None:
        self.start_xy: tuple[float, float] | None = None
        self.start_quat: tuple[float, float, float, float] | None = None
        self.goal_xy = goal_xy
        self.field: Any = None
        self.field_distance: Any = None
        self.geodesic_dist = math.inf
        self.metric = "l2"
        self.robot_xyz = (0.0, 0.0, 0.0)
        self.robot_quat: list[float] = [0.0, 0.0, 0.0, 1.0]
        self.potential = 0.0
        self.distance_to_goal = math.inf
        self.path_length = 0.0
        self.collisions = 0
        self.in_contact = False
        self.steps = 0
        self.success = False
        self.results: dict[str, tuple[bool, bool]] = {}

    def begin(
        self,
        episode: Any,
        reward_type: str,
        xyz: tuple[float, float, float],
        quat: list[float],
        conditions: Any,
    ) -> None:
        """Start from a sampled ``episode``, the robot standing at ``xyz`` / ``quat``.

        ``conditions`` are the termination conditions' names (their results start
        ``(False, False)``). The potential's metric is decided here, once per episode, so
        the potential never jumps between metrics.
        """
        self.start_xy = episode.start_xy
        self.start_quat = episode.start_quat
        self.goal_xy = episode.goal_xy
        self.field = episode.field
        self.field_distance = episode.field.distance
        self.geodesic_dist = geodesic = episode.geodesic
        self.metric = "geodesic" if reward_type == "geodesic" and geodesic < math.inf else "l2"
        x, y, _ = self.robot_xyz = xyz
        self.robot_quat = quat
        self.path_length = 0.0
        self.collisions = 0
        self.in_contact = False
        self.steps = 0
        self.success = False
        self.distance_to_goal = d = self.field_distance(x, y)
        self.potential = self.potential_at(x, y, d, geodesic)
        self.results = {name: (False, False) for name in conditions}

    def advance(self, x: float, y: float, z: float, quat: list[float], contact: bool) -> None:
        """Record one control step that ended at ``(x, y, z)`` / ``quat`` (m)."""
        px, py, _ = self.robot_xyz
        self.path_length += math.hypot(x - px, y - py)
        self.robot_xyz = (x, y, z)
        self.robot_quat = quat
        self.steps += 1
        self.in_contact = contact
        if contact:
            self.collisions += 1
        self.distance_to_goal = geodesic = self.field_distance(x, y)
        self.potential = self.potential_at(x, y, geodesic, self.potential)

    def potential_at(self, x: float, y: float, geodesic: float, held: float) -> float:
        """The potential (m) at ``(x, y)`` whose geodesic is ``geodesic``.

        L2 to the goal, or the geodesic; where there is none (over void, say), ``held``:
        the last potential, so the episode's potential rewards still telescope.
        """
        if self.metric == "l2":
            gx, gy = self.goal_xy  # type: ignore[misc]
            return math.hypot(gx - x, gy - y)
        return geodesic if geodesic < math.inf else held

    def info(
        self,
        success: bool,
        done: bool,
        breakdown: dict[str, float],
        conditions: dict[str, dict[str, bool]],
    ) -> dict[str, Any]:
        """The step's ``info`` dict (keys documented at the task's ``step``)."""
        d0, length, d_t = self.geodesic_dist, self.path_length, self.distance_to_goal
        return {
            "success": success,
            "done": done,
            "path_length": length,
            "spl": spl_values(success, d0, length),
            "soft_spl": soft_spl_values(d_t, d0, length),
            "geodesic_dist": d0,
            "distance_to_goal": d_t,
            "collisions": self.collisions,
            "reward_breakdown": breakdown,
            "termination_conditions": conditions,
            "episode_length": self.steps,
            "potential_metric": self.metric,
        }
