"""The exact shortest path between two points on the tangent graph, without a goal field.

:func:`shortest_path` (what :meth:`Planner.shortest_path
<pointnav_core.geodesic.planner.Planner.shortest_path>` calls) joins the two points straight
where it can; otherwise it searches the whole graph when the planner has it
(:mod:`pointnav_core.geodesic.arc_search`), or runs :class:`PointSearch`, a label-setting
search (A* towards the target) over the planner's tangent edges, built lazily tile by tile.
On the whole graph, with numba, the query is one compiled call from the clearance tests to
the drawn points (:func:`~pointnav_core.geodesic.arc_search.compiled_path`; a crowd plans
this way at each arrival). Everything is in world metres and radians.
"""

from __future__ import annotations

import bisect
import heapq
import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.geodesic.arc_search import arc_graph_path, compiled_path
from pointnav_core.geodesic.arcs import ARC_PIECE, draw_arcs
from pointnav_core.geodesic.tangents import ANG_TOL, COST_TOL

if TYPE_CHECKING:
    from pointnav_core.geodesic.arc_graph import ArcGraph
    from pointnav_core.geodesic.planner import Planner

__all__ = ["PointSearch", "shortest_path"]


def shortest_path(
    planner: Planner, source: ArrayLike, target: ArrayLike, graph: ArcGraph | None, piece: float = ARC_PIECE
) -> tuple[NDArray[np.float64], float] | tuple[None, None]:
    """The exact shortest path from ``source`` to ``target`` (world m): the drawn path (N, 2),
    its arcs in pieces of at most ``piece`` (rad), and its length (m), or ``(None, None)``;
    on ``graph`` (the planner's whole graph) if given, else by the lazy :class:`PointSearch`."""
    p = planner
    src = np.asarray(source, dtype=np.float64)[:2]
    tgt = np.asarray(target, dtype=np.float64)[:2]
    sx, sy, tx, ty = float(src[0]), float(src[1]), float(tgt[0]), float(tgt[1])
    if graph is not None:
        found = compiled_path(graph, (sx, sy), (tx, ty), piece)
        if found is not None:
            return found
    if not (p.is_clear(sx, sy) and p.is_clear(tx, ty)):
        return None, None
    if p.segment_clear(src, tgt):
        return np.array([src, tgt]), math.hypot(tx - sx, ty - sy)
    # Links into the target, seen from the target: reversed, they leave a node.
    finish: dict[tuple[int, int], list[tuple[float, float]]] = {}
    for c, s, pos, length in p.point_links(tx, ty):
        finish.setdefault((c, -s), []).append((p.span_list[c] - pos, length))
    if graph is not None:
        found = arc_graph_path(graph, (sx, sy), (tx, ty), p.point_links(sx, sy),
                               [(c, s, pos, length) for (c, s), deps in finish.items() for pos, length in deps], piece)
        if found is None:
            return None, None
        pts, cost = found
        return pts[::-1].copy(), cost
    search = PointSearch(p, heuristic_to=(tx, ty))
    for c, s, pos, length in p.point_links(sx, sy):
        search.push(length, c, s, pos, -1, 0.0)
    best = search.run(finish)
    if best is None:
        return None, None
    cost, label, dep = best
    pts = [np.array([tx, ty]), *search.trace(label, dep, piece), np.array([sx, sy])]
    return np.array(pts[::-1]), cost


class PointSearch:
    """Label-setting search over the tangent graph (Dijkstra, or A* towards a point)."""

    def __init__(self, planner: Planner, heuristic_to: tuple[float, float] | None = None) -> None:
        self.p = planner
        self.heap: list[tuple[float, float, int, int, int, float, int, float]] = []
        self.count = 0
        self.hx = heuristic_to
        # Settled labels.
        self.node: list[int] = []
        self.side: list[int] = []
        self.pos: list[float] = []
        self.cost: list[float] = []
        self.parent: list[int] = []
        self.parent_dep: list[float] = []
        self.settled: dict[tuple[int, int], list[int]] = {}

    def push(self, g: float, node: int, s: int, pos: float, parent: int, dep: float) -> None:
        f = g
        if self.hx is not None:
            x, y = self.p.node_point(node, s, pos)
            f = g + math.hypot(x - self.hx[0], y - self.hx[1])
        self.count += 1
        heapq.heappush(self.heap, (f, g, self.count, node, s, pos, parent, dep))

    def _dominated(self, node: int, s: int, pos: float, g: float) -> bool:
        labels = self.settled.get((node, s))
        if not labels:
            return False
        r = self.p.radius
        for lab in labels:
            lp = self.pos[lab]
            if lp <= pos + ANG_TOL and self.cost[lab] + r * max(pos - lp, 0.0) <= g + COST_TOL:
                if self.p.arc_free(node, s, lp, pos):
                    return True
        return False

    def run(
        self, finish: dict[tuple[int, int], list[tuple[float, float]]] | None = None
    ) -> tuple[float, int, float] | None:
        """Settle labels in cost order; with ``finish``, stop at the first finished path.

        ``finish`` maps ``(node, side)`` to ``(departure position, length)`` of the final
        tangents to the target. Returns ``(cost, label, departure)`` of the best finish.
        """
        p = self.p
        r = p.radius
        heap = self.heap
        while heap:
            f, g, _, node, s, pos, parent, dep = heapq.heappop(heap)
            if node < 0:  # a finished path
                return g, parent, dep
            if self._dominated(node, s, pos, g):
                continue
            lab = len(self.node)
            self.node.append(node)
            self.side.append(s)
            self.pos.append(pos)
            self.cost.append(g)
            self.parent.append(parent)
            self.parent_dep.append(dep)
            self.settled.setdefault((node, s), []).append(lab)
            if finish is not None:
                for fdep, flen in finish.get((node, s), ()):
                    if fdep >= pos - ANG_TOL and p.arc_free(node, s, pos, fdep):
                        total = g + r * max(fdep - pos, 0.0) + flen
                        self.count += 1
                        heapq.heappush(heap, (total, total, self.count, -1, 0, 0.0, lab, fdep))
            deps, to, side, arr, length = p.edge_lists(node, s)
            start = bisect.bisect_left(deps, pos - ANG_TOL)
            if start >= len(deps):
                continue
            blocked = p.blocked_ccw[node]
            for i in range(start, len(deps)):
                d = deps[i]
                if blocked and not p.arc_free(node, s, pos, d):
                    break
                self.push(g + r * max(d - pos, 0.0) + length[i], to[i], side[i], arr[i], lab, d)
        return None

    def trace(self, label: int, dep: float, piece: float = ARC_PIECE) -> list[NDArray[np.float64]]:
        """Points from the departure at ``dep`` on ``label``'s arc back to the first node, the
        arcs drawn in pieces of at most ``piece`` (rad)."""
        arcs = []
        while label >= 0:
            arcs.append((self.node[label], self.side[label], dep, self.pos[label]))
            dep = self.parent_dep[label]
            label = self.parent[label]
        return list(draw_arcs(self.p, arcs, piece))
