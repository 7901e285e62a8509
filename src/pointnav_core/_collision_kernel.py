"""The compiled path of :meth:`pointnav_core.collision.FloorCollision.segments_clear`'s cell test (imports numba).

Imported only by ``collision`` when numba is installed (the ``fast`` extra), so the package
imports without it. One segment at a time, band row by band row, with the numpy path's
expressions in the same order (``_cells_hit`` and ``_stadium_row``), stopping at the
first blocked row, so both paths give the same answers.
"""

from __future__ import annotations

import math

import numba

__all__ = ["cells_hit"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")


@_jit
def stadium_row(ax, ay, bx, by, rho, y):  # pragma: no cover
    # collision._stadium_row for one segment and one height: (lo, hi), (inf, -inf) if missed.
    lo = math.inf
    hi = -math.inf
    r2 = rho * rho
    d2 = r2 - (y - ay) * (y - ay)
    if d2 >= 0:
        s = math.sqrt(d2)
        lo = min(lo, ax - s)
        hi = max(hi, ax + s)
    d2 = r2 - (y - by) * (y - by)
    if d2 >= 0:
        s = math.sqrt(d2)
        lo = min(lo, bx - s)
        hi = max(hi, bx + s)
    dx = bx - ax
    dy = by - ay
    length = math.hypot(dx, dy)
    if not length > 0:
        return lo, hi
    nx = -dy / length * rho
    ny = dx / length * rho
    cx = (ax + nx, bx + nx, bx - nx, ax - nx)
    cy = (ay + ny, by + ny, by - ny, ay - ny)
    for i in range(4):
        px = cx[i]
        py = cy[i]
        qx = cx[(i + 1) % 4]
        qy = cy[(i + 1) % 4]
        span = qy - py
        if span != 0 and y >= min(py, qy) and y <= max(py, qy):
            t = (y - py) / span
            x = px + t * (qx - px)
            lo = min(lo, x)
            hi = max(hi, x)
    return lo, hi


@_jit
def cells_hit(ax, ay, bx, by, rho, rowcum, outside_blocked, out):  # pragma: no cover
    """``out[i]``: whether segment ``i``'s open ``rho``-stadium (grid cells) meets a blocked square."""
    h = rowcum.shape[0]
    w = rowcum.shape[1] - 1
    for i in range(ax.shape[0]):
        sax = ax[i]
        say = ay[i]
        sbx = bx[i]
        sby = by[i]
        ylo = min(say, sby) - rho
        yhi = max(say, sby) + rho
        k0 = math.floor(ylo)
        k1 = max(math.ceil(yhi) - 1, k0)  # a band starting exactly at yhi only touches
        left_is_a = sax <= sbx
        lx = (sax if left_is_a else sbx) - rho
        ly = say if left_is_a else sby
        rx = (sbx if left_is_a else sax) + rho
        ry = sby if left_is_a else say
        hit = False
        for k in range(k0, k1 + 1):
            y0 = max(float(k), ylo)
            y1 = min(float(k + 1), yhi)
            lo0, hi0 = stadium_row(sax, say, sbx, sby, rho, y0)
            lo1, hi1 = stadium_row(sax, say, sbx, sby, rho, y1)
            lo = min(lo0, lo1)
            hi = max(hi0, hi1)
            if ly >= y0 and ly <= y1:
                lo = min(lo, lx)
            if ry >= y0 and ry <= y1:
                hi = max(hi, rx)
            if not hi > lo:  # then lo, hi are finite: floor and ceil are safe
                continue
            c_lo = math.floor(lo)
            c_hi = math.ceil(hi) - 1
            if c_lo > c_hi:
                continue
            inside_row = k >= 0 and k < h
            if inside_row:
                cl = min(max(c_lo, 0), w)
                ch = min(max(c_hi + 1, 0), w)
                if ch > cl and rowcum[k, ch] - rowcum[k, min(cl, ch)] > 0:
                    hit = True
                    break
            if outside_blocked and (not inside_row or c_lo < 0 or c_hi >= w):
                hit = True
                break
        out[i] = hit
