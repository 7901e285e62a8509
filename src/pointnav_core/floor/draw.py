"""Usable cells near a point: uniform draws within reach (without a distance per cell), and
the nearest one."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pointnav_core.floor.maps import TraversableMap
from pointnav_core.utils import compiled as _compiled

__all__ = ["cell_centre", "draw_cell", "draw_point", "nearest_usable"]


def draw_cell(
    tmap: TraversableMap, radius: float, label: int, ref: NDArray[np.float64], max_distance: float | None,
    rng: np.random.Generator,
) -> int | None:
    """A uniformly drawn cell of one component, within reach of a point.

    The cells within reach are counted row by row, each row an interval of columns settled
    by the exact test at its two ends, then found by bisection in the component's sorted
    cells: a draw costs O(rows), not a distance per cell (compiled with numba:
    ``floor._draw_kernel``, the same spans). The one random number drawn, and so
    the cell, is the one that picks from the list of every cell within reach in row-major
    order.

    Parameters
    ----------
    tmap : TraversableMap
    radius : float
        Robot radius (m) whose components (:meth:`TraversableMap.components`) are drawn from.
    label : int
        The component.
    ref : ndarray, shape (2,)
        World point (m) the reach is measured from.
    max_distance : float or None
        Reach (m): only cells whose centre has ``np.hypot(centre - ref) <= max_distance``;
        None or inf for the whole component.
    rng : numpy.random.Generator
        Draws one integer.

    Returns
    -------
    int or None
        Flat row-major index of the cell drawn; None when no cell is within reach (nothing
        is drawn then).
    """
    flat, _ = tmap.component_cells(radius, label)
    if max_distance is None or not math.isfinite(max_distance):
        return int(flat[int(rng.integers(len(flat)))]) if len(flat) else None
    h, w = tmap.shape
    res, (ox, oy) = tmap.resolution, tmap.origin
    rx, ry = float(ref[0]), float(ref[1])
    # Rows whose centres may be within reach (one row of slack each way).
    first = max(0, math.floor((ry - max_distance - oy) / res - 0.5) - 1)
    rows = np.arange(first, max(first, min(h, math.ceil((ry + max_distance - oy) / res - 0.5) + 2)), dtype=np.int64)
    kernel = _compiled.kernel("pointnav_core.floor._draw_kernel", "row_spans")
    if kernel is not None:
        start, counts = np.empty(len(rows), np.int64), np.empty(len(rows), np.int64)
        kernel(flat, w, oy, ox, res, rx, ry, float(max_distance), rows, start, counts)
    else:
        start, counts = _row_spans(flat, w, oy, ox, res, rx, ry, float(max_distance), rows)
    total = int(counts.sum())
    if total == 0:
        return None
    k = int(rng.integers(total))
    ends = np.cumsum(counts)
    row = int(np.searchsorted(ends, k, side="right"))
    return int(flat[start[row] + k - (ends[row] - counts[row])])


def draw_point(
    tmap: TraversableMap, radius: float, label: int, ref: NDArray[np.float64], max_distance: float | None,
    rng: np.random.Generator,
) -> NDArray[np.float64] | None:
    """:func:`draw_cell`'s cell as its centre ``(x, y)`` (m), the point
    :meth:`Scene.get_random_point <pointnav_core.scenes.Scene.get_random_point>` returns;
    None when no cell is within reach (nothing is drawn then)."""
    index = draw_cell(tmap, radius, label, ref, max_distance, rng)
    return None if index is None else cell_centre(tmap, index)


def cell_centre(tmap: TraversableMap, index: int) -> NDArray[np.float64]:
    """Centre ``(x, y)`` (m) of the cell of flat (row-major) index ``index``."""
    return tmap.cell_to_world(np.array(np.unravel_index(index, tmap.shape)))


def _row_spans(
    flat: NDArray[np.intp], w: int, oy: float, ox: float, res: float, rx: float, ry: float, reach: float,
    rows: NDArray[np.int64],
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """For each of ``rows``: where its cells within ``reach`` (m) of ``(rx, ry)`` start in the
    sorted flat indices ``flat``, and how many there are (the compiled path is
    ``floor._draw_kernel.row_spans``, with these expressions)."""
    dy = (oy + (rows + 0.5) * res) - ry

    def reaches(col: NDArray[np.float64]) -> NDArray[np.bool_]:
        # The same centre and test as listing every cell: cell_to_world, then hypot.
        return np.hypot((ox + (col + 0.5) * res) - rx, dy) <= reach

    half = np.sqrt(np.maximum(reach * reach - dy * dy, 0.0))
    # Each row's interval of columns from the square root; rounding moves an end by at most
    # one column, which the exact test then settles.
    lo = np.ceil((rx - half - ox) / res - 0.5)
    hi = np.floor((rx + half - ox) / res - 0.5)
    before, first_in, last_in, after = reaches(np.stack([lo - 1, lo, hi, hi + 1]))
    lo = np.where(before, lo - 1, np.where(first_in, lo, lo + 1))
    hi = np.where(after, hi + 1, np.where(last_in, hi, hi - 1))
    lo, hi = np.maximum(lo, 0).astype(np.int64), np.minimum(hi, w - 1).astype(np.int64)
    start = np.searchsorted(flat, rows * w + lo)
    counts = np.where(lo <= hi, np.searchsorted(flat, rows * w + hi, side="right") - start, 0)
    return start, counts


def nearest_usable(tmap: TraversableMap, xy: NDArray[np.float64], radius: float, reach: int = 3) -> NDArray[np.float64] | None:
    """Centre (m) of the nearest cell within ``reach`` cells of ``xy`` whose centre a disc of
    ``radius`` m fits at; None if there is none."""
    usable = tmap.usable(radius)
    row, col = (int(v) for v in tmap.world_to_cell(xy))
    h, w = usable.shape
    r0, r1, c0, c1 = max(row - reach, 0), min(row + reach + 1, h), max(col - reach, 0), min(col + reach + 1, w)
    cells = np.argwhere(usable[r0:r1, c0:c1]) + (r0, c0)
    if not len(cells):
        return None
    centres = tmap.cell_to_world(cells)
    return centres[int(np.argmin(np.hypot(*(centres - xy).T)))]
