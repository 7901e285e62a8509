"""Traversability grids of one floor: cell classes, world<->cell conversion, erosion.

A :class:`TraversableMap` is a 2D grid of cell codes (:data:`FREE`, :data:`OBSTACLE`,
:data:`VOID`) with a resolution in metres per cell, a world origin and the height of the
floor. Everything here is pure numpy/scipy and has no notion of robots beyond a radius.

Grid geometry
-------------
Cell ``(row, col)`` covers ``x in [ox + col*res, ox + (col+1)*res)`` and
``y in [oy + row*res, oy + (row+1)*res)``: the row index grows with +y, the column index
with +x, and ``origin = (ox, oy)`` is the outer corner of cell ``(0, 0)``. World<->cell
conversion uses cell centres, so ``world_to_cell(cell_to_world(c)) == c`` exactly. Points
off the map are :data:`VOID`; indices are never wrapped.

Erosion
-------
The robot's centre may stand at a point when its disc of radius ``r`` does not overlap any
blocked (OBSTACLE or VOID) cell square; off the map counts as VOID. :meth:`usable` answers
this exactly for every cell centre, from a Euclidean distance transform (cached per radius).
Two usable cells are connected when they share a side ("8-connected without cutting blocked
corners" has the same components), which is also the planner's rule (see ``geodesic``).
"""

from __future__ import annotations

import math
from collections import OrderedDict
from typing import Any, Callable, Hashable, TypeVar

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from pointnav_core.collision import FloorCollision

__all__ = ["FREE", "OBSTACLE", "VOID", "CELL_CLASSES", "TraversableMap", "BoundedCache"]

FREE = 0
OBSTACLE = 1
VOID = 2
CELL_CLASSES = {"FREE": FREE, "OBSTACLE": OBSTACLE, "VOID": VOID}

_V = TypeVar("_V")


class BoundedCache:
    """A small least-recently-used mapping owned by one object (never module-level).

    Parameters
    ----------
    maxsize : int
        How many entries to keep; the least recently used one is dropped beyond that.
    """

    def __init__(self, maxsize: int) -> None:
        if maxsize < 1:
            raise ValueError(f"maxsize must be >= 1, got {maxsize!r}")
        self.maxsize = int(maxsize)
        self._data: OrderedDict[Hashable, Any] = OrderedDict()

    def get_or_create(self, key: Hashable, factory: Callable[[], _V]) -> _V:
        """Return the cached value for ``key``, building it with ``factory()`` if missing."""
        try:
            value = self._data[key]
        except KeyError:
            value = factory()
            self._data[key] = value
            if len(self._data) > self.maxsize:
                self._data.popitem(last=False)
            return value
        self._data.move_to_end(key)
        return value

    def __len__(self) -> int:
        return len(self._data)

    def __contains__(self, key: Hashable) -> bool:
        return key in self._data

    def clear(self) -> None:
        """Drop every entry."""
        self._data.clear()


def _check_radius(radius: float) -> float:
    radius = float(radius)
    if not math.isfinite(radius) or radius < 0.0:
        raise ValueError(f"radius must be a finite number >= 0 (metres), got {radius!r}")
    return radius


class TraversableMap:
    """One floor: a grid of cell codes with its resolution, origin and height.

    Parameters
    ----------
    grid : array_like of int or bool, shape (H, W)
        Cell codes (:data:`FREE` 0, :data:`OBSTACLE` 1, :data:`VOID` 2), or booleans where
        True is free and False is an obstacle.
    resolution : float
        Metres per cell, > 0.
    origin : (float, float)
        World (x, y) of the outer corner of cell (0, 0), in metres.
    height : float
        World z of the floor, in metres.
    geometry : FloorPlan, optional
        The polygons the grid was rasterised from (anything with ``outline`` and
        ``obstacles``). When given, erosion measures clearance from the polygons themselves
        rather than from their staircase raster, which keeps geodesics unbiased along
        rotated walls and furniture.

    Examples
    --------
    >>> m = TraversableMap([[0, 0, 1], [0, 0, 0]], resolution=0.5, origin=(-1.0, 0.0))
    >>> m.shape
    (2, 3)
    >>> m.cell_to_world([1, 2]).tolist()
    [0.25, 0.75]
    >>> m.world_to_cell([0.25, 0.75]).tolist()
    [1, 2]
    >>> int(m.cell_class_at([-5.0, 0.0]))  # off the map is VOID
    2
    """

    def __init__(
        self,
        grid: ArrayLike,
        resolution: float,
        origin: tuple[float, float] = (0.0, 0.0),
        height: float = 0.0,
        geometry: Any = None,
    ) -> None:
        codes = np.asarray(grid)
        if codes.ndim != 2 or codes.shape[0] < 1 or codes.shape[1] < 1:
            raise ValueError(f"grid must be a non-empty 2D array, got shape {codes.shape}")
        if codes.dtype == bool:
            codes = np.where(codes, FREE, OBSTACLE)
        elif not np.issubdtype(codes.dtype, np.integer):
            raise ValueError(
                f"grid must hold integer cell codes or booleans, got dtype {codes.dtype}"
            )
        bad = ~np.isin(codes, (FREE, OBSTACLE, VOID))
        if bad.any():
            raise ValueError(
                "grid holds unknown cell codes "
                f"{sorted(set(np.unique(codes[bad]).tolist()))[:5]}; valid: {CELL_CLASSES}"
            )
        resolution = float(resolution)
        if not math.isfinite(resolution) or resolution <= 0.0:
            raise ValueError(f"resolution must be a finite number > 0 (m/cell), got {resolution!r}")
        origin_arr = np.asarray(origin, dtype=np.float64)
        if origin_arr.shape != (2,) or not np.isfinite(origin_arr).all():
            raise ValueError(f"origin must be two finite numbers (x, y), got {origin!r}")
        height = float(height)
        if not math.isfinite(height):
            raise ValueError(f"height must be finite, got {height!r}")
        self.codes: NDArray[np.uint8] = np.array(codes, dtype=np.uint8, order="C", copy=True)
        self.codes.flags.writeable = False
        self.resolution = resolution
        self.origin = (float(origin_arr[0]), float(origin_arr[1]))
        self.height = height
        self.geometry = geometry
        self._usable = BoundedCache(8)
        self._labels = BoundedCache(8)
        # Owned by ``geodesic``; kept here so that planners live exactly as long as the map.
        self.planner_cache = BoundedCache(8)
        self._collision: FloorCollision | None = None

    @property
    def collision(self) -> FloorCollision:
        """The floor's :class:`~pointnav_core.collision.FloorCollision` (built once, cached).

        The one blocked set that planning, sampling and every backend's collision test use:
        every non-FREE cell, everything off the map, and the floor plan's polygons.
        """
        if self._collision is None:
            self._collision = FloorCollision.from_map(self)
        return self._collision

    # ------------------------------------------------------------------ geometry
    @property
    def shape(self) -> tuple[int, int]:
        """Grid shape (rows, cols)."""
        return self.codes.shape  # type: ignore[return-value]

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """World bounds ``(xmin, xmax, ymin, ymax)`` in metres."""
        h, w = self.shape
        ox, oy = self.origin
        return (ox, ox + w * self.resolution, oy, oy + h * self.resolution)

    def world_to_grid(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Continuous grid coordinates ``(row, col)`` of world points; cell = floor of them.

        Parameters
        ----------
        xy : array_like, shape (..., 2)
            World points (x, y) in metres.
        """
        xy = _as_points(xy, "xy")
        g = np.empty_like(xy)
        g[..., 0] = (xy[..., 1] - self.origin[1]) / self.resolution
        g[..., 1] = (xy[..., 0] - self.origin[0]) / self.resolution
        return g

    def grid_to_world(self, g: ArrayLike) -> NDArray[np.float64]:
        """World points ``(x, y)`` of continuous grid coordinates ``(row, col)``."""
        g = np.asarray(g, dtype=np.float64)
        xy = np.empty_like(g)
        xy[..., 0] = self.origin[0] + g[..., 1] * self.resolution
        xy[..., 1] = self.origin[1] + g[..., 0] * self.resolution
        return xy

    def world_to_cell(self, xy: ArrayLike) -> NDArray[np.int64]:
        """Cell indices ``(row, col)`` containing world points (may lie off the map).

        Indices are never wrapped or clipped: use :meth:`in_bounds` before indexing, or
        :meth:`cell_class_at`, which reports off-map points as VOID.
        """
        return np.floor(self.world_to_grid(xy)).astype(np.int64)

    def cell_to_world(self, cells: ArrayLike) -> NDArray[np.float64]:
        """World ``(x, y)`` of cell centres."""
        cells = np.asarray(cells)
        if cells.shape[-1:] != (2,):
            raise ValueError(f"cells must have shape (..., 2), got {cells.shape}")
        return self.grid_to_world(cells.astype(np.float64) + 0.5)

    def in_bounds(self, cells: ArrayLike) -> NDArray[np.bool_]:
        """Whether cell indices ``(row, col)`` lie on the grid."""
        cells = np.asarray(cells)
        h, w = self.shape
        return (cells[..., 0] >= 0) & (cells[..., 0] < h) & (cells[..., 1] >= 0) & (cells[..., 1] < w)

    def cell_class_at(self, xy: ArrayLike) -> NDArray[np.uint8]:
        """Cell code at world points: FREE, OBSTACLE, or VOID (also for off-map points)."""
        return self._sample(self.codes, xy, VOID).astype(np.uint8)

    def _sample(self, grid: NDArray[Any], xy: ArrayLike, outside: Any) -> NDArray[Any]:
        """Values of a per-cell ``grid`` at world points; ``outside`` for off-map points."""
        cells = self.world_to_cell(xy)
        inside = self.in_bounds(cells)
        rows = np.where(inside, cells[..., 0], 0)
        cols = np.where(inside, cells[..., 1], 0)
        return np.where(inside, grid[rows, cols], outside)

    # ------------------------------------------------------------------ erosion
    @property
    def free(self) -> NDArray[np.bool_]:
        """Boolean grid of FREE cells."""
        return self.codes == FREE

    def usable(self, radius: float = 0.0) -> NDArray[np.bool_]:
        """Cells where a robot disc of ``radius`` metres can stand (cached, read-only).

        A cell is usable when it is FREE and the disc centred on the cell centre overlaps
        no OBSTACLE or VOID cell square (touching is allowed); off the map is VOID.

        Parameters
        ----------
        radius : float
            Robot radius in metres, >= 0. 0 is a point robot: the FREE cells.

        Examples
        --------
        >>> m = TraversableMap(np.ones((5, 5), bool), resolution=1.0)
        >>> m.usable(0.5).sum(), m.usable(0.6).sum(), m.usable(1.6).sum()
        (np.int64(25), np.int64(9), np.int64(1))
        """
        radius = _check_radius(radius)
        key = round(radius / self.resolution, 9)
        return self._usable.get_or_create(key, lambda: self._erode(key))

    def standable(self, radius: float = 0.0) -> NDArray[np.bool_]:
        """Cells whose centre a robot of ``radius`` m can stand on in every backend.

        The :meth:`usable` cells; on a map built from polygons, also clear of the rasterised
        OBSTACLE and VOID squares, since one backend may collide with the polygons and
        another with the grid. Sampling draws from these, so a start or goal is valid
        everywhere and the same seed gives the same episode on every backend.
        """
        if self.geometry is None:
            return self.usable(radius)
        radius = _check_radius(radius)
        key = ("standable", round(radius / self.resolution, 9))

        def both() -> NDArray[np.bool_]:
            mask = self.usable(radius) & self._erode_squares(key[1])
            mask.flags.writeable = False
            return mask

        return self._usable.get_or_create(key, both)

    def _erode(self, r: float) -> NDArray[np.bool_]:
        if self.geometry is not None:
            return self._erode_polygons(self.codes == FREE, r * self.resolution)
        return self._erode_squares(r)

    def _erode_squares(self, r: float) -> NDArray[np.bool_]:
        """Exact erosion against the grid's blocked cell squares (radius in cells)."""
        free = self.codes == FREE
        if r <= 0.5:
            # The disc stays inside its own cell, or touches a side neighbour exactly.
            mask = free.copy()
            mask.flags.writeable = False
            return mask
        pad = int(math.ceil(r)) + 2
        padded = np.pad(free, pad, constant_values=False)
        # Distance from each free cell centre to the nearest blocked cell centre, in cells.
        edt = ndimage.distance_transform_edt(padded)
        # The true distance d to the nearest blocked square satisfies
        # edt - sqrt(2)/2 <= d <= edt - 1/2; decide the thin shell in between exactly.
        usable = edt - math.sqrt(0.5) >= r
        shell = (edt - 0.5 >= r) & ~usable
        if shell.any():
            rows, cols = np.nonzero(shell)
            blocked = ~padded
            k = int(math.ceil(r + 0.5))
            touched = np.zeros(rows.shape, dtype=bool)
            for dr in range(-k, k + 1):
                gap_r = max(abs(dr) - 0.5, 0.0)
                for dc in range(-k, k + 1):
                    gap_c = max(abs(dc) - 0.5, 0.0)
                    if gap_r * gap_r + gap_c * gap_c < r * r:
                        touched |= blocked[rows + dr, cols + dc]
            usable[rows[~touched], cols[~touched]] = True
        mask = usable[pad:-pad, pad:-pad] & free
        mask.flags.writeable = False
        return mask

    def _erode_polygons(self, free: NDArray[np.bool_], radius: float) -> NDArray[np.bool_]:
        """Exact erosion against the source polygons: centre clearance >= radius."""
        h, w = self.shape
        ys, xs = np.mgrid[0:h, 0:w]
        x = self.origin[0] + (xs + 0.5) * self.resolution
        y = self.origin[1] + (ys + 0.5) * self.resolution
        outline = self.geometry.outline
        inner = outline.buffer(-radius, quad_segs=16, join_style="mitre") if radius > 0 else outline
        mask = free & shapely.contains_xy(inner, x, y)
        obstacles = list(self.geometry.obstacles)
        if obstacles and radius > 0:
            grown = shapely.union_all(obstacles).buffer(radius, quad_segs=16)
            shapely.prepare(grown)
            rows, cols = np.nonzero(mask)
            mask[rows, cols] = ~shapely.intersects_xy(grown, x[rows, cols], y[rows, cols])
        if radius > 0:
            # The buffers draw the disc as an inscribed polygon, so they let through centres
            # up to radius * (1 - cos(pi / 64)) closer than radius; such a centre is on the
            # edge of the mask, so the edge cells are measured exactly.
            edge = mask & ~ndimage.binary_erosion(mask, np.ones((3, 3), bool), border_value=1)
            rows, cols = np.nonzero(edge)
            if len(rows):
                walls = shapely.union_all([outline.boundary, *obstacles])
                near = shapely.distance(walls, shapely.points(x[rows, cols], y[rows, cols]))
                mask[rows, cols] = near >= radius
        mask.flags.writeable = False
        return mask

    def components(self, radius: float = 0.0) -> NDArray[np.int32]:
        """Connected components of :meth:`usable` cells (0 = not usable, 1.. = component id).

        Cells are connected through shared sides, the same rule the planner uses.
        """
        radius = _check_radius(radius)
        key = round(radius / self.resolution, 9)

        def label() -> NDArray[np.int32]:
            labels, _ = ndimage.label(self.usable(radius))
            labels = labels.astype(np.int32)
            labels.flags.writeable = False
            return labels

        return self._labels.get_or_create(key, label)

    def is_usable(self, xy: ArrayLike, radius: float = 0.0) -> NDArray[np.bool_]:
        """Whether world points lie in usable cells for a robot of ``radius`` (off-map: False)."""
        return self._sample(self.usable(radius), xy, False)

    def component_at(self, xy: ArrayLike, radius: float = 0.0) -> NDArray[np.int32]:
        """Component id at world points (0 where the point is not usable or off the map)."""
        return self._sample(self.components(radius), xy, 0).astype(np.int32)

    def __repr__(self) -> str:
        h, w = self.shape
        return (
            f"TraversableMap(shape=({h}, {w}), resolution={self.resolution}, "
            f"origin={self.origin}, height={self.height})"
        )


def _as_points(xy: ArrayLike, name: str) -> NDArray[np.float64]:
    arr = np.asarray(xy, dtype=np.float64)
    if arr.shape[-1:] != (2,):
        raise ValueError(f"{name} must have shape (..., 2) (x, y in metres), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise ValueError(f"{name} must be finite, got {xy!r}")
    return arr
