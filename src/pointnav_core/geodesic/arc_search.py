"""The exact shortest path between two points on the arc graph: one A* in compiled code.

:meth:`Planner.shortest_path <pointnav_core.geodesic.planner.Planner.shortest_path>` takes
this path once the floor's :class:`~pointnav_core.geodesic.arc_graph.ArcGraph` exists (a goal
field built it: every reset of an env does), and the lazy label-setting search
(:mod:`pointnav_core.geodesic.point_search`) before that, on floors too large to build whole.
Both search the same graph with the same straight-line heuristic, so their lengths agree to
rounding (a property test holds them within 1e-9 m); where two paths tie, they may draw
different ones.

The arc graph gets, for one query, the source's tangents as **arrivals** (vertices of their
own, as :meth:`ArcGraph.solve` seeds them) and the target's tangents as **finishes**: a
finish leaves its arc at a departure position and costs its tangent's length; it is entered
from the last vertex of its arc at or before that position (an earlier vertex reaches that
one along the arc at least as cheaply, and where the arc between them is blocked, so is
the way to the departure), and from an arrival on the same arc before it. The search stops
at the first finish it settles: the heuristic (straight-line distance to the target) is
consistent, since no tangent is shorter than its chord and no arc shorter than its chord.
With numba, :func:`compiled_path` does all of a query, from the two points' tangents to
the drawn path, in one compiled call (``geodesic._path_kernel.point_path``), the same
steps as :func:`~pointnav_core.geodesic.point_search.shortest_path` and
:func:`arc_graph_path`. Everything is in world metres and radians.
"""

from __future__ import annotations

import heapq
import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from pointnav_core.floor.collision import TOUCH_TOL
from pointnav_core.geodesic.arc_graph import EPS_W
from pointnav_core.geodesic.arcs import ARC_PIECE, draw_arcs
from pointnav_core.geodesic.tangents import ANG_TOL
from pointnav_core.utils import compiled as _compiled

if TYPE_CHECKING:
    from pointnav_core.geodesic.arc_graph import ArcGraph

__all__ = ["DRAWN", "NOT_CLEAR", "NO_PATH", "PINCHED", "STRAIGHT", "arc_graph_path", "compiled_path", "seeded_astar"]

Link = tuple[int, int, float, float]

#: ``_path_kernel.point_path``'s outcomes: an end where the disc does not fit, no path, the
#: straight segment, a drawn path, a path whose arcs Python must split (drawn, not clear).
NOT_CLEAR, NO_PATH, STRAIGHT, DRAWN, PINCHED = range(5)


def compiled_path(
    graph: ArcGraph, source: tuple[float, float], target: tuple[float, float], piece: float = ARC_PIECE
) -> tuple[NDArray[np.float64], float] | tuple[None, None] | None:
    """:func:`~pointnav_core.geodesic.point_search.shortest_path` on ``graph`` in one
    compiled call (``geodesic._path_kernel.point_path``): the drawn path (N, 2) from
    ``source`` to ``target`` (m), its arcs in pieces of at most ``piece`` (rad), and its
    length (m), ``(None, None)`` without one, or None where the compiled path cannot run
    (no numba, or polygons it cannot read)."""
    p = graph.p
    kernel = _compiled.kernel("pointnav_core.geodesic._path_kernel", "point_path")
    if kernel is None or not p.geo.compiled_polygons:
        return None
    outcome, cost, pts, *arcs = kernel(float(source[0]), float(source[1]), float(target[0]), float(target[1]),
                                       *graph.kernel_arguments(), p.radius, ANG_TOL, TOUCH_TOL, float(piece), EPS_W)
    if outcome in (NOT_CLEAR, NO_PATH):
        return None, None
    if outcome == PINCHED:  # a passage as wide as the robot: its arcs split where it pinches
        drawn = draw_arcs(p, list(zip(*(a.tolist() for a in arcs))), piece)
        pts = np.concatenate([[target], drawn, [source]])[::-1].copy()
    return pts, float(cost)


def arc_graph_path(
    graph: ArcGraph, source: tuple[float, float], target: tuple[float, float], starts: list[Link], finishes: list[Link],
    piece: float = ARC_PIECE,
) -> tuple[NDArray[np.float64], float] | None:
    """The shortest path from ``source`` to ``target`` over ``graph``, or None if none.

    ``starts`` are the source's tangents ``(node, side, arrival, length)``; ``finishes`` the
    tangents into the target, as departures ``(node, side, departure, length)``. Returns
    the drawn points (M, 2) from the target back to the source (as the lazy search's
    trace gives them; arcs in pieces of at most ``piece`` rad) and the exact length (m).
    """
    p = graph.p
    n_v, n_x, n_f = graph.n_vertices, len(starts), len(finishes)
    x_node, x_side, x_pos, x_len = _columns(starts)
    f_node, f_side, f_pos, f_len = _columns(finishes)
    x_to, x_w = graph.arrival_steps(x_node, x_side, x_pos)
    # A finish is entered from the last vertex of its arc at or before its departure.
    f_from, f_arc = graph.departure_steps(f_node, f_side, f_pos)
    f_w = f_arc + f_len
    r = p.radius
    # ... and from an arrival on its arc before it (a path that wraps one node only).
    xf_w = np.full((n_x, n_f), np.inf)
    same = (x_node[:, None] == f_node[None, :]) & (x_side[:, None] == f_side[None, :]) & (x_pos[:, None] <= f_pos[None, :] + ANG_TOL)
    for k, f in zip(*(a.tolist() for a in np.nonzero(same))):
        if p.arc_free(int(f_node[f]), int(f_side[f]), float(x_pos[k]), float(f_pos[f])):
            xf_w[k, f] = r * max(float(f_pos[f] - x_pos[k]), 0.0) + f_len[f]
    x_x, x_y = graph.points(x_node, x_side, x_pos)
    vx, vy = graph.vertex_points()
    order = np.argsort(f_from, kind="stable")
    dist = np.full(n_v + n_x + n_f, np.inf)
    pred = np.full(n_v + n_x + n_f, -1, dtype=np.int64)
    kernel = _compiled.kernel("pointnav_core.geodesic._search_kernel", "seeded_astar")
    search = kernel if kernel is not None else seeded_astar
    best = search(graph.indptr, graph.indices, graph.data, vx, vy, x_len, x_to, x_w, x_x, x_y,
                  f_from[order], order, f_w, xf_w, float(target[0]), float(target[1]), dist, pred)
    if best < 0:
        return None
    arcs = []
    label, dep = int(pred[n_v + n_x + best]), float(f_pos[best])
    while label >= 0:
        # Back along the arc to where the path arrived on it, then to the tangent's start.
        g = _vertex(graph, x_node, x_side, x_pos, label)[:2]
        while pred[label] >= 0 and _vertex(graph, x_node, x_side, x_pos, int(pred[label]))[:2] == g:
            label = int(pred[label])
        arcs.append((g[0], g[1], dep, _vertex(graph, x_node, x_side, x_pos, label)[2]))
        label = int(pred[label])
        if label >= 0:
            dep = _vertex(graph, x_node, x_side, x_pos, label)[2]
    pts = np.concatenate([[target], draw_arcs(p, arcs, piece), [source]])
    return pts, float(dist[n_v + n_x + best])


def _vertex(
    graph: ArcGraph, x_node: NDArray[np.int32], x_side: NDArray[np.int8], x_pos: NDArray[np.float64], v: int
) -> tuple[int, int, float]:
    """Node, side and arc position of vertex ``v``: the graph's, or an arrival's after them."""
    n_v = graph.n_vertices
    if v < n_v:
        return int(graph.node[v]), int(graph.side[v]), float(graph.pos[v])
    return int(x_node[v - n_v]), int(x_side[v - n_v]), float(x_pos[v - n_v])


def _columns(links: list[Link]) -> tuple[NDArray[np.int32], NDArray[np.int8], NDArray[np.float64], NDArray[np.float64]]:
    """``links`` as arrays: nodes, sides, positions (rad) and lengths (m)."""
    return (
        np.array([c for c, _, _, _ in links], dtype=np.int32),
        np.array([s for _, s, _, _ in links], dtype=np.int8),
        np.array([q for _, _, q, _ in links], dtype=np.float64),
        np.array([ln for _, _, _, ln in links], dtype=np.float64),
    )


def seeded_astar(indptr, indices, data, vx, vy, x_cost, x_to, x_w, x_x, x_y, f_from, f_index, f_w, xf_w, tx, ty, dist, pred):  # pragma: no cover
    """A* over a CSR graph from seeded arrivals to the first settled finish, in place.

    Vertices: ``0 .. n_v - 1`` the graph's (at points ``(vx, vy)``, m), then arrival ``k``
    (at ``(x_x[k], x_y[k])``, reached at ``x_cost[k]``, continuing to ``x_to[k]`` if >= 0 at
    ``x_w[k]``), then finish ``f`` (at the target ``(tx, ty)``). Finish ``f_index[i]`` is
    entered from graph vertex ``f_from[i]`` (sorted; -1: none) at ``f_w[f_index[i]]``, and
    from arrival ``k`` at ``xf_w[k, f]`` (inf: not). ``dist`` (inf) and ``pred`` (-1) cover
    every vertex. Returns the finish reached, or -1. Plain Python on scalars, so that numba
    compiles the very same function.
    """
    n_v = vx.shape[0]
    n_x = x_cost.shape[0]
    n_f = f_w.shape[0]
    heap = [(0.0, 0.0, 0)]
    heap.pop()
    for k in range(n_x):
        v = n_v + k
        if x_cost[k] < dist[v]:
            dist[v] = x_cost[k]
            heapq.heappush(heap, (x_cost[k] + math.hypot(x_x[k] - tx, x_y[k] - ty), x_cost[k], v))
    while len(heap) > 0:
        _, d, v = heapq.heappop(heap)
        if d > dist[v]:
            continue
        if v >= n_v + n_x:
            return v - n_v - n_x  # a finish: nothing left in the heap is shorter
        if v >= n_v:
            k = v - n_v
            for f in range(n_f):
                relax(heap, dist, pred, v, n_v + n_x + f, d + xf_w[k, f], 0.0)
            u = x_to[k]
            if u >= 0:
                relax(heap, dist, pred, v, u, d + x_w[k], math.hypot(vx[u] - tx, vy[u] - ty))
            continue
        i = np.searchsorted(f_from, v)
        while i < f_from.shape[0] and f_from[i] == v:
            f = f_index[i]
            relax(heap, dist, pred, v, n_v + n_x + f, d + f_w[f], 0.0)
            i += 1
        for e in range(indptr[v], indptr[v + 1]):
            u = indices[e]
            relax(heap, dist, pred, v, u, d + data[e], math.hypot(vx[u] - tx, vy[u] - ty))
    return -1


def relax(heap, dist, pred, v, u, nd, h):  # pragma: no cover
    """Lower vertex ``u``'s cost to ``nd`` through ``v`` if shorter, queued at ``nd + h``."""
    if nd < dist[u]:
        dist[u] = nd
        pred[u] = v
        heapq.heappush(heap, (nd + h, nd, u))
