"""What a robot meets: the cells of its floor, and the other robots.

:class:`FloorGrid` is a floor's grid as plain numbers, for the point lookups a backend makes
on every step (is the robot over VOID?), and the floor's exact disc test for
``is_valid_pose``. :func:`robots_overlap` is the robot-against-robots half of that test.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np

from pointnav_core.floor.collision import TOUCH_TOL
from pointnav_core.floor.maps import VOID

__all__ = ["FloorGrid", "robots_overlap"]


class FloorGrid:
    """One floor's cell codes and collision geometry, for fast point lookups.

    A backend subclasses it for what else it keeps per floor (a physics space, clearance
    tables), with ``__slots__`` of its own or none.

    Parameters
    ----------
    tmap : TraversableMap
        The floor: ``codes``, ``resolution``, ``origin`` and ``collision``.
    height : float
        World z of the floor in metres.

    Attributes
    ----------
    height : float
        World z of the floor in metres.
    rows, width : int
        Grid shape; cell ``(row, col)`` spans ``x`` in ``ox + col * res + [0, res]`` and
        ``y`` in ``oy + row * res + [0, res]``.
    res, inv_res : float
        Cell size in metres, and its inverse.
    ox, oy : float
        World coordinates of the grid's corner (``tmap.origin``).
    codes : bytes
        Row-major cell codes; cell ``(row, col)`` is ``codes[row * width + col]``.
    collision : FloorCollision
        The floor's one blocked set (``tmap.collision``), for exact disc tests.

    Examples
    --------
    >>> from pointnav_core.floor.maps import TraversableMap
    >>> grid = FloorGrid(TraversableMap([[0, 0, 2]], resolution=0.5), height=1.5)
    >>> grid.cell_index(0.7, 0.2), grid.code(0.7, 0.2), grid.is_void(1.2, 0.2)
    (1, 0, True)
    >>> grid.cell_index(-0.1, 0.2), grid.is_void(-0.1, 0.2)  # off the map counts as VOID
    (-1, True)
    >>> grid.clear(0.5, 0.25, 0.2), grid.clear(0.5, 0.25, 0.6)
    (True, False)
    """

    __slots__ = ("height", "rows", "width", "res", "inv_res", "ox", "oy", "codes", "collision")

    def __init__(self, tmap: Any, height: float) -> None:
        codes = np.asarray(tmap.codes)
        self.height = float(height)
        self.rows, self.width = (int(n) for n in codes.shape)
        self.res = float(tmap.resolution)
        self.inv_res = 1.0 / self.res
        self.ox, self.oy = (float(v) for v in tmap.origin)
        self.codes = codes.astype(np.uint8).tobytes()
        self.collision = tmap.collision

    def cell_index(self, x: float, y: float) -> int:
        """Row-major index of the cell holding world point ``(x, y)``, or -1 off the map."""
        col = math.floor((x - self.ox) * self.inv_res)
        row = math.floor((y - self.oy) * self.inv_res)
        if 0 <= col < self.width and 0 <= row < self.rows:
            return row * self.width + col
        return -1

    def code(self, x: float, y: float) -> int:
        """Cell code under world point ``(x, y)``; VOID off the map."""
        col = math.floor((x - self.ox) * self.inv_res)  # cell_index, inlined: a hot path
        row = math.floor((y - self.oy) * self.inv_res)
        if 0 <= col < self.width and 0 <= row < self.rows:
            return self.codes[row * self.width + col]
        return VOID

    def is_void(self, x: float, y: float) -> bool:
        """Whether world point ``(x, y)`` is over VOID or off the map."""
        return self.code(x, y) == VOID

    def clear(self, x: float, y: float, r: float) -> bool:
        """Whether a disc of radius ``r`` m at world (x, y) misses the floor's blocked set.

        Exactly ``collision.points_clear``: every OBSTACLE and VOID cell square, everything
        off the map and the floor plan's obstacle polygons; touching within
        :data:`~pointnav_core.floor.collision.TOUCH_TOL` is fine. A subclass may answer the
        common case faster, but must give the same answer.
        """
        return self.collision.segment_clear(x, y, x, y, r)


def robots_overlap(
    x: float,
    y: float,
    radius: float,
    others: Iterable[tuple[float, float, float]],
    tolerance: float = TOUCH_TOL,
) -> bool:
    """Whether a disc overlaps any of the other robots' discs by more than ``tolerance``.

    Parameters
    ----------
    x, y, radius : float
        The disc: world centre and radius in metres.
    others : iterable of (x, y, radius)
        The other robots' discs, in metres (rows of an array do too); the caller picks
        them (same floor, solid).
    tolerance : float
        Overlap in metres that still counts as touching, >= 0.

    Returns
    -------
    bool
        True when some other disc's centre is closer than ``radius + its radius -
        tolerance`` (and that reach is positive: two point robots never overlap).

    Notes
    -----
    A loop over plain floats, not numpy: for the few robots a scene holds it is several
    times faster (about 2 us against 15 us for seven others), and it stops at the first
    overlap.

    Examples
    --------
    >>> robots_overlap(0.0, 0.0, 0.5, [(1.0, 0.0, 0.5)])  # touching
    False
    >>> robots_overlap(0.0, 0.0, 0.5, [(3.0, 0.0, 0.5), (0.9, 0.0, 0.5)])
    True
    >>> robots_overlap(0.0, 0.0, 0.5, [])
    False
    """
    for ox, oy, other_radius in others:
        reach = radius + other_radius - tolerance
        if reach > 0.0 and (x - ox) ** 2 + (y - oy) ** 2 < reach * reach:
            return True
    return False
