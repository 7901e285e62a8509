"""The tangent graph's arcs drawn as polylines, for ``entire_path=True``.

A shortest path of the tangent-graph planner (:mod:`pointnav_core.geodesic.planner`) bends
around blocked corners along arcs of the robot's radius. :func:`arc_points` draws such an
arc as pieces of at most :data:`ARC_PIECE` whose vertices lie outside the circle, so that
every piece is tangent to it and keeps the full radius from the corner; where a passage is
exactly as wide as the robot it splits the arc at the passage's narrowest line, so that no
vertex overlaps the other side.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from pointnav_core.geodesic.tangents import ANG_TOL, TWO_PI

if TYPE_CHECKING:
    from pointnav_core.geodesic.planner import Planner

__all__ = ["ARC_PIECE", "arc_points", "draw_arcs"]

#: Largest angle (rad) of one piece of a drawn arc.
ARC_PIECE = math.radians(2.0)


def arc_points(p: Planner, node: int, s: int, pos_from: float, pos_to: float, splits: int = 4,
               piece: float = ARC_PIECE) -> list[NDArray[np.float64]]:
    """Drawn arc of ``node`` from position ``pos_from`` back to ``pos_to`` (both ends on it),
    in pieces of at most ``piece`` (rad).

    Intermediate vertices lie outside the circle, so that every drawn piece is tangent to
    it and keeps the full radius from the corner. Where an obstacle is exactly ``2 r`` from
    this corner (a passage exactly as wide as the robot), a vertex outside the circle near
    the passage's narrowest line overlaps it; the arc is then drawn in two parts that meet
    on the circle at that line (touching both sides, as the path does), so the vertices on
    either side point away from it (``splits`` bounds how often this may recur).
    """
    out = _drawn_arc(p, node, s, pos_from, pos_to, piece)
    if len(out) <= 2 or splits <= 0:
        return list(out)
    return _split_pinched(p, node, s, pos_from, pos_to, out, p.geo.points_clear(out[1:-1], p.radius), splits, piece)


def draw_arcs(p: Planner, arcs: list[tuple[int, int, float, float]], piece: float = ARC_PIECE) -> NDArray[np.float64]:
    """The drawn arcs ``(node, side, pos_from, pos_to)`` one after another, shape (M, 2):
    what :func:`arc_points` gives for each (pieces of at most ``piece`` rad), with one
    clearance test for all of their vertices rather than one per arc (a path's arcs are
    drawn together)."""
    drawn = [_drawn_arc(p, node, s, a, b, piece) for node, s, a, b in arcs]
    inner = [d[1:-1] for d in drawn if len(d) > 2]
    if not inner:
        return np.concatenate(drawn) if drawn else np.zeros((0, 2))
    clear = p.geo.points_clear(np.concatenate(inner), p.radius)
    if clear.all():
        return np.concatenate(drawn)
    out, at = [], 0
    for (node, s, a, b), d in zip(arcs, drawn):
        if len(d) > 2:
            ok = clear[at : at + len(d) - 2]
            at += len(d) - 2
            if not ok.all():
                d = np.array(_split_pinched(p, node, s, a, b, d, ok, 4, piece))
        out.append(d)
    return np.concatenate(out)


def _split_pinched(
    p: Planner, node: int, s: int, pos_from: float, pos_to: float, out: NDArray[np.float64], clear: NDArray[np.bool_],
    splits: int, piece: float,
) -> list[NDArray[np.float64]]:
    """:func:`arc_points`' split at a passage as wide as the robot, given the drawn arc
    ``out`` and whether each of its inner vertices is clear."""
    bad = np.flatnonzero(~clear)
    if not len(bad):
        return list(out)
    pos = _pinch_position(p, node, s, out[1:-1][bad[0]])
    if pos is None or not pos_to + ANG_TOL < pos < pos_from - ANG_TOL:
        return list(out)
    first = arc_points(p, node, s, pos_from, pos, splits - 1, piece)
    return first + arc_points(p, node, s, pos, pos_to, splits - 1, piece)[1:]


def _drawn_arc(p: Planner, node: int, s: int, pos_from: float, pos_to: float, largest: float) -> NDArray[np.float64]:
    """The arc's ends on the circle and, between them, vertices of pieces of at most
    ``largest`` (rad) tangent to it (each at ``r / cos(piece / 2)`` from the corner), (k, 2)."""
    a = p.node_point(node, s, pos_from)
    delta = pos_from - pos_to
    if delta <= ANG_TOL or p.radius == 0.0:
        return np.array([a])
    n = max(1, math.ceil(delta / largest))
    piece = delta / n
    reach = p.radius / math.cos(piece / 2)
    pos = pos_from - piece * (np.arange(n) + 0.5)
    ang = p.phi0_list[node] + (pos if s > 0 else p.span_list[node] - pos)
    out = np.empty((n + 2, 2))
    out[0] = a
    out[1:-1, 0] = p.cx_list[node] + reach * np.cos(ang)
    out[1:-1, 1] = p.cy_list[node] + reach * np.sin(ang)
    out[-1] = p.node_point(node, s, pos_to)
    return out


def _pinch_position(p: Planner, node: int, s: int, vertex: NDArray[np.float64]) -> float | None:
    """Arc position (rad) of the narrowest line from ``node``'s corner to the blocked cells
    ``vertex`` overlaps: towards the nearest such cell corner, or along the normal of the
    nearest such cell face (cells are axis-aligned). None if there is none on the grid."""
    geo, r = p.geo, p.radius
    cx, cy = p.cx_list[node], p.cy_list[node]
    res, (ox, oy) = geo.resolution, geo.origin
    col, row = math.floor((vertex[0] - ox) / res), math.floor((vertex[1] - oy) / res)
    k = math.ceil(r / res) + 1
    rows, cols = np.mgrid[max(row - k, 0) : row + k + 1, max(col - k, 0) : col + k + 1]
    inside = (rows < geo.shape[0]) & (cols < geo.shape[1])
    rows, cols = rows[inside], cols[inside]
    keep = geo.blocked[rows, cols]
    x0, y0 = ox + cols[keep] * res, oy + rows[keep] * res
    qx = np.clip(vertex[0], x0, x0 + res)
    qy = np.clip(vertex[1], y0, y0 + res)
    # The other side of the passage: farther than 1.5 r from this corner (about 2 r).
    far = np.hypot(qx - cx, qy - cy) > 1.5 * r
    if not far.any():
        return None
    i = np.flatnonzero(far)[np.argmin(np.hypot(qx[far] - vertex[0], qy[far] - vertex[1]))]
    on_x = qx[i] in (x0[i], x0[i] + res)  # the nearest point is on a vertical face
    on_y = qy[i] in (y0[i], y0[i] + res)
    if on_x and on_y:  # a corner
        ang = math.atan2(qy[i] - cy, qx[i] - cx)
    elif on_x:
        ang = 0.0 if qx[i] > cx else math.pi
    else:
        ang = 0.5 * math.pi if qy[i] > cy else -0.5 * math.pi
    ccw = (ang - p.phi0_list[node]) % TWO_PI
    return ccw if s > 0 else p.span_list[node] - ccw
