"""The compiled path of :meth:`pointnav_core.floor.collision.FloorCollision.segments_clear`'s cell test (imports numba).

Imported only through :func:`pointnav_core.utils.compiled.kernel` when numba is installed
(the ``fast`` extra), so the package imports without it. One segment at a time, band row by
band row, with the numpy path's expressions in the same order (``_cells_hit`` and
``_stadium_row``), stopping at the first blocked row, so both paths give the same answers.
"""

from __future__ import annotations

import math

import numba

__all__ = ["cells_hit", "segment_clear", "segment_hits", "segments_clear"]

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
def segment_hits_cells(sax, say, sbx, sby, rho, rowcum, outside_blocked):  # pragma: no cover
    """Whether one segment's open ``rho``-stadium (grid cells) meets a blocked square."""
    h = rowcum.shape[0]
    w = rowcum.shape[1] - 1
    ylo = min(say, sby) - rho
    yhi = max(say, sby) + rho
    k0 = math.floor(ylo)
    k1 = max(math.ceil(yhi) - 1, k0)  # a band starting exactly at yhi only touches
    left_is_a = sax <= sbx
    lx = (sax if left_is_a else sbx) - rho
    ly = say if left_is_a else sby
    rx = (sbx if left_is_a else sax) + rho
    ry = sby if left_is_a else say
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
                return True
        if outside_blocked and (not inside_row or c_lo < 0 or c_hi >= w):
            return True
    return False


@_jit
def cells_hit(ax, ay, bx, by, rho, rowcum, outside_blocked, out):  # pragma: no cover
    """``out[i]``: whether segment ``i``'s open ``rho``-stadium (grid cells) meets a blocked square."""
    for i in range(ax.shape[0]):
        out[i] = segment_hits_cells(ax[i], ay[i], bx[i], by[i], rho, rowcum, outside_blocked)


@_jit
def _point_segment_d2(px, py, ax, ay, bx, by):  # pragma: no cover
    # Squared distance from point p to segment a-b.
    dx = bx - ax
    dy = by - ay
    n = dx * dx + dy * dy
    t = 0.0
    if n > 0:
        t = min(max(((px - ax) * dx + (py - ay) * dy) / n, 0.0), 1.0)
    ex = ax + t * dx - px
    ey = ay + t * dy - py
    return ex * ex + ey * ey


@_jit
def _orient(ax, ay, bx, by, cx, cy):  # pragma: no cover
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@_jit
def _segments_d2(ax, ay, bx, by, cx, cy, dx, dy):  # pragma: no cover
    # Squared distance between segments a-b and c-d: 0 where they cross.
    o1 = _orient(ax, ay, bx, by, cx, cy)
    o2 = _orient(ax, ay, bx, by, dx, dy)
    o3 = _orient(cx, cy, dx, dy, ax, ay)
    o4 = _orient(cx, cy, dx, dy, bx, by)
    if ((o1 > 0 and o2 < 0) or (o1 < 0 and o2 > 0)) and ((o3 > 0 and o4 < 0) or (o3 < 0 and o4 > 0)):
        return 0.0
    return min(
        min(_point_segment_d2(ax, ay, cx, cy, dx, dy), _point_segment_d2(bx, by, cx, cy, dx, dy)),
        min(_point_segment_d2(cx, cy, ax, ay, bx, by), _point_segment_d2(dx, dy, ax, ay, bx, by)),
    )


@_jit
def segment_hits_polygons(ax, ay, bx, by, reach, boxes, first, last, x0, y0, x1, y1):  # pragma: no cover
    """Whether segment ``a -> b`` comes within ``reach`` (closed) of a polygon.

    Polygon ``k`` has the bounding box ``boxes[k]`` (xmin, ymin, xmax, ymax) and the ring
    edges ``first[k]:last[k]`` of ``(x0, y0) -> (x1, y1)`` (every ring, holes too). A
    segment is within reach of it when an edge is, or when its first end lies inside it
    (even-odd rule over the rings): then it does not cross the boundary, so it is inside.
    """
    r2 = reach * reach
    lo_x = min(ax, bx) - reach
    hi_x = max(ax, bx) + reach
    lo_y = min(ay, by) - reach
    hi_y = max(ay, by) + reach
    for k in range(boxes.shape[0]):
        if boxes[k, 0] > hi_x or boxes[k, 2] < lo_x or boxes[k, 1] > hi_y or boxes[k, 3] < lo_y:
            continue
        inside = False
        for e in range(first[k], last[k]):
            if _segments_d2(ax, ay, bx, by, x0[e], y0[e], x1[e], y1[e]) <= r2:
                return True
            # Crossings of a ray from the first end towards +x (even-odd rule).
            if (y0[e] > ay) != (y1[e] > ay):
                xc = x0[e] + (ay - y0[e]) * (x1[e] - x0[e]) / (y1[e] - y0[e])
                if xc > ax:
                    inside = not inside
        if inside:
            return True
    return False


@_jit
def polygons_hit(ax, ay, bx, by, reach, boxes, first, last, x0, y0, x1, y1, out):  # pragma: no cover
    """``out[i]``: :func:`segment_hits_polygons` of segment ``i``."""
    for i in range(ax.shape[0]):
        out[i] = segment_hits_polygons(ax[i], ay[i], bx[i], by[i], reach, boxes, first, last, x0, y0, x1, y1)


@_jit
def segment_hits(ax, ay, bx, by, ox, oy, inv, rho, rowcum, outside_blocked, reach, boxes, first, last, ex0, ey0, ex1,
                 ey1, use_polygons):  # pragma: no cover
    """``FloorCollision.segments_clear``'s test, negated, for one segment in world metres
    (``inv`` = 1 / resolution; ``rho`` and ``reach`` as :meth:`FloorCollision._cells_hit` and
    :meth:`FloorCollision._polygons_hit` derive them from the radius)."""
    if segment_hits_cells((ax - ox) * inv, (ay - oy) * inv, (bx - ox) * inv, (by - oy) * inv, rho, rowcum,
                          outside_blocked):
        return True
    return use_polygons and segment_hits_polygons(ax, ay, bx, by, reach, boxes, first, last, ex0, ey0, ex1, ey1)


@_jit
def segment_clear(ax, ay, bx, by, walls):  # pragma: no cover
    """``FloorCollision.segment_clear`` for one segment, ``walls`` being
    ``FloorCollision.kernel_arguments(radius)``: False where an end is not finite."""
    if not (math.isfinite(ax) and math.isfinite(ay) and math.isfinite(bx) and math.isfinite(by)):
        return False
    ox, oy, inv, rho, rowcum, outside, reach, boxes, first, last, ex0, ey0, ex1, ey1, use_polygons = walls
    return not segment_hits(ax, ay, bx, by, ox, oy, inv, rho, rowcum, outside, reach, boxes, first, last, ex0, ey0,
                            ex1, ey1, use_polygons)


@_jit
def segments_clear(a, b, ox, oy, inv, rho, rowcum, outside_blocked, reach, boxes, first, last, ex0, ey0, ex1, ey1,
                   use_polygons, out):  # pragma: no cover
    """``FloorCollision.segments_clear`` for the segments ``a[i]`` to ``b[i]`` (``(N, 2)``, m)
    in one call: False where an end is not finite, else not :func:`segment_hits`."""
    for i in range(a.shape[0]):
        ax = a[i, 0]
        ay = a[i, 1]
        bx = b[i, 0]
        by = b[i, 1]
        if not (math.isfinite(ax) and math.isfinite(ay) and math.isfinite(bx) and math.isfinite(by)):
            out[i] = False
        else:
            out[i] = not segment_hits(ax, ay, bx, by, ox, oy, inv, rho, rowcum, outside_blocked, reach, boxes, first,
                                      last, ex0, ey0, ex1, ey1, use_polygons)
