"""The compiled point-to-point search on the whole arc graph (imports numba).

Imported only through :func:`pointnav_core.utils.compiled.kernel` when numba is installed (the
``fast`` extra). :func:`point_path` is :func:`pointnav_core.geodesic.point_search.
shortest_path` on a floor whose :class:`~pointnav_core.geodesic.arc_graph.ArcGraph` exists,
in one call: the two clearance tests, both points' tangent links (the sight balls by brute
force, then ``_roots_kernel.point_links``), where each link joins its arc
(``ArcGraph.arrival_steps`` and ``departure_steps``), the links that share an arc, the A*
(``_search_kernel.seeded_astar``), the trace back through its predecessors, and the arcs
drawn as ``arcs.draw_arcs`` draws them. Where a drawn vertex is not clear (a passage exactly
as wide as the robot), it hands the arcs back and Python splits them (``arcs._split_pinched``).
Every statement follows the Python path's in the same order; cosines may round differently
in the last bit from numpy's, so a property test holds the two within 1e-9 m.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from pointnav_core.floor._collision_kernel import segment_clear as _clear
from pointnav_core.geodesic import arc_search as _outcome  # the outcomes' names
from pointnav_core.geodesic._roots_kernel import _arc_free, point_links
from pointnav_core.geodesic._search_kernel import seeded_astar

__all__ = ["point_path"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")


@_jit
def _links(px, py, nodes, geometry, r, ang_tol, touch_tol):  # pragma: no cover
    # Planner.point_links: the nodes whose sight ball holds the point (NodeBalls.query), in
    # order, then their clear tangents; sides as +1 / -1.
    cx, cy, phi0, span, ball, profile = nodes
    cand = np.empty(cx.shape[0], np.int64)
    n = 0
    for c in range(cx.shape[0]):
        if np.hypot(px - cx[c], py - cy[c]) <= ball[c]:
            cand[n] = c
            n += 1
    cand = cand[:n]
    node, side = np.empty(2 * n, np.int64), np.empty(2 * n, np.int64)
    pos, length = np.empty(2 * n), np.empty(2 * n)
    ox, oy, res, rowcum, outside, boxes, first, last, ex0, ey0, ex1, ey1, use_polygons = geometry
    k = point_links(px, py, cand, cx, cy, phi0, span, r, ang_tol, touch_tol, profile, ox, oy, res, rowcum, outside,
                    boxes, first, last, ex0, ey0, ex1, ey1, use_polygons, node, side, pos, length)
    return node[:k], 1 - 2 * side[:k], pos[:k], length[:k]


@_jit
def _arc_steps(node, side, q, forward, arcs, r, ang_tol):  # pragma: no cover
    # ArcGraph._arc_steps: per arc position q[k], the vertex it goes on to (forward: the
    # first at or after it) or comes from (the last at or before it), -1 where none is or
    # the arc between is blocked, and that arc's cost (m).
    grp_start, grp_end, vpos, blocked, has_blocked, span = arcs
    to = np.full(q.shape[0], -1, np.int64)
    cost = np.zeros(q.shape[0])
    for k in range(q.shape[0]):
        g = 2 * node[k] + (1 if side[k] < 0 else 0)
        lo, hi = grp_start[g], grp_end[g]
        a, b = lo, hi
        key = q[k] - ang_tol if forward else q[k] + ang_tol
        while a < b:  # ArcGraph.locate: the first vertex at or after (after: past) key
            mid = (a + b) // 2
            if (vpos[mid] < key) if forward else (vpos[mid] <= key):
                a = mid + 1
            else:
                b = mid
        j = a if forward else a - 1
        if (j >= hi) if forward else (j < lo):
            continue
        at = vpos[j]
        lo_pos, hi_pos = (q[k], at) if forward else (at, q[k])
        if _arc_free(blocked, has_blocked, span, node[k], side[k], lo_pos, hi_pos, ang_tol):
            to[k] = j
            cost[k] = r * max(hi_pos - lo_pos, 0.0)
    return to, cost


@_jit
def _node_point(nodes, node, s, pos, reach):  # pragma: no cover
    # Planner.node_point at distance reach (m) from the node's centre.
    cx, cy, phi0, span, _, _ = nodes
    a = phi0[node] + (pos if s > 0 else span[node] - pos)
    return cx[node] + reach * math.cos(a), cy[node] + reach * math.sin(a)


@_jit
def _draw(arcs_node, arcs_side, arcs_from, arcs_to, nodes, r, ang_tol, piece_max, walls, out, at):  # pragma: no cover
    # arcs.draw_arcs into out[at:]: each arc's ends on the circle and, between them, the
    # vertices of pieces of at most piece_max (rad) tangent to it. Returns the next row, or
    # -1 where an inner vertex is not clear (the arc must be split at its pinch).
    for a in range(arcs_node.shape[0]):
        node, s, p_from, p_to = arcs_node[a], arcs_side[a], arcs_from[a], arcs_to[a]
        out[at, 0], out[at, 1] = _node_point(nodes, node, s, p_from, r)
        at += 1
        delta = p_from - p_to
        if delta <= ang_tol or r == 0.0:
            continue
        n = max(1, math.ceil(delta / piece_max))
        piece = delta / n
        reach = r / math.cos(piece / 2)
        for i in range(n):
            x, y = _node_point(nodes, node, s, p_from - piece * (i + 0.5), reach)
            if not _clear(x, y, x, y, walls):
                return -1
            out[at, 0], out[at, 1] = x, y
            at += 1
        out[at, 0], out[at, 1] = _node_point(nodes, node, s, p_to, r)
        at += 1
    return at


@_jit
def _same_arc(x_node, x_side, x_pos, f_node, f_side, f_pos, f_len, arcs, r, ang_tol):  # pragma: no cover
    # arc_search.arc_graph_path's xf_w: finish f entered from arrival k on its arc before it
    # (a path that wraps one node only), at the arc's cost and the finish's tangent; inf: not.
    _, _, _, blocked, has_blocked, span = arcs
    xf_w = np.full((x_node.shape[0], f_node.shape[0]), np.inf)
    for k in range(x_node.shape[0]):
        for f in range(f_node.shape[0]):
            if x_node[k] == f_node[f] and x_side[k] == f_side[f] and x_pos[k] <= f_pos[f] + ang_tol and _arc_free(
                    blocked, has_blocked, span, f_node[f], f_side[f], x_pos[k], f_pos[f], ang_tol):
                xf_w[k, f] = r * max(f_pos[f] - x_pos[k], 0.0) + f_len[f]
    return xf_w


@_jit
def _drawn_path(sx, sy, tx, ty, arcs_node, arcs_side, arcs_from, arcs_to, nodes, r, ang_tol, piece_max,
                walls):  # pragma: no cover
    # The drawn path from the source to the target, (N, 2): the target, the arcs drawn by
    # _draw, the source, reversed; (0, 2) where a drawn vertex is not clear.
    size = 2
    for a in range(arcs_node.shape[0]):
        delta = arcs_from[a] - arcs_to[a]
        size += 1 if delta <= ang_tol or r == 0.0 else max(1, math.ceil(delta / piece_max)) + 2
    out = np.empty((size, 2))
    out[0, 0], out[0, 1] = tx, ty
    at = _draw(arcs_node, arcs_side, arcs_from, arcs_to, nodes, r, ang_tol, piece_max, walls, out, 1)
    if at < 0:
        return np.zeros((0, 2))
    out[at, 0], out[at, 1] = sx, sy
    return out[::-1].copy()


@_jit
def _trace(pred, first, g_node, g_side, g_pos, x_node, x_side, x_pos, dep):  # pragma: no cover
    # arc_search.arc_graph_path's trace: from the finish's predecessor ``first`` back to the
    # source, each arc as (node, side, departure, arrival), target side first.
    n_v = g_node.shape[0]
    count = 0
    v = first
    while v >= 0:
        count += 1
        v = pred[v]
    arcs_node, arcs_side = np.empty(count, np.int64), np.empty(count, np.int64)
    arcs_from, arcs_to = np.empty(count), np.empty(count)
    k = 0
    label = first
    while label >= 0:
        node = g_node[label] if label < n_v else x_node[label - n_v]
        side = g_side[label] if label < n_v else x_side[label - n_v]
        while pred[label] >= 0:  # back along the arc to where the path arrived on it
            u = pred[label]
            if (g_node[u] if u < n_v else x_node[u - n_v]) != node or (g_side[u] if u < n_v else x_side[u - n_v]) != side:
                break
            label = u
        arcs_node[k], arcs_side[k], arcs_from[k] = node, side, dep
        arcs_to[k] = g_pos[label] if label < n_v else x_pos[label - n_v]
        k += 1
        label = pred[label]
        if label >= 0:
            dep = g_pos[label] if label < n_v else x_pos[label - n_v]
    return arcs_node[:k], arcs_side[:k], arcs_from[:k], arcs_to[:k]


@_jit
def point_path(sx, sy, tx, ty, nodes, geometry, walls, arcs, graph, r, ang_tol, touch_tol, piece_max, eps_w):  # pragma: no cover
    """The shortest path from ``(sx, sy)`` to ``(tx, ty)`` (m) on the whole arc graph.

    Parameters
    ----------
    nodes : tuple
        The planner's node centres ``cx, cy`` (m), arc starts ``phi0`` and spans (rad),
        sight-ball radii (m) and sight profile.
    geometry : tuple
        ``FloorCollision.kernel_geometry()``.
    walls : tuple
        ``FloorCollision.kernel_arguments(r)``.
    arcs : tuple
        The graph's arc ranges ``grp_start, grp_end``, vertex positions (rad), and the
        planner's blocked arc samples, which nodes have any, and spans
        (``Planner.blocked_arcs``).
    graph : tuple
        The graph's CSR ``indptr, indices, data``, vertex nodes and sides, and vertex points
        ``vx, vy`` (m).
    r, ang_tol, touch_tol, piece_max, eps_w : float
        The planner's radius (m), the angle and touch tolerances, a drawn piece's largest
        angle (rad) and the graph's zero-weight offset.

    Returns
    -------
    outcome : int
        One of ``geodesic.arc_search``'s ``NOT_CLEAR`` (an end where the disc does not
        fit), ``NO_PATH``, ``STRAIGHT``, ``DRAWN`` or ``PINCHED`` (found, not drawn).
    cost : float
        The length (m), inf without a path.
    points : (N, 2) float64
        The drawn path from the source to the target (outcomes STRAIGHT and DRAWN).
    arcs_node, arcs_side, arcs_from, arcs_to
        The path's arcs (target side first), as ``arcs.draw_arcs`` takes them.
    """
    none_i, none_f = np.zeros(0, np.int64), np.zeros(0)
    empty = np.zeros((0, 2))
    if not (_clear(sx, sy, sx, sy, walls) and _clear(tx, ty, tx, ty, walls)):
        return _outcome.NOT_CLEAR, math.inf, empty, none_i, none_i, none_f, none_f
    if _clear(sx, sy, tx, ty, walls):
        pts = np.empty((2, 2))
        pts[0, 0], pts[0, 1], pts[1, 0], pts[1, 1] = sx, sy, tx, ty
        return _outcome.STRAIGHT, math.hypot(tx - sx, ty - sy), pts, none_i, none_i, none_f, none_f
    span = nodes[3]
    # Links into the target, seen from the target: reversed, they leave a node.
    f_node, f_side, f_pos, f_len = _links(tx, ty, nodes, geometry, r, ang_tol, touch_tol)
    f_side = -f_side
    f_pos = span[f_node] - f_pos
    x_node, x_side, x_pos, x_len = _links(sx, sy, nodes, geometry, r, ang_tol, touch_tol)
    n_x, n_f = x_node.shape[0], f_node.shape[0]
    x_to, x_w = _arc_steps(x_node, x_side, x_pos, True, arcs, r, ang_tol)
    for k in range(n_x):
        if x_to[k] >= 0:
            x_w[k] += eps_w
    f_from, f_arc = _arc_steps(f_node, f_side, f_pos, False, arcs, r, ang_tol)
    f_w = f_arc + f_len
    xf_w = _same_arc(x_node, x_side, x_pos, f_node, f_side, f_pos, f_len, arcs, r, ang_tol)
    indptr, indices, data, g_node, g_side, vx, vy = graph
    n_v = vx.shape[0]
    x_x, x_y = np.empty(n_x), np.empty(n_x)
    for k in range(n_x):
        x_x[k], x_y[k] = _node_point(nodes, x_node[k], x_side[k], x_pos[k], r)
    order = np.argsort(f_from, kind="mergesort")
    dist = np.full(n_v + n_x + n_f, np.inf)
    pred = np.full(n_v + n_x + n_f, -1, np.int64)
    best = seeded_astar(indptr, indices, data, vx, vy, x_len, x_to, x_w, x_x, x_y, f_from[order], order, f_w, xf_w,
                        tx, ty, dist, pred)
    if best < 0:
        return _outcome.NO_PATH, math.inf, empty, none_i, none_i, none_f, none_f
    cost = dist[n_v + n_x + best]
    arc_n, arc_s, arc_a, arc_b = _trace(pred, pred[n_v + n_x + best], g_node, g_side, arcs[2], x_node, x_side, x_pos,
                                        f_pos[best])
    out = _drawn_path(sx, sy, tx, ty, arc_n, arc_s, arc_a, arc_b, nodes, r, ang_tol, piece_max, walls)
    if out.shape[0] == 0:
        return _outcome.PINCHED, cost, empty, arc_n, arc_s, arc_a, arc_b
    return _outcome.DRAWN, cost, out, arc_n, arc_s, arc_a, arc_b
