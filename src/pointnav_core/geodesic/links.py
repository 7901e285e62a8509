"""Tangent links from a point to the nodes of the tangent graph it sees: where a straight,
clear segment from the point touches a node's arc, and how long it is."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pointnav_core.floor.collision import TOUCH_TOL
from pointnav_core.geodesic.roots import compiled
from pointnav_core.geodesic.tangents import ANG_TOL, ccw_pos, tangent_from_point

if TYPE_CHECKING:
    from pointnav_core.geodesic.planner import Planner

__all__ = ["point_links"]


def point_links(planner: Planner, x: float, y: float) -> list[tuple[int, int, float, float]]:
    """Tangents from point ``(x, y)`` (m) to the nodes it sees: ``(node, side, arrival, length)``.

    ``side`` is the winding of a path that leaves the point and wraps the node; the reverse
    path (node to point) winds ``-side`` and leaves at ``span - arrival`` (rad); ``length``
    is in metres. The compiled path gives the same links (``geodesic._roots_kernel``).
    """
    if not planner.n_nodes:
        return []
    r = planner.radius
    cand = planner.nodes_seeing(np.array([x]), np.array([y]))[1]
    links: list[tuple[int, int, float, float]] = []
    if not len(cand):
        return links
    kernel = compiled(planner, "point_links")
    if kernel is not None:
        # The same tangents in compiled code (the sight profile first rules out hidden ones).
        node, side = np.empty(2 * len(cand), np.int64), np.empty(2 * len(cand), np.int64)
        pos, length = np.empty(2 * len(cand)), np.empty(2 * len(cand))
        n = kernel(float(x), float(y), cand, planner.cx, planner.cy, planner.phi0, planner.span, r, ANG_TOL, TOUCH_TOL,
                   planner.sight_profile, *planner.geo.kernel_geometry(), node, side, pos, length)
        return list(zip(node[:n].tolist(), (1 - 2 * side[:n]).tolist(), pos[:n].tolist(), length[:n].tolist()))
    for s in (1, -1):
        ang, length, _, ok = tangent_from_point(x, y, planner.cx[cand], planner.cy[cand], r, s)
        ccw, ok_arc = ccw_pos(ang, planner.phi0[cand], planner.span[cand])
        ok &= ok_arc
        idx = np.flatnonzero(ok)
        if not len(idx):
            continue
        q = np.stack([planner.cx[cand[idx]] + r * np.cos(ang[idx]), planner.cy[cand[idx]] + r * np.sin(ang[idx])], axis=1)
        clear = planner.geo.segments_clear(np.array([x, y]), q, r)
        for i in idx[clear].tolist():
            c = int(cand[i])
            pos = float(ccw[i]) if s > 0 else planner.span_list[c] - float(ccw[i])
            links.append((c, s, pos, float(length[i])))
    return links
