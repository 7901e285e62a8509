"""The tangent graph as a plain weighted digraph, solved by scipy's Dijkstra.

A label of the tangent-graph search is a position on a node's arc; the arc between two
positions costs ``r * angle``. Splitting every arc at the ends of the tangent edges on it
turns the graph into an ordinary digraph with non-negative weights:

- a **vertex** is one end of one tangent edge: ``(node, side, position)``;
- an **arc edge** joins consecutive vertices of one ``(node, side)`` arc in winding order,
  weighted ``r * (pos2 - pos1)``, where the arc between them is clear;
- a **tangent edge** joins its departure vertex to its arrival vertex, weighted by the
  segment's length.

Shortest paths in this graph are the label-setting search's shortest paths (a label that
an earlier label on the same arc dominates is exactly a vertex reached more cheaply along
the arc), so a goal field is one call of :func:`scipy.sparse.csgraph.dijkstra` in C instead
of a Python heap loop. Distances are exact; only the vertex set is fixed per planner.
"""

from __future__ import annotations

import heapq
import itertools
import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from scipy import sparse
from scipy.sparse import csgraph

from pointnav_core.geodesic.tangents import ANG_TOL
from pointnav_core.utils import compiled as _compiled

if TYPE_CHECKING:
    from pointnav_core.geodesic.planner import Planner

__all__ = ["EPS_W", "ArcGraph", "FieldLabels", "seeded_dijkstra"]

#: Added to every weight: scipy reads a stored zero as no edge.
EPS_W = 1e-300


class ArcGraph:
    """Every tangent edge of a planner, with its arcs split at the edges' ends.

    Parameters
    ----------
    planner : Planner
        Its edges are built for every node first.
    """

    def __init__(self, planner: Planner) -> None:
        p = planner
        self.p = p
        p.build_all_edges()
        keys = list(p.edge_store.keys())
        vals = [p.edge_store[k] for k in keys]
        counts = np.fromiter((len(v[0]) for v in vals), dtype=np.int64, count=len(vals))
        n_e = int(counts.sum())
        a_node = np.repeat(np.fromiter((k[0] for k in keys), dtype=np.int64, count=len(keys)), counts)
        a_side = np.repeat(np.fromiter((k[1] for k in keys), dtype=np.int8, count=len(keys)), counts)

        def flat(i: int, dtype: Any) -> NDArray[Any]:
            return np.fromiter(itertools.chain.from_iterable(v[i] for v in vals), dtype=dtype, count=n_e)

        dep, to, sb, arr, length = flat(0, np.float64), flat(1, np.int64), flat(2, np.int8), flat(3, np.float64), flat(4, np.float64)
        # Vertex e: departure of edge e; vertex n_e + e: its arrival.
        node = np.concatenate([a_node, to])
        side = np.concatenate([a_side, sb])
        pos = np.concatenate([dep, arr])
        group = node * 2 + (side < 0)
        order = np.lexsort((pos, group))
        rank = np.empty(len(order), dtype=np.int64)
        rank[order] = np.arange(len(order))
        self.node = node[order].astype(np.int32)
        self.side = side[order]
        self.pos = pos[order]
        self.group = group[order]
        self.n_vertices = n_v = len(order)
        g = self.group
        self.grp_start = np.searchsorted(g, np.arange(2 * p.n_nodes), side="left")
        self.grp_end = np.searchsorted(g, np.arange(2 * p.n_nodes), side="right")
        # Arc edges between consecutive vertices of one arc, where the arc is clear.
        k = np.flatnonzero(g[1:] == g[:-1])
        free = self._arcs_free(k, k + 1)
        k = k[free]
        d = self.pos[k + 1] - self.pos[k]
        tie = k[d <= ANG_TOL]  # positions equal within tolerance: both ways
        rows = [k, rank[:n_e], tie + 1]
        cols = [k + 1, rank[n_e:], tie]
        wts = [p.radius * np.maximum(d, 0.0), length, np.zeros(len(tie))]
        self._rows = np.concatenate(rows)
        self._cols = np.concatenate(cols)
        self._w = np.concatenate(wts) + EPS_W
        # The graph once, for the compiled search (which seeds the source's arrivals itself).
        csr = sparse.csr_matrix((self._w, (self._rows, self._cols)), shape=(n_v, n_v))
        self.indptr, self.indices, self.data = csr.indptr.astype(np.int64), csr.indices.astype(np.int64), csr.data
        self._vertex_xy: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
        self._kernel_args: tuple[tuple[Any, ...], ...] | None = None

    def kernel_arguments(self) -> tuple[tuple[Any, ...], ...]:
        """What ``geodesic._path_kernel.point_path`` reads of this graph, its planner and
        their floor, as its ``nodes, geometry, walls, arcs, graph`` arguments; made once."""
        if getattr(self, "_kernel_args", None) is None:  # (a copy pickled before it was made has none)
            p = self.p
            blocked, has_blocked = p.blocked_arcs()
            self._kernel_args = (
                (p.cx, p.cy, p.phi0, p.span, p.sight_reach, p.sight_profile),
                p.geo.kernel_geometry(),
                p.geo.kernel_arguments(p.radius),
                (self.grp_start, self.grp_end, self.pos, blocked, has_blocked, p.span),
                (self.indptr, self.indices, self.data, self.node, self.side, *self.vertex_points()),
            )
        return self._kernel_args

    def arc_range(self, node: int, side: int) -> tuple[int, int]:
        """The vertices ``[lo, hi)`` on the arc of ``node`` winding ``side``, by position."""
        gi = 2 * node + (side < 0)
        return int(self.grp_start[gi]), int(self.grp_end[gi])

    def points(
        self, node: NDArray[np.integer], side: NDArray[np.integer], pos: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World points (m) of arc positions ``pos`` (rad) of ``node`` winding ``side``."""
        p = self.p
        node = np.asarray(node, dtype=np.int64)
        ccw = np.where(np.asarray(side) > 0, pos, p.span[node] - pos)
        ang = p.phi0[node] + ccw
        return p.cx[node] + p.radius * np.cos(ang), p.cy[node] + p.radius * np.sin(ang)

    def vertex_points(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Every vertex's world point (m), computed once (a point search's heuristic)."""
        if self._vertex_xy is None:
            self._vertex_xy = self.points(self.node, self.side, self.pos)
        return self._vertex_xy

    def locate(
        self, node: NDArray[np.integer], side: NDArray[np.integer], q: NDArray[np.float64], after: bool
    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
        """For each arc position ``q`` (rad) of ``node`` winding ``side``, the first vertex of
        that arc at or after ``q`` (``after``: strictly after), with the arc's ``[lo, hi)``:
        ``np.searchsorted`` within each arc, for all of them at once."""
        g = 2 * np.asarray(node, dtype=np.int64) + (np.asarray(side) < 0)
        lo, hi = self.grp_start[g], self.grp_end[g]
        a, b = lo.copy(), hi.copy()
        last = max(len(self.pos) - 1, 0)
        while True:
            active = a < b
            if not active.any():
                return a, lo, hi
            mid = (a + b) // 2
            at = self.pos[np.minimum(mid, last)]
            go = active & ((at <= q) if after else (at < q))
            a = np.where(go, mid + 1, a)
            b = np.where(active & ~go, mid, b)

    def arrival_steps(
        self, x_node: NDArray[np.integer], x_side: NDArray[np.integer], x_pos: NDArray[np.float64]
    ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Where each arrival at ``(x_node, x_side, x_pos)`` continues along its arc: the
        first vertex at or after it (-1 where none is, or the arc there is blocked), and
        the arc's cost to it (m, with the graph's zero-weight offset)."""
        x_to, x_w = self._arc_steps(x_node, x_side, x_pos, forward=True)
        x_w[x_to >= 0] += EPS_W
        return x_to, x_w

    def departure_steps(
        self, f_node: NDArray[np.integer], f_side: NDArray[np.integer], f_pos: NDArray[np.float64]
    ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Where a path leaving at ``(f_node, f_side, f_pos)`` is entered from: the last
        vertex of its arc at or before it (-1 where none is, or the arc there is blocked),
        and the arc's cost from it (m)."""
        return self._arc_steps(f_node, f_side, f_pos, forward=False)

    def _arc_steps(
        self, node: NDArray[np.integer], side: NDArray[np.integer], q: NDArray[np.float64], forward: bool
    ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """The vertex each arc position ``q`` goes on to (``forward``: the first at or after
        it) or comes from (the last at or before it), -1 where none is or the arc between
        them is blocked, and that arc's cost (m)."""
        if forward:
            j, _, hi = self.locate(node, side, q - ANG_TOL, after=False)
            ok = j < hi
        else:
            j, lo, _ = self.locate(node, side, q + ANG_TOL, after=True)
            j = j - 1
            ok = j >= lo
        node = np.asarray(node, dtype=np.int64)
        side = np.asarray(side, dtype=np.int64)
        at, here = self.pos[j[ok]], q[ok]
        free = self.p.arcs_free(node[ok], side[ok], *((here, at) if forward else (at, here)))
        ok[ok] = free
        cost = np.zeros(len(j))
        at, here = at[free], here[free]
        cost[ok] = self.p.radius * np.maximum(at - here if forward else here - at, 0.0)
        return np.where(ok, j, -1).astype(np.int64), cost

    def _arcs_free(self, i: NDArray[np.int64], j: NDArray[np.int64]) -> NDArray[np.bool_]:
        """Whether the arc between vertices ``i`` and ``j`` (same arc, ``pos_i <= pos_j``) is clear."""
        p = self.p
        out = np.ones(len(i), dtype=bool)
        has = np.fromiter((bool(p.blocked_ccw[n]) for n in self.node[i].tolist()), dtype=bool, count=len(i))
        for q in np.flatnonzero(has).tolist():
            a, b = int(i[q]), int(j[q])
            out[q] = p.arc_free(int(self.node[a]), int(self.side[a]), float(self.pos[a]), float(self.pos[b]))
        return out

    def solve(self, links: list[tuple[int, int, float, float]]) -> FieldLabels:
        """Dijkstra from a point whose tangents arrive at ``links``: ``(node, side, pos, length)``.

        Each arrival is a vertex of its own (after the graph's), entered at its tangent's
        length, that continues along its arc to the first vertex at or after it. With numba
        the search runs compiled on the graph built once (:func:`seeded_dijkstra`); without
        it, scipy's Dijkstra runs on the graph with a source vertex added. Same distances.
        """
        n_v = self.n_vertices
        n_x = len(links)
        x_node = np.array([c for c, _, _, _ in links], dtype=np.int32)
        x_side = np.array([s for _, s, _, _ in links], dtype=np.int8)
        x_pos = np.array([q for _, _, q, _ in links], dtype=np.float64)
        x_len = np.array([ln for _, _, _, ln in links], dtype=np.float64)
        # Each arrival continues to the first vertex at or after it on its arc.
        x_to, x_w = self.arrival_steps(x_node, x_side, x_pos)
        kernel = _compiled.kernel("pointnav_core.geodesic._search_kernel", "seeded_dijkstra")
        if kernel is not None:
            dist = np.full(n_v + n_x, np.inf)
            pred = np.full(n_v + n_x, -9999, dtype=np.int64)
            kernel(self.indptr, self.indices, self.data, n_v, x_len + EPS_W, x_to, x_w, dist, pred)
            return FieldLabels(self, dist, pred, x_node, x_side, x_pos)
        src = n_v + n_x
        has = np.flatnonzero(x_to >= 0)
        rows = np.concatenate([self._rows, np.full(n_x, src), n_v + has])
        cols = np.concatenate([self._cols, n_v + np.arange(n_x), x_to[has]])
        wts = np.concatenate([self._w, x_len + EPS_W, x_w[has]])
        n = src + 1
        graph = sparse.csr_matrix((wts, (rows, cols)), shape=(n, n))
        dist, pred = csgraph.dijkstra(graph, directed=True, indices=src, return_predecessors=True)
        return FieldLabels(self, dist[:src], pred[:src], x_node, x_side, x_pos)


def seeded_dijkstra(indptr, indices, data, n_v, x_cost, x_to, x_w, dist, pred):  # pragma: no cover
    """Dijkstra over a CSR graph of ``n_v`` vertices from seeded arrivals, in place.

    Arrival ``k`` is vertex ``n_v + k``, reached at ``x_cost[k]`` from the source (``pred``
    -1) and continuing to vertex ``x_to[k]`` (if >= 0) at ``x_w[k]``. ``dist`` (inf) and
    ``pred`` (-9999: not reached, as scipy writes it) have ``n_v + len(x_cost)`` entries.
    Plain Python on scalars, so that numba compiles the very same function.
    """
    heap = [(0.0, 0)]
    heap.pop()
    for k in range(x_cost.shape[0]):
        if x_cost[k] < dist[n_v + k]:
            dist[n_v + k] = x_cost[k]
            pred[n_v + k] = -1
            heapq.heappush(heap, (x_cost[k], n_v + k))
    while len(heap) > 0:
        d, v = heapq.heappop(heap)
        if d > dist[v]:
            continue
        if v >= n_v:
            u = x_to[v - n_v]
            if u >= 0:
                nd = d + x_w[v - n_v]
                if nd < dist[u]:
                    dist[u] = nd
                    pred[u] = v
                    heapq.heappush(heap, (nd, u))
            continue
        for e in range(indptr[v], indptr[v + 1]):
            u = indices[e]
            nd = d + data[e]
            if nd < dist[u]:
                dist[u] = nd
                pred[u] = v
                heapq.heappush(heap, (nd, u))


class FieldLabels:
    """The vertices one Dijkstra run reached: exact costs and the predecessor tree.

    Vertex ``v < n_vertices`` is a vertex of the :class:`ArcGraph`; the rest are the
    arrivals of the source's own tangents. ``parent`` is -1 for those and for vertices
    not reached. Arrays are compact (float64 cost, int32 parent, shared vertex data).
    """

    def __init__(
        self,
        graph: ArcGraph,
        dist: NDArray[np.float64],
        pred: NDArray[np.int32],
        x_node: NDArray[np.int32],
        x_side: NDArray[np.int8],
        x_pos: NDArray[np.float64],
    ) -> None:
        self.graph = graph
        n_v = graph.n_vertices
        self.cost = dist
        parent = pred.astype(np.int32)
        parent[parent >= n_v + len(x_node)] = -1  # the source
        self.parent = parent
        self.node = np.concatenate([graph.node, x_node])
        self.side = np.concatenate([graph.side, x_side])
        self.pos = np.concatenate([graph.pos, x_pos])
        self.group = self.node.astype(np.int64) * 2 + (self.side < 0)
        self._extra: dict[tuple[int, int], list[int]] = {}
        for k in range(len(x_node)):
            self._extra.setdefault((int(x_node[k]), int(x_side[k])), []).append(n_v + k)

    @property
    def nbytes(self) -> int:
        """Bytes held by this run (the shared graph vertices are not counted)."""
        n_x = len(self.node) - self.graph.n_vertices
        return int(self.cost.nbytes + self.parent.nbytes + self.group.nbytes + n_x * 13 + self.node.nbytes + self.side.nbytes + self.pos.nbytes)

    def on_arc(self, node: int, side: int) -> list[int]:
        """Reached vertices on the arc of ``node`` winding ``side``."""
        lo, hi = self.graph.arc_range(node, side)
        out = [lo + i for i in np.flatnonzero(np.isfinite(self.cost[lo:hi])).tolist()]
        extra = self._extra.get((node, side))
        if extra:
            out += [v for v in extra if math.isfinite(self.cost[v])]
        return out

    def arrivals(self) -> NDArray[np.int64]:
        """Reached vertices entered by a tangent (not along their own arc)."""
        reached = np.flatnonzero(np.isfinite(self.cost))
        par = self.parent[reached]
        along = (par >= 0) & (self.group[np.maximum(par, 0)] == self.group[reached])
        return reached[~along]

    def trace(
        self, label: int, dep: float, start: tuple[float, float] | None = None, max_length: float = math.inf
    ) -> tuple[list[NDArray[np.float64]], bool]:
        """Points from the departure at ``dep`` on ``label``'s arc back to the source.

        With ``start`` (the point the path leaves from) and a finite ``max_length`` (m),
        tracing stops at the first arc whose end lies ``max_length`` or more along the
        path from ``start``. Returns the points and whether the trace reached the source.
        """
        from pointnav_core.geodesic.arcs import arc_points

        p = self.graph.p
        pts: list[NDArray[np.float64]] = []
        grp, par = self.group, self.parent
        last = None if start is None else np.asarray(start, dtype=np.float64)
        walked = 0.0
        while label >= 0:
            # Follow the arc back to where the path arrived on it.
            while par[label] >= 0 and grp[par[label]] == grp[label]:
                label = int(par[label])
            arc = arc_points(p, int(self.node[label]), int(self.side[label]), dep, float(self.pos[label]))
            pts += arc
            label = int(par[label])
            if label >= 0:
                dep = float(self.pos[label])
            if last is not None and math.isfinite(max_length):
                for q in arc:
                    walked += math.hypot(q[0] - last[0], q[1] - last[1])
                    last = q
                if walked >= max_length and label >= 0:
                    return pts, False
        return pts, True
