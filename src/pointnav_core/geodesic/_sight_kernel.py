"""The compiled paths of :mod:`pointnav_core.geodesic.sight` and ``edges`` (imports numba).

Imported only through :func:`pointnav_core.utils.compiled.kernel` when numba is installed (the
``fast`` extra), so the package imports without it. :func:`sight_rays` is
:func:`pointnav_core.geodesic.sight.sight_rays` itself, compiled; the plain helpers it calls
are registered with numba (``register_jitable``), so that its calls to them compile to
theirs. :func:`misses_full` is
``edges._misses_full``'s: each segment's samples, at the numpy path's positions, stop at the
first that lies in a fully blocked cell.
"""

from __future__ import annotations

import math

import numba
from numba.extending import register_jitable

from pointnav_core.geodesic import sight

__all__ = ["misses_full", "sight_rays"]

for _helper in (sight.march_ray, sight.mark_profile, sight.no_bound):
    register_jitable(cache=True, nogil=True, error_model="numpy")(_helper)
sight_rays = numba.njit(cache=True, nogil=True, error_model="numpy")(sight.sight_rays)


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
