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
The robot's centre may stand at a point when its disc of radius ``r`` misses the floor's
blocked set, :attr:`TraversableMap.collision` (every non-FREE cell square, off the map, and
the floor plan's polygons; see :mod:`pointnav_core.floor.collision`). :meth:`usable` answers this
exactly for every cell centre (cached per radius), :meth:`is_usable` for any point; the
planner, the sampler and every backend ask the same geometry.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from typing import Any, Callable, Hashable, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from pointnav_core.errors import ArgumentError
from pointnav_core.floor.collision import FloorCollision
from pointnav_core.utils import validation
from pointnav_core.utils.compiled import kernel

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
            raise ArgumentError(f"maxsize must be >= 1, got {maxsize!r}")
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
    return validation.real("radius", radius, minimum=0.0, unit="metres")


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
        ``obstacles``). Its obstacle polygons join the blocked set, so a wall thinner than
        a cell still blocks (see :attr:`collision`).

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
            raise ArgumentError(f"grid must be a non-empty 2D array, got shape {codes.shape}")
        validation.cell_budget("grid", *codes.shape)
        if codes.dtype == bool:
            codes = np.where(codes, FREE, OBSTACLE)
        elif not np.issubdtype(codes.dtype, np.integer):
            raise ArgumentError(
                f"grid must hold integer cell codes or booleans, got dtype {codes.dtype}"
            )
        bad = ~np.isin(codes, (FREE, OBSTACLE, VOID))
        if bad.any():
            raise ArgumentError(
                "grid holds unknown cell codes "
                f"{sorted(set(np.unique(codes[bad]).tolist()))[:5]}; valid: {CELL_CLASSES}"
            )
        resolution = validation.real("resolution", resolution, minimum=0.0, strict=True, unit="m/cell")
        origin_arr = validation.vector("origin", origin, sizes=(2,))
        height = validation.real("height", height)
        self.codes: NDArray[np.uint8] = np.array(codes, dtype=np.uint8, order="C", copy=True)
        self.codes.flags.writeable = False
        self.resolution = resolution
        self.origin = (float(origin_arr[0]), float(origin_arr[1]))
        self.height = height
        self.geometry = geometry
        self._usable = BoundedCache(8)
        self._labels = BoundedCache(8)
        self._component_cells = BoundedCache(32)
        # Owned by ``geodesic``; kept here so that planners live exactly as long as the map.
        self.planner_cache = BoundedCache(8)
        self._collision: FloorCollision | None = None

    @property
    def collision(self) -> FloorCollision:
        """The floor's :class:`~pointnav_core.floor.collision.FloorCollision` (built once, cached).

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
            raise ArgumentError(f"cells must have shape (..., 2), got {cells.shape}")
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
        """Cells whose centre a robot disc of ``radius`` metres can stand on (cached, read-only).

        A centre is usable when the disc misses the floor's blocked set
        (:attr:`collision`: every non-FREE cell square, off the map, and the floor plan's
        polygons); touching is allowed. This is :meth:`FloorCollision.points_clear` at every
        cell centre, computed fast: a distance transform decides all cells but a thin shell
        (and those near polygons), which are tested exactly.

        Parameters
        ----------
        radius : float
            Robot radius in metres, >= 0. 0 is a point robot.

        Examples
        --------
        >>> m = TraversableMap(np.ones((5, 5), bool), resolution=1.0)
        >>> m.usable(0.5).sum(), m.usable(0.6).sum(), m.usable(1.6).sum()
        (np.int64(25), np.int64(9), np.int64(1))
        """
        radius = _check_radius(radius)
        key = round(radius, 12)
        return self._usable.get_or_create(key, lambda: self._erode(key))

    def _erode(self, radius: float) -> NDArray[np.bool_]:
        geo = self.collision
        res = self.resolution
        free = self.codes == FREE
        pad = 1
        padded = np.pad(free, pad, constant_values=False)
        # Distance (cells) from each cell centre to the nearest blocked cell centre, D. The
        # nearest blocked square is between D - sqrt(1/2) and D - 1/2 cells away.
        edt = np.asarray(ndimage.distance_transform_edt(padded))[pad:-pad, pad:-pad]
        r = radius / res
        sure = free & (edt - math.sqrt(0.5) >= r)
        maybe = free & ~sure & (edt - 0.5 >= r - 1e-9)
        if geo.polygons:
            maybe |= sure
            sure = np.zeros_like(sure)
        rows, cols = np.nonzero(maybe)
        if len(rows):
            centres = np.stack([self.origin[0] + (cols + 0.5) * res, self.origin[1] + (rows + 0.5) * res], axis=1)
            sure[rows, cols] = geo.points_clear(centres, radius)
        sure.flags.writeable = False
        return sure

    def components(self, radius: float = 0.0) -> NDArray[np.int32]:
        """Connected components of :meth:`usable` cells (0 = not usable, 1.. = component id).

        Two usable cells (side or diagonal neighbours) are connected when the disc can move
        straight between their centres, checked exactly; so cells of one component are truly
        reachable from each other. A passage no row of cell centres runs through (a door
        narrower than the robot plus a cell) may split a component in two; the planner still
        finds the way through it.
        """
        radius = _check_radius(radius)
        key = round(radius, 12)
        return self._labels.get_or_create(key, lambda: self._label(radius))

    def usable_indices(self, radius: float) -> NDArray[np.intp]:
        """Flat (row-major) indices of the :meth:`usable` cells (cached, read-only), so that
        draws over the whole floor do not scan the grid each time."""
        radius = _check_radius(radius)

        def build() -> NDArray[np.intp]:
            flat = np.flatnonzero(self.usable(radius))
            flat.flags.writeable = False
            return flat

        return self._component_cells.get_or_create((round(radius, 12), None), build)

    def component_cells(self, radius: float, label: int) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
        """The cells of component ``label`` of :meth:`components` (row-major flat indices) and
        their centres (world metres, ``(N, 2)``); cached, so that sampling many points in one
        component scans it once."""
        radius = _check_radius(radius)

        def build() -> tuple[NDArray[np.intp], NDArray[np.float64]]:
            flat = np.flatnonzero(self.components(radius) == label)
            rr, cc = np.divmod(flat, self.shape[1])
            return flat, self.cell_to_world(np.stack([rr, cc], axis=-1))

        return self._component_cells.get_or_create((round(radius, 12), int(label)), build)

    def _label(self, radius: float) -> NDArray[np.int32]:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        usable = self.usable(radius)
        h, w = self.shape
        res = self.resolution
        ids = np.arange(h * w).reshape(h, w)
        src, dst = [], []
        for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
            c0, c1 = max(0, -dc), w - max(0, dc)
            a = usable[0 : h - dr, c0:c1]
            b = usable[dr:, c0 + dc : c1 + dc]
            both = a & b
            # A segment whose ends both have clearance >= r + length/2 is clear: every point
            # of it is within length/2 of an end. The rest are tested exactly.
            wide = self.usable(radius + 0.5 * res * math.hypot(dr, dc))
            sure = both & wide[0 : h - dr, c0:c1] & wide[dr:, c0 + dc : c1 + dc]
            ia = ids[0 : h - dr, c0:c1]
            ib = ids[dr:, c0 + dc : c1 + dc]
            test = both & ~sure
            if test.any():
                ta, tb = ia[test], ib[test]
                pa = self.cell_to_world(np.stack(np.divmod(ta, w), axis=1))
                pb = self.cell_to_world(np.stack(np.divmod(tb, w), axis=1))
                ok = self.collision.segments_clear(pa, pb, radius)
                src += [ia[sure], ta[ok]]
                dst += [ib[sure], tb[ok]]
            else:
                src.append(ia[sure])
                dst.append(ib[sure])
        s, d = np.concatenate(src), np.concatenate(dst)
        graph = coo_matrix((np.ones(len(s), np.int8), (s, d)), shape=(h * w, h * w))
        _, comp = connected_components(graph, directed=False)
        # Number components 1.. in order of first usable cell; 0 for unusable cells.
        flat = usable.ravel()
        _, first = np.unique(comp[flat], return_index=True)
        order = np.argsort(first)
        rank = np.zeros(comp.max() + 1, dtype=np.int32)
        rank[np.unique(comp[flat])[order]] = np.arange(1, len(order) + 1, dtype=np.int32)
        labels = np.where(flat, rank[comp], 0).astype(np.int32).reshape(h, w)
        labels.flags.writeable = False
        return labels

    def is_usable(self, xy: ArrayLike, radius: float = 0.0) -> NDArray[np.bool_]:
        """Whether a robot disc of ``radius`` m fits at world points (exact; off-map: False)."""
        pts = _as_points(xy, "xy")
        return self.collision.points_clear(pts, _check_radius(radius))

    def component_at(self, xy: ArrayLike, radius: float = 0.0) -> NDArray[np.int32]:
        """Component id at world points: of a usable cell centre the disc can move to straight.

        0 where the disc does not fit at the point, or sees no usable cell centre within two
        cells (a point deep in a passage narrower than the robot plus a cell).
        """
        pts = _as_points(xy, "xy")
        flat = pts.reshape(-1, 2)
        labels = self.components(radius)
        if len(flat) == 1:
            own = self._point_label(float(flat[0, 0]), float(flat[0, 1]), labels, radius)
            if own is not None:
                return np.full(pts.shape[:-1], own, dtype=np.int32)
        out = np.zeros(len(flat), dtype=np.int32)
        # A point on a labelled cell's centre (every sampled point) is that cell's: the
        # nearest candidate, at distance 0, which the loop below would find first. The
        # labelled cells are the usable ones, exact at their centres, so such a point
        # needs no disc test of its own.
        cells = self.world_to_cell(flat)
        inside = self.in_bounds(cells)
        rows, cols = np.where(inside, cells[:, 0], 0), np.where(inside, cells[:, 1], 0)
        own = labels[rows, cols]
        centred = inside & (own > 0) & (self.cell_to_world(cells) == flat).all(axis=1)
        out[centred] = own[centred]
        clear = np.zeros(len(flat), dtype=bool)
        if not centred.all():
            clear[~centred] = self.is_usable(flat[~centred], radius)
        span = np.arange(-2, 3)
        for i in np.flatnonzero(clear & ~centred):
            cell = self.world_to_cell(flat[i])
            cand = np.stack(np.meshgrid(cell[0] + span, cell[1] + span, indexing="ij"), -1).reshape(-1, 2)
            cand = cand[self.in_bounds(cand)]
            cand = cand[labels[cand[:, 0], cand[:, 1]] > 0]
            if not len(cand):
                continue
            centres = self.cell_to_world(cand)
            order = np.argsort(np.hypot(*(centres - flat[i]).T), kind="stable")
            ok = self.collision.segments_clear(np.broadcast_to(flat[i], centres.shape), centres, radius)
            hit = order[ok[order]]
            if len(hit):
                out[i] = labels[cand[hit[0], 0], cand[hit[0], 1]]
        return out.reshape(pts.shape[:-1])

    def _point_label(self, x: float, y: float, labels: NDArray[np.int32], radius: float) -> int | None:
        """One point's label, in floats where that is quicker than the general path (the
        same answer: property tests hold both ways equal): a sampled point (a cell centre),
        or with numba any finite point (``floor._component_kernel``); None otherwise."""
        own = self._centre_label(x, y, labels)
        if own > 0:
            return own
        fn = kernel("pointnav_core.floor._component_kernel", "point_component")
        collision = self.collision
        if fn is None or not collision.compiled_polygons or not (math.isfinite(x) and math.isfinite(y)):
            return None
        (ox, oy), res = self.origin, self.resolution
        return int(fn(x, y, labels, float(ox), float(oy), float(res), *collision.kernel_arguments(_check_radius(radius))))

    def _centre_label(self, x: float, y: float, labels: NDArray[np.int32]) -> int:
        """The label of the cell whose centre is exactly ``(x, y)`` (m), else 0: the general
        path's centred test (``world_to_cell``, ``cell_to_world``) for one point in floats, the
        same expressions (a property test holds them equal)."""
        (ox, oy), res = self.origin, self.resolution
        col, row = math.floor((x - ox) / res), math.floor((y - oy) / res)
        h, w = self.shape
        if 0 <= row < h and 0 <= col < w and ox + (col + 0.5) * res == x and oy + (row + 0.5) * res == y:
            return int(labels[row, col])
        return 0

    def __repr__(self) -> str:
        h, w = self.shape
        return (
            f"TraversableMap(shape=({h}, {w}), resolution={self.resolution}, "
            f"origin={self.origin}, height={self.height})"
        )


def _as_points(xy: ArrayLike, name: str) -> NDArray[np.float64]:
    arr = np.asarray(xy, dtype=np.float64)
    if arr.shape[-1:] != (2,):
        raise ArgumentError(f"{name} must have shape (..., 2) (x, y in metres), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise ArgumentError(f"{name} must be finite, got {xy!r}")
    return arr
