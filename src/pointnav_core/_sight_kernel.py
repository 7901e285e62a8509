"""The compiled paths of :mod:`pointnav_core.tangent_edges` (imports numba).

Imported only by ``tangent_edges`` when numba is installed (the ``fast`` extra), so the
package imports without it. :func:`march` is ``sight_radii``'s: each ray marches on its
own, with the numpy path's expressions in the same order, so both paths give the same
bounds. :func:`misses_full` is ``_misses_full``'s: each segment's samples, at the numpy
path's positions, stop at the first that lies in a fully blocked cell.
"""

from __future__ import annotations

import math

import numba

__all__ = ["march", "misses_full"]

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


@numba.njit(cache=True, nogil=True, error_model="numpy")
def misses_full(ax, ay, bx, by, full, h, w, ox, oy, res, step, outside, out):  # pragma: no cover
    # Per segment s, whether none of its samples (n of them, evenly from a to b, at most
    # step cells apart) lies in a cell of the padded mask full (h x w, flat) or, where
    # outside is set, off it: out[s].
    cell = step * res
    for s in range(ax.shape[0]):
        dx = bx[s] - ax[s]
        dy = by[s] - ay[s]
        n = max(int(math.ceil(math.hypot(dx, dy) / cell)), 1) + 1
        ok = True
        for i in range(n):
            t = i / (n - 1)
            col = int(math.floor((ax[s] + t * dx - ox) / res)) + 1
            row = int(math.floor((ay[s] + t * dy - oy) / res)) + 1
            if col >= 0 and col < w and row >= 0 and row < h:
                bad = full[row * w + col]
            else:
                bad = outside
            if bad:
                ok = False
                break
        out[s] = ok
