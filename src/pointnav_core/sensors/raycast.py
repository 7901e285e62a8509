"""Exact ray casting on one floor: what a range scan sees, vectorised over robots and rays.

:class:`ScanGeometry` holds the part of a floor's collision geometry a range sensor sees:

- the square of every OBSTACLE cell,
- everything off the map (the edge of the map reads as a wall: a ray has to end somewhere,
  and :class:`~pointnav_core.floor.collision.FloorCollision` blocks off-map too), and
- the edges of the floor plan's obstacle polygons (a wall thinner than a cell is seen).

VOID cells (holes, stairwells) are *not* seen: a ray passes over them, as a real lidar's
beam passes over a stairwell. Other robots are discs, passed to :func:`cast_rays` per call.

Touching counts: a ray stops at the first point where it meets the closed blocked set, so a
ray through the corner two diagonal squares share, or along the face of a square, stops
there (within :data:`TOUCH_EPS`), and no ray ever passes a blocked cell.

How the grid part is exact without a loop per ray
-------------------------------------------------
Every cell a ray traverses after its first is entered through a vertical grid line (an
*x-crossing*) or a horizontal one (a *y-crossing*). The ray's k-th x-crossing is at the k-th
grid line ahead of it, at ``t = (X_k - x) / cos``; the cell it enters there is the next
column at the row under the crossing point. The crossings of a family form an arithmetic
sequence in ``t``, so the first blocked one is an ``argmax`` along it, and the range is
the nearer of the two families' first hits. All crossings of all rays of all robots are
computed at once, as ``(family, robots, rays, crossings)`` arrays: a fixed number of numpy
operations, no loop over rays or traversal steps (Amanatides and Woo's traversal visits
the same cells one step at a time). A crossing within :data:`TOUCH_EPS` of a grid line
tests the cells on both sides of it.

Polygons are tested edge by edge: the edges whose bounding box is within ``max_range``,
less those the origin sees from their back (the material's side), against every ray at
once.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
import shapely
import shapely.geometry
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentTypeError
from pointnav_core.floor.maps import OBSTACLE, TraversableMap
from pointnav_core.sensors import raycast_jit
from pointnav_core.sensors.clearance import open_radius, quadrant_clearance
from pointnav_core.utils.compiled import check_method, choose

__all__ = ["TOUCH_EPS", "ScanGeometry", "cast_pose_compiled", "cast_rays", "inside_polygon", "polygon_hits"]

#: Metres within which a ray counts as touching a blocked square's face or corner.
TOUCH_EPS = 1e-9

# Stand-in for a zero direction component (its crossings are then far beyond any range).
_TINY = 1e-300

_NO_DISCS = np.zeros((0, 3))


class ScanGeometry:
    """What a range scan sees on one floor (see the module docstring), ready for queries.

    Parameters
    ----------
    tmap : TraversableMap
        The floor. Its OBSTACLE cells, its edge and the obstacle polygons of its
        :attr:`~pointnav_core.floor.maps.TraversableMap.collision` geometry are seen.

    Examples
    --------
    >>> tmap = TraversableMap([[0, 0, 0, 1]], resolution=0.5)
    >>> geo = ScanGeometry(tmap)
    >>> cast_rays(geo, [[0.25, 0.25]], [0.0], [0.0, np.pi / 2], 10.0).round(6).tolist()
    [[1.25, 0.25]]
    """

    def __init__(self, tmap: TraversableMap) -> None:
        if not isinstance(tmap, TraversableMap):
            raise ArgumentTypeError(f"tmap must be a TraversableMap, got {type(tmap).__name__}")
        self.tmap = tmap
        self.resolution = float(tmap.resolution)
        self.origin = (float(tmap.origin[0]), float(tmap.origin[1]))
        # One ring of blocked cells around the map: off the map reads as a wall.
        pad = np.pad(np.asarray(tmap.codes) == OBSTACLE, 1, constant_values=True)
        self.shape = pad.shape
        # Three stacked lookups: [0] a cell itself; [1] the cell or the one below it, [2] the
        # cell or the one to its left (a crossing that grazes a grid line touches both).
        below = pad.copy()
        below[1:] |= pad[:-1]
        left = pad.copy()
        left[:, 1:] |= pad[:, :-1]
        self.lookup = np.concatenate([pad.ravel(), below.ravel(), left.ravel()])
        self.plane = pad.size
        hp, wp = pad.shape
        # Per crossing family (x, y), shaped to broadcast over (family, robots, rays, k).
        fam = (2, 1, 1, 1)
        self.across_max = np.array([hp - 1.0, wp - 1.0]).reshape(fam)
        self.along_max = np.array([wp - 1.0, hp - 1.0]).reshape(fam)
        self.plane_of = np.array([pad.size, 2.0 * pad.size]).reshape(fam)
        self.hi_stride = np.array([float(wp), 1.0]).reshape(fam)
        self.entered_stride = np.array([1.0, float(wp)]).reshape(fam)
        polygons = tuple(tmap.collision.polygons)
        self.polygons = polygons
        starts: list[NDArray[np.float64]] = []
        ends: list[NDArray[np.float64]] = []
        for poly in polygons:
            # Counter-clockwise exteriors and clockwise holes: the material is on the left
            # of every edge, so a ray can first meet only edges it sees from their right.
            poly = shapely.geometry.polygon.orient(poly, 1.0)
            for ring in (poly.exterior, *poly.interiors):
                xy = np.asarray(ring.coords, dtype=np.float64)
                starts.append(xy[:-1])
                ends.append(xy[1:])
        if starts:
            self.edge_a = np.concatenate(starts)
            self.edge_b = np.concatenate(ends)
        else:
            self.edge_a = self.edge_b = np.zeros((0, 2))
        self.edge_vec = self.edge_b - self.edge_a
        length = np.hypot(self.edge_vec[:, 0], self.edge_vec[:, 1])
        # |u - 1/2| <= this: the edge's parameter u in [0, 1], widened by TOUCH_EPS metres.
        self.edge_half_slack = 0.5 + TOUCH_EPS / np.maximum(length, TOUCH_EPS)
        self.edge_lo = np.minimum(self.edge_a, self.edge_b)
        self.edge_hi = np.maximum(self.edge_a, self.edge_b)
        # Cells a polygon touches (padded grid): only an origin in one can be inside one.
        near = np.zeros(self.shape, dtype=bool)
        self.poly_tree: Any = None
        if polygons:
            self.poly_tree = shapely.STRtree(list(polygons))
            res, (ox, oy) = self.resolution, self.origin
            rows, cols = np.indices(self.shape)
            boxes = shapely.box(
                ox + (cols - 1) * res, oy + (rows - 1) * res, ox + cols * res, oy + rows * res
            ).ravel()
            hit = self.poly_tree.query(boxes, predicate="intersects")[0]
            near.ravel()[hit] = True
        self.near_polygon = near.ravel()
        # The compiled path's edge table, one row per edge: a, b - a, low corner, high
        # corner, the |u - 1/2| slack (raycast_jit).
        self._jit_edges = np.ascontiguousarray(np.column_stack(
            [self.edge_a, self.edge_vec, self.edge_lo, self.edge_hi, self.edge_half_slack]
        ).reshape(-1, 9))
        self._jit_base = (self.resolution, *self.origin)
        self._clearance_cells: NDArray[np.uint8] | None = None
        self._open_cells: NDArray[np.float64] | None = None
        self._jit_params_of: dict[float, NDArray[np.float64]] = {}

    @property
    def clearance(self) -> NDArray[np.uint8]:
        """Per padded cell and quadrant, the free square ahead of it (cells).

        Flat, ``[cell * 4 + quadrant]`` (:func:`~pointnav_core.sensors.clearance.quadrant_clearance`
        of the free cells). The compiled path skips the crossings of a ray that lie in such
        a square (raycast_jit); built on first use.
        """
        if self._clearance_cells is None:
            free = ~self.lookup[: self.plane].reshape(self.shape)
            self._clearance_cells = quadrant_clearance(free)
        return self._clearance_cells

    @property
    def open_radius(self) -> NDArray[np.float64]:
        """Per padded cell, a lower bound (m) on the distance from any point of it to a
        blocked cell (:func:`~pointnav_core.sensors.clearance.open_radius`), flat; built on
        first use. The batched scan skips the grid walks of a robot with more than its
        range here (obstacle polygons are cast apart, so they do not count)."""
        if self._open_cells is None:
            free = ~self.lookup[: self.plane].reshape(self.shape)
            self._open_cells = np.ascontiguousarray(open_radius(free).ravel() * self.resolution)
        return self._open_cells

    def jit_params(self, max_range: float) -> NDArray[np.float64]:
        """The compiled path's scalars: resolution, origin, max_range, padded shape."""
        params = self._jit_params_of.get(max_range)
        if params is None:  # a scan asks for the same max_range at every step
            params = np.array((*self._jit_base, max_range, *self.shape), dtype=np.float64)
            params.flags.writeable = False
            self._jit_params_of[max_range] = params
        return params

    @property
    def edge_table(self) -> NDArray[np.float64]:
        """The obstacle polygons' edges as the compiled kernels read them, ``(E, 9)``
        float64: per edge its start ``a``, ``b - a``, low corner, high corner (m) and the
        ``|u - 1/2|`` slack (``sensors._raycast_kernel.polygon_range``)."""
        return self._jit_edges

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["poly_tree"] = None  # rebuilt, not shipped
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        if self.polygons:
            self.poly_tree = shapely.STRtree(list(self.polygons))

    def __repr__(self) -> str:
        return f"ScanGeometry(shape={self.shape}, polygons={len(self.polygons)})"


def cast_rays(
    geometry: ScanGeometry,
    origins: ArrayLike,
    yaws: ArrayLike,
    angles: ArrayLike,
    max_range: float,
    discs: ArrayLike | None = None,
    own_disc: ArrayLike | None = None,
    method: str = "auto",
) -> NDArray[np.float64]:
    """Distances (m) from each origin along each ray to the first thing the scan sees.

    Parameters
    ----------
    geometry : ScanGeometry
        The floor's seen geometry.
    origins : array_like, shape (N, 2)
        Ray origins (the robots' centres), world x, y in metres.
    yaws : array_like, shape (N,)
        Each robot's heading (rad).
    angles : array_like, shape (R,)
        Ray bearings in the robot frame (rad, 0 ahead, positive to the left).
    max_range : float
        Rays end here (m): a ray that meets nothing reads ``max_range``.
    discs : array_like, shape (M, 3), optional
        Other robots as discs ``(x, y, radius)`` in metres, seen by every ray.
    own_disc : array_like of int, shape (N,), optional
        Index into ``discs`` of each origin's own disc, which it does not see (-1: none).
    method : {"auto", "array", "numba"}
        ``"array"``: the array path of this module (numpy); ``"numba"``: the compiled kernel of
        :mod:`~pointnav_core.sensors.raycast_jit` (the ``fast`` extra), the same ranges at a
        fraction of the cost; ``"auto"`` (default): numba when installed, else numpy.

    Returns
    -------
    ndarray of float64, shape (N, R)
        Range in ``[0, max_range]``; 0 when the origin itself touches the blocked set.

    Examples
    --------
    >>> geo = ScanGeometry(TraversableMap([[0, 0, 0, 0]], resolution=1.0))
    >>> cast_rays(geo, [[0.5, 0.5]], [0.0], [0.0, np.pi], 10.0).round(9).tolist()
    [[3.5, 0.5]]
    >>> cast_rays(geo, [[0.5, 0.5]], [0.0], [0.0], 10.0, discs=[[2.5, 0.5, 0.5]]).tolist()
    [[1.5]]
    >>> cast_rays(geo, [[0.5, 0.5]], [0.0], [0.0], 1.0).tolist()  # capped
    [[1.0]]
    """
    check_method(method)
    p = np.asarray(origins, dtype=np.float64).reshape(-1, 2)
    yaw = np.asarray(yaws, dtype=np.float64).reshape(-1)
    ang = np.asarray(angles, dtype=np.float64).reshape(-1)
    # Directions: the rays' robot-frame directions turned by the heading (the compiled path
    # evaluates the same products, so both give the same bits).
    cy, sy = np.cos(yaw), np.sin(yaw)
    ca, sa = np.cos(ang), np.sin(ang)
    if choose(method, *raycast_jit.KERNEL) is not None:
        return _cast_compiled(geometry, p, (cy, sy, ca, sa), float(max_range), discs, own_disc)
    c = cy[:, None] * ca[None, :] - sy[:, None] * sa[None, :]
    s = sy[:, None] * ca[None, :] + cy[:, None] * sa[None, :]
    best = np.minimum(
        _grid_hits(geometry, p, c, s, float(max_range)), float(max_range)
    )
    if len(geometry.edge_a):
        np.minimum(best, polygon_hits(geometry, p, c, s, float(max_range)), out=best)
    if discs is not None:
        d = np.asarray(discs, dtype=np.float64).reshape(-1, 3)
        if len(d):
            own = None if own_disc is None else np.asarray(own_disc, dtype=np.int64).reshape(-1)
            np.minimum(best, _disc_hits(p, c, s, d, own), out=best)
    return best


def _cast_compiled(
    geometry: ScanGeometry,
    p: NDArray[np.float64],
    trig: tuple[NDArray[np.float64], ...],
    max_range: float,
    discs: ArrayLike | None,
    own_disc: ArrayLike | None,
) -> NDArray[np.float64]:
    """:func:`cast_rays`' compiled path: ``trig`` is the headings' and bearings' cosines and
    sines ``(cy, sy, ca, sa)``."""
    d = _NO_DISCS if discs is None else np.asarray(discs, dtype=np.float64).reshape(-1, 3)
    own = _no_own(len(p)) if own_disc is None else np.ascontiguousarray(own_disc, dtype=np.int64).reshape(-1)
    best, near = raycast_jit.cast_rays_compiled(
        geometry, np.ascontiguousarray(p), *trig, max_range, np.ascontiguousarray(d), own
    )
    if near:  # an origin in a cell a polygon touches: shapely decides if it is inside
        best[inside_polygon(geometry, p)] = 0.0
    return best


def cast_pose_compiled(
    geometry: ScanGeometry,
    origin: NDArray[np.float64],
    heading: NDArray[np.float64],
    angles: tuple[NDArray[np.float64], NDArray[np.float64]],
    max_range: float,
    discs: NDArray[np.float64] | None = None,
) -> NDArray[np.float64] | None:
    """One origin's ranges (m), ``(R,)``, by the compiled path, or None without numba.

    :func:`cast_rays` for one robot, with its conversions left out: ``origin`` is a
    ``(1, 2)`` float64 array, ``heading`` a ``(2,)`` float64 array of the yaw's ``np.cos``
    and ``np.sin`` (one ``np.cos`` and one ``np.sin`` of a length-1 yaw array), ``angles``
    the bearings' ``np.cos`` and ``np.sin``, computed once, and ``discs`` None or a
    C-contiguous ``(M, 3)`` float64 array of the discs it sees (other robots, pedestrians).
    A scan calls it at every step.
    """
    if not raycast_jit.available():
        return None
    best, near = raycast_jit.cast_rays_compiled(
        geometry, origin, heading[:1], heading[1:], angles[0], angles[1], max_range,
        _NO_DISCS if discs is None else discs, _no_own(1)
    )
    if near:
        best[inside_polygon(geometry, origin)] = 0.0
    return best[0]


@functools.lru_cache(maxsize=64)
def _no_own(n: int) -> NDArray[np.int64]:
    """``n`` times -1 (no origin has a disc of its own), shared (the kernel only reads it)."""
    # Writable like a caller's own_disc, so the kernel is compiled for one array type.
    return np.full(n, -1, dtype=np.int64)


def _grid_hits(
    geo: ScanGeometry, p: NDArray[np.float64], c: NDArray[np.float64], s: NDArray[np.float64], max_range: float
) -> NDArray[np.float64]:
    """Range (m) to the first OBSTACLE or off-map cell along each ray, inf beyond max_range."""
    res = geo.resolution
    inv = 1.0 / res
    hp, wp = geo.shape
    # Continuous coordinates on the padded grid (cell units; the map starts at 1).
    gx = ((p[:, 0] - geo.origin[0]) * inv + 1.0)[:, None, None]
    gy = ((p[:, 1] - geo.origin[1]) * inv + 1.0)[:, None, None]
    e = TOUCH_EPS * inv
    reach = max_range * inv
    n_cross = int(min(math.ceil(reach) + 1, max(hp, wp) + 1))
    k = np.arange(n_cross, dtype=np.float64)[None, None, :]
    lookup, plane = geo.lookup, geo.plane

    # Both families at once, stacked on a leading axis: [0] x-crossings (vertical lines),
    # [1] y-crossings (horizontal lines); "along" is the coordinate the lines cut.
    cs = np.concatenate([c[None], s[None]])
    d_along, d_across = cs, cs[::-1]
    g2 = np.concatenate([gx[None, :, :, 0], gy[None, :, :, 0]])  # (2, N, 1)
    g_along, g_across = g2, g2[::-1]
    # Per ray: the first grid line ahead (floor(g)+1 going up, ceil(g)-1 going down), the
    # step between lines (+-1), the ray length per line (dt) and the first crossing's t and
    # across-coordinate. The k-th crossing is at t0 + k dt.
    pos = d_along >= 0.0
    sgn = np.where(pos, 1.0, -1.0)
    base = np.where(pos, np.floor(g_along) + 1.0, np.ceil(g_along) - 1.0)
    dt = 1.0 / np.maximum(np.abs(d_along), _TINY)  # a zero component: lines at "infinity"
    t0 = (base - g_along) * sgn * dt
    a0 = g_across + t0 * d_across
    step = dt * d_across
    k4 = k[None]
    # Every crossing of every ray of every robot: (family, robots, rays, crossings).
    across = a0[..., None] + step[..., None] * k4
    hi = np.floor(across + e)
    # lo < hi: the crossing grazes the line between rows (columns) hi - 1 and hi.
    grazing = np.floor(across - e) < hi
    np.maximum(hi, 0.0, out=hi)
    np.minimum(hi, geo.across_max, out=hi)
    entered = (base - ~pos)[..., None] + sgn[..., None] * k4
    np.maximum(entered, 0.0, out=entered)
    np.minimum(entered, geo.along_max, out=entered)
    # x: column `entered`, row hi (and hi - 1 if grazing): plane 1 ORs the row below;
    # y: row `entered`, column hi (and hi - 1 if grazing): plane 2 ORs the column left.
    idx = grazing * geo.plane_of + hi * geo.hi_stride + entered * geo.entered_stride
    hit = lookup[idx.astype(np.intp)]
    # Crossings come in order along the ray: the first blocked one is the nearest.
    first = hit.argmax(axis=3)
    found = hit.any(axis=3)
    t = t0 + first * dt
    best = np.where(found & (t <= reach), t, np.inf).min(axis=0)

    # An origin touching a blocked cell (or off the map) reads 0: test the cells within
    # TOUCH_EPS of it (one, or two or four on a grid line or vertex).
    x0 = gx[:, 0, 0]
    y0 = gy[:, 0, 0]
    c0 = np.minimum(np.maximum(np.floor(x0 - e), 0), wp - 1).astype(np.intp)
    c1 = np.minimum(np.maximum(np.floor(x0 + e), 0), wp - 1).astype(np.intp)
    r0 = np.minimum(np.maximum(np.floor(y0 - e), 0), hp - 1).astype(np.intp) * wp
    r1 = np.minimum(np.maximum(np.floor(y0 + e), 0), hp - 1).astype(np.intp) * wp
    flat = lookup[:plane]
    touching = flat[r0 + c0] | flat[r0 + c1] | flat[r1 + c0] | flat[r1 + c1]
    best[touching] = 0.0
    return best * res


def polygon_hits(
    geo: ScanGeometry, p: NDArray[np.float64], c: NDArray[np.float64], s: NDArray[np.float64], max_range: float
) -> NDArray[np.float64]:
    """Range (m) to the first obstacle-polygon edge along each ray (inf: none in range).

    The array path's definition of a polygon hit, for the single env and the batched
    engine alike (:mod:`pointnav_core.vector.scan`): origins ``p`` ``(N, 2)`` (m), ray
    directions ``c``, ``s`` ``(N, R)``; ``(N, R)`` ranges, 0 for an origin inside (or on) a
    polygon.
    """
    n, r = c.shape
    best = np.full((n, r), np.inf)
    # Candidate edges: those whose bounding box is within max_range of the origin.
    lo, hi = geo.edge_lo, geo.edge_hi
    near = (
        (hi[None, :, 0] >= p[:, 0, None] - max_range) & (lo[None, :, 0] <= p[:, 0, None] + max_range)
        & (hi[None, :, 1] >= p[:, 1, None] - max_range) & (lo[None, :, 1] <= p[:, 1, None] + max_range)
    )
    robot, edge = np.nonzero(near)
    e = geo.edge_vec[edge]
    f = geo.edge_a[edge] - p[robot]
    # Back faces: an origin on the material's side of an edge's line cannot first meet it
    # (an origin inside a polygon reads 0 below).
    keep = np.flatnonzero(e[:, 1] * f[:, 0] - e[:, 0] * f[:, 1] <= 0.0)
    if len(keep):
        robot, edge, e, f = robot[keep], edge[keep], e[keep], f[keep]
        ex, ey, fx, fy = e[:, 0:1], e[:, 1:2], f[:, 0:1], f[:, 1:2]
        # One robot: its rays broadcast against every edge; several: one row per pair.
        dx = c if n == 1 else c[robot]
        dy = s if n == 1 else s[robot]
        # p + t d = a + u e:  t = (f x e) / (d x e),  u = (f x d) / (d x e); a ray parallel
        # to an edge gives inf or NaN, which no comparison below accepts.
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            inv = 1.0 / (dx * ey - dy * ex)
            t = (fx * ey - fy * ex) * inv
            u = (fx * dy - fy * dx) * inv
            # Touching an end counts: u within TOUCH_EPS metres of [0, 1].
            hit = (t >= 0.0) & (np.abs(u - 0.5) <= geo.edge_half_slack[edge, None])
        t = np.where(hit, t, np.inf)
        if n == 1:
            best[0] = t.min(axis=0)
        else:  # per robot, the nearest over its candidate edges (pairs grouped by robot)
            starts = np.flatnonzero(np.r_[True, robot[1:] != robot[:-1]])
            best[robot[starts]] = np.minimum.reduceat(t, starts, axis=0)
    best[inside_polygon(geo, p)] = 0.0
    return best


def inside_polygon(geo: ScanGeometry, p: NDArray[np.float64]) -> NDArray[np.intp]:
    """Indices of the origins ``p`` ``(N, 2)`` (m) inside (or on) an obstacle polygon:
    they read 0."""
    # Only an origin in a cell a polygon touches can be inside one.
    hp, wp = geo.shape
    inv = 1.0 / geo.resolution
    col = np.minimum(np.maximum(np.floor((p[:, 0] - geo.origin[0]) * inv) + 1, 0), wp - 1).astype(np.intp)
    row = np.minimum(np.maximum(np.floor((p[:, 1] - geo.origin[1]) * inv) + 1, 0), hp - 1).astype(np.intp)
    check = np.flatnonzero(geo.near_polygon[row * wp + col])
    if len(check):
        return check[geo.poly_tree.query(shapely.points(p[check]), predicate="intersects")[0]]
    return check


def _disc_hits(
    p: NDArray[np.float64],
    c: NDArray[np.float64],
    s: NDArray[np.float64],
    discs: NDArray[np.float64],
    own: NDArray[np.int64] | None,
) -> NDArray[np.float64]:
    """Range (m) to the first of ``discs`` (closed) along each ray (inf: none)."""
    fx = (p[:, 0, None] - discs[None, :, 0])[:, None, :]  # (N, 1, M)
    fy = (p[:, 1, None] - discs[None, :, 1])[:, None, :]
    r2 = (discs[:, 2] ** 2)[None, None, :]
    b = fx * c[:, :, None] + fy * s[:, :, None]  # (N, R, M)
    cc = fx * fx + fy * fy - r2
    disc = b * b - cc
    # The nearer root, -b - sqrt(disc), written without cancellation as cc / (-b + sqrt).
    root = np.sqrt(np.maximum(disc, 0.0))
    denom = root - b
    with np.errstate(over="ignore"):  # a subnormal denom: the root is beyond any range (inf)
        t = np.where(denom > 0.0, cc / np.where(denom > 0.0, denom, 1.0), np.inf)
    hit = (disc >= 0.0) & (b <= 0.0)
    t = np.where(cc <= 0.0, 0.0, np.where(hit, t, np.inf))
    if own is not None:
        m = discs.shape[0]
        mine = own[:, None] == np.arange(m)[None, :]
        t = np.where(mine[:, None, :], np.inf, t)
    return t.min(axis=2)
