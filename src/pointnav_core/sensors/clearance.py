"""Free squares ahead of a cell, per quadrant: the jump table of the compiled scan walks.

A ray heading into a quadrant (the signs of its direction's x and y) moves away from the
cell it is in towards growing (or shrinking) columns and rows. If the ``K x K`` square of
cells whose corner is the cell diagonally *behind* the ray's cell, and which extends in the
ray's quadrant, is free, the ray stays inside that square until it crosses its far sides,
at least one cell away from its near sides; no crossing inside it can meet a blocked cell.
The compiled walks (``sensors._raycast_kernel.grid_range`` and ``vector._scan_kernel.walk``)
jump over those crossings. A square anchored behind the ray reaches about twice as far
ahead as a square centred on its cell (the chessboard clearance), for the same cells.

:func:`open_radius` is the per-cell bound of the batched scan's early exit: a robot whose
cell is farther than its scan's range from every blocked cell reads the range on every ray
without walking any (``vector._scan_kernel.cast_worlds``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError

__all__ = ["QUADRANTS", "open_radius", "quadrant_clearance"]

#: The quadrants' (sign of x, sign of y), in the table's order: index
#: ``(0 if dx >= 0 else 1) + (0 if dy >= 0 else 2)``.
QUADRANTS: tuple[tuple[int, int], ...] = ((1, 1), (-1, 1), (1, -1), (-1, -1))
# A side is stored in one byte; a smaller side than the true one is still free (a shorter
# jump), so clipping is safe.
_MAX_SIDE = 255


def quadrant_clearance(free: ArrayLike) -> NDArray[np.uint8]:
    """Side of the largest free square ahead of each cell, per quadrant.

    Parameters
    ----------
    free : array_like of bool, shape (rows, cols)
        True where a cell is free; row index grows with y, column index with x. Cells off
        the array count as blocked.

    Returns
    -------
    numpy.ndarray of uint8, shape (rows * cols * 4,)
        Flat, ``[(row * cols + col) * 4 + q]`` for quadrant ``q`` of :data:`QUADRANTS`
        with signs ``(sx, sy)``: the largest ``K`` (cells, at most 255) such that every cell
        ``(row - sy + sy * i, col - sx + sx * j)`` with ``0 <= i, j < K`` is on the array
        and free; 0 when the cell diagonally behind is blocked or off the array.

    Examples
    --------
    >>> t = quadrant_clearance(np.ones((3, 3), bool)).reshape(3, 3, 4)
    >>> int(t[1, 1, 0]), int(t[1, 1, 3]), int(t[0, 0, 0])
    (3, 3, 0)
    """
    free = np.asarray(free, dtype=bool)
    if free.ndim != 2:
        raise ArgumentError(f"free must be a 2-D array, got shape {free.shape}")
    hp, wp = free.shape
    out = np.zeros((hp, wp, 4), np.int64)
    for q, (sx, sy) in enumerate(QUADRANTS):
        # Flip so that the quadrant grows both indices, then the classic largest-square
        # recurrence: side(i, j) = min(run right, run up, 1 + side(i + 1, j + 1)).
        g = free[::sy, ::sx]
        right = np.zeros((hp, wp + 1), np.int64)
        for j in range(wp - 1, -1, -1):
            right[:, j] = g[:, j] * (1 + right[:, j + 1])
        up = np.zeros((hp + 1, wp), np.int64)
        for i in range(hp - 1, -1, -1):
            up[i] = g[i] * (1 + up[i + 1])
        side = np.zeros((hp + 1, wp + 1), np.int64)
        for i in range(hp - 1, -1, -1):
            side[i, :wp] = np.minimum(np.minimum(right[i, :wp], up[i]), 1 + side[i + 1, 1:])
        side = side[:hp, :wp][::sy, ::sx]
        # Stored at the cell diagonally ahead of the square's corner: (row, col) reads the
        # square anchored at (row - sy, col - sx).
        r0, r1 = (1, hp) if sy > 0 else (0, hp - 1)
        c0, c1 = (1, wp) if sx > 0 else (0, wp - 1)
        out[r0:r1, c0:c1, q] = side[r0 - sy : r1 - sy, c0 - sx : c1 - sx]
    return np.ascontiguousarray(np.minimum(out, _MAX_SIDE).astype(np.uint8).ravel())


def open_radius(free: ArrayLike) -> NDArray[np.float64]:
    """Per cell, a lower bound (cells) on the distance from any point of it to any blocked cell.

    Parameters
    ----------
    free : array_like of bool, shape (H, W)
        The free cells (the scan's padded grid: its ring of blocked cells included).

    Returns
    -------
    ndarray of float64, shape (H, W)
        The Euclidean distance between the cell's centre and the nearest blocked cell's
        centre, less the two half-diagonals (``sqrt(2)``), never below 0 (0 on a blocked cell).
        Points of two cells are within a half-diagonal of their centres, so no point of the
        cell is nearer a blocked cell than this.

    Examples
    --------
    >>> free = np.ones((1, 7), bool)
    >>> free[0, 0] = False
    >>> open_radius(free).round(3).tolist()
    [[0.0, 0.0, 0.586, 1.586, 2.586, 3.586, 4.586]]
    """
    from scipy.ndimage import distance_transform_edt

    free = np.asarray(free, dtype=bool)
    if free.ndim != 2:
        raise ArgumentError(f"free must be a 2-D grid of cells, got shape {free.shape}")
    if free.all():  # no blocked cell: nothing to be near
        return np.full(free.shape, np.inf)
    centres = distance_transform_edt(free)  # to the nearest False (blocked) centre
    return np.maximum(centres - np.sqrt(2.0), 0.0)
