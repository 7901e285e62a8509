"""The range scan of a batch of worlds: ``(W, R, n_rays)`` ranges in one call.

Every world has its own floor and up to ``R`` robots; each present robot casts the
rays of a :class:`~pointnav_core.sensors.RangeScan` from its centre and reads, per ray,
the distance (m) to the first thing the single env's scan sees
(:mod:`pointnav_core.sensors.raycast`): an OBSTACLE cell, the map's edge (one ring of
blocked cells around the map), an edge of the floor's obstacle polygons (floor plans; an
origin inside a polygon reads 0) or the disc of another present robot of the same world.
The polygon edges are the single scan's own definitions, called, not copied:
``raycast.polygon_hits`` on the array path (on the host, for torch too) and
``sensors._raycast_kernel.polygon_range`` compiled.
VOID is not seen; touching counts (within :data:`~pointnav_core.sensors.TOUCH_EPS`); an
origin touching a blocked cell reads 0. Absent robots neither see nor are seen; their rows
read ``max_range``.

Two paths give the same ranges (``property_tests/test_compiled_paths.py``, ``tests/pairs_vector.py``):

- the array path (numpy, or torch on any device, through
  :class:`~pointnav_core.vector.xp.Arrays`): the single env's crossing formulas
  (``raycast._grid_hits``) for every ray of every robot at once, the crossings taken in a
  fixed number of blocks of :data:`BLOCK` (set by ``max_range`` and the finest cell size,
  not by the scene), so that the temporaries stay small;
- the compiled path (numpy on the CPU with numba, the ``fast`` extra): the single env's
  kernel (``sensors._raycast_kernel.grid_range``, which jumps over the free squares ahead
  of the ray, :mod:`pointnav_core.sensors.clearance`) ray by ray, in one compiled loop over worlds, robots and
  rays (:mod:`pointnav_core.vector._scan_kernel`).

Both take the rays' directions from the same products ``cos(yaw) cos(a) - sin(yaw) sin(a)``
(and the sine alike), so they decide every crossing on the same numbers.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from pointnav_core.errors import ArgumentError
from pointnav_core.sensors.noise import episode_key, scan_noise, seed_entropy
from pointnav_core.sensors.raycast import (
    TOUCH_EPS,
    ScanGeometry,
    inside_polygon,
    polygon_hits,
)
from pointnav_core.sensors.scan import RangeScan
from pointnav_core.utils.compiled import check_method, choose, kernel
from pointnav_core.vector.xp import Arrays

__all__ = [
    "BLOCK", "KERNEL", "ScanTables", "VectorScan", "cast_batch", "compiled_available", "directions", "requested_scan",
]

#: Crossings per family taken together by one iteration of the array path.
BLOCK = 8
_TINY = 1e-300  # raycast._TINY: a zero direction component puts its lines at "infinity"
#: The compiled path's kernel module and function (:func:`pointnav_core.utils.compiled.kernel`).
KERNEL = ("pointnav_core.vector._scan_kernel", "cast_worlds")


class ScanTables:
    """What the scan sees on one floor per scene, as flat arrays (numpy and ``arrays``).

    Parameters
    ----------
    scenes : sequence of Scene
        Their floor ``floor`` is used: its cells and the edges of its obstacle polygons.
    floor : int
        The task's floor.
    arrays : Arrays
        Namespace and device of the array path.
    """

    def __init__(self, scenes: Sequence[Any], floor: int, arrays: Arrays) -> None:
        lookups, clears, opens, edges, meta = [], [], [], [], []
        lo = co = eo = oo = 0
        #: Per scene, the single scan's geometry of its floor (cells and polygon edges).
        self.geometries = [ScanGeometry(scene.floors[floor]) for scene in scenes]
        for geo in self.geometries:
            hp, wp = geo.shape
            lookups.append(geo.lookup)
            clears.append(geo.clearance)
            opens.append(geo.open_radius)
            edges.append(geo.edge_table)
            n_edges = len(geo.edge_table)
            # lookup offset, clearance offset, padded rows, padded columns, cell size, origin,
            # first polygon edge, number of edges, open-radius offset
            meta.append((lo, co, hp, wp, geo.resolution, geo.origin[0], geo.origin[1], eo, n_edges, oo))
            lo += geo.lookup.size
            co += geo.clearance.size
            eo += n_edges
            oo += geo.open_radius.size
        #: Per scene: lookup offset, clearance offset, hp, wp, resolution, ox, oy, first
        #: edge, edges, open-radius offset (float64).
        self.meta = np.ascontiguousarray(meta, dtype=np.float64)
        #: The three lookup planes of every padded grid, end to end (bool, numpy).
        self.lookup = np.ascontiguousarray(np.concatenate(lookups))
        #: Per padded cell and quadrant, the free square ahead (sensors.clearance, uint8).
        self.clearance = np.ascontiguousarray(np.concatenate(clears), dtype=np.uint8)
        #: Per padded cell, how far (m) every point of it is from a blocked cell at least
        #: (ScanGeometry.open_radius, float64): the compiled cast's early exit.
        self.open_radius = np.ascontiguousarray(np.concatenate(opens), dtype=np.float64)
        #: Every floor's polygon edges (ScanGeometry.edge_table rows), end to end.
        self.edges = np.ascontiguousarray(np.concatenate(edges).reshape(-1, 9))
        #: The scenes whose floor has obstacle polygons.
        self.polygon_scenes = [k for k, geo in enumerate(self.geometries) if len(geo.polygons)]
        self.min_res = float(self.meta[:, 4].min())
        self.max_side = int(self.meta[:, 2:4].max())
        a = self.arrays = arrays
        self.lookup_x = a.asarray(self.lookup, a.boolean)
        m = self.meta
        self.m_off = a.asarray(m[:, 0], a.i64)
        self.m_hp, self.m_wp, self.m_res, self.m_ox, self.m_oy = (a.asarray(m[:, i]) for i in (2, 3, 4, 5, 6))


def requested_scan(sensors: Any) -> RangeScan | None:
    """The range scan a batched engine's ``sensors`` asks for, or None.

    The single envs' checks apply (unknown sensors and keys); the batched engines take a
    ``"scan"`` and a ``"local_map"`` only: any other sensor raises a ValueError naming it.
    """
    from pointnav_core.sensors import make_sensors

    terms = make_sensors(sensors)
    unsupported = [term.name for term in terms if term.name not in ("scan", "local_map")]
    if unsupported:
        raise ArgumentError(f"sensors: {unsupported[0]!r} is not supported by the batched engine (only 'scan', 'local_map')")
    return next((term for term in terms if isinstance(term, RangeScan)), None)


def compiled_available() -> bool:
    """Whether the compiled path can run (numba importable, outside ``numpy_paths()``)."""
    return kernel(*KERNEL) is not None


def directions(arrays: Arrays, yaw: Any, angles: Any) -> tuple[Any, Any]:
    """Cosines and sines ``(W, R, n)`` of the bearings ``yaw + angles`` (rad), by the
    angle-sum products: one cosine and sine per robot, not per ray."""
    xp = arrays.xp
    cy, sy = xp.cos(yaw)[..., None], xp.sin(yaw)[..., None]
    ca, sa = xp.cos(angles), xp.sin(angles)
    return cy * ca - sy * sa, sy * ca + cy * sa


def cast_batch(
    tables: ScanTables,
    scene: Any,
    x: Any,
    y: Any,
    yaw: Any,
    present: Any,
    radius: Any,
    angles: Any,
    max_range: float,
    method: str = "auto",
    crowd: Any = None,
) -> Any:
    """Exact ranges (m) of every present robot's rays, before the min-range rule.

    Parameters
    ----------
    tables : ScanTables
        The scenes' floors.
    scene : int array, shape (W,)
        Each world's scene (index into ``tables``' scenes).
    x, y, yaw : float64 arrays, shape (W, R)
        Robot centres (m) and headings (rad).
    present : bool array, shape (W, R)
        Robots that see and are seen.
    radius : float or float array broadcasting to (W, R)
        Robot radius (m), one for all or each robot's own: the discs the other robots see.
    angles : float64 array, shape (n,)
        Ray bearings in the robot frame (rad).
    max_range : float
        Longest reading (m).
    method : {"auto", "array", "numba"}
        ``"array"``: the array path (numpy or torch); ``"numba"``: the compiled path;
        ``"auto"``: numba for arrays on the CPU (numpy, or torch ``"cpu"``) when installed,
        else the array path.
    crowd : (qx, qy, qr, qn), optional
        Discs every robot of a world sees besides the other robots (its pedestrians):
        centres and radii ``(W, Q)`` (m) and each world's count ``(W,)`` (its first discs).

    Returns
    -------
    float64 array, shape (W, R, n)
        In ``[0, max_range]``; ``max_range`` for absent robots.

    Examples
    --------
    Two robots 0.1 m apart (radius 0.02 m) before a wall from x = 0.5 m to 0.6 m, looking
    ahead and back:

    >>> from pointnav_core.scenes import Scene
    >>> from pointnav_core.vector.xp import make_arrays
    >>> grid = np.zeros((5, 8), np.uint8)
    >>> grid[:, 5] = 1
    >>> tables = ScanTables([Scene.from_array(grid, 0.1)], 0, make_arrays("numpy"))
    >>> x, y, yaw = np.array([[0.25, 0.15]]), np.full((1, 2), 0.25), np.zeros((1, 2))
    >>> d = cast_batch(tables, np.zeros(1, np.int64), x, y, yaw, np.ones((1, 2), bool), 0.02,
    ...                np.array([0.0, np.pi]), 2.0)
    >>> d.round(9).tolist()  # the wall and the other robot; the other robot and the map's edge
    [[[0.25, 0.08], [0.08, 0.15]]]
    """
    check_method(method)
    a = tables.arrays
    on_cpu = not a.is_torch or a.device == "cpu"
    cast_worlds = choose(method, *KERNEL, usable=on_cpu, needs="arrays on the CPU and numba")
    angles = a.asarray(angles)
    radius = a.xp.zeros_like(x) + radius  # (W, R)
    if cast_worlds is not None:
        return _cast_compiled(cast_worlds, tables, scene, x, y, yaw, angles, present, radius, float(max_range), crowd)
    c, s = directions(a, yaw, angles)
    best = _grid_ranges(tables, scene, x, y, c, s, float(max_range))
    best = a.xp.minimum(best, _disc_ranges(a, x, y, c, s, present, radius))
    if crowd is not None:
        crowd = a.discs(crowd)
        best = a.xp.minimum(best, _crowd_ranges(a, x, y, c, s, crowd))
    best = _polygon_ranges(tables, scene, x, y, c, s, float(max_range), best)
    return a.xp.where(present[..., None], best, a.xp.full_like(best, float(max_range)))


def _cast_compiled(
    cast_worlds: Any, tables: ScanTables, scene: Any, x: Any, y: Any, yaw: Any, angles: Any, present: Any,
    radius: Any, max_range: float, crowd: Any = None,
) -> Any:
    """:func:`cast_batch`'s compiled path (the kernel ``cast_worlds``), on numpy arrays or
    torch CPU tensors."""
    a = tables.arrays
    # torch CPU tensors are read through numpy views of their memory (no copies).
    view = (lambda v: v.numpy()) if a.is_torch else (lambda v: v)
    x, y, yaw, angles = view(x), view(y), view(yaw), view(angles)
    w, r = x.shape
    if crowd is None:
        qx = qy = qr = np.zeros((w, 0))
        qn = np.zeros(w, np.int64)
    else:  # (the engine's crowds are numpy)
        qx, qy, qr = (np.ascontiguousarray(v, dtype=np.float64) for v in crowd[:3])
        qn = np.ascontiguousarray(crowd[3], dtype=np.int64)
    out = np.empty((w, r, angles.shape[0]))
    cast_worlds(
        np.ascontiguousarray(view(scene), dtype=np.int64), np.ascontiguousarray(x, dtype=np.float64),
        np.ascontiguousarray(y, dtype=np.float64), np.cos(yaw), np.sin(yaw), np.cos(angles), np.sin(angles),
        np.ascontiguousarray(view(present), dtype=np.bool_), np.ascontiguousarray(view(radius), dtype=np.float64),
        max_range,
        tables.meta, tables.lookup, tables.clearance, tables.open_radius, tables.edges, qx, qy, qr, qn, out,
    )
    _zero_inside(tables, view(scene), x, y, view(present), out)
    return a.asarray(out) if a.is_torch else out


def _polygon_ranges(tables: ScanTables, scene: Any, x: Any, y: Any, c: Any, s: Any, max_range: float, best: Any) -> Any:
    """``best`` (W, R, n) lowered to each ray's first obstacle-polygon edge, by the single
    scan's own definition (``raycast.polygon_hits``, on the host: it culls edges per
    origin); an origin inside a polygon reads 0."""
    if not tables.polygon_scenes:
        return best
    a = tables.arrays
    host = a.numpy if a.is_torch else np.asarray
    scene_h = host(scene)
    x_h, y_h, c_h, s_h = host(x), host(y), host(c), host(s)
    n = c_h.shape[2]
    for k in tables.polygon_scenes:
        worlds = np.flatnonzero(scene_h == k)
        if not len(worlds):
            continue
        p = np.stack([x_h[worlds].ravel(), y_h[worlds].ravel()], axis=1)
        hits = polygon_hits(tables.geometries[k], p, c_h[worlds].reshape(-1, n), s_h[worlds].reshape(-1, n), max_range)
        w = a.asarray(worlds, a.i64) if a.is_torch else worlds
        best[w] = a.xp.minimum(best[w], a.asarray(hits.reshape(len(worlds), -1, n)))
    return best


def _zero_inside(tables: ScanTables, scene: Any, x: Any, y: Any, present: Any, out: Any) -> None:
    """Set to 0 the rays (numpy ``out`` (W, R, n)) of present robots inside (or on) an
    obstacle polygon (``raycast.inside_polygon``, as the single compiled scan does)."""
    for k in tables.polygon_scenes:
        worlds = np.flatnonzero(np.asarray(scene) == k)
        if not len(worlds):
            continue
        p = np.stack([np.asarray(x)[worlds].ravel(), np.asarray(y)[worlds].ravel()], axis=1)
        inside = inside_polygon(tables.geometries[k], p)
        w, r = np.divmod(inside, x.shape[1])
        keep = np.asarray(present)[worlds[w], r]
        out[worlds[w[keep]], r[keep]] = 0.0


def _grid_ranges(tables: ScanTables, scene: Any, x: Any, y: Any, c: Any, s: Any, max_range: float) -> Any:
    """Range (m) to the first blocked cell along each ray, at most ``max_range``."""
    a, xp = tables.arrays, tables.arrays.xp
    sc = scene[:, None]  # (W, 1): broadcasts over robots
    inv = 1.0 / tables.m_res[sc]
    hp, wp, off = tables.m_hp[sc], tables.m_wp[sc], tables.m_off[sc]
    gx = (x - tables.m_ox[sc]) * inv + 1.0
    gy = (y - tables.m_oy[sc]) * inv + 1.0
    e = TOUCH_EPS * inv
    reach = max_range * inv
    plane = hp * wp
    lookup = tables.lookup_x
    # The crossings the finest floor can need (raycast._grid_hits' n_cross), in blocks.
    n_cross = min(math.ceil(max_range / tables.min_res) + 1, tables.max_side + 1)
    ks = a.asarray(np.arange(BLOCK, dtype=np.float64))
    best = None
    unit = xp.ones_like(hp)
    # x-crossings (vertical lines): along x, across y, the row hi is looked up (plane 1
    # ORs the row below); y-crossings: along y, across x (plane 2 ORs the column left).
    for g_along, g_across, d_along, d_across, across_max, along_max, plane_of, hi_stride, ent_stride in (
        (gx, gy, c, s, hp - 1.0, wp - 1.0, plane, wp, unit),
        (gy, gx, s, c, wp - 1.0, hp - 1.0, 2.0 * plane, unit, wp),
    ):
        ga, gc = g_along[..., None], g_across[..., None]
        pos = d_along >= 0.0
        one = xp.ones_like(d_along)  # torch.where of two numbers would give float32
        sgn = xp.where(pos, one, -one)
        base = xp.where(pos, xp.floor(ga) + 1.0, xp.ceil(ga) - 1.0)
        dt = 1.0 / xp.abs(d_along).clip(_TINY, None)
        t0 = (base - ga) * sgn * dt
        a0 = gc + t0 * d_across
        step = dt * d_across
        ent0 = base - xp.where(pos, 0.0 * one, one)
        ee = e[..., None, None]
        amax, lmax = across_max[..., None, None], along_max[..., None, None]
        pl, hs, es = plane_of[..., None, None], hi_stride[..., None, None], ent_stride[..., None, None]
        base_idx = off[..., None, None]
        first = xp.full_like(t0, math.inf)
        for k0 in range(0, n_cross, BLOCK):
            k = ks + float(k0)  # (BLOCK,)
            k = k[: min(BLOCK, n_cross - k0)]
            across = a0[..., None] + step[..., None] * k
            hi = xp.floor(across + ee)
            grazing = xp.floor(across - ee) < hi
            hi = xp.minimum(hi.clip(0.0, None), amax)
            entered = xp.minimum((ent0[..., None] + sgn[..., None] * k).clip(0.0, None), lmax)
            idx = xp.where(grazing, pl, 0.0) + hi * hs + entered * es
            hit = lookup[a.to_int(idx) + base_idx]
            t = t0[..., None] + k * dt[..., None]
            # Crossings come in order along the ray: the nearest blocked one is the first.
            tk = _min_last(xp, xp.where(hit, t, math.inf))
            first = xp.where(xp.isinf(first), tk, first)
        best = first if best is None else xp.minimum(best, first)
    best = xp.where(best <= reach[..., None], best, math.inf)
    best = (best * tables.m_res[sc][..., None]).clip(None, max_range)
    # An origin touching a blocked cell (or off the map) reads 0.
    flat = lookup
    col0 = xp.minimum(xp.floor(gx - e).clip(0.0, None), wp - 1.0)
    col1 = xp.minimum(xp.floor(gx + e).clip(0.0, None), wp - 1.0)
    row0 = xp.minimum(xp.floor(gy - e).clip(0.0, None), hp - 1.0) * wp
    row1 = xp.minimum(xp.floor(gy + e).clip(0.0, None), hp - 1.0) * wp
    touching = xp.zeros_like(gx) > 1.0
    for rr in (row0, row1):
        for cc in (col0, col1):
            touching = touching | flat[a.to_int(rr + cc) + off]
    return xp.where(touching[..., None], xp.zeros_like(best), best)


def _disc_ranges(a: Arrays, x: Any, y: Any, c: Any, s: Any, present: Any, radius: Any) -> Any:
    """Range (m) to the first other present robot's disc of the same world (inf: none);
    ``radius`` (W, R) each robot's disc (m)."""
    xp = a.xp
    r = x.shape[1]
    if r == 1:
        return xp.full_like(c, math.inf)
    t = _ray_discs(xp, x, y, c, s, x, y, radius)
    other = a.asarray(~np.eye(r, dtype=bool), a.boolean)
    seen = (other[None] & present[:, None, :])[:, :, None, :]
    return _min_last(xp, xp.where(seen, t, math.inf))


def _ray_discs(xp: Any, x: Any, y: Any, c: Any, s: Any, dx: Any, dy: Any, dr: Any) -> Any:
    """``(W, R, n, M)``: how far (m) robot ``i``'s ray ``k`` runs to disc ``m`` of its world
    (centres ``dx``, ``dy`` and radii ``dr``, ``(W, M)``); inf where it misses, 0 from inside."""
    fx = (x[:, :, None] - dx[:, None, :])[:, :, None, :]
    fy = (y[:, :, None] - dy[:, None, :])[:, :, None, :]
    b = fx * c[..., None] + fy * s[..., None]
    cc = fx * fx + fy * fy - (dr * dr)[:, None, None, :]
    disc = b * b - cc
    # The nearer root, written without cancellation (raycast._disc_hits).
    denom = xp.sqrt(disc.clip(0.0, None)) - b
    t = xp.where(denom > 0.0, cc / xp.where(denom > 0.0, denom, 1.0), math.inf)
    hit = (disc >= 0.0) & (b <= 0.0)
    return xp.where(cc <= 0.0, 0.0, xp.where(hit, t, math.inf))


def _crowd_ranges(a: Arrays, x: Any, y: Any, c: Any, s: Any, crowd: Any) -> Any:
    """Range (m) to the first of each world's ``crowd`` discs ``(qx, qy, qr, qn)`` (inf: none)."""
    xp = a.xp
    qx, qy, qr, qn = crowd
    if not qx.shape[1]:
        return xp.full_like(c, math.inf)
    t = _ray_discs(xp, x, y, c, s, qx, qy, qr)
    seen = (a.asarray(np.arange(qx.shape[1])) < qn[:, None])[:, None, None, :]
    return _min_last(xp, xp.where(seen, t, math.inf))


def _min_last(xp: Any, v: Any) -> Any:
    """Minimum over the last axis, for numpy and torch alike."""
    if xp is np:
        return v.min(axis=-1)
    return xp.amin(v, dim=-1)


class VectorScan:
    """A :class:`~pointnav_core.sensors.RangeScan` for a batch of worlds.

    Applies the single scan's reading rules (its module docstring) to :func:`cast_batch`'s
    ranges: a return nearer than ``min_range`` reads ``max_range``; then, if configured,
    Gaussian noise on the readings below ``max_range`` (clipped to ``[0, max_range]``)
    and dropout. Noise and dropout are the single scan's counter-based draws
    (:mod:`pointnav_core.sensors.noise`), computed with numpy on the host and moved to the
    arrays' device: world ``w`` of an engine seeded with ``s`` (:meth:`seed`) keys its
    episodes with base ``s + w`` and counts them from 0 (:meth:`begin`), and robot ``r``'s
    ray ``i`` at step ``k`` of the episode reads what a single env reset with seed
    ``s + w`` (and reset again after each episode) reads for robot ``r``, ray ``i``, step
    ``k``. Nothing is drawn from a generator.

    Parameters
    ----------
    term : RangeScan
        The configuration (rays, ranges, noise).
    tables : ScanTables
        The floors.
    method : {"auto", "array", "numba"}
        The path of :func:`cast_batch`.
    """

    def __init__(self, term: RangeScan, tables: ScanTables, method: str = "auto") -> None:
        if not isinstance(term, RangeScan):
            raise ArgumentError(f"term must be a RangeScan, got {term!r}")
        check_method(method)  # refused now, not at the first reading
        self.term = term
        self.tables = tables
        self.method = method
        a = tables.arrays
        self.angles = a.asarray(np.array(term.angles))
        self.noisy = term.noise_std > 0.0 or term.dropout > 0.0
        self._base = 0  # the seeding's entropy (mod 2**64); world w's base is this + w
        self._episodes: np.ndarray = np.zeros(0, np.int64)  # per world: episodes begun since
        self._keys: np.ndarray = np.zeros(0, np.uint64)  # per world: its episode's key

    def seed(self, rng: np.random.Generator) -> None:
        """Key the noise by the entropy of ``rng``'s seed sequence (``reset(seed=s)`` gives
        ``s``); the worlds' episodes count from 0 again. ``rng``'s stream is not drawn from
        (a generator without a seed sequence gives one draw)."""
        self._base = seed_entropy(rng)[1]
        self._episodes = np.zeros(0, np.int64)

    def begin(self, worlds: Any, num_envs: int) -> None:
        """Worlds ``worlds`` (a bool mask ``(num_envs,)``, numpy or on the device) begin an
        episode: the next in their count since :meth:`seed`."""
        if not self.noisy:
            return
        if self._episodes.shape[0] != num_envs:
            self._episodes = np.full(num_envs, -1, np.int64)
            self._keys = np.zeros(num_envs, np.uint64)
        a = self.tables.arrays
        mask = np.asarray(a.numpy(worlds) if a.is_torch else worlds, dtype=bool)
        self._episodes[mask] += 1
        w = np.nonzero(mask)[0]
        self._keys[w] = episode_key(_world_base(self._base, w), self._episodes[w])

    def readings(self, scene: Any, x: Any, y: Any, yaw: Any, present: Any, radius: Any, steps: Any = None,
                 crowd: Any = None) -> Any:
        """The scan's readings (m), ``(W, R, n_rays)`` float64 on the arrays' device;
        ``radius`` and ``crowd`` as for :func:`cast_batch`; ``steps`` ``(W, R)`` each robot's step within
        its world's episode (0 at reset), needed with noise or dropout (after :meth:`begin`)."""
        t, a = self.term, self.tables.arrays
        xp = a.xp
        d = cast_batch(self.tables, scene, x, y, yaw, present, radius, self.angles, t.max_range, self.method, crowd)
        top = t.max_range
        if t.min_range > 0.0:
            d = xp.where(d < t.min_range, top, d)
        if not self.noisy:
            return d
        w, r = d.shape[0], d.shape[1]
        if steps is None or self._keys.shape[0] != w:
            raise ArgumentError(f"steps: noise needs each robot's step (W, R) after begin() for all {w} worlds")
        k = np.asarray(a.numpy(steps) if a.is_torch else steps, dtype=np.int64).reshape(w, r, 1)
        noise, lost = scan_noise(self._keys[:, None, None], np.arange(r)[None, :, None], k, d.shape[2],
                                 t.noise_std, t.dropout)
        if noise is not None:
            d = xp.where(d < top, d + a.asarray(noise), d)
            d = d.clip(0.0, top)
        if lost is not None:
            d = xp.where(a.asarray(lost, a.boolean), top, d)
        return d


def _world_base(base: int, worlds: Any) -> np.ndarray:
    """World ``worlds``' base entropy: ``base + w`` modulo 2**64 (gymnasium's sub-env seeds)."""
    with np.errstate(over="ignore"):
        return np.uint64(base) + np.asarray(worlds, dtype=np.uint64)
