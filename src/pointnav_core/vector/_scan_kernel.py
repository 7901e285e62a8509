"""The compiled path of :func:`pointnav_core.vector.scan.cast_batch` (imports numba).

Imported only when the compiled path runs, so the package imports without numba. One loop
over worlds, robots and rays, inside the kernel; each ray is the single env's crossing walk
(``sensors._raycast_kernel.grid_range``) on its world's grid, then the discs of the world's
other present robots and of its pedestrians, with the same expressions as the array path, then its floor's
obstacle-polygon edges by the single kernel's ``polygon_range``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from pointnav_core.sensors._raycast_kernel import disc_range, grid_range, polygon_range
from pointnav_core.sensors.raycast import TOUCH_EPS

__all__ = ["cast_worlds"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")


@_jit
def _near_discs(w, i, px, py, x, y, present, radius, qx, qy, qr, qn, max_range, near):  # pragma: no cover
    # The discs robot i of world w can reach: the other present robots, then the world's
    # pedestrians, whose centres lie within max_range + radius; their indices go to near,
    # robots first. Returns (robots among them, all of them).
    n_near = 0
    for m in range(x.shape[1]):
        if m != i and present[w, m]:
            fx, fy = px - x[w, m], py - y[w, m]
            # Farther than this (m^2, with a margin for rounding) the disc is out of every ray's reach.
            reach2 = ((max_range + radius[w, m]) * (1.0 + 1e-9) + 1e-12) ** 2
            if fx * fx + fy * fy <= reach2:
                near[n_near] = m
                n_near += 1
    n_robot_near = n_near
    for m in range(qn[w]):
        fx, fy = px - qx[w, m], py - qy[w, m]
        reach2 = ((max_range + qr[w, m]) * (1.0 + 1e-9) + 1e-12) ** 2
        if fx * fx + fy * fy <= reach2:
            near[n_near] = m
            n_near += 1
    return n_robot_near, n_near


@_jit
def cast_worlds(scene, x, y, cyaw, syaw, ca, sa, present, radius, max_range, meta, lookup, clear, open_radius, edges,
                qx, qy, qr, qn, out):  # pragma: no cover
    n_worlds, n_robots = x.shape
    n_rays = ca.shape[0]
    # radius (W, R): each robot's disc (m); qx, qy, qr (W, Q): other discs every robot sees
    # (pedestrians), the first qn[w] of world w.
    c = np.empty(n_rays)
    s = np.empty(n_rays)
    phi = np.empty(n_rays)
    near = np.empty(n_robots + qx.shape[1], np.int64)
    for w in range(n_worlds):
        k = scene[w]
        loff = int(meta[k, 0])
        coff = int(meta[k, 1])
        hp = int(meta[k, 2])
        wp = int(meta[k, 3])
        res = meta[k, 4]
        ox = meta[k, 5]
        oy = meta[k, 6]
        e0 = int(meta[k, 7])
        own_edges = edges[e0 : e0 + int(meta[k, 8])]
        inv = 1.0 / res
        e = TOUCH_EPS * inv
        reach = max_range * inv
        n_cross = min(math.ceil(reach) + 1, max(hp, wp) + 1)
        plane = hp * wp
        fhp = float(hp)
        fwp = float(wp)
        look = lookup[loff : loff + 3 * plane]
        clr = clear[coff : coff + 4 * plane]  # four quadrants a cell
        opened = open_radius[int(meta[k, 9]) : int(meta[k, 9]) + plane]
        # Past this (m) from every blocked cell, no ray's walk meets one within max_range
        # (a touch counts from TOUCH_EPS; the margin covers the walk's rounding).
        open_enough = max_range + TOUCH_EPS + 1e-6
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
            n_robot_near, n_near = _near_discs(w, i, px, py, x, y, present, radius, qx, qy, qr, qn, max_range, near)
            # In open space every ray's walk reads max_range: none is walked.
            walk = opened[int(min(max(math.floor(gy), 0.0), hp - 1.0)) * wp
                          + int(min(max(math.floor(gx), 0.0), wp - 1.0))] <= open_enough
            for r in range(n_rays):
                dx = c[r]
                dy = s[r]
                best = max_range
                if walk:
                    best = min(grid_range(gx, gy, dx, dy, fhp, fwp, plane, look, clr, e, n_cross, reach) * res, max_range)
                for j in range(n_robot_near):
                    m = near[j]
                    best = min(best, disc_range(px - x[w, m], py - y[w, m], dx, dy, radius[w, m] * radius[w, m]))
                for j in range(n_robot_near, n_near):
                    m = near[j]
                    best = min(best, disc_range(px - qx[w, m], py - qy[w, m], dx, dy, qr[w, m] * qr[w, m]))
                out[w, i, r] = best
            if own_edges.shape[0]:  # the single scan's polygon edges (origins inside: the caller)
                polygon_range(px, py, c, s, phi, own_edges, max_range, out[w, i])
