"""The compiled path of :func:`pointnav_core.geodesic.roots.cell_roots` (imports numba).

Imported only through :func:`pointnav_core.utils.compiled.kernel` when numba is installed (the
``fast`` extra). :func:`best_links` makes the numpy path's decision one cell at a time: of
the direct segment and every visible link, the smallest ``(total, order)``. The previous
cell's winner is tried first (neighbours mostly share a root); every other candidate whose
lower bound is below the best so far is evaluated, in any order, since the smallest
``(total, order)`` does not depend on it. The segment test is the collision kernel's (cell
squares, then polygon edges), after the node's sight profile has ruled out the links that
surely are hidden (:func:`pointnav_core.geodesic.sight.blocked_by_profile`). The scalar
math may round differently from numpy's array loops in the last bit, so the two paths agree
in value (a property test holds them equal within 1e-9 m), and in the root wherever two
roots do not tie. :func:`arc_tables` builds a field's
:class:`~pointnav_core.geodesic.roots.ArcTables` in one pass, the same arrays as numpy's.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from pointnav_core.floor._collision_kernel import segment_hits as _hits

__all__ = ["arc_tables", "best_links", "cell_links", "point_links", "table_roots"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")


@_jit
def _arc_free(blocked, has_blocked, span, node, s, p1, p2, tol):  # pragma: no cover
    # Planner.arcs_free for one arc piece: no blocked sample strictly between p1 and p2.
    if not has_blocked[node]:
        return True
    if s > 0:
        lo = p1
        hi = p2
    else:
        lo = span[node] - p2
        hi = span[node] - p1
    for j in range(blocked.shape[1]):
        b = blocked[node, j]
        if lo + tol < b and b < hi - tol:
            return False
    return True


@_jit
def _link_value(c, s, dep, length, r, ang_tol, span, lab_start, graph_end, labels, lab_pos, lab_cost, blocked,
                has_blocked):  # pragma: no cover
    """The best total (m; inf: none) and label of a link of winding ``s`` to node ``c``, its
    reverse path leaving the arc at ``dep`` (rad) after a tangent of ``length`` (m)."""
    # The link's best label on the arc its reverse path leaves along (winding -s). Along the
    # arc, Dijkstra's costs grow by at most r per radian from vertex to vertex, so of the
    # graph's vertices the last at or before the departure is the best (a blocked piece of
    # arc between it and the departure blocks every earlier one too); the field's own
    # arrivals are looked at one by one.
    g = 2 * c + (1 if s > 0 else 0)
    value = math.inf
    lab = -1
    lo_j = lab_start[g]
    hi_j = graph_end[g]
    while lo_j < hi_j:
        mid = (lo_j + hi_j) // 2
        if lab_pos[labels[mid]] <= dep + ang_tol:
            lo_j = mid + 1
        else:
            hi_j = mid
    for j in range(max(lo_j - 1, lab_start[g]), lab_start[g + 1]):
        if j < graph_end[g] and j != lo_j - 1:
            continue
        lb = labels[j]
        lp = lab_pos[lb]
        if lp <= dep + ang_tol and _arc_free(blocked, has_blocked, span, c, -s, lp, dep, ang_tol):
            v = lab_cost[lb] + r * max(dep - lp, 0.0) + length
            if v < value:
                value = v
                lab = lb
    return value, lab


@_jit
def _link(px, py, c, s, cx, cy, phi0, span, r, ang_tol, touch_tol, profile):  # pragma: no cover
    """The tangent from ``(px, py)`` to node ``c`` arriving winding ``s`` (``tangents.
    tangent_from_point`` and ``ccw_pos`` on scalars): ``(ok, ccw, length, qx, qy)``, ``ok``
    False where the point is inside the circle, the tangent misses the arc, or the node's
    sight profile says it is surely hidden."""
    two_pi = 2.0 * math.pi
    dx = cx[c] - px
    dy = cy[c] - py
    L = math.hypot(dx, dy)
    if not (L >= r - touch_tol):
        return False, 0.0, 0.0, 0.0, 0.0
    heading = math.atan2(dy, dx) + (-s * math.asin(min(max(r / max(L, r), -1.0), 1.0)))
    ang = heading - s * (math.pi / 2)
    length = math.sqrt(max(L * L - r * r, 0.0))
    ccw = (ang - phi0[c]) % two_pi
    if ccw > two_pi - ang_tol:
        ccw = 0.0
    if not ccw <= span[c] + ang_tol:
        return False, 0.0, 0.0, 0.0, 0.0
    qx = cx[c] + r * math.cos(ang)
    qy = cy[c] + r * math.sin(ang)
    # Surely hidden: longer than the node's sight in the direction it would leave.
    n_bins = profile.shape[1]
    b = int(math.floor((math.atan2(py - qy, px - qx) % two_pi) / (two_pi / n_bins))) % n_bins
    if length > profile[c, b]:
        return False, 0.0, 0.0, 0.0, 0.0
    return True, min(ccw, span[c]), length, qx, qy


@_jit
def best_links(  # pragma: no cover
    x, y, gx, gy, cand, cand_lo, cand_hi, by_cheap, slack,
    cx, cy, phi0, span, r, ang_tol, touch_tol, ball,
    profile, cheapest, lab_start, graph_end, labels, lab_pos, lab_cost, blocked, has_blocked,
    ox, oy, res, rowcum, outside_blocked, boxes, first, last, ex0, ey0, ex1, ey1, use_polygons,
    kind, best_lab, best_value, best_dep,
):
    """Per clear point ``(x[i], y[i])``, over the candidate nodes ``cand[cand_lo[i]:cand_hi[i]]``
    (those whose sight ball, radius ``ball``, holds the point count): the kind (0 none, 1 the
    goal ``(gx, gy)`` directly, 2 a label), label and total (m; inf: none) of the smallest
    visible ``(total, order)``, the direct segment first, written into ``kind``, ``best_lab``
    and ``best_value``, and the departure (rad) on the label's arc into ``best_dep``. With ``by_cheap`` the candidates are in ascending order of their
    arcs' cheapest label, and the scan stops where that alone passes the best."""
    inv = 1.0 / res
    rho = max(r - touch_tol, touch_tol) * inv
    reach = max(r - 2 * touch_tol, touch_tol / 2)
    n_nodes = cx.shape[0]
    hint = -1
    for i in range(x.shape[0]):
        px = x[i]
        py = y[i]
        winner = -1
        best = math.inf
        if not _hits(px, py, gx, gy, ox, oy, inv, rho, rowcum, outside_blocked, reach, boxes, first, last, ex0, ey0,
                     ex1, ey1, use_polygons):
            best = math.hypot(gx - px, gy - py)
        kind[i] = 1 if best < math.inf else 0
        best_lab[i] = -1
        best_dep[i] = 0.0
        best_order = -1
        # The previous point's winner first (neighbours mostly share a root): its total bounds
        # the rest, which are skipped where their lower bound (the arcs' cheapest label plus
        # the distance less r) is no better. The smallest (total, order) does not depend on
        # the order of evaluation.
        for step in range(cand_lo[i] - 1, cand_hi[i]):
            if step < cand_lo[i]:
                c = hint
                if c < 0:
                    continue
            else:
                c = cand[step]
                if c == hint:
                    continue
            cheap = min(cheapest[2 * c], cheapest[2 * c + 1])
            if by_cheap and step >= cand_lo[i] and not cheap - r - slack * (1.0 + cheap) < best:
                break
            dx = cx[c] - px
            dy = cy[c] - py
            if dx * dx + dy * dy > ball[c] * ball[c]:
                continue
            dist = math.sqrt(dx * dx + dy * dy)
            if not cheap + (dist - r) - slack * (1.0 + cheap + dist) < best:
                continue
            for side_rank in range(2):
                s = 1.0 if side_rank == 0 else -1.0
                ok, ccw, length, qx, qy = _link(px, py, c, s, cx, cy, phi0, span, r, ang_tol, touch_tol, profile)
                if not ok:
                    continue
                pos = ccw if s > 0 else span[c] - ccw
                order = side_rank * n_nodes + c
                value, lab = _link_value(c, s, span[c] - pos, length, r, ang_tol, span, lab_start, graph_end, labels,
                                         lab_pos, lab_cost, blocked, has_blocked)
                if lab < 0:
                    continue
                if not (value < best or (value == best and order < best_order)):
                    continue
                if _hits(px, py, qx, qy, ox, oy, inv, rho, rowcum, outside_blocked, reach, boxes, first, last, ex0, ey0,
                         ex1, ey1, use_polygons):
                    continue
                best = value
                best_order = order
                best_lab[i] = lab
                best_dep[i] = span[c] - pos
                kind[i] = 2
                winner = c
        hint = winner
        best_value[i] = best


@_jit
def point_links(  # pragma: no cover
    px, py, cand, cx, cy, phi0, span, r, ang_tol, touch_tol, profile,
    ox, oy, res, rowcum, outside_blocked, boxes, first, last, ex0, ey0, ex1, ey1, use_polygons,
    node_out, side_out, pos_out, length_out,
):
    """``Planner.point_links`` of ``(px, py)`` over the candidate nodes ``cand``: each side
    (+1 first), each candidate in order, the tangents that land on the node's arc and are
    clear. Writes them into the ``*_out`` arrays (room for ``2 * len(cand)``); returns how many."""
    inv = 1.0 / res
    rho = max(r - touch_tol, touch_tol) * inv
    reach = max(r - 2 * touch_tol, touch_tol / 2)
    n = 0
    for side_rank in range(2):
        s = 1.0 if side_rank == 0 else -1.0
        for k in range(cand.shape[0]):
            c = cand[k]
            ok, ccw, length, qx, qy = _link(px, py, c, s, cx, cy, phi0, span, r, ang_tol, touch_tol, profile)
            if not ok:
                continue
            if _hits(px, py, qx, qy, ox, oy, inv, rho, rowcum, outside_blocked, reach, boxes, first, last, ex0, ey0,
                     ex1, ey1, use_polygons):
                continue
            node_out[n] = c
            side_out[n] = side_rank
            pos_out[n] = ccw if s > 0 else span[c] - ccw
            length_out[n] = length
            n += 1
    return n


@_jit
def cell_links(  # pragma: no cover
    x, y, cand, cand_lo, cand_hi, cx, cy, phi0, span, r, ang_tol, touch_tol, ball, profile,
    ox, oy, res, rowcum, outside_blocked, boxes, first, last, ex0, ey0, ex1, ey1, use_polygons,
    node_out, side_out, pos_out, length_out, count,
):
    """Every visible link of each point ``(x[i], y[i])`` over the candidate nodes
    ``cand[cand_lo[i]:cand_hi[i]]``: the tangents that land on a node's arc, within its sight
    ball (radius ``ball``), and are clear, as :func:`best_links` tests them. Writes them point
    after point into the ``*_out`` arrays (``side_out`` 0 for winding +1, 1 for -1; ``pos_out``
    as :func:`best_links` computes it) and each point's number into ``count``; returns the
    total, or -1 when the ``*_out`` arrays are too short."""
    inv = 1.0 / res
    rho = max(r - touch_tol, touch_tol) * inv
    reach = max(r - 2 * touch_tol, touch_tol / 2)
    n = 0
    cap = node_out.shape[0]
    for i in range(x.shape[0]):
        px = x[i]
        py = y[i]
        count[i] = 0
        for step in range(cand_lo[i], cand_hi[i]):
            c = cand[step]
            dx = cx[c] - px
            dy = cy[c] - py
            if dx * dx + dy * dy > ball[c] * ball[c]:
                continue
            for side_rank in range(2):
                s = 1.0 if side_rank == 0 else -1.0
                ok, ccw, length, qx, qy = _link(px, py, c, s, cx, cy, phi0, span, r, ang_tol, touch_tol, profile)
                if not ok:
                    continue
                if _hits(px, py, qx, qy, ox, oy, inv, rho, rowcum, outside_blocked, reach, boxes, first, last, ex0, ey0,
                         ex1, ey1, use_polygons):
                    continue
                if n == cap:
                    return -1
                node_out[n] = c
                side_out[n] = side_rank
                pos_out[n] = ccw if s > 0 else span[c] - ccw
                length_out[n] = length
                n += 1
                count[i] += 1
    return n


@_jit
def table_roots(  # pragma: no cover
    x, y, gx, gy, link_first, link_count, link_node, link_side, link_pos, link_length, n_nodes,
    span, r, ang_tol, touch_tol, lab_start, graph_end, labels, lab_pos, lab_cost, blocked, has_blocked,
    ox, oy, res, rowcum, outside_blocked, boxes, first, last, ex0, ey0, ex1, ey1, use_polygons,
    kind, best_lab, best_value,
):
    """:func:`best_links`' decision for clear points whose visible links are known
    (``link_*[link_first[i]:link_first[i] + link_count[i]]``, from :func:`cell_links`): the
    direct segment to the goal (its one segment test), then the smallest ``(total, order)``
    over the links, with no further segment test."""
    inv = 1.0 / res
    rho = max(r - touch_tol, touch_tol) * inv
    reach = max(r - 2 * touch_tol, touch_tol / 2)
    for i in range(x.shape[0]):
        px = x[i]
        py = y[i]
        best = math.inf
        if not _hits(px, py, gx, gy, ox, oy, inv, rho, rowcum, outside_blocked, reach, boxes, first, last, ex0, ey0,
                     ex1, ey1, use_polygons):
            best = math.hypot(gx - px, gy - py)
        kind[i] = 1 if best < math.inf else 0
        best_lab[i] = -1
        best_order = -1
        for j in range(link_first[i], link_first[i] + link_count[i]):
            c = link_node[j]
            side_rank = link_side[j]
            s = 1.0 if side_rank == 0 else -1.0
            value, lab = _link_value(c, s, span[c] - link_pos[j], link_length[j], r, ang_tol, span, lab_start,
                                     graph_end, labels, lab_pos, lab_cost, blocked, has_blocked)
            if lab < 0:
                continue
            order = side_rank * n_nodes + c
            if value < best or (value == best and order < best_order):
                best = value
                best_order = order
                best_lab[i] = lab
                kind[i] = 2
        best_value[i] = best


@_jit
def arc_tables(cost, group, n_vertices, n_groups):  # pragma: no cover
    """:class:`~pointnav_core.geodesic.roots.ArcTables`' arrays in one pass: the reached
    labels grouped by arc (a stable counting sort, so each group keeps label order, graph
    vertices first), each group's start and graph end, each group's cheapest cost, and the
    nodes with a reached arc by their cheapest label (a stable sort)."""
    start = np.zeros(n_groups + 1, dtype=np.int64)
    for lab in range(cost.shape[0]):
        if math.isfinite(cost[lab]):
            start[group[lab] + 1] += 1
    for g in range(n_groups):
        start[g + 1] += start[g]
    labels = np.empty(start[n_groups], dtype=np.int64)
    fill = start[:n_groups].copy()
    graph_end = start[:n_groups].copy()
    cheapest = np.full(n_groups, math.inf)
    for lab in range(cost.shape[0]):
        c = cost[lab]
        if math.isfinite(c):
            g = group[lab]
            labels[fill[g]] = lab
            fill[g] += 1
            if lab < n_vertices:
                graph_end[g] += 1
            if c < cheapest[g]:
                cheapest[g] = c
    node_cheap = np.minimum(cheapest[0::2], cheapest[1::2])
    reached = np.flatnonzero(np.isfinite(node_cheap))
    by_cheap = reached[np.argsort(node_cheap[reached], kind="mergesort")].astype(np.int64)
    return labels, start, graph_end, cheapest, by_cheap
