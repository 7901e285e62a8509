"""The compiled path of :func:`pointnav_core.tangent_edges.sight_radii` (imports numba).

Imported only by ``tangent_edges`` when numba is installed (the ``fast`` extra), so the
package imports without it. Each ray marches on its own, with the numpy path's
expressions in the same order, so both paths give the same bounds.
"""

from __future__ import annotations

import math

import numba

__all__ = ["march"]

_SQRT2 = math.sqrt(2.0)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def march(flat, h, w, gx0, gy0, ux, uy, start, limit, max_steps, out):  # pragma: no cover
    # Per point p (grid coordinates gx0[p], gy0[p]), the longest of its rays (ux, uy),
    # each advanced by what the distance field leaves free until it stops: out[p] in cells.
    for p in range(gx0.shape[0]):
        best = -math.inf
        for r in range(ux.shape[0]):
            t = 0.0
            for _ in range(max_steps):
                gx = gx0[p] + t * ux[r]
                gy = gy0[p] + t * uy[r]
                col = math.floor(gx)
                row = math.floor(gy)
                inside = col >= 0 and col < w and row >= 0 and row < h
                d = flat[row * w + col] if inside else 0.0
                if not inside or (d < 0.5 and t > start) or t > limit:
                    break
                t = t + max(d - _SQRT2, 0.25)
            best = max(best, t)
        out[p] = best
