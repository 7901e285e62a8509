"""The floors of a batch of worlds as flat arrays: cell codes, edge obstacles, clearance.

Every world's floor is a grid; the grids of all scenes are stored end to end in flat
arrays, and each world keeps the offset, shape, origin and cell size of its grid, so that
a cell lookup for every robot at once is one gather. The clearance table and the edge
flags are the kinematic backend's own (:class:`pointnav_kinematic.geometry.FloorGeometry`),
so the batched engine takes its fast path exactly where the backend does.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from pointnav_core.maps import VOID
from pointnav_core.vector.xp import Arrays

__all__ = ["FloorTables"]


class FloorTables:
    """One floor per scene as flat arrays on ``arrays.device``.

    ``fast`` is the clearance table for ``radius``; :meth:`fast_for` gives the table of
    any other radius (robots of several radii in one world), the backend's own per radius.

    Parameters
    ----------
    scenes : sequence of Scene
        Their floor ``floor`` is used; it must have no obstacle polygons (grid cells only).
    floor : int
        The task's floor.
    radius : float
        Robot radius (m), for the clearance table ``fast``.
    arrays : Arrays
        Namespace and device.

    Raises
    ------
    ValueError
        Naming ``scene`` when a floor holds obstacle polygons.
    """

    def __init__(self, scenes: Sequence[Any], floor: int, radius: float, arrays: Arrays) -> None:
        from pointnav_kinematic.geometry import FloorGeometry

        codes, edge, meta = [], [], []
        offset = 0
        self.geometries = []
        self._edges: list[np.ndarray] = []
        self._walls: dict[float, Any] = {}
        for k, scene in enumerate(scenes):
            tmap = scene.floors[floor]
            if len(tmap.collision.polygons):
                raise ValueError(
                    f"scene {k} has obstacle polygons on floor {floor}; the batched engine "
                    "collides with grid cells only (build the scene with Scene.from_array)"
                )
            geom = FloorGeometry(tmap, float(scene.get_floor_height(floor)))
            self.geometries.append(geom)
            grid = np.asarray(tmap.codes, dtype=np.uint8)
            codes.append(grid.ravel())
            edge.append(np.frombuffer(geom.edge, dtype=np.uint8).astype(bool))
            meta.append((offset, geom.rows, geom.width, geom.ox, geom.oy, geom.res, geom.height))
            self._edges.append(np.frombuffer(geom.edge, dtype=np.uint8).astype(bool).reshape(grid.shape))
            offset += grid.size
        m = np.array(meta, dtype=np.float64)
        a = arrays
        self.codes = a.asarray(np.concatenate(codes), a.i64)
        self.edge = a.asarray(np.concatenate(edge), a.boolean)
        self.offset = a.asarray(m[:, 0], a.i64)
        self.rows = a.asarray(m[:, 1], a.i64)
        self.width = a.asarray(m[:, 2], a.i64)
        self.ox, self.oy, self.res, self.height = (a.asarray(m[:, i]) for i in (3, 4, 5, 6))
        self.inv_res = 1.0 / self.res  # the backend multiplies by it: the same cells at the edges
        self.min_res = float(m[:, 5].min())
        #: Per scene, on the host: flat offset, rows, width, origin x, y, cell size, and
        #: 1 / cell size as ``inv_res`` holds it (float64, ``(scenes, 7)``), for compiled code.
        self.host_meta = np.ascontiguousarray(np.column_stack([m[:, :6], 1.0 / m[:, 5]]))
        self.arrays = a
        self._fast: dict[float, Any] = {}
        self.fast = self.fast_for(radius)

    def fast_for(self, radius: float) -> Any:
        """The clearance table for robots of ``radius`` (m): per cell of every floor, the
        travel budget (m) within which such a disc meets nothing (the backend's
        ``FloorGeometry.fast_clearance``), a float array ``(all cells,)``. Cached per radius."""
        radius = float(radius)
        table = self._fast.get(radius)
        if table is None:
            table = self.arrays.asarray(np.concatenate(
                [np.asarray(g.fast_clearance(radius), dtype=np.float64) for g in self.geometries]))
            self._fast[radius] = table
        return table

    def wall_table(self, reach: float) -> Any:
        """Per cell, the flat indices of the edge obstacle cells whose squares come within
        ``reach`` (m) of some point of the cell, in row-major order, padded with -1:
        an int array ``(all cells, K)``, K the most any cell has. Cached per ``reach``."""
        table = self._walls.get(reach)
        if table is not None:
            return table
        blocks, offset = [], 0
        for edge, res in zip(self._edges, self.arrays.numpy(self.res)):
            rows, cols = edge.shape
            k = math.ceil(reach / res) + 1
            r, c = np.divmod(np.arange(rows * cols), cols)
            found = []
            for dr in range(-k, k + 1):
                for dc in range(-k, k + 1):
                    # The nearest points of two cell squares dr, dc apart are this far apart.
                    if math.hypot(max(abs(dr) - 1, 0), max(abs(dc) - 1, 0)) * res > reach:
                        continue
                    rr, cc = r + dr, c + dc
                    ok = (rr >= 0) & (rr < rows) & (cc >= 0) & (cc < cols)
                    ok[ok] = edge[rr[ok], cc[ok]]
                    found.append(np.where(ok, offset + rr * cols + cc, -1))
            ids = np.stack(found, 1)
            # Walls first, each row keeping its row-major order.
            order = np.argsort(ids < 0, axis=1, kind="stable")
            blocks.append(np.take_along_axis(ids, order, 1))
            offset += rows * cols
        width = max(int((b >= 0).sum(1).max()) if b.size else 0 for b in blocks)
        width = max(width, 1)
        table = np.concatenate([b[:, :width] if b.shape[1] >= width else
                                np.pad(b, ((0, 0), (0, width - b.shape[1])), constant_values=-1) for b in blocks])
        table = self.arrays.asarray(table, self.arrays.i64)
        self._walls[reach] = table
        return table

    def cells(self, scene: Any, x: Any, y: Any) -> tuple[Any, Any, Any]:
        """Row, column (int arrays) and on-map mask of the points ``(x, y)`` of worlds on ``scene`` (index array)."""
        xp = self.arrays.xp
        inv = self.inv_res[scene]
        col = self.arrays.to_int(xp.floor((x - self.ox[scene]) * inv))
        row = self.arrays.to_int(xp.floor((y - self.oy[scene]) * inv))
        inside = (col >= 0) & (col < self.width[scene]) & (row >= 0) & (row < self.rows[scene])
        return row, col, inside

    def flat_index(self, scene: Any, row: Any, col: Any, inside: Any) -> Any:
        """Index into the flat arrays (0 where off the map: mask it with ``inside``)."""
        xp = self.arrays.xp
        idx = self.offset[scene] + row * self.width[scene] + col
        return xp.where(inside, idx, xp.zeros_like(idx))

    def is_void(self, scene: Any, x: Any, y: Any) -> Any:
        """Whether each point is over VOID or off the map (the backend's ``is_void``)."""
        row, col, inside = self.cells(scene, x, y)
        code = self.codes[self.flat_index(scene, row, col, inside)]
        return ~inside | (code == VOID)
