"""The compiled path of :func:`pointnav_core.vector.scan.cast_batch` (imports numba).

Imported only when the compiled path runs, so the package imports without numba. One loop
over worlds, robots and rays, inside the kernel; each ray is the single env's
crossing walk (:func:`walk`: the crossing test of ``sensors._raycast_kernel.grid_range``
with cheaper jumps over the free squares ahead) on its world's grid, then
the discs of the world's other present robots, with the same expressions as the array
path.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from pointnav_core.sensors.raycast import TOUCH_EPS

__all__ = ["cast_worlds", "walk"]

_INF = math.inf
_TINY = 1e-300  # raycast._TINY
_jit = numba.njit(cache=True, nogil=True, error_model="numpy")


@_jit
def walk(gx, gy, dx, dy, hp, wp, look, clr, e, n_cross, reach):  # pragma: no cover
    # Nearest blocked crossing (cell units) of one ray, _INF past reach: the crossing
    # families and the crossing test of raycast._grid_hits (the same expressions, so the
    # same decisions), walked in order of t, with integer cells and the jumps over the free
    # squares ahead of sensors._raycast_kernel.grid_range (see there why they are safe).
    plane = hp * wp
    plane2 = 2 * plane
    posx = dx >= 0.0
    sx = 1.0 if posx else -1.0
    bx = math.floor(gx) + 1.0 if posx else math.ceil(gx) - 1.0
    adx = max(abs(dx), _TINY)
    dtx = 1.0 / adx
    t0x = (bx - gx) * sx * dtx
    a0x = gy + t0x * dy
    stx = dtx * dy
    enx = bx - (0.0 if posx else 1.0)
    posy = dy >= 0.0
    sy = 1.0 if posy else -1.0
    by = math.floor(gy) + 1.0 if posy else math.ceil(gy) - 1.0
    ady = max(abs(dy), _TINY)
    dty = 1.0 / ady
    t0y = (by - gy) * sy * dty
    a0y = gx + t0y * dx
    sty = dty * dx
    eny = by - (0.0 if posy else 1.0)
    isx = 1 if posx else -1
    isy = 1 if posy else -1
    enx_i = int(enx)
    eny_i = int(eny)
    col0 = enx_i - isx  # the ray's cell while kx, ky are its next crossings
    row0 = eny_i - isy
    quad = (0 if posx else 1) + (0 if posy else 2)
    margin = 1e-6 + 2.0 * e
    kx = 0
    ky = 0
    while True:
        col = col0 + isx * kx
        row = row0 + isy * ky
        if 0 <= col < wp and 0 <= row < hp:
            side = clr[(row * wp + col) * 4 + quad]
            if side >= 3:  # far sides: crossings kx + side - 2 and ky + side - 2
                farx = t0x + float(kx + side - 2) * dtx
                fary = t0y + float(ky + side - 2) * dty
                # The nearer far side's family goes to it (its crossing before is a whole
                # cell earlier, far beyond the margin); the other to its first crossing
                # after the margin.
                if farx <= fary:
                    kx += side - 2
                    target = farx - margin
                    if t0y < target:
                        ky = max(ky, math.ceil((target - t0y) * ady))
                else:
                    ky += side - 2
                    target = fary - margin
                    if t0x < target:
                        kx = max(kx, math.ceil((target - t0x) * adx))
        fkx = float(kx)
        fky = float(ky)
        tx = t0x + fkx * dtx if kx < n_cross else _INF
        ty = t0y + fky * dty if ky < n_cross else _INF
        if tx <= ty:
            if tx > reach:  # t grows along the walk: nothing nearer is left
                return _INF
            across = a0x + stx * fkx
            hi = math.floor(across + e)
            graze = across - e < hi  # floor(across - e) < hi, as hi is whole
            hi = min(max(hi, 0), hp - 1)
            ent = min(max(enx_i + isx * kx, 0), wp - 1)
            if look[plane * int(graze) + hi * wp + ent]:
                return tx
            kx += 1
        else:
            if ty > reach:
                return _INF
            across = a0y + sty * fky
            hi = math.floor(across + e)
            graze = across - e < hi
            hi = min(max(hi, 0), wp - 1)
            ent = min(max(eny_i + isy * ky, 0), hp - 1)
            if look[plane2 * int(graze) + hi + ent * wp]:
                return ty
            ky += 1


@_jit
def cast_worlds(scene, x, y, cyaw, syaw, ca, sa, present, radius, max_range, meta, lookup, clear, out):  # pragma: no cover
    n_worlds, n_robots = x.shape
    n_rays = ca.shape[0]
    r2 = radius * radius
    c = np.empty(n_rays)
    s = np.empty(n_rays)
    near = np.empty(n_robots, np.int64)
    # Farther than this (m^2, with a margin for rounding) a disc is out of every ray's reach.
    reach2 = ((max_range + radius) * (1.0 + 1e-9) + 1e-12) ** 2
    for w in range(n_worlds):
        k = scene[w]
        loff = int(meta[k, 0])
        coff = int(meta[k, 1])
        hp = int(meta[k, 2])
        wp = int(meta[k, 3])
        res = meta[k, 4]
        ox = meta[k, 5]
        oy = meta[k, 6]
        inv = 1.0 / res
        e = TOUCH_EPS * inv
        reach = max_range * inv
        n_cross = min(math.ceil(reach) + 1, max(hp, wp) + 1)
        plane = hp * wp
        look = lookup[loff : loff + 3 * plane]
        clr = clear[coff : coff + 4 * plane]  # four quadrants a cell
        for i in range(n_robots):
            if not present[w, i]:
                out[w, i, :] = max_range
                continue
            px = x[w, i]
            py = y[w, i]
            gx = (px - ox) * inv + 1.0
            gy = (py - oy) * inv + 1.0
            # An origin touching a blocked cell (or off the map) reads 0.
            c0 = int(min(max(math.floor(gx - e), 0.0), wp - 1.0))
            c1 = int(min(max(math.floor(gx + e), 0.0), wp - 1.0))
            q0 = int(min(max(math.floor(gy - e), 0.0), hp - 1.0)) * wp
            q1 = int(min(max(math.floor(gy + e), 0.0), hp - 1.0)) * wp
            if look[q0 + c0] or look[q0 + c1] or look[q1 + c0] or look[q1 + c1]:
                out[w, i, :] = 0.0
                continue
            for r in range(n_rays):  # the products of scan.directions, in its order
                c[r] = cyaw[w, i] * ca[r] - syaw[w, i] * sa[r]
                s[r] = syaw[w, i] * ca[r] + cyaw[w, i] * sa[r]
            # The discs a ray can reach: present, not its own, centre within max_range + radius.
            n_near = 0
            for m in range(n_robots):
                if m != i and present[w, m]:
                    fx = px - x[w, m]
                    fy = py - y[w, m]
                    if fx * fx + fy * fy <= reach2:
                        near[n_near] = m
                        n_near += 1
            for r in range(n_rays):
                dx = c[r]
                dy = s[r]
                best = min(walk(gx, gy, dx, dy, hp, wp, look, clr, e, n_cross, reach) * res, max_range)
                for j in range(n_near):
                    m = near[j]
                    fx = px - x[w, m]
                    fy = py - y[w, m]
                    b = fx * dx + fy * dy
                    cc = fx * fx + fy * fy - r2
                    if cc <= 0.0:
                        t = 0.0
                    else:
                        disc = b * b - cc
                        if disc >= 0.0 and b <= 0.0:
                            denom = math.sqrt(max(disc, 0.0)) - b
                            t = cc / denom if denom > 0.0 else _INF
                        else:
                            t = _INF
                    best = min(best, t)
                out[w, i, r] = best
