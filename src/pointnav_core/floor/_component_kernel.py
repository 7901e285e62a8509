"""The compiled path of :meth:`pointnav_core.floor.maps.TraversableMap.component_at` for one
point off the cell centres (imports numba).

Imported only through :func:`pointnav_core.utils.compiled.kernel`, so the package imports
without numba. A pedestrian's new goal (``Scene.get_random_point`` with its position as the
reference) asks this once per plan; the general path spends about 0.1 ms of numpy on its 25
candidate cells. The same expressions in the same order: the disc's own test, the candidate
cells of the 5 x 5 block around the point's cell (row by row) that carry a label, taken
nearest first (ties in that order: a stable sort), the first whose centre the disc reaches
along a clear segment.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from pointnav_core.floor._collision_kernel import segment_hits

__all__ = ["point_component"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")


@_jit
def point_component(x, y, labels, ox, oy, res, gox, goy, inv, rho, rowcum, outside, reach, boxes, first, last, ex0,
                    ey0, ex1, ey1, use_polygons):  # pragma: no cover
    """The component label (0: none) of the finite point ``(x, y)`` (m), on a map of origin
    ``(ox, oy)`` and cell size ``res`` (m) whose cells carry ``labels`` ``(h, w)``; the rest
    are :func:`segment_hits`' arguments after the segment (the collision geometry's)."""
    if segment_hits(x, y, x, y, gox, goy, inv, rho, rowcum, outside, reach, boxes, first, last, ex0, ey0, ex1, ey1,
                    use_polygons):
        return 0
    h, w = labels.shape
    row = math.floor((y - oy) / res)
    col = math.floor((x - ox) / res)
    cx = np.empty(25)
    cy = np.empty(25)
    d = np.empty(25)
    lab = np.empty(25, np.int64)
    n = 0
    for r in range(row - 2, row + 3):
        for c in range(col - 2, col + 3):
            if 0 <= r < h and 0 <= c < w and labels[r, c] > 0:
                cx[n] = ox + (c + 0.5) * res
                cy[n] = oy + (r + 0.5) * res
                d[n] = np.hypot(cx[n] - x, cy[n] - y)
                lab[n] = labels[r, c]
                n += 1
    used = np.zeros(n, np.bool_)
    for _ in range(n):
        best = -1
        for j in range(n):  # the nearest left, the first of equals (a stable sort's order)
            if not used[j] and (best < 0 or d[j] < d[best]):
                best = j
        used[best] = True
        if not segment_hits(x, y, cx[best], cy[best], gox, goy, inv, rho, rowcum, outside, reach, boxes, first, last,
                            ex0, ey0, ex1, ey1, use_polygons):
            return lab[best]
    return 0
