"""The local map of a batch of worlds: ``(W, R, cells * cells)`` codes in one gather.

Every present robot reads the single env's :class:`~pointnav_core.sensors.LocalMap`: the
centres of a ``cells x cells`` grid of side ``size`` (m) turned by its heading, each
mapped to the floor cell under it (``floor`` of the centre over the cell size, the
backend's :meth:`~pointnav_core.vector.floors.FloorTables.cells`), whose code is looked up
in the floors' flat code array (off the map: VOID); then the discs of the other robots of
its world that are present (the scan's rule) are drawn over it as code 3, and its world's
pedestrians (the batched crowds, :mod:`pointnav_core.vector.crowd`) as code 4. The arithmetic
is the single term's, operation for operation, on the heading the single env's frame
derives from the planar quaternion, so the codes are equal; a cell centre that falls
within rounding of a cell edge or a disc's rim may read the neighbouring value where the
two sides round differently (``docs/decisions.md``, "The local map in the batched engine").

The same code runs on numpy and on torch on any device (:class:`~pointnav_core.vector.xp.Arrays`),
on a CPU in blocks of worlds of about :data:`CPU_BLOCK` cells, on a GPU in one call;
its temporaries are ``(W, R, cells * cells)`` arrays, and ``(W, R, R, k * k)`` for the
discs when there are several robots per world (``k`` cells around each other robot, about
``2 radius / cell size + 3`` for the largest radius; each disc has its robot's radius).

Examples
--------
A robot at (0.25, 0.25) m facing +x in a 0.8 x 0.5 m room with a wall from x = 0.5 m to
0.6 m; its 4 x 4 map of 0.8 m (0.2 m cells, centres 0.1 m and 0.3 m from it) reads the
wall in row 0 (0.3 m ahead), and off the map (VOID) beyond y = 0.5 m (column 0, on its
left), below y = 0 (column 3) and behind x = 0 (row 3):

>>> import numpy as np
>>> from pointnav_core.scenes import Scene
>>> from pointnav_core.sensors import LocalMap
>>> from pointnav_core.vector.floors import FloorTables
>>> from pointnav_core.vector.xp import make_arrays
>>> grid = np.zeros((5, 8), np.uint8)
>>> grid[:, 5] = 1
>>> floors = FloorTables([Scene.from_array(grid, 0.1)], 0, 0.05, make_arrays("numpy"))
>>> lm = VectorLocalMap(LocalMap(size=0.8, cells=4), floors)
>>> one = np.ones((1, 1))
>>> lm.values(np.zeros(1, np.int64), 0.25 * one, 0.25 * one, 0 * one, one > 0, 0.05).reshape(4, 4)
array([[2., 1., 1., 2.],
       [2., 0., 0., 2.],
       [2., 0., 0., 2.],
       [2., 2., 2., 2.]], dtype=float32)
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from pointnav_core.errors import ArgumentError
from pointnav_core.sensors.local_map import (
    _LUT,
    LOCAL_PEDESTRIAN,
    LOCAL_ROBOT,
    LOCAL_VOID,
    LocalMap,
)
from pointnav_core.vector.floors import FloorTables
from pointnav_core.vector.xp import as_dtype, cat

__all__ = ["CPU_BLOCK", "VectorLocalMap", "frame_heading", "local_map_term"]

_TWO_PI = 2.0 * math.pi
#: Map cells computed together on a CPU (worlds x robots x cells per side squared).
CPU_BLOCK = 65_536


def local_map_term(sensors: Mapping[str, Any] | None) -> LocalMap | None:
    """The :class:`~pointnav_core.sensors.LocalMap` ``sensors`` asks for, or None (the
    single envs' checks: a bad ``cells`` or ``size`` raises their ValueError)."""
    from pointnav_core.sensors import make_sensors

    return next((t for t in make_sensors(sensors) if isinstance(t, LocalMap)), None)


def frame_heading(xp: Any, yaw: Any) -> tuple[Any, Any]:
    """Cosine and sine of the heading as the single env's frame reads them.

    The backend reports the planar quaternion of ``remainder(yaw, 2 pi)``
    (``backend_kit.planar_quat_floats``); :meth:`~pointnav_core.task.observations.Frame.set_pose`
    takes the heading from its rotation matrix. These are the same operations on arrays.

    Parameters
    ----------
    xp : module
        numpy or torch.
    yaw : float64 array
        Headings (rad), any shape.

    Returns
    -------
    tuple of float64 arrays
        ``(cos, sin)``, the shape of ``yaw``.
    """
    half = 0.5 * (yaw - _TWO_PI * xp.round(yaw / _TWO_PI))
    qz, qw = xp.sin(half), xp.cos(half)
    scale = 2.0 / (qz * qz + qw * qw)
    r00 = 1.0 - scale * (qz * qz)
    r10 = scale * (qz * qw)
    h = xp.hypot(r00, r10)
    return r00 / h, r10 / h


class VectorLocalMap:
    """A :class:`~pointnav_core.sensors.LocalMap` for a batch of worlds.

    Parameters
    ----------
    term : LocalMap
        The configuration (``size``, ``cells``; its ``dtype`` only shapes the single env's
        ``Dict`` observation: the flat observation holds the codes as float32 either way).
    floors : FloorTables
        The worlds' floors, on the arrays' device.

    Raises
    ------
    ValueError
        Naming ``term`` if it is not a LocalMap.
    """

    def __init__(self, term: LocalMap, floors: FloorTables) -> None:
        if not isinstance(term, LocalMap):
            raise ArgumentError(f"term must be a LocalMap, got {term!r}")
        self.term = term
        self.floors = floors
        a = self.arrays = floors.arrays
        # The single term's cell centres in the robot frame (forward u, left v), row by row.
        self._u = a.asarray(term.u)
        self._v = a.asarray(term.v)
        # The floors' codes as local map codes, once (one gather per cell, not two).
        self._codes = a.asarray(_LUT[a.numpy(floors.codes)], a.i64)
        # Float copies of the grids' shapes, to index in float until one cast.
        self._rows, self._width = a.asarray(a.numpy(floors.rows)), a.asarray(a.numpy(floors.width))

    @property
    def size(self) -> int:
        """Values per robot in the flat observation, ``cells * cells``."""
        return self.term.size

    def values(self, scene: Any, x: Any, y: Any, yaw: Any, present: Any, radius: Any, crowd: Any = None) -> Any:
        """Every robot's local map, row by row, as float32 codes on the arrays' device.

        Parameters
        ----------
        scene : int array, shape (W,)
            Each world's scene (index into the floors).
        x, y, yaw : float64 arrays, shape (W, R)
            Robot centres (m) and headings (rad).
        present : bool array, shape (W, R)
            Robots drawn on the others' maps (an absent robot's own map is still computed;
            the env hides it).
        radius : float or float array broadcasting to (W, R)
            Robot radius (m), one for all or each robot's own: the discs drawn as code 3.
        crowd : (qx, qy, qr, qn), optional
            Each world's pedestrians (numpy, as :func:`~pointnav_core.vector.scan.cast_batch`
            takes them): centres and radii ``(W, Q)`` (m) and counts ``(W,)``, drawn as
            code 4 over everything else, as the single term draws them.

        Returns
        -------
        float32 array, shape (W, R, cells * cells)
            Codes 0 free, 1 blocked, 2 void or off the map, 3 another robot, 4 a pedestrian.
        """
        a, xp = self.arrays, self.arrays.xp
        w, n = x.shape
        radius = xp.zeros_like(x) + radius  # (W, R)
        block = max(1, CPU_BLOCK // (n * self.size))
        if crowd is not None:
            crowd = a.discs(crowd)
        if w <= block or a.on_gpu:
            return self._values(scene, x, y, yaw, present, radius, crowd)
        # On a CPU, blocks of worlds whose temporaries stay in cache (about twice as fast
        # at 1,024 x 4 robots with 32 x 32 maps as one call); a GPU takes the whole batch.
        parts = [self._values(scene[i : i + block], x[i : i + block], y[i : i + block], yaw[i : i + block],
                              present[i : i + block], radius[i : i + block],
                              None if crowd is None else tuple(v[i : i + block] for v in crowd))
                 for i in range(0, w, block)]
        return cat(xp, parts)

    def _values(self, scene: Any, x: Any, y: Any, yaw: Any, present: Any, radius: Any, crowd: Any) -> Any:
        """:meth:`values` of one block of worlds."""
        a, xp, fl = self.arrays, self.arrays.xp, self.floors
        c0, s0 = frame_heading(xp, yaw)
        c, s = c0[..., None], s0[..., None]
        wx = x[..., None] + c * self._u - s * self._v
        wy = y[..., None] + s * self._u + c * self._v
        # FloorTables.cells and flat_index (the backend's cell of a point), kept in float
        # until one cast: the same floors, fewer full-size temporaries.
        sc = scene[:, None, None]
        inv = fl.inv_res[sc]
        col = xp.floor((wx - fl.ox[sc]) * inv)
        row = xp.floor((wy - fl.oy[sc]) * inv)
        width = self._width[sc]
        inside = (col >= 0.0) & (col < width) & (row >= 0.0) & (row < self._rows[sc])
        flat = a.to_int(xp.where(inside, row * width + col, 0.0)) + fl.offset[sc]
        code = self._codes[flat]
        out = xp.where(inside, code, xp.full_like(code, LOCAL_VOID))
        if x.shape[1] > 1:
            other = a.asarray(~np.eye(x.shape[1], dtype=bool), a.boolean)
            out = self._draw_discs(out, x, y, c0, s0, x, y, radius, other[None] & present[:, None, :], LOCAL_ROBOT)
        if crowd is not None and crowd[0].shape[1]:
            qx, qy, qr, qn = crowd
            walkers = a.asarray(np.arange(qx.shape[1]))[None] < qn[:, None]  # (W, Q)
            seen = walkers[:, None, :] & (xp.ones_like(x) > 0.0)[:, :, None]
            out = self._draw_discs(out, x, y, c0, s0, qx, qy, qr, seen, LOCAL_PEDESTRIAN)
        return as_dtype(xp, out, xp.float32)

    def _draw_discs(self, out: Any, x: Any, y: Any, c: Any, s: Any, ox: Any, oy: Any, dr: Any, seen: Any,
                    code: int) -> Any:
        """``out`` with ``code`` where a disc covers a cell centre: disc ``m`` of each world
        (centres ``ox``, ``oy`` and radii ``dr``, ``(W, M)``, m) on robot ``i``'s map where
        ``seen`` ``(W, R, M)``.

        Only a window of ``k x k`` cells around each disc (where it can reach) is tested,
        with the full map's expressions for the centres, so the test is the single term's
        on the same numbers.
        """
        a, xp, term = self.arrays, self.arrays.xp, self.term
        w, n = x.shape
        m_n = ox.shape[1]
        cells, cs = term.cells, term.cell_size
        # The disc spans at most floor(2 r / cs) + 1 rows; one more each side for rounding.
        # One window size for all, from the largest disc.
        k = min(math.ceil(2.0 * float(dr.max()) / cs) + 3, cells)
        rm = dr[:, None, :]  # (W, 1, M): disc m's radius
        dx = ox[:, None, :] - x[:, :, None]  # (W, R, M): disc m relative to robot i
        dy = oy[:, None, :] - y[:, :, None]
        c, s = c[..., None], s[..., None]
        fwd, left = c * dx + s * dy, c * dy - s * dx
        # Fractional row and column of robot m in robot i's map (row i's centre: u_i).
        half = cells / 2.0 - 0.5
        r0 = (xp.floor(half - fwd / cs - rm / cs) - 1.0).clip(0.0, float(cells - k))
        c0 = (xp.floor(half - left / cs - rm / cs) - 1.0).clip(0.0, float(cells - k))
        ks = a.asarray(np.arange(k, dtype=np.float64))
        cell = a.to_int((r0[..., None, None] + ks[:, None]) * cells + (c0[..., None, None] + ks[None, :]))
        cell = cell.reshape(w, n, m_n, k * k)
        u, v = self._u[cell], self._v[cell]
        cx, cy = c[..., None], s[..., None]
        wx = x[:, :, None, None] + cx * u - cy * v  # the centres of values(), operation for operation
        wy = y[:, :, None, None] + cy * u + cx * v
        ex = wx - ox[:, None, :, None]
        ey = wy - oy[:, None, :, None]
        hit = (ex * ex + ey * ey <= (rm * rm)[..., None]) & seen[..., None]
        base = a.asarray(np.arange(w * n, dtype=np.int64).reshape(w, n, 1, 1) * (cells * cells), a.i64)
        flat = out.reshape(-1)
        # Every write is the one code, so windows overlapping on a cell need no reduction.
        flat[(base + cell)[hit]] = code
        return flat.reshape(out.shape)
