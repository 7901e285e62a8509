"""Goal fields on the tangent graph: exact point queries and the per-step lookup table.

A :class:`GoalField` is one Dijkstra run of :mod:`pointnav_core.tangent_graph` from a goal:
the exact distance of every node it reaches. :meth:`GoalField.point_distance` and
:meth:`GoalField.path` are exact for any point (the tangents the point sees, then the
settled labels). :meth:`GoalField.distance` is the per-step lookup through a root table
built on first use: a seeded multi-source Dijkstra on the grid proposes each cell's root
label, each proposal is checked exactly, and cells whose proposal fails try their
neighbours' roots. Everything is in world metres.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage, sparse
from scipy.sparse import csgraph

from pointnav_core.tangent_graph import _ANG_TOL, _TWO_PI, Planner, _ccw_pos, _tangent_from_point

__all__ = ["GoalField"]

#: Most neighbour-inheritance passes of the root table (each reaches one cell further).
_ADOPT_PASSES = 64


class GoalField:
    """Geodesic distances (m) to one goal from every point of the floor.

    Build it through :meth:`Planner.goal_field` (cached). A Dijkstra run from the goal
    settles every node the goal reaches; :meth:`point_distance` and :meth:`path` are exact
    for any point; :meth:`distance` is the per-step lookup through a root table.

    Parameters
    ----------
    planner : Planner
    goal : array_like, shape (2,)
        Goal in world metres.
    """

    def __init__(self, planner: Planner, goal: ArrayLike) -> None:
        self.planner = planner
        self.goal = np.asarray(goal, dtype=np.float64).reshape(-1)[:2].copy()
        gx, gy = float(self.goal[0]), float(self.goal[1])
        self.goal_usable = planner.is_clear(gx, gy)
        links = planner.point_links(gx, gy) if self.goal_usable else []
        self._search = planner.arc_graph().solve(links)
        self._table: dict[str, Any] | None = None

    @property
    def reachable_from_anywhere(self) -> bool:
        """False when the robot does not fit at the goal (nothing reaches it)."""
        return self.goal_usable

    @property
    def nbytes(self) -> int:
        """Approximate memory held by this field, in bytes."""
        table = 0 if self._table is None else sum(v.nbytes for v in self._table.values() if isinstance(v, np.ndarray))
        table += 0 if self._table is None else 100 * len(self._table["fallback"])
        return self._search.nbytes + table

    # ------------------------------------------------------------- exact queries
    def _best(self, x: float, y: float) -> tuple[float, int, float]:
        """Best way to the goal from ``(x, y)``: ``(cost, label, departure)``; label -1: direct."""
        p = self.planner
        if not self.goal_usable or not p.is_clear(x, y):
            return math.inf, -2, 0.0
        gx, gy = float(self.goal[0]), float(self.goal[1])
        best = (math.inf, -2, 0.0)
        if p.segment_clear((x, y), (gx, gy)):
            best = (math.hypot(gx - x, gy - y), -1, 0.0)
        r = p.radius
        search = self._search
        for c, s, pos, length in p.point_links(x, y):
            side = -s
            dep = p._span[c] - pos
            for lab in search.on_arc(c, side):
                lp = search.pos[lab]
                if lp <= dep + _ANG_TOL and p._arc_free(c, side, lp, dep):
                    total = search.cost[lab] + r * max(dep - lp, 0.0) + length
                    if total < best[0]:
                        best = (total, lab, dep)
        return best

    def point_distance(self, xy: ArrayLike) -> float:
        """Exact geodesic distance (m) from world point ``xy`` to the goal (inf if none)."""
        x, y = (float(v) for v in np.asarray(xy, dtype=np.float64).reshape(-1)[:2])
        return self._best(x, y)[0]

    def path(self, xy: ArrayLike, exact: bool = True) -> tuple[NDArray[np.float64], float] | tuple[None, None]:
        """Shortest path (N, 2) from world point ``xy`` to the goal and its length (m).

        ``exact`` is kept for compatibility: every path is exact.
        """
        x, y = (float(v) for v in np.asarray(xy, dtype=np.float64).reshape(-1)[:2])
        cost, label, dep = self._best(x, y)
        if label == -2:
            return None, None
        pts = [np.array([x, y])]
        if label >= 0:
            pts += self._search.trace(label, dep)
        pts.append(self.goal.copy())
        return np.array(pts), cost

    # ------------------------------------------------------------- lookup table
    def distance(self, x: float, y: float) -> float:
        """Per-step geodesic lookup (m) from world point ``(x, y)``; ``inf`` if unreachable."""
        t = self._table
        if t is None:
            t = self._build_table()
        geo = self.planner.geo
        col = math.floor((x - geo.origin[0]) / geo.resolution)
        row = math.floor((y - geo.origin[1]) / geo.resolution)
        h, w = geo.shape
        if not (0 <= row < h and 0 <= col < w):
            return math.inf
        i = int(self.planner.near_usable[row * w + col])
        if i < 0:
            return math.inf
        kind = t["kind"][i]
        if kind == 0:
            return math.inf
        if kind == 1:  # straight to the goal
            return math.hypot(x - t["gx"], y - t["gy"])
        if kind == 3:
            # No checked root was proposed here: find the cell centre's exact one, once.
            kind = self._settle_cell(i)
            if kind == 1:
                return math.hypot(x - t["gx"], y - t["gy"])
            if kind != 2:
                return math.inf
        lab = int(t["label"][i])
        p = self.planner
        search = self._search
        c, side = int(search.node[lab]), int(search.side[lab])
        r = p.radius
        dx = p._cx[c] - x
        dy = p._cy[c] - y
        L = math.hypot(dx, dy)
        if L > r:
            # The tangent from (x, y) arriving winding -side is the one leaving the node.
            heading = math.atan2(dy, dx) + side * math.asin(r / L) if r > 0 else math.atan2(dy, dx)
            ccw = (heading + side * (math.pi / 2) - p._phi0[c]) % _TWO_PI
            if ccw > _TWO_PI - _ANG_TOL:
                ccw = 0.0
            span = p._span[c]
            if ccw <= span + _ANG_TOL:
                dep = min(ccw, span) if side > 0 else span - min(ccw, span)
                lp = search.pos[lab]
                if dep >= lp - _ANG_TOL:
                    return search.cost[lab] + r * max(dep - lp, 0.0) + math.sqrt(L * L - r * r)
        qx, qy = p.node_point(c, side, search.pos[lab])
        return search.cost[lab] + math.hypot(x - qx, y - qy)

    def _settle_cell(self, i: int) -> int:
        """Give table cell ``i`` its exact root (the best way from its centre); its new kind."""
        t = self._table
        assert t is not None
        geo = self.planner.geo
        ci, cj = divmod(i, geo.shape[1])
        cost, lab, _ = self._best(geo.origin[0] + (cj + 0.5) * geo.resolution, geo.origin[1] + (ci + 0.5) * geo.resolution)
        kind = 0 if lab == -2 else 1 if lab == -1 else 2
        t["kind"][i] = kind
        t["label"][i] = max(lab, -1)
        t["fallback"].pop(i, None)
        return kind

    def _root_values(
        self, cells: NDArray[np.int64], labs: NDArray[np.int64], px: NDArray[np.float64], py: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Exact value of leaving cell centres along settled labels' nodes; inf where not valid."""
        p = self.planner
        search = self._search
        nodes = np.asarray(search.node)[labs]
        sides = np.asarray(search.side)[labs]
        lpos = np.asarray(search.pos)[labs]
        lcost = np.asarray(search.cost)[labs]
        ang, length, _, ok = _tangent_from_point(px, py, p.cx[nodes], p.cy[nodes], p.radius, -sides)
        ccw, in_arc = _ccw_pos(ang, p.phi0[nodes], p.span[nodes])
        dep = np.where(sides > 0, ccw, p.span[nodes] - ccw)
        ok &= in_arc & (dep >= lpos - _ANG_TOL)
        out = np.full(len(cells), np.inf)
        if ok.any():
            sub = np.flatnonzero(ok)
            q = np.stack([p.cx[nodes[sub]] + p.radius * np.cos(ang[sub]), p.cy[nodes[sub]] + p.radius * np.sin(ang[sub])], 1)
            clear = p.geo.segments_clear(np.stack([px[sub], py[sub]], 1), q, p.radius)
            sub = sub[clear]
            out[sub] = lcost[sub] + p.radius * np.maximum(dep[sub] - lpos[sub], 0.0) + length[sub]
        return out

    def _adopt_roots(self, kind, label, cx_all, cy_all, usable, gx, gy) -> None:  # type: ignore[no-untyped-def]
        """Let cells try their neighbours' roots, and keep the best that checks out.

        A neighbour's root is usually visible from a cell too (as Theta* inherits parents).
        The first pass takes the cells whose proposal failed and the cells on the border
        between two roots (where the grid metric may have picked the worse of two routes
        that almost tie); each pass tests every distinct (cell, root) pair once, own root
        included, and the next pass only cells next to a cell that changed.
        """
        p = self.planner
        h, w = usable.shape
        use = usable.ravel()
        key = np.where(kind == 1, -1, np.where(kind == 2, label, -2))  # -2: no root
        grid_key = key.reshape(h, w)
        border = np.zeros((h, w), dtype=bool)
        for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
            a = grid_key[0 : h - dr, max(0, -dc) : w - max(0, dc)]
            b = grid_key[dr:, max(0, dc) : w - max(0, -dc)]
            differ = (a != b) & (a > -2) & (b > -2)
            border[0 : h - dr, max(0, -dc) : w - max(0, dc)] |= differ
            border[dr:, max(0, dc) : w - max(0, -dc)] |= differ
        todo_mask = use & ((key == -2) | border.ravel())
        for _ in range(_ADOPT_PASSES):
            todo = np.flatnonzero(todo_mask)
            if not len(todo):
                return
            rows, cols = np.divmod(todo, w)
            cells, roots = [todo[key[todo] > -2]], [key[todo][key[todo] > -2]]
            for dr in (-1, 0, 1):
                for dc in (-1, 0, 1):
                    if not (dr or dc):
                        continue
                    nr, nc = rows + dr, cols + dc
                    inside = (nr >= 0) & (nr < h) & (nc >= 0) & (nc < w)
                    nb = np.where(inside, nr * w + nc, 0)
                    k = np.where(inside, key[nb], -2)
                    sel = k > -2
                    cells.append(todo[sel])
                    roots.append(k[sel])
            pair = np.unique(np.stack([np.concatenate(cells), np.concatenate(roots)], axis=1), axis=0)
            if not len(pair):
                return
            pc, pr = pair[:, 0], pair[:, 1]
            val = np.full(len(pair), np.inf)
            direct = pr < 0
            if direct.any():
                c = pc[direct]
                clear = p.geo.segments_clear(np.stack([cx_all[c], cy_all[c]], 1), np.array([gx, gy]), p.radius)
                val[np.flatnonzero(direct)[clear]] = np.hypot(cx_all[c[clear]] - gx, cy_all[c[clear]] - gy)
            if (~direct).any():
                c = pc[~direct]
                val[~direct] = self._root_values(c, pr[~direct], cx_all[c], cy_all[c])
            ok = np.isfinite(val)
            if not ok.any():
                return
            pc, pr, val = pc[ok], pr[ok], val[ok]
            # The best pair of each cell: sort by value, keep the first of each cell.
            order = np.lexsort((val, pc))
            pc, pr = pc[order], pr[order]
            first = np.concatenate([[True], pc[1:] != pc[:-1]])
            cells, best = pc[first], pr[first]
            moved = key[cells] != best
            cells, best = cells[moved], best[moved]
            if not len(cells):
                return
            key[cells] = best
            kind[cells] = np.where(best < 0, 1, 2)
            label[cells] = np.where(best < 0, -1, best)
            # Only cells next to a cell that changed can gain a better root next pass.
            fresh = np.zeros(h * w, dtype=bool)
            fresh[cells] = True
            near = ndimage.binary_dilation(fresh.reshape(h, w), structure=np.ones((3, 3), bool)).ravel()
            todo_mask = near & use

    def _build_table(self) -> dict[str, Any]:
        p = self.planner
        geo = p.geo
        h, w = geo.shape
        res = geo.resolution
        usable = p.usable
        n_cells = h * w
        flat = usable.ravel()
        idx = np.flatnonzero(flat)
        # Usable cells start unsettled (3): the grid may not reach a cell the planner does
        # (a passage no row of cell centres runs through), so only an exact query says 0.
        kind = np.where(flat, 3, 0).astype(np.int8)
        label = np.full(n_cells, -1, dtype=np.int64)
        value = np.full(n_cells, np.inf)
        rows, cols = np.divmod(idx, w)
        px = geo.origin[0] + (cols + 0.5) * res
        py = geo.origin[1] + (rows + 0.5) * res
        cx_all = np.full(n_cells, np.nan)
        cy_all = np.full(n_cells, np.nan)
        cx_all[idx], cy_all[idx] = px, py
        gx, gy = float(self.goal[0]), float(self.goal[1])
        if self.goal_usable and len(idx):
            # Seed each arrival at points along its arc ahead of it, so that a cell behind the
            # corner is proposed the arc point it leaves from; the goal is seed 0.
            search = self._search
            arr_lab = search.arrivals()
            a_node = search.node[arr_lab].astype(np.int64)
            a_side = search.side[arr_lab].astype(np.int64)
            a_pos = search.pos[arr_lab]
            rest = p.span[a_node] - a_pos
            xs, ys, costs, owner = [np.array([gx])], [np.array([gy])], [np.array([0.0])], [np.array([0])]
            for f in (0.0, 0.25, 0.5, 0.75, 1.0):
                q = a_pos + f * rest
                ok = np.ones(len(q), bool) if f == 0 else (rest > _ANG_TOL) & p.arcs_free(a_node, a_side, a_pos, q)
                ccw = np.where(a_side > 0, q, p.span[a_node] - q)
                ang = p.phi0[a_node] + ccw
                xs.append((p.cx[a_node] + p.radius * np.cos(ang))[ok])
                ys.append((p.cy[a_node] + p.radius * np.sin(ang))[ok])
                costs.append((search.cost[arr_lab] + p.radius * (q - a_pos))[ok])
                owner.append(arr_lab[ok] + 1)
            xs, ys, costs, owner = (np.concatenate(v) for v in (xs, ys, costs, owner))
            seed_x, seed_y, seed_cost, seed_owner = xs, ys, costs, owner
            scol = np.floor((seed_x - geo.origin[0]) / res).astype(np.int64)
            srow = np.floor((seed_y - geo.origin[1]) / res).astype(np.int64)
            inside = (scol >= 0) & (scol < w) & (srow >= 0) & (srow < h)
            scell = np.where(inside, srow * w + scol, 0)
            ok = inside & flat[scell]
            seeds = np.flatnonzero(ok)
            seed_val = seed_cost[seeds] + np.hypot(cx_all[scell[seeds]] - seed_x[seeds], cy_all[scell[seeds]] - seed_y[seeds])
            graph = p.cell_graph
            # A super-source (index n_cells) joined to each seed's cell, weighted by its cost.
            n = n_cells + 1 + len(seeds)
            # One virtual node per seed, so the predecessor chain names the seed.
            virt = n_cells + 1 + np.arange(len(seeds))
            extra = sparse.csr_matrix(
                (
                    np.concatenate([seed_val + 1e-300, np.full(len(seeds), 1e-300)]),
                    (np.concatenate([np.full(len(seeds), n_cells), virt]), np.concatenate([virt, scell[seeds]])),
                ),
                shape=(n, n),
            )
            big = sparse.bmat([[graph, None], [None, sparse.csr_matrix((n - n_cells, n - n_cells))]], format="csr") + extra
            dist, pred = csgraph.dijkstra(big, directed=True, indices=n_cells, return_predecessors=True)
            dist = dist[:n_cells]
            # Find each cell's seed by pointer doubling up the predecessor tree.
            anc = pred.astype(np.int64)
            anc[anc < 0] = n_cells
            anc[virt] = virt
            anc[n_cells] = n_cells
            while True:
                nxt = anc[anc]
                if np.array_equal(nxt, anc):
                    break
                anc = nxt
            top = anc[:n_cells]
            cell_seed = np.where(top > n_cells, top - (n_cells + 1), -1)
            reach = np.isfinite(dist) & (cell_seed >= 0)
            value[reach] = dist[reach]
            kind[reach] = 3
            seed_of = np.where(reach, seed_owner[seeds[np.maximum(cell_seed, 0)]], -1)
            # Check each proposal: the straight segment from the cell centre to the goal, or
            # the tangent from the seed's node, must be clear and leave the arc forward.
            cells = np.flatnonzero(reach)
            direct = seed_of[cells] == 0
            if direct.any():
                c = cells[direct]
                clear = geo.segments_clear(np.stack([cx_all[c], cy_all[c]], 1), np.array([gx, gy]), p.radius)
                kind[c[clear]] = 1
            c = cells[~direct]
            if len(c):
                lab = seed_of[c] - 1
                good = np.isfinite(self._root_values(c, lab, cx_all[c], cy_all[c]))
                kind[c[good]] = 2
                label[c[good]] = lab[good]
            self._adopt_roots(kind, label, cx_all, cy_all, usable, gx, gy)
        # Compact: one byte of kind and an int32 root per cell; grid fallback values are few.
        fb = np.flatnonzero(kind == 3)
        table = {
            "kind": kind,
            "label": label.astype(np.int32),
            "fallback": dict(zip(fb.tolist(), value[fb].tolist())),
            "gx": gx,
            "gy": gy,
        }
        self._table = table
        # The table made this field bigger: keep the planner's cache within its budget.
        self.planner._trim_fields()
        return table


def _cell_graph(usable: NDArray[np.bool_], res: float) -> sparse.csr_matrix:
    """8-connected graph of usable cells (diagonals only past two usable sides), metres."""
    h, w = usable.shape
    ids = np.arange(h * w).reshape(h, w)
    src, dst, wt = [], [], []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        r0, r1 = 0, h - dr
        c0, c1 = max(0, -dc), w - max(0, dc)
        a = usable[r0:r1, c0:c1]
        b = usable[r0 + dr : r1 + dr, c0 + dc : c1 + dc]
        m = a & b
        if dr and dc:
            m &= usable[r0 + dr : r1 + dr, c0:c1] & usable[r0:r1, c0 + dc : c1 + dc]
        ia = ids[r0:r1, c0:c1][m]
        ib = ids[r0 + dr : r1 + dr, c0 + dc : c1 + dc][m]
        d = res * math.hypot(dr, dc)
        src += [ia, ib]
        dst += [ib, ia]
        wt += [np.full(len(ia), d), np.full(len(ia), d)]
    return sparse.csr_matrix(
        (np.concatenate(wt), (np.concatenate(src), np.concatenate(dst))), shape=(h * w, h * w)
    )
