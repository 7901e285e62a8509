"""An independent range-scan reference from first principles, with shapely.

Every ray is a shapely LineString from the origin to ``max_range`` ahead. It is intersected
with every OBSTACLE cell square (``shapely.box``), a one-cell frame around the map, every
obstacle polygon, and every other robot's disc (the closest approach of the ray's line to
the centre, then Pythagoras). The range is the distance from the origin to the nearest
intersection. Nothing here uses pointnav_core's ray casting or collision code.

Rays that graze a corner or run along a face are decided by rounding, here as in any float
code. So the reference gives an interval per ray: ``loose`` intersects the shapes grown by
``touch`` metres, ``strict`` the shapes shrunk by it (discs are exact in both). Away from
such grazes the two agree to about ``touch``; a correct scan lies between them.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import LineString, Point


def blocked_shapes(codes, resolution, origin, polygons=()):
    """Shapely geometries of what a scan sees: OBSTACLE squares, a frame, polygons."""
    codes = np.asarray(codes)
    h, w = codes.shape
    ox, oy = origin
    res = resolution
    shapes = [
        shapely.box(ox + c * res, oy + r * res, ox + (c + 1) * res, oy + (r + 1) * res)
        for r, c in zip(*np.nonzero(codes == 1))
    ]
    x0, x1, y0, y1 = ox, ox + w * res, oy, oy + h * res
    shapes += [
        shapely.box(x0 - res, y0 - res, x1 + res, y0),  # below
        shapely.box(x0 - res, y1, x1 + res, y1 + res),  # above
        shapely.box(x0 - res, y0, x0, y1),  # left
        shapely.box(x1, y0, x1 + res, y1),  # right
    ]
    return shapes + list(polygons)


def _first_hit(ray, start, shapes, best):
    for shape in shapes:
        if shape.is_empty:
            continue
        inter = ray.intersection(shape)
        if not inter.is_empty:
            best = min(best, start.distance(inter))
    return best


def reference_ranges(shapes, origin, bearings, max_range, discs=(), touch=1e-9):
    """``(loose, strict)`` ranges (m) along each world bearing from ``origin``."""
    px, py = float(origin[0]), float(origin[1])
    start = Point(px, py)
    grown = [s.buffer(touch, join_style="mitre") for s in shapes]
    shrunk = [s.buffer(-touch, join_style="mitre") for s in shapes]
    loose_tree = shapely.STRtree(grown)
    loose, strict = [], []
    for theta in bearings:
        end = (px + max_range * math.cos(theta), py + max_range * math.sin(theta))
        ray = LineString([(px, py), end])
        near = loose_tree.query(ray, predicate="intersects")
        lo = _first_hit(ray, start, [grown[i] for i in near], max_range)
        hi = _first_hit(ray, start, [shrunk[i] for i in near], max_range)
        for cx, cy, r in discs:
            if start.distance(Point(cx, cy)) <= r:
                lo = hi = 0.0
                continue
            # Closest approach of the ray's line to the centre: along it, and off it.
            dx, dy = cx - px, cy - py
            along = dx * math.cos(theta) + dy * math.sin(theta)
            miss = abs(dy * math.cos(theta) - dx * math.sin(theta))
            if miss <= r and 0.0 < along:
                d = along - math.sqrt(max(r * r - miss * miss, 0.0))
                lo, hi = min(lo, d), min(hi, d)
        loose.append(lo)
        strict.append(hi)
    return np.array(loose), np.array(strict)


def assert_within(got, loose, strict, atol):
    """Every range between its loose and strict reference, within ``atol`` metres."""
    got = np.asarray(got)
    bad = (got < loose - atol) | (got > strict + atol)
    assert not bad.any(), (
        f"ranges {got[bad].tolist()} outside the reference [{loose[bad].tolist()}, "
        f"{strict[bad].tolist()}] at rays {np.flatnonzero(bad).tolist()}"
    )
