"""The tangent constructions and tolerances every part of the geodesic package shares.

A path of the robot's centre wraps a blocked corner ``c`` on a circle of radius ``r``,
clockwise or counter-clockwise (the winding side ``s``: +1 puts the corner on the path's
left). A node's free arc runs counter-clockwise from ``phi0`` over ``span`` radians; a
position on it is measured along the winding. Angles are in radians, lengths in metres.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pointnav_core.floor.collision import TOUCH_TOL

__all__ = ["ANG_TOL", "COST_TOL", "TWO_PI", "ccw_pos", "tangent_from_point"]

TWO_PI = 2.0 * math.pi
#: Angles (rad) closer than this are equal: arc positions, departures, arrivals.
ANG_TOL = 1e-9
#: Costs (m) closer than this are equal in the label-setting search.
COST_TOL = 1e-12


def tangent_from_point(px: Any, py: Any, cx: Any, cy: Any, r: float, s: Any) -> tuple[Any, Any, Any, Any]:
    """Tangent from point ``p`` to the circle at ``c`` that arrives winding on side ``s``.

    Returns the arrival angle on the circle (rad), the tangent length (m), the heading (rad)
    and a validity mask (``p`` outside the circle). Scalars or arrays, broadcast.
    """
    dx = cx - px
    dy = cy - py
    L = np.hypot(dx, dy)
    # A point on the circle (within the touching tolerance: a robot following a path that
    # wraps this corner stands there) is its own tangent point, at length 0.
    ok = L >= r - TOUCH_TOL if r > 0 else L > 0
    safe = np.where(ok, np.maximum(L, r), 1.0)
    theta = -s * np.arcsin(np.clip(r / safe, -1.0, 1.0))
    heading = np.arctan2(dy, dx) + theta
    ang = heading - s * (math.pi / 2)
    length = np.sqrt(np.maximum(L * L - r * r, 0.0))
    return ang, length, heading, ok


def ccw_pos(ang: Any, phi0: Any, span: Any) -> tuple[Any, Any]:
    """Counter-clockwise position (rad) of angles on arcs ``[phi0, phi0 + span]``, and validity."""
    ccw = np.mod(ang - phi0, TWO_PI)
    ccw = np.where(ccw > TWO_PI - ANG_TOL, 0.0, ccw)
    ok = ccw <= span + ANG_TOL
    return np.minimum(ccw, span), ok
