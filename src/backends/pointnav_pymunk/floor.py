"""One floor of the pymunk backend: its static shapes, its grid and its standing test.

The static shapes are the floor's blocked set for motion (OBSTACLE cell squares and the
floor plan's polygons, :func:`~pointnav_pymunk.geometry.floor_pieces`), each grown by a thin
skin. pymunk leaves a resting contact overlapping by its slop, so without the skin a robot
resting on a wall would overlap the true blocked set and stand where ``is_valid_pose``,
which asks the floor's :class:`~pointnav_core.floor.collision.FloorCollision`, says it may not.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pymunk

from pointnav_core.backends.kit import FloorGrid
from pointnav_pymunk.geometry import floor_pieces

__all__ = ["CONTACT_SLOP", "TOUCH_TOLERANCE"]

#: Overlap (m) that pymunk leaves in a resting contact (``Space.collision_slop``).
CONTACT_SLOP = 1e-7
#: Overlap (m) up to which two robots count as touching: deeper overlaps left at the end
#: of a step are removed, and :meth:`PymunkBackend.is_valid_pose` accepts a robot that
#: overlaps another by at most this much (so two robots resting in contact stand validly).
#: The static shapes are grown by half of it (see ``_WALL_SKIN``).
TOUCH_TOLERANCE = 10.0 * CONTACT_SLOP

#: Metres by which every static shape is grown (a rounded polygon): a robot resting
#: against it overlaps the grown shape by pymunk's slop at most, so it stays clear of the
#: floor's true blocked set and its pose stays valid for ``is_valid_pose``.
_WALL_SKIN = 0.5 * TOUCH_TOLERANCE

_WALL, _ROBOT = 1, 2  # collision types, and shape-filter categories
_WALLS_ONLY = pymunk.ShapeFilter(mask=_WALL)


class _Floor(FloorGrid):
    """One floor: its grid, its pymunk Space of static obstacles, its standing test."""

    __slots__ = ("pieces", "thickness", "grid", "space", "depth")

    def __init__(self, tmap: Any, height: float) -> None:
        super().__init__(tmap, height)
        self.pieces, self.thickness = floor_pieces(tmap)
        self.grid = np.asarray(tmap.codes)
        self.space: pymunk.Space = None  # type: ignore[assignment]  # set by build_space
        self.depth = 0.0  # deepest overlap seen while measuring (m)

    def build_space(self, hit_wall: Any, hit_robot: Any) -> None:
        """A fresh space holding this floor's obstacles as static convex shapes."""
        space = pymunk.Space()
        space.collision_slop = CONTACT_SLOP
        space.collision_bias = 0.0  # correct an overlap fully in the next sub-step
        space.iterations = 10
        static = pymunk.Body(body_type=pymunk.Body.STATIC)  # ours, so it can be removed
        shapes = []
        for ring in self.pieces:
            shape = pymunk.Poly(static, ring, radius=_WALL_SKIN)
            shape.collision_type = _WALL
            shape.filter = pymunk.ShapeFilter(categories=_WALL)
            shape.friction = 0.0
            shape.elasticity = 0.0
            shapes.append(shape)
        space.add(static, *shapes)
        space.on_collision(_ROBOT, _WALL, post_solve=hit_wall)
        space.on_collision(_ROBOT, _ROBOT, post_solve=hit_robot)
        self.space = space

    def clear(self, x: float, y: float, r: float) -> bool:
        """Whether a disc of radius ``r`` m at world (x, y) misses the floor's blocked set.

        Exactly ``FloorGrid.clear``: every non-FREE cell, off the map, the polygons.
        """
        if self._far_from_walls(x, y, r):
            return True
        return super().clear(x, y, r)

    def _far_from_walls(self, x: float, y: float, r: float) -> bool:
        # A quick yes, about 20 times cheaper than the exact test, for the usual disc in
        # open floor: only FREE cells in a window one cell wider than its bounding box, and
        # no obstacle shape within r plus two skins. Every other disc goes to the exact test.
        c0 = math.floor((x - r - self.ox) * self.inv_res) - 1
        c1 = math.floor((x + r - self.ox) * self.inv_res) + 1
        r0 = math.floor((y - r - self.oy) * self.inv_res) - 1
        r1 = math.floor((y + r - self.oy) * self.inv_res) + 1
        if c0 < 0 or r0 < 0 or c1 >= self.width or r1 >= self.rows:
            return False
        if self.grid[r0 : r1 + 1, c0 : c1 + 1].any():  # FREE is 0
            return False
        return not self.space.point_query((x, y), r + 2.0 * _WALL_SKIN, _WALLS_ONLY)
