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

from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import VOID
from pointnav_core.vector.xp import Arrays

__all__ = ["FloorTables", "stencil_offsets"]


class FloorTables:
    """One floor per scene as flat arrays on ``arrays.device``.

    ``fast`` is the clearance table for ``radius``; :meth:`fast_for` gives the table of
    any other radius (robots of several radii in one world), the backend's own per radius.

    Parameters
    ----------
    scenes : sequence of Scene
        Their floor ``floor`` is used: its cells and the edges of its obstacle polygons
        (the backend's ``FloorGeometry.edges``), which only the compiled contacts take
        (on the CPU, with numba).
    floor : int
        The task's floor.
    radius : float
        Robot radius (m), for the clearance table ``fast``.
    arrays : Arrays
        Namespace and device.
    geometries : sequence of FloorGeometry, optional
        Each scene's floor as the kinematic backend built it already (the samplers'
        backends, ``KinematicBackend.floor_geometry``): shared, not built again.

    Raises
    ------
    ValueError
        Naming ``scene`` when a floor holds obstacle polygons and the compiled contacts
        cannot run (on a GPU, or without numba).
    """

    def __init__(self, scenes: Sequence[Any], floor: int, radius: float, arrays: Arrays,
                 geometries: Sequence[Any] | None = None) -> None:
        from pointnav_kinematic.geometry import FloorGeometry

        from pointnav_core.vector import contacts_jit  # it imports this module

        codes, edge, meta = [], [], []
        offset = 0
        self.geometries = []
        self.arrays = arrays
        self._stencils: dict[float, tuple[Any, Any, Any]] = {}
        segments, seg_off = [], [0]
        for k, scene in enumerate(scenes):
            tmap = scene.floors[floor]
            if len(tmap.collision.polygons) and not contacts_jit.available(self):
                raise ArgumentError(
                    f"scene {k} has obstacle polygons on floor {floor}; the batched engine collides with "
                    "them on the CPU with numba (the fast extra) only: use device='numpy' or 'cpu' with "
                    "numba installed, or build the scene from the floor's cells (Scene.from_array)"
                )
            geom = geometries[k] if geometries is not None else FloorGeometry(tmap, float(scene.get_floor_height(floor)))
            segments.extend(geom.edges.segments)
            seg_off.append(len(segments))
            self.geometries.append(geom)
            grid = np.asarray(tmap.codes, dtype=np.uint8)
            codes.append(grid.ravel())
            edge.append(np.frombuffer(geom.edge, dtype=np.uint8).astype(bool))
            meta.append((offset, geom.rows, geom.width, geom.ox, geom.oy, geom.res, geom.height))
            offset += grid.size
        m = np.array(meta, dtype=np.float64)
        a = arrays
        self.codes = a.asarray(np.concatenate(codes), a.i64)
        #: Per cell of every floor, whether it is an edge obstacle cell (the backend's ``edge``).
        self.host_edge = np.concatenate(edge)
        #: The polygon edges of every floor, ``(ax, ay, bx, by, ux, uy, length)`` (m), float64
        #: ``(N, 7)``: scene ``s``'s at rows ``segment_offsets[s]:segment_offsets[s + 1]``.
        self.host_segments = np.array(segments, dtype=np.float64).reshape(-1, 7)
        self.segment_offsets = np.array(seg_off, dtype=np.int64)
        #: Whether any floor has obstacle polygons (only the compiled contacts take them).
        self.has_polygons = bool(len(segments))
        self.edge = a.asarray(self.host_edge, a.boolean)
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

    def stencil(self, reach: float) -> tuple[Any, Any, Any]:
        """The cell offsets whose squares come within ``reach`` (m) of some point of a cell.

        Per scene, the row and column offsets ``(dr, dc)`` of every cell square whose nearest
        point is within ``reach`` of the centre cell's square, in row-major order (as the
        backend lists walls), padded with ``valid`` False to the longest scene's count: int
        arrays ``dr``, ``dc`` and bool ``valid``, ``(scenes, P)``. The edge obstacle cells of
        a robot's window are those of its cell's stencil (:func:`~pointnav_core.vector.contacts.window`),
        found when a robot needs them, so no table per cell is ever built (a 1024 x 1024
        floor at 0.05 m would need hundreds of MB). Cached per ``reach``.
        """
        out = self._stencils.get(reach)
        if out is not None:
            return out
        per_scene = [stencil_offsets(reach, float(res)) for res in self.host_meta[:, 5]]
        width = max(len(d) for d in per_scene)
        dr = np.zeros((len(per_scene), width), np.int64)
        dc = np.zeros_like(dr)
        valid = np.zeros(dr.shape, bool)
        for s, d in enumerate(per_scene):
            dr[s, :len(d)], dc[s, :len(d)], valid[s, :len(d)] = d[:, 0], d[:, 1], True
        a = self.arrays
        out = (a.asarray(dr, a.i64), a.asarray(dc, a.i64), a.asarray(valid, a.boolean))
        self._stencils[reach] = out
        return out

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


def stencil_offsets(reach: float, res: float) -> np.ndarray:
    """The ``(dr, dc)`` offsets (int ``(P, 2)``, row-major) of the cell squares within
    ``reach`` (m) of some point of a cell of side ``res`` (m): two squares ``dr, dc`` apart
    have nearest points ``hypot(max(|dr| - 1, 0), max(|dc| - 1, 0)) * res`` apart."""
    k = math.ceil(reach / res) + 1
    d = np.arange(-k, k + 1)
    dr, dc = (v.ravel() for v in np.meshgrid(d, d, indexing="ij"))
    gap = np.hypot(np.maximum(np.abs(dr) - 1, 0), np.maximum(np.abs(dc) - 1, 0)) * res
    keep = gap <= reach
    return np.column_stack([dr[keep], dc[keep]])

