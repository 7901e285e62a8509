"""One collision geometry per floor: exact disc-clearance tests of points and segments.

The *blocked set* of a floor is the union of

- the square of every blocked grid cell (for planning and standing: every cell that is not
  FREE, since a robot may neither collide with OBSTACLE nor stand over VOID),
- everything off the grid (``outside_blocked=True``), and
- the obstacle polygons of a floor built from shapely geometry, so that a wall thinner
  than a cell is blocked even when it covers no cell centre.

A disc of radius ``r`` centred at ``p`` is *clear* when it does not overlap the blocked set:
the distance from ``p`` to the set is at least ``r`` (touching is allowed, within
:data:`TOUCH_TOL`). A segment is clear for ``r`` when every point of it is. The planner, the
sampler, every backend's ``is_valid_pose`` and the range sensors ask this one object, so a
pose is valid for the task exactly when it is valid for a backend.

How a segment is tested exactly
-------------------------------
The points closer than ``r`` to a segment form an open *stadium* (a rectangle with two
half-discs). A blocked cell square meets the stadium exactly when the cell's columns
overlap the stadium's x-extent over the cell's row band, because a square spans its whole
band. The x-extent of a convex set over a band is read off its boundary at the band's two
edges and at its leftmost and rightmost points, so each (segment, row) pair costs O(1)
numpy work plus one prefix-sum lookup of the blocked cells in a column range. Polygons are
tested with shapely's exact ``dwithin``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.utils import compiled as _compiled

__all__ = ["TOUCH_TOL", "FloorCollision", "convex_corners"]

#: Metres by which a disc may overlap the blocked set and still count as touching. Absorbs
#: floating-point error in tangent constructions (a path hugging a wall at exactly ``r``).
TOUCH_TOL = 1e-9


class FloorCollision:
    """The blocked set of one floor and exact clearance tests against it.

    Parameters
    ----------
    blocked : array_like of bool, shape (H, W)
        Blocked cells; row grows with +y, column with +x.
    resolution : float
        Metres per cell.
    origin : (float, float)
        World (x, y) of the outer corner of cell (0, 0), in metres.
    polygons : sequence of shapely.Polygon, optional
        Extra blocked polygons (walls and furniture of a floor plan), in metres.
    outside_blocked : bool, default True
        Whether everything off the grid is blocked.

    Examples
    --------
    >>> g = np.zeros((5, 5), bool); g[2, 2] = True
    >>> geo = FloorCollision(g, 0.5, (0.0, 0.0))
    >>> geo.points_clear([[0.6, 1.25], [1.25, 1.25]], 0.18).tolist()
    [True, False]
    >>> bool(geo.segments_clear([0.6, 1.25], [1.9, 1.25], 0.18))  # straight through
    False
    >>> bool(geo.segments_clear([0.6, 0.3], [1.9, 0.3], 0.18))    # below the square
    True
    """

    def __init__(
        self,
        blocked: ArrayLike,
        resolution: float,
        origin: tuple[float, float] = (0.0, 0.0),
        polygons: Sequence[Any] = (),
        outside_blocked: bool = True,
    ) -> None:
        mask = np.asarray(blocked, dtype=bool)
        if mask.ndim != 2 or mask.size == 0:
            raise ArgumentError(f"blocked must be a non-empty 2D array, got shape {mask.shape}")
        self.blocked = mask.copy()
        self.blocked.flags.writeable = False
        self.resolution = float(resolution)
        self.origin = (float(origin[0]), float(origin[1]))
        self.outside_blocked = bool(outside_blocked)
        self.shape = mask.shape
        h, w = mask.shape
        cum = np.zeros((h, w + 1), dtype=np.int32)
        np.cumsum(mask, axis=1, out=cum[:, 1:])
        cum.flags.writeable = False
        self._rowcum = cum
        self.polygons = tuple(polygons)
        self._poly_tree = shapely.STRtree(list(self.polygons)) if self.polygons else None
        self._poly_edges = _polygon_edges(self.polygons)
        self._radius_args: dict[float, tuple[Any, ...]] = {}  # kernel_arguments', per radius

    @classmethod
    def from_map(cls, tmap: Any) -> FloorCollision:
        """The planning geometry of a :class:`~pointnav_core.floor.maps.TraversableMap`.

        Every non-FREE cell and everything off the map is blocked (a robot may neither
        collide with OBSTACLE nor stand over VOID), plus the obstacle polygons of the floor
        plan the map was rasterised from, if any.
        """
        polygons = tuple(tmap.geometry.obstacles) if getattr(tmap, "geometry", None) is not None else ()
        return cls(np.asarray(tmap.codes) != 0, tmap.resolution, tmap.origin, polygons=polygons)

    # ------------------------------------------------------------------ state
    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_poly_tree"] = None  # the spatial index is rebuilt, not shipped
        state["_radius_args"] = {}
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._poly_tree = shapely.STRtree(list(self.polygons)) if self.polygons else None
        if "_poly_edges" not in state:
            self._poly_edges = _polygon_edges(self.polygons)
        self.__dict__.setdefault("_radius_args", {})

    @property
    def compiled_polygons(self) -> bool:
        """Whether the compiled tests can read every polygon (none, or all of them polygons)."""
        return self._poly_edges is not None or not self.polygons

    def kernel_geometry(self) -> tuple[Any, ...]:
        """Everything the compiled clearance tests read, in their argument order: origin x, y
        (m), resolution (m), each grid row's running count of blocked cells ``(H, W + 1)``,
        whether off the map is blocked,
        :meth:`polygon_edges`' seven arrays, and whether there are polygons to test."""
        return (float(self.origin[0]), float(self.origin[1]), float(self.resolution), self._rowcum,
                self.outside_blocked, *self.polygon_edges(), bool(self.polygons))

    def polygon_edges(self) -> tuple[NDArray[Any], ...]:
        """The polygons as the compiled tests read them: ``boxes (K, 4), first, last (K,),
        x0, y0, x1, y1 (E,)`` (empty without polygons)."""
        if self._poly_edges is not None and self.polygons:
            return self._poly_edges
        return (np.zeros((0, 4)), np.zeros(0, np.int64), np.zeros(0, np.int64), *(np.zeros(0),) * 4)

    # ------------------------------------------------------------------ queries
    def segment_clear(self, ax: float, ay: float, bx: float, by: float, radius: float) -> bool:
        """:meth:`segments_clear` for one segment from ``(ax, ay)`` to ``(bx, by)`` (m), without
        its array set-up: the compiled test called on the numbers where numba is installed
        (a tenth of the cost for one point; a property test holds the two equal)."""
        kernel = _compiled.kernel("pointnav_core.floor._collision_kernel", "segment_hits")
        if kernel is None or not self.compiled_polygons:
            return bool(self.segments_clear(np.array([ax, ay]), np.array([bx, by]), radius))
        if not (math.isfinite(ax) and math.isfinite(ay) and math.isfinite(bx) and math.isfinite(by)):
            return False
        return not kernel(float(ax), float(ay), float(bx), float(by), *self.kernel_arguments(float(radius)))

    def kernel_arguments(self, radius: float) -> tuple[Any, ...]:
        """:func:`~pointnav_core.floor._collision_kernel.segment_hits`' arguments after the segment,
        for a disc of ``radius`` m (``rho`` and ``reach`` as ``_cells_hit`` and
        ``_polygons_hit`` derive them); kept per radius, as a step's tests ask for one or two."""
        args = self._radius_args.get(radius)
        if args is None:
            ox, oy, res, rowcum, outside, *poly, use_polygons = self.kernel_geometry()
            inv = 1.0 / res
            rho = max(radius - TOUCH_TOL, TOUCH_TOL) * inv
            reach = max(radius - 2 * TOUCH_TOL, TOUCH_TOL / 2)
            args = (ox, oy, inv, rho, rowcum, outside, reach, *poly, use_polygons)
            if len(self._radius_args) >= 64:  # an oracle's arcs add their sagitta: many radii
                self._radius_args.clear()
            self._radius_args[radius] = args
        return args

    def points_clear(self, points: ArrayLike, radius: float) -> NDArray[np.bool_]:
        """Whether discs of ``radius`` metres centred at world ``points`` miss the blocked set.

        Parameters
        ----------
        points : array_like, shape (..., 2)
            Disc centres (x, y) in metres.
        radius : float
            Disc radius in metres, >= 0.

        Returns
        -------
        ndarray of bool, shape (...)
        """
        p = np.asarray(points, dtype=np.float64)
        return self.segments_clear(p, p, radius)

    def segments_clear(self, a: ArrayLike, b: ArrayLike, radius: float) -> NDArray[np.bool_]:
        """Whether a disc of ``radius`` swept from ``a`` to ``b`` misses the blocked set.

        Exact (within :data:`TOUCH_TOL`) for the cell squares and the polygons.

        Parameters
        ----------
        a, b : array_like, shape (..., 2)
            Segment ends (x, y) in metres; they broadcast against each other.
        radius : float
            Disc radius in metres, >= 0.

        Returns
        -------
        ndarray of bool, shape (...)
        """
        a = np.asarray(a, dtype=np.float64)
        b = np.asarray(b, dtype=np.float64)
        if a.shape != b.shape:
            a, b = np.broadcast_arrays(a, b)
        shape = a.shape[:-1]
        a = a.reshape(-1, 2)
        b = b.reshape(-1, 2)
        kernel = _compiled.kernel("pointnav_core.floor._collision_kernel", "segments_clear")
        if kernel is not None and self.compiled_polygons:
            # Both tests in one compiled loop: the oracle asks about a few segments at a time,
            # where the array set-up cost more than the tests.
            out = np.empty(len(a), dtype=np.bool_)
            kernel(np.ascontiguousarray(a), np.ascontiguousarray(b), *self.kernel_arguments(float(radius)), out)
            return out.reshape(shape)
        ok = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
        out = np.zeros(len(a), dtype=bool)
        idx = np.flatnonzero(ok)
        if len(idx):
            clear = ~self._cells_hit(a[idx], b[idx], float(radius))
            if self._poly_tree is not None and clear.any():
                sub = idx[clear]
                clear[clear] = ~self._polygons_hit(a[sub], b[sub], float(radius))
            out[idx] = clear
        return out.reshape(shape)

    def _polygons_hit(self, a: NDArray[np.float64], b: NDArray[np.float64], radius: float) -> NDArray[np.bool_]:
        # dwithin is closed (distance <= d); touching at exactly the radius is allowed.
        reach = max(radius - 2 * TOUCH_TOL, TOUCH_TOL / 2)
        kernel = _compiled.kernel("pointnav_core.floor._collision_kernel", "polygons_hit")
        if kernel is not None and self._poly_edges is not None:  # compiled: each edge's distance, and containment
            out = np.empty(len(a), dtype=np.bool_)
            kernel(np.ascontiguousarray(a[:, 0]), np.ascontiguousarray(a[:, 1]), np.ascontiguousarray(b[:, 0]),
                   np.ascontiguousarray(b[:, 1]), reach, *self._poly_edges, out)
            return out
        same = (a == b).all(axis=1)
        geoms = np.empty(len(a), dtype=object)
        if same.any():
            geoms[same] = shapely.points(a[same])
        if (~same).any():
            geoms[~same] = shapely.linestrings(np.stack([a[~same], b[~same]], axis=1))
        idx, _ = self._poly_tree.query(geoms, predicate="dwithin", distance=reach)
        hit = np.zeros(len(a), dtype=bool)
        hit[idx] = True
        return hit

    def _cells_hit(self, a: NDArray[np.float64], b: NDArray[np.float64], radius: float) -> NDArray[np.bool_]:
        """Whether each segment's open radius-stadium meets a blocked cell square."""
        inv = 1.0 / self.resolution
        ox, oy = self.origin
        ax = (a[:, 0] - ox) * inv
        ay = (a[:, 1] - oy) * inv
        bx = (b[:, 0] - ox) * inv
        by = (b[:, 1] - oy) * inv
        # A point robot is a disc of radius TOUCH_TOL: it may not squeeze through the corner
        # two diagonal squares share.
        rho = max(radius - TOUCH_TOL, TOUCH_TOL) * inv
        kernel = _compiled.kernel("pointnav_core.floor._collision_kernel", "cells_hit")
        if kernel is not None:  # the same test, segment by segment, in compiled code
            out = np.empty(len(a), dtype=np.bool_)
            kernel(ax, ay, bx, by, rho, self._rowcum, self.outside_blocked, out)
            return out
        h, w = self.shape
        ylo = np.minimum(ay, by) - rho
        yhi = np.maximum(ay, by) + rho
        k0 = np.floor(ylo).astype(np.int64)
        # A band starting exactly at yhi only touches the open stadium's boundary.
        k1 = np.ceil(yhi).astype(np.int64) - 1
        k1 = np.maximum(k1, k0)
        counts = k1 - k0 + 1
        seg = np.repeat(np.arange(len(a)), counts)
        start = np.repeat(np.cumsum(counts) - counts, counts)
        k = k0[seg] + (np.arange(len(seg)) - start)
        y0 = np.maximum(k, ylo[seg])
        y1 = np.minimum(k + 1, yhi[seg])
        sax, say, sbx, sby = ax[seg], ay[seg], bx[seg], by[seg]
        lo0, hi0 = _stadium_row(sax, say, sbx, sby, rho, y0)
        lo1, hi1 = _stadium_row(sax, say, sbx, sby, rho, y1)
        lo = np.minimum(lo0, lo1)
        hi = np.maximum(hi0, hi1)
        # The leftmost / rightmost points of the stadium, when inside the band.
        left_is_a = sax <= sbx
        lx = np.where(left_is_a, sax, sbx) - rho
        ly = np.where(left_is_a, say, sby)
        rx = np.where(left_is_a, sbx, sax) + rho
        ry = np.where(left_is_a, sby, say)
        lo = np.where((ly >= y0) & (ly <= y1), np.minimum(lo, lx), lo)
        hi = np.where((ry >= y0) & (ry <= y1), np.maximum(hi, rx), hi)
        c_lo = np.floor(lo).astype(np.int64)
        c_hi = np.ceil(hi).astype(np.int64) - 1
        nonempty = (c_lo <= c_hi) & (hi > lo)
        inside_row = (k >= 0) & (k < h)
        cl = np.clip(c_lo, 0, w)
        ch = np.clip(c_hi + 1, 0, w)
        rows = np.clip(k, 0, h - 1)
        count = np.where(
            inside_row & (ch > cl), self._rowcum[rows, ch] - self._rowcum[rows, np.minimum(cl, ch)], 0
        )
        hit = nonempty & (count > 0)
        if self.outside_blocked:
            hit |= nonempty & (~inside_row | (c_lo < 0) | (c_hi >= w))
        # bincount, not logical_or.at: the unbuffered ufunc loop is far slower.
        return np.bincount(seg[hit], minlength=len(a)) > 0


def _polygon_edges(polygons: Sequence[Any]) -> tuple[NDArray[Any], ...] | None:
    """Every polygon part's bounding box and ring edges, flat: ``boxes (K, 4), first (K,),
    last (K,), x0, y0, x1, y1 (E,)`` (the compiled polygon test's layout); None when a part
    is not a polygon (shapely's test then serves)."""
    boxes, first, last, edges = [], [], [], []
    n = 0
    for poly in polygons:
        for part in getattr(poly, "geoms", [poly]):
            if part.is_empty:
                continue
            if part.geom_type != "Polygon":
                return None
            start = n
            for ring in [part.exterior, *part.interiors]:
                pts = np.asarray(ring.coords, dtype=np.float64)
                edges.append(np.concatenate([pts[:-1], pts[1:]], axis=1))
                n += len(pts) - 1
            boxes.append(part.bounds)
            first.append(start)
            last.append(n)
    cat = np.concatenate(edges) if edges else np.zeros((0, 4))
    return (np.asarray(boxes, dtype=np.float64).reshape(-1, 4), np.asarray(first, dtype=np.int64),
            np.asarray(last, dtype=np.int64), *(np.ascontiguousarray(cat[:, j]) for j in range(4)))


def _stadium_row(
    ax: NDArray[np.float64],
    ay: NDArray[np.float64],
    bx: NDArray[np.float64],
    by: NDArray[np.float64],
    rho: float,
    y: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """x-interval of the line at height ``y`` inside the stadium of radius ``rho``.

    Returns ``(lo, hi)`` with ``lo = +inf, hi = -inf`` where the line misses it.
    """
    lo = np.full(y.shape, np.inf)
    hi = np.full(y.shape, -np.inf)
    r2 = rho * rho
    for cx, cy in ((ax, ay), (bx, by)):
        d2 = r2 - (y - cy) ** 2
        ok = d2 >= 0
        s = np.sqrt(np.where(ok, d2, 0.0))
        lo = np.where(ok, np.minimum(lo, cx - s), lo)
        hi = np.where(ok, np.maximum(hi, cx + s), hi)
    dx = bx - ax
    dy = by - ay
    length = np.hypot(dx, dy)
    has = length > 0
    safe = np.where(has, length, 1.0)
    nx = -dy / safe * rho
    ny = dx / safe * rho
    corners = (
        (ax + nx, ay + ny),
        (bx + nx, by + ny),
        (bx - nx, by - ny),
        (ax - nx, ay - ny),
    )
    for i in range(4):
        px, py = corners[i]
        qx, qy = corners[(i + 1) % 4]
        ymn = np.minimum(py, qy)
        ymx = np.maximum(py, qy)
        span = qy - py
        ok = has & (span != 0) & (y >= ymn) & (y <= ymx)
        t = np.where(ok, (y - py) / np.where(span != 0, span, 1.0), 0.0)
        x = px + t * (qx - px)
        lo = np.where(ok, np.minimum(lo, x), lo)
        hi = np.where(ok, np.maximum(hi, x), hi)
    return lo, hi


def convex_corners(
    blocked: NDArray[np.bool_], outside_blocked: bool = True
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """Grid vertices where exactly one of the four incident cells is blocked.

    These are the convex corners of the union of blocked squares: the only grid vertices a
    taut path of a disc can bend around.

    Parameters
    ----------
    blocked : ndarray of bool, shape (H, W)
    outside_blocked : bool
        Whether cells off the grid count as blocked.

    Returns
    -------
    rows, cols : ndarray of int
        Vertex indices: vertex ``(i, j)`` is the corner shared by cells ``(i-1, j-1)`` ..
        ``(i, j)``, at world ``origin + (j, i) * resolution``.
    quadrant : ndarray of int
        Which incident cell is blocked: 0 = (i-1, j-1) (below left), 1 = (i-1, j) (below
        right), 2 = (i, j) (above right), 3 = (i, j-1) (above left). The free arc around
        the vertex faces the opposite quadrant.

    Examples
    --------
    >>> r, c, q = convex_corners(np.array([[False, True]]), outside_blocked=False)
    >>> sorted(zip(r.tolist(), c.tolist(), q.tolist()))
    [(0, 1, 2), (0, 2, 3), (1, 1, 1), (1, 2, 0)]
    """
    pad = np.pad(blocked, 1, constant_values=outside_blocked)
    sw = pad[:-1, :-1]
    se = pad[:-1, 1:]
    ne = pad[1:, 1:]
    nw = pad[1:, :-1]
    n = sw.astype(np.int8) + se + ne + nw
    one = n == 1
    rows, cols = np.nonzero(one)
    quadrant = np.select(
        [sw[rows, cols], se[rows, cols], ne[rows, cols]], [0, 1, 2], default=3
    ).astype(np.int64)
    return rows.astype(np.int64), cols.astype(np.int64), quadrant
