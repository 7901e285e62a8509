"""Where a pedestrian walks next: its goal and the exact path there.

One definition for every engine: the single env's :class:`~pointnav_core.crowds.Crowd`
plans with :func:`plan_walk` at a spawn and at each arrival or block, and so do the batched
engine's crowds (:mod:`pointnav_core.vector.crowd`), so a world's pedestrians draw the same
goals and walk the same paths as a single env's.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from pointnav_core.floor import reachability
from pointnav_core.floor.draw import draw_point, nearest_usable
from pointnav_core.geodesic import planner_for

__all__ = ["MIN_GOAL_DISTANCE", "WALK_PIECE", "Walk", "padded", "plan_walk"]

#: Goals nearer than this (m) to the pedestrian are drawn again (up to 10 times).
MIN_GOAL_DISTANCE = 1.0

#: Largest angle (rad) of one piece of a pedestrian's path where it bends around a corner
#: (``Planner.shortest_path``'s ``piece``): 10 deg, where a robot's drawn path takes 2.
#: Every piece stays tangent to the arc, so the path keeps its radius from the corner; its
#: vertices stand at most 0.4 % of the radius farther out (1.3 mm at 0.35 m). A fifth of the
#: vertices is a fifth of their clearance tests in each plan, and of the waypoints a
#: pedestrian passes (docs/decisions.md, "A pedestrian's path in 10 degree pieces").
WALK_PIECE = math.radians(10.0)


def padded(points: NDArray[np.float64], length: int) -> NDArray[np.float64]:
    """Paths ``(..., N, 2)`` as the crowds store them, ``(..., length, 2)`` with ``length >= N``:
    each padded with its last point, so a walker past its end stands on it."""
    n = points.shape[-2]
    return np.concatenate([points, np.repeat(points[..., -1:, :], length - n, axis=-2)], axis=-2)


class Walk:
    """A pedestrian's goals: the fixed list it walks (``walk``, round and round when
    ``loop``), where it is in it (``index``, -1 before the first) and its goal now (m)."""

    __slots__ = ("goal", "index", "loop", "walk")

    def __init__(self, walk: tuple[tuple[float, float], ...], loop: bool, index: int, goal: NDArray[np.float64]) -> None:
        self.walk, self.loop, self.index, self.goal = walk, loop, index, goal


class Planned(NamedTuple):
    """:func:`plan_walk`'s answer."""

    points: NDArray[np.float64]  #: the path ``(N, 2)`` (m) from where it stands (one point: none)
    drawn: bool  #: whether a goal was drawn (from ``rng``) on the way


def plan_walk(scene: Any, floor: int, radius: float, here: NDArray[np.float64], walk: Walk, new_goal: bool,
              rng: np.random.Generator) -> Planned:
    """A pedestrian's path from ``here`` (m) to its goal: a new one if ``new_goal``, or if
    the old one cannot be reached; a one-point path when none is reachable. A new goal is
    the next of its fixed list while there is one, else drawn from ``rng`` in ``here``'s
    part of the floor, at least :data:`MIN_GOAL_DISTANCE` away (10 tries). ``walk`` is
    updated in place; paths keep ``radius`` (m) from the walls."""
    tmap = scene.floors[floor]
    planner = planner_for(tmap, radius)
    # Where to plan from: here, or the nearest cell centre within 3 cells where the paths'
    # radius fits (a neighbour's push can leave a pedestrian nearer a wall than its path runs).
    x, y = float(here[0]), float(here[1])
    start = here if tmap.collision.segment_clear(x, y, x, y, radius) else nearest_usable(tmap, here, radius)
    if start is None:
        return Planned(here[None].copy(), False)
    label = None  # start's part of the floor, which goals are drawn from: found at the first draw
    drawn = False
    for attempt in range(10):
        fresh = False  # a goal drawn now, from start's component
        if new_goal:
            walk.index += 1
        k = walk.index
        if walk.walk and (walk.loop or k < len(walk.walk)):  # the next goal of its list (round and round)
            walk.goal = np.array(walk.walk[k % len(walk.walk)], dtype=np.float64)
            new_goal = True  # an unreachable fixed goal: try the next one
        elif new_goal or attempt:
            goal = start
            drawn = fresh = True
            if label is None:
                label = int(tmap.component_at(start, radius))
            for _ in range(10):
                goal = draw_point(tmap, radius, label, start, None, rng) if label else None
                if goal is None:  # Scene.get_random_point's errors where it has no draw
                    goal = scene.get_random_point(floor, reference_point=start, robot=radius, rng=rng)[1][:2]
                if math.dist(goal, start) >= MIN_GOAL_DISTANCE:
                    break
            walk.goal = np.asarray(goal, dtype=np.float64)
        # Scene.get_shortest_path's search on the planner itself, its arcs in WALK_PIECE. A
        # goal drawn from start's component is reachable: its O(1) proof of no path is not run.
        points = None
        if fresh or not reachability.disconnected(tmap, radius, start, walk.goal):
            points, _ = planner.shortest_path(start, walk.goal, WALK_PIECE)
        if points is not None:
            points = np.asarray(points, dtype=np.float64)
            return Planned(points if start is here else np.concatenate([here[None], points]), drawn)
    return Planned(here[None].copy(), drawn)
