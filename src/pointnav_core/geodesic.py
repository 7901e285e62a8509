"""Exact any-angle geodesic distances and paths on a robot-eroded grid.

The robot's centre may move through the union of the *usable* cells of a floor
(:meth:`TraversableMap.usable`), touching a blocked cell nowhere: a straight segment is
free when every cell its closed extent meets is usable, so it cannot squeeze between two
blocked cells that share a corner nor clip a blocked corner. Shortest paths in that space
are polylines that bend only at *corner cells*: usable cells diagonal to a blocked cell
whose two side neighbours towards it are usable. So the geodesic is exact on the
visibility graph of those corners (computed once per floor and radius), not a count of grid
steps, and paths are any-angle (string-pulled) from the true source to the true target.

A :class:`GoalField` holds, for one goal, the exact geodesic distance of every corner (one
Dijkstra run on the corner graph); exact point queries search the corners a point sees. On
its first per-step lookup it also builds a root table, so that any later query to the same
goal is a lookup:

====================  =====================================================  ===========
stage                 work                                                   cached per
====================  =====================================================  ===========
:class:`Planner`      usable cells, components, corners, corner graph,       floor, radius
                      cell graph with one seed node per corner
:class:`GoalField`    goal visibility, Dijkstra over corners                 floor, radius, goal
root table            one seeded multi-source Dijkstra on the cell grid      goal field
                      proposes each cell's root corner
a cell's first use    root pulled taut, checked visible, else searched       goal field
query                 ``|p - root| + D(root)``                               --
====================  =====================================================  ===========

Internally everything is in *grid units* (cells) and grid coordinates ``(row, col)`` whose
floor is the cell index; the public functions speak metres and world ``(x, y)``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import sparse
from scipy.sparse import csgraph

from pointnav_core.maps import FREE, BoundedCache

if TYPE_CHECKING:
    from pointnav_core.maps import TraversableMap

__all__ = ["Planner", "GoalField", "planner_for", "resample_path", "path_length"]

_EPS = 1e-9
_CORNER_INSET = 1e-6
_STEPS = ((0, 1), (1, 0), (1, 1), (1, -1))
# How many segments' worth of band checks to vectorise at once (bounds peak memory).
_CHUNK_BANDS = 1 << 21
_COARSE = 4
# Parent codes in a goal field's cell table (corner ids are >= 0).
_TO_GOAL = -1
_UNREACHABLE = -2


def planner_for(tmap: TraversableMap, radius: float) -> Planner:
    """Return the cached :class:`Planner` of ``tmap`` for a robot of ``radius`` metres."""
    key = round(float(radius) / tmap.resolution, 9)
    return tmap.planner_cache.get_or_create(key, lambda: Planner(tmap, radius))


class Planner:
    """Corner visibility graph of one floor for one robot radius.

    Parameters
    ----------
    tmap : TraversableMap
        The floor.
    radius : float
        Robot radius in metres (0 for a point robot).
    field_cache_size : int
        How many goal fields to keep (least recently used are dropped).
    """

    def __init__(self, tmap: TraversableMap, radius: float, field_cache_size: int = 32) -> None:
        self.tmap = tmap
        self.radius = float(radius)
        self.usable = tmap.usable(radius)
        self.labels = tmap.components(radius)
        self.shape = self.usable.shape
        h, w = self.shape
        self._sight = _Sightlines(~self.usable)
        # Blocks of _COARSE x _COARSE cells that are entirely blocked: a segment touching one
        # is blocked, which rejects most corner pairs at a fraction of the cost.
        hb, wb = -(-h // _COARSE), -(-w // _COARSE)
        padded = np.ones((hb * _COARSE, wb * _COARSE), dtype=bool)
        padded[:h, :w] = ~self.usable
        self._coarse = _Sightlines(padded.reshape(hb, _COARSE, wb, _COARSE).all(axis=(1, 3)))
        self.corners, self.corner_diag = self._find_corners()
        rows = self.corners[:, 0].astype(np.int64)
        cols = self.corners[:, 1].astype(np.int64)
        self.corner_cells = rows * w + cols
        self.corner_labels = self.labels[rows, cols]
        self._cell_graph: sparse.csr_matrix | None = None
        self._margins: tuple[NDArray[np.int64], NDArray[np.int64]] | None = None
        self._seed_graph: tuple[sparse.csr_matrix, int] | None = None
        self._component_graphs: dict[int, tuple[NDArray[np.int64], sparse.csr_matrix]] = {}
        self._fields = BoundedCache(field_cache_size)

    # --------------------------------------------------------------- visibility
    def visible(self, p: ArrayLike, q: ArrayLike) -> NDArray[np.bool_]:
        """Whether straight segments between grid points are free (vectorised).

        Parameters
        ----------
        p, q : array_like, shape (..., 2)
            Segment ends in grid coordinates ``(row, col)``; they broadcast.

        Returns
        -------
        ndarray of bool
            True where every cell the closed segment meets is usable.
        """
        return self._sight.visible(p, q)

    def visible_one(self, pr: float, pc: float, qr: float, qc: float) -> bool:
        """:meth:`visible` for one segment, in plain Python (cheaper for a single query)."""
        return self._sight.visible_one(pr, pc, qr, qc)

    # ------------------------------------------------------------------ corners
    def _find_corners(self) -> tuple[NDArray[np.float64], NDArray[np.int8]]:
        """Corner points (V, 2) in grid coordinates and the blocked diagonal (V, 2) of each."""
        u = self.usable
        h, w = u.shape
        pad = np.pad(u, 1, constant_values=False)

        def shifted(dr: int, dc: int) -> NDArray[np.bool_]:
            return pad[1 + dr : 1 + dr + h, 1 + dc : 1 + dc + w]

        points, diags = [], []
        inset = 0.5 - _CORNER_INSET
        for dr in (-1, 1):
            for dc in (-1, 1):
                rows, cols = np.nonzero(u & shifted(dr, 0) & shifted(0, dc) & ~shifted(dr, dc))
                # The corner of the usable cell that touches the blocked one, pulled in by a
                # hair so that segments leaving it tangentially do not touch the blocked cell.
                # Bending there (not at the cell centre) keeps the path on the usable region's
                # boundary, which is what keeps the geodesic unbiased.
                points.append(np.stack([rows + 0.5 + dr * inset, cols + 0.5 + dc * inset], axis=1))
                diags.append(np.tile(np.array([dr, dc], dtype=np.int8), (len(rows), 1)))
        return np.concatenate(points), np.concatenate(diags)

    def tangent(self, ids: ArrayLike, direction: ArrayLike) -> NDArray[np.bool_]:
        """Whether lines through corners ``ids`` along ``direction`` stay clear of their cell.

        A shortest path can only bend at a corner, or arrive at it, along such a line: one
        that does not enter the open quadrant of the blocked diagonal cell.
        """
        d = self.corner_diag[np.asarray(ids, dtype=np.int64)]
        e = np.asarray(direction, dtype=np.float64)
        return (e[..., 0] * d[..., 0]) * (e[..., 1] * d[..., 1]) <= 0.0

    def component_graph(self, label: int) -> tuple[NDArray[np.int64], sparse.csr_matrix]:
        """Corner ids of one component and their visibility graph (edge weights in cells).

        Only bitangent edges are kept (tangent at both ends): no shortest path uses others.
        """
        try:
            return self._component_graphs[label]
        except KeyError:
            pass
        ids = np.flatnonzero(self.corner_labels == label)
        n = len(ids)
        pts = self.corners[ids]
        edges_i, edges_j = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
        # Rows of the pair triangle in blocks, to bound memory on large maps.
        step = max(1, (1 << 22) // max(n, 1))
        for start in range(0, max(n - 1, 0), step):
            rows = np.arange(start, min(start + step, n - 1))
            counts = n - 1 - rows
            i = np.repeat(rows, counts)
            j = np.arange(len(i)) - np.repeat(np.cumsum(counts) - counts, counts) + i + 1
            e = pts[j] - pts[i]
            keep = self.tangent(ids[i], e) & self.tangent(ids[j], e)
            i, j = i[keep], j[keep]
            keep = ~self._coarse.touches_blocked(pts[i] / _COARSE, pts[j] / _COARSE)
            i, j = i[keep], j[keep]
            keep = self.visible(pts[i], pts[j])
            edges_i.append(i[keep])
            edges_j.append(j[keep])
        i = np.concatenate(edges_i)
        j = np.concatenate(edges_j)
        weight = np.maximum(np.hypot(*(pts[i] - pts[j]).T), _EPS)
        graph = sparse.csr_matrix((weight, (i, j)), shape=(n, n))
        self._component_graphs[label] = (ids, graph)
        return ids, graph

    def seed_graph(self) -> tuple[sparse.csr_matrix, int]:
        """The cell graph plus one seed node per corner and one for a goal (cached).

        Seed node ``first + i`` has a single edge to corner i's cell, and the last seed an
        edge to a goal's cell; goal fields write their weights (and the goal's cell) in
        place before each Dijkstra run, so the graph is built once per floor and radius.
        """
        if self._seed_graph is None:
            base = self.cell_graph()
            first = base.shape[0]
            n_seeds = len(self.corners) + 1
            n_nodes = first + n_seeds
            graph = sparse.csr_matrix(
                (
                    np.concatenate([base.data, np.ones(n_seeds)]),
                    np.concatenate([base.indices, self.corner_cells, [0]]).astype(base.indices.dtype),
                    np.concatenate([base.indptr, base.nnz + np.arange(1, n_seeds + 1)]),
                ),
                shape=(n_nodes, n_nodes),
            )
            self._seed_graph = (graph, first)
        return self._seed_graph

    def margin_sources(self) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Margin cells (FREE, not usable) and, for each, a usable cell a few steps away.

        The link spreads through FREE cells only, never across a wall, up to the robot
        radius plus two cells deep. Flat cell indices; cached.
        """
        if self._margins is not None:
            return self._margins
        h, w = self.shape
        source = np.where(self.usable, np.arange(h * w).reshape(h, w), -1)
        margin = (self.tmap.codes == FREE) & ~self.usable
        for _ in range(int(math.ceil(self.radius / self.tmap.resolution)) + 2):
            todo = margin & (source < 0)
            if not todo.any():
                break
            padded = np.pad(source, 1, constant_values=-1)
            for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
                nb = padded[1 + dr : 1 + dr + h, 1 + dc : 1 + dc + w]
                take = todo & (nb >= 0)
                source[take] = nb[take]
                todo &= ~take
        linked = margin & (source >= 0)
        self._margins = (np.flatnonzero(linked), source[linked])
        return self._margins

    def cell_graph(self) -> sparse.csr_matrix:
        """8-connected graph of usable cells, plus one spare empty row; edge weights in cells.

        Nodes are flat cell indices. A step is an edge when the segment between the two
        cell centres is free (the rule of :meth:`visible`), so no diagonal step cuts a
        blocked corner. The grid metric only proposes each cell's route (see GoalField);
        distances come from the corners.
        """
        if self._cell_graph is not None:
            return self._cell_graph
        u = self.usable
        h, w = u.shape
        index = np.arange(h * w).reshape(h, w)
        pad = 2
        padded = np.pad(u, pad, constant_values=False)
        src, dst, wts = [], [], []
        for dr, dc in _STEPS:
            ok = u.copy()
            for tr, tc in _touched_cells(dr, dc):
                ok &= padded[pad + tr : pad + tr + h, pad + tc : pad + tc + w]
            rows, cols = np.nonzero(ok)
            a = index[rows, cols]
            b = (rows + dr) * w + (cols + dc)
            length = math.hypot(dr, dc)
            src += [a, b]
            dst += [b, a]
            wts += [np.full(len(a), length)] * 2
        n = h * w + 1
        graph = sparse.csr_matrix(
            (np.concatenate(wts), (np.concatenate(src), np.concatenate(dst))), shape=(n, n)
        )
        graph.sort_indices()
        self._cell_graph = graph
        return graph

    # -------------------------------------------------------------------- goals
    def goal_field(self, goal: ArrayLike) -> GoalField:
        """Return the cached :class:`GoalField` rooted at ``goal`` (grid coordinates)."""
        g = np.asarray(goal, dtype=np.float64)
        key = (float(g[0]), float(g[1]))
        return self._fields.get_or_create(key, lambda: GoalField(self, g))

    def label_at(self, g: ArrayLike) -> int:
        """Component id at a grid point (0 when off the map or not usable)."""
        r, c = (int(math.floor(v)) for v in np.asarray(g, dtype=np.float64))
        h, w = self.shape
        if 0 <= r < h and 0 <= c < w:
            return int(self.labels[r, c])
        return 0


class GoalField:
    """Geodesic distances to one goal, for every point of the goal's component.

    Build it through :meth:`Planner.goal_field` (cached). Distances are in grid units
    (cells) here; ``Scene`` converts to metres.

    ``corner_dist`` is the exact geodesic distance of every corner (Dijkstra on the corner
    visibility graph), solved when the field is made. That alone answers exact point
    queries (:meth:`path`, :meth:`point_distance`) by searching the corners a point sees.

    For the per-step hot path, :meth:`distance` reads a *root table*, built on its first
    call: for every cell, the corner (or the goal) through which its shortest path leaves
    it. One multi-source Dijkstra on the 8-connected cell grid, seeded with the corners'
    exact distances, proposes each cell's root; the grid metric can pick a corner the cell
    could pass by, so on first use a cell's root is pulled up its corner chain until the
    path wraps it tautly. Then a query is ``|p - root| + D(root)``: a lookup and a hypot.

    Parameters
    ----------
    planner : Planner
        The floor and radius.
    goal : array_like, shape (2,)
        Goal in grid coordinates ``(row, col)``.
    """

    def __init__(self, planner: Planner, goal: ArrayLike) -> None:
        self.planner = planner
        self.goal = np.asarray(goal, dtype=np.float64).copy()
        self.label = planner.label_at(self.goal)
        self._root_rows: list[list[int]] | None = None
        if self.label == 0:
            self.corner_ids = np.zeros(0, dtype=np.int64)
            self.corner_pos = np.zeros((0, 2))
            self.corner_dist = np.zeros(0)
            self.corner_pred = np.zeros(0, dtype=np.int64)
        else:
            self._solve_corners()
        # Plain Python copies for the per-step scalar work (faster than numpy scalars).
        n = len(self.corner_ids)
        self._n = n
        self._pos_r = self.corner_pos[:, 0].tolist() + [float(self.goal[0])]
        self._pos_c = self.corner_pos[:, 1].tolist() + [float(self.goal[1])]
        self._dist = self.corner_dist.tolist() + [0.0]
        self._pred = self.corner_pred.tolist()
        diag = planner.corner_diag[self.corner_ids]
        self._diag_r = diag[:, 0].tolist()
        self._diag_c = diag[:, 1].tolist()

    @property
    def reachable_from_anywhere(self) -> bool:
        """False when the goal itself is not usable (every query is unreachable)."""
        return self.label != 0

    def _solve_corners(self) -> None:
        planner = self.planner
        ids, graph = planner.component_graph(self.label)
        n = len(ids)
        pos = planner.corners[ids]
        sees_goal = planner.visible(pos, self.goal[None, :]) & planner.tangent(ids, self.goal - pos)
        rows = np.flatnonzero(sees_goal)
        to_goal = np.maximum(np.hypot(*(pos[rows] - self.goal).T), _EPS)
        # The corner graph plus one last node, the goal, linked to the corners that see it.
        full = sparse.csr_matrix(
            (
                np.concatenate([graph.data, to_goal]),
                np.concatenate([graph.indices, rows]),
                np.concatenate([graph.indptr, [graph.nnz + len(rows)]]),
            ),
            shape=(n + 1, n + 1),
        )
        dist, pred = csgraph.dijkstra(full, directed=False, indices=n, return_predecessors=True)
        self.corner_ids = ids
        self.corner_pos = pos
        self.corner_dist = dist[:n]
        # Predecessor of each corner on its way to the goal: a corner index, or n (the goal).
        self.corner_pred = pred[:n].astype(np.int64)
        self.corner_pred[self.corner_pred < 0] = n

    def _solve_cells(self) -> list[list[int]]:
        """Build the root table (raw grid-Dijkstra roots; pulled taut lazily per cell)."""
        planner = self.planner
        h, w = planner.shape
        n_cells = h * w
        root = np.full(n_cells, _UNREACHABLE, dtype=np.int64)
        if self.label != 0:
            root = self._grid_roots()
            # A robot can stand in a FREE cell whose *centre* is too close to an obstacle
            # (the erosion is decided at cell centres): such margin cells take the root of
            # a nearby usable cell, so the distance never jumps to infinity.
            cells, sources = planner.margin_sources()
            root[cells] = root[sources]
        self._root_rows = root.reshape(h, w).tolist()
        return self._root_rows

    def _grid_roots(self) -> NDArray[np.int64]:
        planner = self.planner
        h, w = planner.shape
        n_cells = h * w
        graph, first = planner.seed_graph()
        n_corners = len(planner.corners)
        # The seed edges' weights are the exact distances of this goal's corners (inf for
        # the others), and the last seed is the goal's own cell.
        weight = np.full(n_corners + 1, np.inf)
        weight[self.corner_ids] = np.maximum(self.corner_dist, _EPS)
        weight[-1] = _EPS
        graph.data[-(n_corners + 1) :] = weight
        graph.indices[-1] = int(math.floor(self.goal[0])) * w + int(math.floor(self.goal[1]))
        _, _, sources = csgraph.dijkstra(
            graph,
            directed=True,
            indices=np.arange(first, first + n_corners + 1),
            min_only=True,
            return_predecessors=True,
        )
        seed = sources[:n_cells] - first
        local = np.full(n_corners + 1, _UNREACHABLE, dtype=np.int64)
        local[self.corner_ids] = np.arange(len(self.corner_ids))
        local[-1] = self._n
        root = np.where(seed >= 0, local[np.maximum(seed, 0)], _UNREACHABLE)
        # The goal's own code; corners keep their index and are pulled taut on first use.
        root[root == self._n] = _TO_GOAL
        return root

    def _taut_root(self, r: int, c: int, v: int) -> int:
        """Pull corner ``v`` (the raw root of cell (r, c)) up its chain until it is taut.

        A path c -> v -> next only bends at v if the leg to v is tangent there, the turn is
        towards v's blocked cell and it bends by at most 90 degrees; otherwise the cell hangs
        from ``next``. Returns a corner
        index or -1 (the goal).
        """
        cr, cc = r + 0.5, c + 0.5
        n = self._n
        while v != n:
            vr, vc = self._pos_r[v], self._pos_c[v]
            ar, ac = vr - cr, vc - cc
            nxt = self._pred[v]
            br, bc = self._pos_r[nxt] - vr, self._pos_c[nxt] - vc
            dr, dc = self._diag_r[v], self._diag_c[v]
            # Turn towards the blocked cell, arrive tangentially, and bend by at most 90
            # degrees: the blocked region at a corner is locally a quadrant.
            if (
                (ar * bc - ac * br) * (ar * dc - ac * dr) > 0
                and (ar * dr) * (ac * dc) <= 0
                and ar * br + ac * bc >= 0
            ):
                return v
            v = nxt
        return _TO_GOAL

    def _lookup(self, r: int, c: int) -> int:
        """Root of cell (r, c): a corner index, -1 (the goal) or -2 (unreachable).

        The table holds raw roots (a corner index >= 0, -1 for the goal, -2 unreachable)
        until a cell is first looked up; then the root is pulled taut, checked visible from
        the cell centre (else the corners are searched exactly), and stored as final:
        -3 for the goal, ``-k - 4`` for corner k. So each cell is settled once, the same way
        whatever the order of queries.
        """
        rows = self._root_rows if self._root_rows is not None else self._solve_cells()
        code = rows[r][c]
        if code <= -3:
            return _TO_GOAL if code == -3 else -code - 4
        if code == _UNREACHABLE:
            return code
        labels = self.planner.labels
        if labels[r, c] == 0:
            # A margin cell: leave the way its nearest usable neighbour does.
            root = self._margin_root(r, c, code)
        else:
            root = self._taut_root(r, c, code) if code >= 0 else _TO_GOAL
            if not self.planner.visible_one(r + 0.5, c + 0.5, self._pos_r[root], self._pos_c[root]):
                root = int(self._search(np.array([[r + 0.5, c + 0.5]]))[0])
        rows[r][c] = -3 if root == _TO_GOAL else -root - 4
        return root

    def _margin_root(self, r: int, c: int, code: int) -> int:
        labels = self.planner.labels
        h, w = self.planner.shape
        for ring in range(1, 3):
            for dr in range(-ring, ring + 1):
                for dc in range(-ring, ring + 1):
                    rr, cc = r + dr, c + dc
                    if max(abs(dr), abs(dc)) == ring and 0 <= rr < h and 0 <= cc < w:
                        if labels[rr, cc] == self.label:
                            return self._lookup(rr, cc)
        return self._taut_root(r, c, code) if code >= 0 else _TO_GOAL

    # ------------------------------------------------------------------ lookups
    def distance(self, gr: float, gc: float) -> float:
        """Geodesic distance from grid point (gr, gc) to the goal, in cells (inf if none).

        This is the per-step hot path: plain Python on cached tables, no search.
        """
        r = math.floor(gr)
        c = math.floor(gc)
        h, w = self.planner.shape
        if not (0 <= r < h and 0 <= c < w):
            return math.inf
        rows = self._root_rows
        code = rows[r][c] if rows is not None else _UNREACHABLE + 1
        if code <= -3:  # settled (see _lookup): the common case, inlined
            root = _TO_GOAL if code == -3 else -code - 4
        else:
            root = self._lookup(r, c)
            if root == _UNREACHABLE:
                return math.inf
        return math.hypot(gr - self._pos_r[root], gc - self._pos_c[root]) + self._dist[root]

    def point_distance(self, g: NDArray[np.float64]) -> float:
        """Exact geodesic distance from grid point ``g`` (cells; inf if unreachable)."""
        parent = self.best_parent(np.asarray(g, dtype=np.float64))
        if parent == _UNREACHABLE:
            return math.inf
        return math.hypot(g[0] - self._pos_r[parent], g[1] - self._pos_c[parent]) + self._dist[parent]

    def best_parent(self, g: NDArray[np.float64], exact: bool = True) -> int:
        """First corner (or -1: the goal) on the shortest path from an exact grid point.

        ``exact=True`` searches the corners the point sees (optimal, independent of what
        was looked up before). ``exact=False`` follows the root of the point's cell when
        the point sees it (a lookup and one segment test; what a controller needs each
        step) and searches only when it does not.
        """
        r, c = math.floor(g[0]), math.floor(g[1])
        h, w = self.planner.shape
        if self.label == 0 or not (0 <= r < h and 0 <= c < w):
            return _UNREACHABLE
        label = self.planner.labels[r, c]
        if label == 0:
            # A margin cell (see _solve_cells): leave along the nearest usable cell's root.
            return self._lookup(r, c)
        if label != self.label:
            return _UNREACHABLE
        if not exact:
            root = self._lookup(r, c)
            if root != _UNREACHABLE:
                gr, gc = float(g[0]), float(g[1])
                tr, tc = self._pos_r[root], self._pos_c[root]
                tangent = root == _TO_GOAL or (
                    (tr - gr) * self._diag_r[root] * (tc - gc) * self._diag_c[root] <= 0.0
                )
                if tangent and self.planner.visible_one(gr, gc, tr, tc):
                    return root
        return int(self._search(g[None, :])[0])

    def path(
        self, g: NDArray[np.float64], exact: bool = True
    ) -> tuple[NDArray[np.float64], float] | tuple[None, None]:
        """Any-angle path from grid point ``g`` to the goal and its length (cells).

        See :meth:`best_parent` for ``exact``.
        """
        g = np.asarray(g, dtype=np.float64)
        parent = self.best_parent(g, exact)
        if parent == _UNREACHABLE:
            return None, None
        points = [g]
        node = self._n if parent == _TO_GOAL else parent
        length = math.hypot(g[0] - self._pos_r[node], g[1] - self._pos_c[node]) + self._dist[node]
        while node != self._n:
            points.append(self.corner_pos[node])
            node = self._pred[node]
        points.append(self.goal)
        return np.array(points), length

    def _search(self, points: NDArray[np.float64]) -> NDArray[np.int32]:
        """Best visible candidate (goal or corner) for each point, exactly.

        Candidates are tried in increasing order of ``|p - corner| + D(corner)`` (``|p - goal|``
        for the goal, which is the smallest key of all); the first visible one is optimal.
        """
        n = len(self.corner_ids)
        cand_pos = np.vstack([self.corner_pos, self.goal[None, :]])
        cand_dist = np.append(self.corner_dist, 0.0)
        keys = np.hypot(
            points[:, None, 0] - cand_pos[None, :, 0], points[:, None, 1] - cand_pos[None, :, 1]
        ) + cand_dist[None, :]
        for i, p in enumerate(points):
            # A path can only bend at a corner it meets tangentially.
            keys[i, :n][~self.planner.tangent(self.corner_ids, self.corner_pos - p)] = np.inf
        best = np.full(len(points), _UNREACHABLE, dtype=np.int32)
        todo = np.arange(len(points))
        batch = 32
        while len(todo):
            k = min(batch, n + 1)
            sub = keys[todo]
            if k < n + 1:
                order = np.argpartition(sub, k - 1, axis=1)[:, :k]
            else:
                order = np.broadcast_to(np.arange(n + 1), (len(todo), n + 1)).copy()
            cand_keys = np.take_along_axis(sub, order, axis=1)
            seen = self.planner.visible(
                np.repeat(points[todo], k, axis=0), cand_pos[order.ravel()]
            ).reshape(len(todo), k)
            seen &= np.isfinite(cand_keys)
            masked = np.where(seen, cand_keys, np.inf)
            pick = np.argmin(masked, axis=1)
            found = np.isfinite(masked[np.arange(len(todo)), pick])
            chosen = order[np.arange(len(todo)), pick]
            best[todo[found]] = np.where(chosen[found] == n, _TO_GOAL, chosen[found])
            # Everything tested and not chosen is either invisible or worse: rule it out.
            rest = todo[~found]
            keys[rest[:, None], order[~found]] = np.inf
            exhausted = ~np.isfinite(keys[rest]).any(axis=1)
            todo = rest[~exhausted]
            batch = min(batch * 4, n + 1)
        return best


class _Sightlines:
    """Segment tests against a boolean grid of blocked cells, via row/column prefix sums."""

    def __init__(self, blocked: NDArray[np.bool_]) -> None:
        h, w = blocked.shape
        counts = blocked.astype(np.int32)
        # A run of cells in one row (or column) is free iff its blocked count is zero, so a
        # segment test costs one lookup per row (or column) it crosses.
        self._row_cum = np.zeros((h, w + 1), dtype=np.int32)
        np.cumsum(counts, axis=1, out=self._row_cum[:, 1:])
        self._col_cum = np.zeros((w, h + 1), dtype=np.int32)
        np.cumsum(counts.T, axis=1, out=self._col_cum[:, 1:])
        # Python copies for visible_one, made on first use.
        self._rows: list[list[int]] | None = None
        self._cols: list[list[int]] | None = None

    def visible(self, p: ArrayLike, q: ArrayLike) -> NDArray[np.bool_]:
        """True where the closed segment p-q meets no blocked cell and stays on the grid."""
        p, q = np.broadcast_arrays(np.asarray(p, dtype=np.float64), np.asarray(q, dtype=np.float64))
        shape = p.shape[:-1]
        p = p.reshape(-1, 2)
        q = q.reshape(-1, 2)
        out = np.empty(len(p), dtype=bool)
        # Walk the axis the segment crosses fewer cells of: rows, or columns (transposed).
        by_rows = np.abs(q[:, 0] - p[:, 0]) <= np.abs(q[:, 1] - p[:, 1])
        if by_rows.any():
            out[by_rows] = self._banded(p[by_rows], q[by_rows], self._row_cum)
        by_cols = ~by_rows
        if by_cols.any():
            out[by_cols] = self._banded(p[by_cols][:, ::-1], q[by_cols][:, ::-1], self._col_cum)
        return out.reshape(shape)

    def visible_one(self, pr: float, pc: float, qr: float, qc: float) -> bool:
        """The same test for one segment, band by band in plain Python (no array overhead)."""
        if abs(qr - pr) <= abs(qc - pc):
            if self._rows is None:
                self._rows = self._row_cum.tolist()
            cum, p0, p1, q0, q1 = self._rows, pr, pc, qr, qc
        else:
            if self._cols is None:
                self._cols = self._col_cum.tolist()
            cum, p0, p1, q0, q1 = self._cols, pc, pr, qc, qr
        n_bands, n_cells = len(cum), len(cum[0]) - 1
        a0, a1 = min(p0, q0), max(p0, q0)
        d0 = q0 - p0
        flat = abs(d0) < _EPS
        slope = 0.0 if flat else (q1 - p1) / d0
        for k in range(math.ceil(a0 - _EPS) - 1, math.floor(a1 + _EPS) + 1):
            if k < 0 or k >= n_bands:
                return False
            if flat:
                lo, hi = min(p1, q1), max(p1, q1)
            else:
                o_a = p1 + (max(k, a0) - p0) * slope
                o_b = p1 + (min(k + 1, a1) - p0) * slope
                lo, hi = min(o_a, o_b), max(o_a, o_b)
            j_lo = math.ceil(lo - _EPS) - 1
            j_hi = math.floor(hi + _EPS) + 1
            if j_lo < 0 or j_hi > n_cells:
                return False
            row = cum[k]
            if row[j_hi] != row[j_lo]:
                return False
        return True

    def touches_blocked(self, p: ArrayLike, q: ArrayLike) -> NDArray[np.bool_]:
        """True where the closed segment meets a blocked cell (leaving the grid aside)."""
        h, w = self._row_cum.shape[0], self._col_cum.shape[0]
        # Clamp into the grid: off-grid parts are for the exact test to judge, not this one.
        lim = np.array([h, w], dtype=np.float64) - 1e-6
        p = np.clip(np.asarray(p, dtype=np.float64), 1e-6, lim)
        q = np.clip(np.asarray(q, dtype=np.float64), 1e-6, lim)
        return ~self.visible(p, q)

    @staticmethod
    def _banded(
        p: NDArray[np.float64], q: NDArray[np.float64], cum: NDArray[np.int32]
    ) -> NDArray[np.bool_]:
        """Segment test over bands (rows of ``cum``); column 0 of p, q is the band axis.

        Each band the closed segment meets is checked in O(1): the run of cells it covers
        in that band must hold no blocked cell (a difference of two prefix sums).
        """
        n_bands, n_cells = cum.shape[0], cum.shape[1] - 1
        p0, p1, q0, q1 = p[:, 0], p[:, 1], q[:, 0], q[:, 1]
        a0 = np.minimum(p0, q0)
        a1 = np.maximum(p0, q0)
        k_lo = np.ceil(a0 - _EPS).astype(np.int64) - 1
        counts = np.floor(a1 + _EPS).astype(np.int64) - k_lo + 1
        d0 = q0 - p0
        flat = np.abs(d0) < _EPS
        slope = np.divide(q1 - p1, d0, out=np.zeros_like(d0), where=~flat)
        free = np.empty(len(p), dtype=bool)
        ends = np.cumsum(counts)
        start = 0
        while start < len(p):
            # Chunk segments so that the flattened band arrays stay bounded in memory.
            stop = int(np.searchsorted(ends, ends[start] - counts[start] + _CHUNK_BANDS, "right"))
            stop = max(stop, start + 1)
            n = counts[start:stop]
            seg = np.repeat(np.arange(start, stop), n)
            first = ends[start:stop] - n
            k = np.arange(first[0], first[0] + len(seg)) - np.repeat(first - k_lo[start:stop], n)
            sp0, sp1, sl = p0[seg], p1[seg], slope[seg]
            o_a = sp1 + (np.maximum(k, a0[seg]) - sp0) * sl
            o_b = sp1 + (np.minimum(k + 1, a1[seg]) - sp0) * sl
            lo = np.minimum(o_a, o_b)
            hi = np.maximum(o_a, o_b)
            flat_band = flat[seg]
            if flat_band.any():
                # A segment along the band covers its whole extent inside its band(s).
                lo[flat_band] = np.minimum(p1, q1)[seg[flat_band]]
                hi[flat_band] = np.maximum(p1, q1)[seg[flat_band]]
            j_lo = np.ceil(lo - _EPS).astype(np.int64) - 1
            j_hi = np.floor(hi + _EPS).astype(np.int64) + 1
            off_map = (k < 0) | (k >= n_bands) | (j_lo < 0) | (j_hi > n_cells)
            kc = np.minimum(np.maximum(k, 0), n_bands - 1)
            j_lo = np.minimum(np.maximum(j_lo, 0), n_cells)
            j_hi = np.minimum(np.maximum(j_hi, 0), n_cells)
            blocked = off_map | (cum[kc, j_hi] != cum[kc, j_lo])
            free[start:stop] = ~np.logical_or.reduceat(blocked, first - first[0])
            start = stop
        return free



def _touched_cells(dr: int, dc: int) -> list[tuple[int, int]]:
    """Cell offsets met by the closed segment from cell (0, 0)'s centre to (dr, dc)'s."""
    touched = []
    for r in range(min(0, dr) - 1, max(0, dr) + 2):
        for c in range(min(0, dc) - 1, max(0, dc) + 2):
            # Clip the segment p(t) = (0.5 + t*dr, 0.5 + t*dc) to the closed square.
            t0, t1 = 0.0, 1.0
            for start, delta, low in ((0.5, dr, r), (0.5, dc, c)):
                if delta == 0:
                    if not low <= start <= low + 1:
                        t0, t1 = 1.0, 0.0
                    continue
                a, b = (low - start) / delta, (low + 1 - start) / delta
                t0, t1 = max(t0, min(a, b)), min(t1, max(a, b))
            if t0 <= t1 + 1e-12:
                touched.append((r, c))
    return touched


def path_length(points: ArrayLike) -> float:
    """Length of a polyline, shape (N, 2), in its own units."""
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) < 2:
        return 0.0
    return float(np.hypot(*np.diff(pts, axis=0).T).sum())


def resample_path(points: ArrayLike, spacing: float, count: int) -> NDArray[np.float64]:
    """First ``count`` points spaced ``spacing`` apart along a polyline, padded with its end.

    Parameters
    ----------
    points : array_like, shape (N, 2)
        The polyline, N >= 1.
    spacing : float
        Arc-length spacing (same units as ``points``), > 0.
    count : int
        Number of points returned, >= 1.

    Returns
    -------
    ndarray, shape (count, 2)
        Points at arc lengths 0, spacing, 2*spacing, ...; past the end of the polyline the
        last point repeats (as OmniGibson pads its waypoints with the target).

    Examples
    --------
    >>> resample_path([[0.0, 0.0], [1.0, 0.0]], 0.4, 4).tolist()
    [[0.0, 0.0], [0.4, 0.0], [0.8, 0.0], [1.0, 0.0]]
    """
    pts = np.asarray(points, dtype=np.float64)
    seg = np.hypot(*np.diff(pts, axis=0).T) if len(pts) > 1 else np.zeros(0)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.minimum(np.arange(count) * float(spacing), arc[-1])
    x = np.interp(s, arc, pts[:, 0])
    y = np.interp(s, arc, pts[:, 1])
    return np.stack([x, y], axis=1)
