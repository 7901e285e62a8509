"""The numba kernel behind :mod:`pointnav_core.sensors.raycast_jit` (imports numba).

Imported only by :func:`pointnav_core.utils.compiled.kernel`, so that the package
imports without numba. Module-level functions, so that ``cache=True`` stores the compiled
code on disk and later processes load it instead of compiling again. See
:mod:`~pointnav_core.sensors.raycast_jit` for what the kernel does and why it is exact.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from pointnav_core.sensors.raycast import TOUCH_EPS

__all__ = ["cast", "polygon_range"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")
# A helper called edge by edge allocates nothing: it runs without numba's reference
# counting of the arrays it is handed (_nrt=False; numba refuses to compile one that would
# need it), which would otherwise cost atomic operations on every call.
_edge_jit = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
_EPS = TOUCH_EPS
_TINY = 1e-300  # raycast._TINY
_INF = math.inf
# An edge's angular span (see cast): used when the origin is at least _SPAN_MIN_DIST
# (m) from its line and _SPAN_MIN_END from its ends; widened by _SPAN_MARGIN (rad).
_SPAN_MIN_DIST = 1e-4
_SPAN_MIN_END = 1e-2
_SPAN_MARGIN = 1e-3
_SPAN_MIN_DIST2 = _SPAN_MIN_DIST * _SPAN_MIN_DIST
_SPAN_MIN_END2 = _SPAN_MIN_END * _SPAN_MIN_END
# An edge whose nearest point is farther than this (m) beyond every ray's range so far is
# skipped: it lies beyond all of them (the margin covers rounding and TOUCH_EPS).
_CULL_MARGIN = 1e-6


@_jit
def crossings(g_along, d_along, g_across, d_across):  # pragma: no cover
    # One crossing family of one ray: sign, dt, t0, a0, step, first cell entered.
    pos = d_along >= 0.0
    sgn = 1.0 if pos else -1.0
    base = math.floor(g_along) + 1.0 if pos else math.ceil(g_along) - 1.0
    dt = 1.0 / max(abs(d_along), _TINY)
    t0 = (base - g_along) * sgn * dt
    return sgn, dt, t0, g_across + t0 * d_across, dt * d_across, base - (0.0 if pos else 1.0)

@_jit
def grid_range(gx, gy, dx, dy, fhp, fwp, plane, lookup, clear, e, n_cross, reach):  # pragma: no cover
    # Nearest blocked crossing (cell units) of one ray, _INF past reach: both crossing
    # families of raycast._grid_hits (the same expressions, so the same decisions), merged
    # in order of t so the walk ends at the first blocked crossing of either.
    sx, dtx, t0x, a0x, stx, enx = crossings(gx, dx, gy, dy)
    sy, dty, t0y, a0y, sty, eny = crossings(gy, dy, gx, dx)
    hp = int(fhp)
    wp = int(fwp)
    plane2 = 2 * plane
    adx = 1.0 / dtx
    ady = 1.0 / dty
    # Integer steps and cells; the crossing k of a family enters column (row) ent + s * k,
    # and while kx, ky are the next crossings the ray is in column col0 + isx * kx, row
    # row0 + isy * ky (the same count of crossings passed), so no point is rounded per step.
    isx = 1 if sx > 0.0 else -1
    isy = 1 if sy > 0.0 else -1
    enx_i = int(enx)
    eny_i = int(eny)
    col0 = enx_i - isx
    row0 = eny_i - isy
    quad = (0 if isx > 0 else 1) + (0 if isy > 0 else 2)
    # Free squares ahead (sensors.clearance): if the square of side K >= 3 anchored at the
    # cell diagonally behind the ray's cell is free, the ray stays in it up to crossings
    # kx + K - 2 and ky + K - 2 (its far sides) and at least a cell from its near sides,
    # so the crossings before the nearer far side (less a margin for rounding and e) touch
    # free cells only: the walk jumps to the first crossing of each family after that.
    margin = 1e-6 + 2.0 * e
    kx = 0
    ky = 0
    while True:
        col = col0 + isx * kx
        row = row0 + isy * ky
        if 0 <= col < wp and 0 <= row < hp:
            side = clear[(row * wp + col) * 4 + quad]
            if side >= 3:
                farx = t0x + float(kx + side - 2) * dtx
                fary = t0y + float(ky + side - 2) * dty
                # The nearer far side's family goes to it (its crossing before is a whole
                # cell earlier, far beyond the margin); the other to its first crossing
                # after the margin.
                if farx <= fary:
                    kx += side - 2
                    target = farx - margin
                    if t0y < target:
                        ky = min(max(ky, math.ceil((target - t0y) * ady)), n_cross)
                else:
                    ky += side - 2
                    target = fary - margin
                    if t0x < target:
                        kx = min(max(kx, math.ceil((target - t0x) * adx)), n_cross)
        fkx = float(kx)
        fky = float(ky)
        tx = t0x + fkx * dtx if kx < n_cross else _INF
        ty = t0y + fky * dty if ky < n_cross else _INF
        if tx <= ty:
            if tx > reach:  # t grows along the walk: nothing nearer is left
                return _INF
            # raycast._grid_hits' test: floor(across - e) < hi is across - e < hi (hi whole).
            across = a0x + stx * fkx
            hi = math.floor(across + e)
            graze = across - e < hi
            hi = min(max(hi, 0), hp - 1)
            ent = min(max(enx_i + isx * kx, 0), wp - 1)
            if lookup[plane * int(graze) + hi * wp + ent]:
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
            if lookup[plane2 * int(graze) + hi + ent * wp]:
                return ty
            ky += 1

@_jit
def disc_range(fx, fy, dx, dy, r2):  # pragma: no cover
    # Range along (dx, dy) from a point at (fx, fy) from a disc's centre, radius squared r2:
    # raycast._disc_hits' expressions (0 inside, inf when missed or behind).
    b = fx * dx + fy * dy
    cc = fx * fx + fy * fy - r2
    if cc <= 0.0:
        return 0.0
    disc = b * b - cc
    if disc >= 0.0 and b <= 0.0:
        denom = math.sqrt(max(disc, 0.0)) - b
        return cc / denom if denom > 0.0 else _INF
    return _INF

@_jit
def pseudo_angle(y, x):  # pragma: no cover
    # A monotone stand-in for atan2(y, x), in (-2, 2] (the "diamond angle"), without atan2.
    # Its slope is 1/2 to 1 per rad, so a margin of m rad is covered by a margin of m, and
    # half a turn is 2 (spans of less than half a turn stay below 2).
    q = x / (abs(x) + abs(y))
    return 1.0 - q if y >= 0.0 else q - 1.0


@_jit
def polygon_range(px, py, c, s, phi, edges, max_range, out):  # pragma: no cover
    # The rays of one origin (px, py) (m), of directions c, s (n_rays,), against the polygon
    # edges (ScanGeometry.edge_table rows): out (n_rays,), each ray's range so far (m),
    # becomes the nearer of it and the ray's first edge hit. phi (n_rays,) is scratch.
    # The one definition of a polygon edge's hit for the compiled scans (the single env's
    # cast and the batched engine's vector._scan_kernel.cast_worlds).
    n_edges = edges.shape[0]
    n_rays = c.shape[0]
    far = 0.0
    for r in range(n_rays):  # the rays' directions, as pseudo_angle gives the edges' ends
        phi[r] = pseudo_angle(s[r], c[r])
        far = max(far, out[r])
    far += _CULL_MARGIN
    order = np.argsort(phi)
    sphi = phi[order]
    # The polygon edges, each against the rays in its angular span only.
    for j in range(n_edges):
        if not (edges[j, 6] >= px - max_range and edges[j, 4] <= px + max_range
                and edges[j, 7] >= py - max_range and edges[j, 5] <= py + max_range):
            continue
        fx = edges[j, 0] - px
        fy = edges[j, 1] - py
        ex = edges[j, 2]
        ey = edges[j, 3]
        num0 = ey * fx - ex * fy
        if num0 > 0.0:  # seen from its back (the material's side)
            continue
        # The edge's nearest point beyond every ray's range so far: no ray reaches it.
        ee = ex * ex + ey * ey
        tt = min(max(-(fx * ex + fy * ey) / ee, 0.0), 1.0) if ee > 0.0 else 0.0
        nx = fx + tt * ex
        ny = fy + tt * ey
        if nx * nx + ny * ny > far * far:
            continue
        full, lo, hi = edge_span(fx, fy, ex, ey, num0, ee)
        for wrap in range(3):  # the span, and its parts shifted by a full turn
            if full:
                if wrap != 1:
                    continue
                k0 = 0
                k1 = n_rays
            else:
                a = lo + (wrap - 1) * 4.0
                b = hi + (wrap - 1) * 4.0
                if b < -2.0 or a > 2.0:
                    continue
                k0 = np.searchsorted(sphi, a)
                k1 = np.searchsorted(sphi, b, side="right")
            edge_hits(fx, fy, ex, ey, edges[j, 8], c, s, order, k0, k1, out)


@_jit
def edge_span(fx, fy, ex, ey, num0, ee):  # pragma: no cover
    # The pseudo-angles (lo, hi) of the rays an edge can meet, from an origin at -(fx, fy)
    # from its first end (m), the edge (ex, ey) (m), num0 its cross product with (fx, fy)
    # and ee its squared length: (full, lo, hi), full when every ray must be tested.
    gx2 = fx + ex
    gy2 = fy + ey
    # (Squared distances: no square roots.)
    if (num0 * num0 >= _SPAN_MIN_DIST2 * ee and fx * fx + fy * fy >= _SPAN_MIN_END2
            and gx2 * gx2 + gy2 * gy2 >= _SPAN_MIN_END2):
        # Far enough from the edge's line and ends: a ray more than _SPAN_MARGIN
        # outside the directions of its ends misses it by far more than
        # rounding and TOUCH_EPS, so only the rays between them are tested.
        pa = pseudo_angle(fy, fx)
        pb = pseudo_angle(gy2, gx2)
        width = pb - pa
        if width > 2.0:
            width -= 4.0
        elif width < -2.0:
            width += 4.0
        return False, min(pa, pa + width) - _SPAN_MARGIN, max(pa, pa + width) + _SPAN_MARGIN
    return True, 0.0, 0.0


@_edge_jit
def edge_hits(fx, fy, ex, ey, half, c, s, order, k0, k1, out):  # pragma: no cover
    # The rays order[k0:k1] (directions c, s) against one edge (fx, fy, ex, ey as in
    # edge_span; half its |u - 1/2| slack, edge_table's last column): out[r], the ray's
    # range so far (m), becomes the hit's range where it is nearer.
    for k in range(k0, k1):
        r = order[k]
        best = out[r]
        dx = c[r]
        dy = s[r]
        cross = dx * ey - dy * ex
        num = fx * ey - fy * ex
        # Without dividing: t = num / cross surely negative (opposite signs,
        # num far from underflow) or surely beyond best changes nothing.
        if abs(num) > 1e-250 and (num < 0.0) != (cross < 0.0) and cross != 0.0:
            continue
        if abs(num) > best * abs(cross) * (1.0 + 1e-12):
            continue
        den = 1.0 / cross
        t = num * den
        if t >= 0.0 and t < best:
            u = (fx * dy - fy * dx) * den
            if abs(u - 0.5) <= half:
                out[r] = t


@_jit
def cast(p, cy, sy, ca, sa, params, lookup, clear, near_polygon, edges, discs, own, out):  # pragma: no cover
    res = params[0]
    ox = params[1]
    oy = params[2]
    max_range = params[3]
    hp = int(params[4])
    wp = int(params[5])
    inv = 1.0 / res
    e = _EPS * inv
    reach = max_range * inv
    n_cross = min(math.ceil(reach) + 1, max(hp, wp) + 1)
    plane = hp * wp
    fhp = float(hp)
    fwp = float(wp)
    n_edges = edges.shape[0]
    n_discs = discs.shape[0]
    n_rays = ca.shape[0]
    phi = np.empty(n_rays)
    c = np.empty(n_rays)
    s = np.empty(n_rays)
    n_near = 0
    for i in range(p.shape[0]):
        px = p[i, 0]
        py = p[i, 1]
        gx = (px - ox) * inv + 1.0
        gy = (py - oy) * inv + 1.0
        # An origin in a cell a polygon touches may be inside one (raycast.inside_polygon).
        col = int(min(max(math.floor((px - ox) * inv) + 1.0, 0.0), wp - 1))
        row = int(min(max(math.floor((py - oy) * inv) + 1.0, 0.0), hp - 1))
        if near_polygon[row * wp + col]:
            n_near += 1
        # An origin touching a blocked cell (or off the map) reads 0.
        c0 = int(min(max(math.floor(gx - e), 0.0), wp - 1))
        c1 = int(min(max(math.floor(gx + e), 0.0), wp - 1))
        r0 = int(min(max(math.floor(gy - e), 0.0), hp - 1)) * wp
        r1 = int(min(max(math.floor(gy + e), 0.0), hp - 1)) * wp
        if lookup[r0 + c0] or lookup[r0 + c1] or lookup[r1 + c0] or lookup[r1 + c1]:
            out[i, :] = 0.0  # nothing is nearer; the rest are ranges >= 0
            continue
        for r in range(n_rays):  # the rays' directions: raycast.cast_rays' products
            c[r] = cy[i] * ca[r] - sy[i] * sa[r]
            s[r] = sy[i] * ca[r] + cy[i] * sa[r]
        # The grid and the discs, ray by ray.
        for r in range(n_rays):
            dx = c[r]
            dy = s[r]
            best = min(grid_range(gx, gy, dx, dy, fhp, fwp, plane, lookup, clear, e, n_cross, reach) * res,
                       max_range)
            for m in range(n_discs):
                if own[i] == m:
                    continue
                best = min(best, disc_range(px - discs[m, 0], py - discs[m, 1], dx, dy, discs[m, 2] * discs[m, 2]))
            out[i, r] = best
        if n_edges:
            polygon_range(px, py, c, s, phi, edges, max_range, out[i])
    return n_near
