"""The tangent graph's nodes: the convex corners of a floor's blocked set, each with the arc
of the robot's disc around it that the robot can roll along.

A node is a convex corner, on the cell grid or on an obstacle polygon, with its arc: centre
``(cx, cy)`` (m), starting angle ``phi0`` and counter-clockwise ``span`` (rad). A corner whose
arc is blocked at every sample (another obstacle within the radius all round) is no node.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray
from shapely.geometry.polygon import orient

from pointnav_core.floor.collision import FloorCollision, convex_corners
from pointnav_core.geodesic.tangents import TWO_PI

__all__ = ["ARC_SAMPLES", "corner_arcs"]

#: Samples along a node's arc used to find the parts of it within ``r`` of something else.
ARC_SAMPLES = 9


def corner_arcs(
    geo: FloorCollision, radius: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
           NDArray[np.bool_], NDArray[np.float64]]:
    """The nodes of ``geo`` for a disc of ``radius`` metres.

    Returns
    -------
    cx, cy, phi0, span : ndarray of float64, shape (N,)
        Each node's corner (m), arc start and counter-clockwise span (rad).
    arc_clear : ndarray of bool, shape (N, ARC_SAMPLES)
        Which of the arc's evenly spaced samples are clear of everything else.
    samples : ndarray of float64, shape (ARC_SAMPLES,)
        The samples' fractions of the span, 0 to 1.
    """
    res = geo.resolution
    ox, oy = geo.origin
    rows, cols, quad = convex_corners(geo.blocked, geo.outside_blocked)
    xs = [ox + cols * res]
    ys = [oy + rows * res]
    phi0 = [quad * (math.pi / 2)]
    span = [np.full(len(rows), math.pi / 2)]
    for poly in geo.polygons:
        for ring in _rings(poly):
            pts = np.asarray(ring.coords)[:-1]
            if len(pts) < 3:
                continue
            e1 = pts - np.roll(pts, 1, axis=0)
            e2 = np.roll(pts, -1, axis=0) - pts
            cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
            dot = (e1 * e2).sum(axis=1)
            convex = cross > 1e-12
            a1 = np.arctan2(-e1[:, 0], e1[:, 1])  # outward normal of the edge before
            turn = np.arctan2(cross, dot)
            xs.append(pts[convex, 0])
            ys.append(pts[convex, 1])
            phi0.append(a1[convex])
            span.append(turn[convex])
    cx = np.concatenate(xs).astype(np.float64)
    cy = np.concatenate(ys).astype(np.float64)
    phi0_all = np.mod(np.concatenate(phi0).astype(np.float64), TWO_PI)
    span_all = np.concatenate(span).astype(np.float64)
    # Which samples of each arc are clear of everything else.
    k = np.linspace(0.0, 1.0, ARC_SAMPLES)
    ang = phi0_all[:, None] + span_all[:, None] * k[None, :]
    pts = np.stack([cx[:, None] + radius * np.cos(ang), cy[:, None] + radius * np.sin(ang)], axis=-1)
    clear = geo.points_clear(pts, radius) if len(cx) else np.zeros((0, ARC_SAMPLES), bool)
    keep = clear.any(axis=1)
    return cx[keep], cy[keep], phi0_all[keep], span_all[keep], clear[keep], k


def _rings(poly: Any) -> list[Any]:
    """Exterior rings of a polygon's parts, counter-clockwise (the blocked side on the left)."""
    return [orient(part, 1.0).exterior for part in getattr(poly, "geoms", [poly])]
