"""The local map: an egocentric grid of the floor around the robot, as an observation term.

:class:`LocalMap` (observation key ``"local_map"``) is a ``cells x cells`` grid covering a
square of ``size`` metres centred on the robot, turned so that the robot's heading points
up: row 0 is the far edge ahead, the last row the edge behind; column 0 is the robot's left
edge, the last column its right. Each cell holds the class of the floor under its centre:

=====================  =====  =======================================================
value                  code   what is under the cell's centre
=====================  =====  =======================================================
:data:`LOCAL_FREE`     0      FREE floor
:data:`LOCAL_BLOCKED`  1      an OBSTACLE cell of the floor's grid
:data:`LOCAL_VOID`     2      VOID (a hole), or off the map
:data:`LOCAL_ROBOT`    3      another robot present on the floor (its disc covers it)
:data:`LOCAL_PEDESTRIAN` 4    a pedestrian (:mod:`pointnav_core.crowds`; only in an env with them)
=====================  =====  =======================================================

The floor is read from its grid of cell codes at the map's resolution (the grid a floor
plan was rasterised to), so an obstacle polygon thinner than a map cell may not show;
the range scan (:mod:`~pointnav_core.sensors.scan`) sees polygons exactly. The robot itself
is not drawn: it stands at the centre of the grid (between the four middle cells when
``cells`` is even).

The values are the codes above, as ``uint8`` (the default) or ``float32``
(``dtype="float32"``), in a ``Box(0, 3, (cells, cells))`` of that dtype (``Box(0, 4, ...)``
in an env with pedestrians) in the ``Dict`` observation, and row by row (row 0 first) in the flat one.

Examples
--------
>>> from pointnav_core.floor.maps import TraversableMap
>>> lm = LocalMap(size=1.0, cells=4)
>>> lm.cell_size
0.25
>>> LocalMap(cells=0)
Traceback (most recent call last):
...
pointnav_core.errors.ArgumentError: cells must be an integer >= 1, got 0
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID
from pointnav_core.sensors._checks import check_int, check_number
from pointnav_core.sensors.scan import other_robot_discs, pedestrian_discs
from pointnav_core.task.observations import Frame, ObservationTerm

__all__ = [
    "LOCAL_BLOCKED", "LOCAL_FREE", "LOCAL_MAP_DTYPES", "LOCAL_PEDESTRIAN", "LOCAL_ROBOT", "LOCAL_VOID", "LocalMap",
]

LOCAL_FREE = 0
LOCAL_BLOCKED = 1
LOCAL_VOID = 2
LOCAL_ROBOT = 3
LOCAL_PEDESTRIAN = 4
#: The dtypes a local map can be declared with.
LOCAL_MAP_DTYPES = ("uint8", "float32")

# Floor code -> local map value (the codes are the same numbers, kept explicit).
_LUT = np.zeros(256, dtype=np.uint8)
_LUT[FREE], _LUT[OBSTACLE], _LUT[VOID] = LOCAL_FREE, LOCAL_BLOCKED, LOCAL_VOID


class LocalMap(ObservationTerm):
    """An egocentric grid of the floor, heading up (observation key ``"local_map"``).

    Parameters
    ----------
    size : float
        Side of the square it covers (m), > 0 (default 5.0, iGibson's occupancy grid).
    cells : int
        Cells per side, >= 1 (default 32; iGibson uses 128).
    dtype : {"uint8", "float32"}
        The dtype of the ``Dict`` observation's array (default ``"uint8"``).

    Attributes
    ----------
    cell_size : float
        ``size / cells`` (m).
    shape : tuple of int
        ``(cells, cells)``.
    size : int
        ``cells * cells`` values in the flat observation.

    Raises
    ------
    ValueError
        Naming the parameter, for a value of the wrong type or out of range.
    """

    name = "local_map"
    array_values = True

    def __init__(self, size: float = 5.0, cells: int = 32, dtype: str = "uint8") -> None:
        self.extent = check_number("size", size, low=0.0, strict_low=True, unit="m")
        self.cells = check_int("cells", cells, 1)
        if not isinstance(dtype, str) or dtype not in LOCAL_MAP_DTYPES:
            raise ArgumentError(f"dtype must be one of {list(LOCAL_MAP_DTYPES)}, got {dtype!r}")
        self.dtype = np.dtype(dtype)
        self.shape = (self.cells, self.cells)
        self.size = self.cells * self.cells
        self.cell_size = self.extent / self.cells
        # Cell centres in the robot frame: forward u (row 0 ahead), left v (column 0 left).
        half = self.cells / 2.0
        idx = np.arange(self.cells, dtype=np.float64)
        self.u = np.repeat((half - idx - 0.5) * self.cell_size, self.cells)
        self.v = np.tile((half - idx - 0.5) * self.cell_size, self.cells)

    @property
    def doc_rows(self) -> tuple[tuple[str, str, str], ...]:  # type: ignore[override]
        return tuple(
            (f"local map cell ({i // self.cells}, {i % self.cells}): 0 free, 1 blocked, 2 void, 3 robot",
             "0", "3")
            for i in range(self.size)
        )

    def bounds(self, task: Any, env: Any) -> tuple[Sequence[float], Sequence[float]]:
        top = LOCAL_ROBOT if getattr(env, "crowd", None) is None else LOCAL_PEDESTRIAN
        return (0.0,) * self.size, (float(top),) * self.size

    def cell_centres(self, x: float, y: float, yaw: float) -> NDArray[np.float64]:
        """World ``(x, y)`` of every cell centre, row by row, shape ``(cells * cells, 2)``."""
        c, s = math.cos(yaw), math.sin(yaw)
        return np.stack([x + c * self.u - s * self.v, y + s * self.u + c * self.v], axis=1)

    def grid(self, frame: Frame) -> NDArray[np.uint8]:
        """The local map at the frame's pose, ``(cells, cells)`` uint8 codes."""
        task, env = frame.task, frame.env
        tmap = env.scene.floors[task.floor]
        c, s = frame.cos_yaw, frame.sin_yaw
        u, v = self.u, self.v
        wx = frame.x + c * u - s * v
        wy = frame.y + s * u + c * v
        inv = 1.0 / tmap.resolution
        col = np.floor((wx - tmap.origin[0]) * inv)
        row = np.floor((wy - tmap.origin[1]) * inv)
        h, w = tmap.shape
        inside = (row >= 0) & (row < h) & (col >= 0) & (col < w)
        flat = np.where(inside, row * w + col, 0).astype(np.intp)
        out = np.where(inside, _LUT[tmap.codes.ravel()[flat]], LOCAL_VOID).astype(np.uint8)
        for ox, oy, r in other_robot_discs(env, task.robot_idn, task.floor).tolist():
            out[(wx - ox) ** 2 + (wy - oy) ** 2 <= r * r] = LOCAL_ROBOT
        for ox, oy, r in pedestrian_discs(env, task.floor).tolist():
            out[(wx - ox) ** 2 + (wy - oy) ** 2 <= r * r] = LOCAL_PEDESTRIAN
        return out.reshape(self.shape)

    def values(self, frame: Frame) -> NDArray[np.uint8]:
        return self.grid(frame).ravel()

    def __repr__(self) -> str:
        return f"LocalMap(size={self.extent:g}, cells={self.cells}, dtype={str(self.dtype)!r})"
