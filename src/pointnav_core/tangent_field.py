"""Goal fields on the tangent graph: exact point queries and the per-step lookup table.

A :class:`GoalField` is one Dijkstra run of :mod:`pointnav_core.tangent_graph` from a goal:
the exact distance of every node it reaches. :meth:`GoalField.point_distance` and
:meth:`GoalField.path` are exact for any point (the tangents the point sees, then the
settled labels). :meth:`GoalField.distance` is the per-step lookup through a root table:
on the first lookup a seeded multi-source Dijkstra on the grid proposes every cell's root
label (cheap); the exact checks are made one block of cells at a time, when a lookup first
lands in the block: each proposal is checked, cells whose proposal fails and cells on the
border of two roots try their neighbours' roots, and a cell left without one takes its
centre's exact root on its own first lookup (or, settling the whole table, all such cells at
once, :meth:`GoalField._settle_cells`). Everything is in world metres.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage, sparse
from scipy.sparse import csgraph

from pointnav_core.field_roots import cell_roots
from pointnav_core.frozen import ThawOnUnpickle
from pointnav_core.tangent_graph import (
    _ANG_TOL,
    _TWO_PI,
    Planner,
    _ccw_pos,
    _tangent_from_point,
)

__all__ = ["GoalField"]

#: Most neighbour-inheritance passes of the root table (each reaches one cell further).
_ADOPT_PASSES = 64
#: Side (cells) of the square blocks of the root table, each checked on its first lookup.
_BLOCK = 16
#: Table kind of a cell whose proposed root has not been checked yet (its block has not).
_UNCHECKED = 4
#: Cells (each side) around a block whose roots may flow into it while it is checked.
_MARGIN = 8


class GoalField(ThawOnUnpickle):
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

    def path(
        self, xy: ArrayLike, exact: bool = True, max_length: float = math.inf
    ) -> tuple[NDArray[np.float64], float] | tuple[None, None]:
        """Shortest path (N, 2) from world point ``xy`` to the goal and its length (m).

        ``exact`` is kept for compatibility: every path is exact. With a finite
        ``max_length`` (m) only the path's beginning is drawn: it ends at the first vertex
        ``max_length`` or more along it (a follower needs no more); the length returned is
        still the whole path's.
        """
        x, y = (float(v) for v in np.asarray(xy, dtype=np.float64).reshape(-1)[:2])
        cost, label, dep = self._best(x, y)
        if label == -2:
            return None, None
        pts = [np.array([x, y])]
        whole = True
        if label >= 0:
            traced, whole = self._search.trace(label, dep, (x, y), max_length)
            pts += traced
        if whole:
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
        if kind == _UNCHECKED:
            self._check_block(i)
            kind = t["kind"][i]
        if kind == 0:
            return math.inf
        if kind == 1:  # straight to the goal
            return math.hypot(x - t["gx"], y - t["gy"])
        if kind == 3:
            # No checked root was found here: find the cell centre's exact one, once.
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
        return kind

    def _settle_cells(self, cells: ArrayLike) -> NDArray[np.int8]:
        """Give table cells ``cells`` their exact roots at once; their new kinds.

        Each cell gets exactly the kind and label :meth:`_settle_cell` would give it (the
        same decision, made on arrays: :func:`pointnav_core.field_roots.cell_roots`).

        Parameters
        ----------
        cells : array_like of int, shape (N,)
            Flat table indices (``row * width + col``), each in ``[0, height * width)``.
        """
        t = self._table
        assert t is not None
        idx = np.asarray(cells)
        n_cells = len(t["kind"])
        if idx.ndim != 1 or (idx.size and not np.issubdtype(idx.dtype, np.integer)):
            raise ValueError(f"cells must be a 1D array of integer cell indices, got shape {idx.shape} of {idx.dtype}")
        idx = idx.astype(np.int64)
        if idx.size and (idx.min() < 0 or idx.max() >= n_cells):
            raise ValueError(f"cells must lie in [0, {n_cells}), got {idx.min()} to {idx.max()}")
        kind, label = cell_roots(self, idx)
        t["kind"][idx] = kind
        t["label"][idx] = label
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

    def _key_values(self, cells: NDArray[np.int64], keys: NDArray[np.int64]) -> NDArray[np.float64]:
        """Exact value of leaving cell centres by root ``keys`` (-1: the goal directly); inf if not valid."""
        p = self.planner
        geo = p.geo
        rows, cols = np.divmod(cells, geo.shape[1])
        px = geo.origin[0] + (cols + 0.5) * geo.resolution
        py = geo.origin[1] + (rows + 0.5) * geo.resolution
        val = np.full(len(cells), np.inf)
        direct = keys == -1
        if direct.any():
            gx, gy = float(self.goal[0]), float(self.goal[1])
            d = np.flatnonzero(direct)
            clear = geo.segments_clear(np.stack([px[d], py[d]], 1), np.array([gx, gy]), p.radius)
            d = d[clear]
            val[d] = np.hypot(px[d] - gx, py[d] - gy)
        lab = np.flatnonzero(keys >= 0)
        if len(lab):
            val[lab] = self._root_values(cells[lab], keys[lab], px[lab], py[lab])
        return val

    def _check_block(self, i: int, memo: NDArray[np.int8] | None = None) -> None:
        """Check the proposed roots of the block holding cell ``i``, then let its cells adopt.

        Each proposal (the goal directly, or a label's tangent) is checked exactly at the cell
        centre; a cell whose proposal fails gets kind 3, one with none kind 0. Then, as Theta*
        inherits parents, the cells whose proposal failed and those on the border between two
        roots try their neighbours' roots (a neighbour's root is usually visible too, and the
        grid metric may have picked the worse of two routes that almost tie). Each pass tests
        every distinct (cell, root) pair once, own root included, keeps each cell's best, and
        the next pass takes only cells next to one that changed.

        The passes run on the block and a margin of :data:`_MARGIN` cells around it, so that a
        better root found next door can still flow in; only the block's cells are written.
        Margin cells start from their table root where their block is checked, else from their
        own proposal, checked here first: nothing unchecked is ever adopted.

        An unchecked cell's proposal never changes, so neither does its check: ``memo`` (per
        table cell, 0 not yet checked, 1 passed, 2 failed; updated here) lets a caller that
        checks many blocks (:func:`pointnav_core.vector.fields.settle`) check each proposal
        once, not again in the margin of every neighbouring block. With it, the passes also
        value each (cell, root) pair once, not again in each pass that tests it (about half
        the pairs on a 1000 x 1000 map of random boxes). The table comes out the same.
        """
        t = self._table
        assert t is not None
        kind, label = t["kind"], t["label"]
        h, w = self.planner.geo.shape
        b, m = _BLOCK, _MARGIN
        r0, c0 = (i // w) // b * b, (i % w) // b * b
        t["done"][(r0 // b) * t["blocks_w"] + c0 // b] = True
        # The working window: the block and its margin, clipped to the map.
        wr0, wr1, wc0, wc1 = max(r0 - m, 0), min(r0 + b + m, h), max(c0 - m, 0), min(c0 + b + m, w)
        wh, ww = wr1 - wr0, wc1 - wc0
        ids = (np.arange(wr0, wr1)[:, None] * w + np.arange(wc0, wc1)[None, :]).ravel()
        lr_all, lc_all = np.divmod(np.arange(len(ids)), ww)
        mine = ((lr_all + wr0) // b == r0 // b) & ((lc_all + wc0) // b == c0 // b)
        k = kind[ids]
        key = np.where(k == 1, -1, np.where(k == 2, label[ids], -2)).astype(np.int64)
        fresh = np.flatnonzero(k == _UNCHECKED)
        prop = label[ids[fresh]].astype(np.int64)
        has = prop > -2
        ok = np.zeros(len(fresh), dtype=bool)
        if memo is None:
            ok[has] = np.isfinite(self._key_values(ids[fresh[has]], prop[has]))
        else:
            seen = memo[ids[fresh]]
            todo = has & (seen == 0)
            ok[todo] = np.isfinite(self._key_values(ids[fresh[todo]], prop[todo]))
            ok |= has & (seen == 1)
            memo[ids[fresh[todo]]] = np.where(ok[todo], 1, 2)
        key[fresh[ok]] = prop[ok]
        # The block's own cells take their checked proposals now; margin cells stay unchecked.
        sel = mine[fresh]
        # A cell with no proposal is not known unreachable: the grid cannot cross a passage
        # no row of cell centres runs through, the planner can. It settles exactly (3).
        kind[ids[fresh[sel]]] = np.where(ok, np.where(prop == -1, 1, 2), 3)[sel]
        label[ids[fresh[sel]]] = np.where(ok, prop, -1)[sel]
        # Roots of the window padded by one cell of none (-2), so that shifts stay inside.
        pad = np.full((wh + 2, ww + 2), -2, dtype=np.int64)
        pad[1:-1, 1:-1] = key.reshape(wh, ww)
        grid = pad[1:-1, 1:-1]  # a view: updates show in the neighbour shifts below
        use = self.planner.usable.ravel()[ids].reshape(wh, ww)
        shifts = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]
        border = np.zeros((wh, ww), dtype=bool)
        for dr, dc in shifts:
            nk = pad[1 + dr : 1 + dr + wh, 1 + dc : 1 + dc + ww]
            border |= (nk != grid) & (nk > -2) & (grid > -2)
        todo_mask = use & ((grid == -2) | border)
        changed = np.zeros(wh * ww, dtype=bool)
        # With a memo, the (cell, root) pairs valued in earlier passes (sorted keys, values).
        seen_key, seen_val = np.zeros(0, dtype=np.int64), np.zeros(0)
        for _ in range(_ADOPT_PASSES):
            loc = np.flatnonzero(todo_mask)
            if not len(loc):
                break
            lr, lc = lr_all[loc], lc_all[loc]
            cells, roots = [loc], [grid.ravel()[loc]]
            for dr, dc in shifts:
                cells.append(loc)
                roots.append(pad[1 + lr + dr, 1 + lc + dc])
            pair = _unique_pairs(np.concatenate(cells), np.concatenate(roots))
            pair = pair[pair[:, 1] > -2]
            if not len(pair):
                break
            if memo is None:
                val = self._key_values(ids[pair[:, 0]], pair[:, 1])
            else:
                val, seen_key, seen_val = _remembered_values(self, ids, pair, seen_key, seen_val)
            good = np.isfinite(val)
            if not good.any():
                break
            pl, pk, val = pair[good, 0], pair[good, 1], val[good]
            # The best pair of each cell: sort by value, keep the first of each cell.
            order = np.lexsort((val, pl))
            pl, pk = pl[order], pk[order]
            first = np.concatenate([[True], pl[1:] != pl[:-1]])
            pl, pk = pl[first], pk[first]
            moved = grid.ravel()[pl] != pk
            pl, pk = pl[moved], pk[moved]
            if not len(pl):
                break
            grid[lr_all[pl], lc_all[pl]] = pk
            changed[pl] = True
            # Only cells next to a cell that changed can gain a better root next pass.
            now = np.zeros((wh, ww), dtype=bool)
            now[lr_all[pl], lc_all[pl]] = True
            todo_mask = use & ndimage.binary_dilation(now, structure=np.ones((3, 3), bool))
        put = np.flatnonzero(changed & mine)
        best = grid.ravel()[put]
        kind[ids[put]] = np.where(best < 0, 1, 2)
        label[ids[put]] = best

    def _build_table(self) -> dict[str, Any]:
        """Propose every cell's root (one seeded grid Dijkstra); blocks are checked on first use."""
        p = self.planner
        geo = p.geo
        h, w = geo.shape
        res = geo.resolution
        usable = p.usable
        n_cells = h * w
        flat = usable.ravel()
        idx = np.flatnonzero(flat)
        kind = np.zeros(n_cells, dtype=np.int8)
        label = np.full(n_cells, -2, dtype=np.int32)  # -1: the goal directly, -2: no proposal
        gx, gy = float(self.goal[0]), float(self.goal[1])
        if self.goal_usable and len(idx):
            kind[idx] = _UNCHECKED
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
            seed_x, seed_y, seed_cost, seed_owner = (np.concatenate(v) for v in (xs, ys, costs, owner))
            scol = np.floor((seed_x - geo.origin[0]) / res).astype(np.int64)
            srow = np.floor((seed_y - geo.origin[1]) / res).astype(np.int64)
            inside = (scol >= 0) & (scol < w) & (srow >= 0) & (srow < h)
            scell = np.where(inside, srow * w + scol, 0)
            seeds = np.flatnonzero(inside & flat[scell])
            sc = scell[seeds]
            seed_val = seed_cost[seeds] + np.hypot(
                geo.origin[0] + (sc % w + 0.5) * res - seed_x[seeds], geo.origin[1] + (sc // w + 0.5) * res - seed_y[seeds]
            )
            graph = p.cell_graph
            # A super-source (index n_cells) joined to each seed's cell, weighted by its cost.
            n = n_cells + 1 + len(seeds)
            # One virtual node per seed, so the predecessor chain names the seed.
            virt = n_cells + 1 + np.arange(len(seeds))
            extra = sparse.csr_matrix(
                (
                    np.concatenate([seed_val + 1e-300, np.full(len(seeds), 1e-300)]),
                    (np.concatenate([np.full(len(seeds), n_cells), virt]), np.concatenate([virt, sc])),
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
            # The proposal, checked with its block: seed owner 0 is the goal (-1), else label + 1.
            label[reach] = seed_owner[seeds[cell_seed[reach]]] - 1
        b = _BLOCK
        blocks_w = -(-w // b)
        table = {
            "kind": kind,
            "label": label,
            # Whether each block (row-major, _BLOCK cells square) has been checked.
            "done": np.zeros(-(-h // b) * blocks_w, dtype=bool),
            "blocks_w": blocks_w,
            "gx": gx,
            "gy": gy,
        }
        self._table = table
        # The table made this field bigger: keep the planner's cache within its budget.
        self.planner._trim_fields()
        return table


def _remembered_values(
    field: GoalField, ids: NDArray[np.int64], pair: NDArray[np.int64], seen_key: NDArray[np.int64],
    seen_val: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
    """``field._key_values(ids[pair[:, 0]], pair[:, 1])``, valuing only the pairs not among
    ``seen_key`` (sorted keys ``cell * 2**32 + root + 2``, values ``seen_val``); the values
    and the keys and values seen now. A pair's value depends on nothing but the pair (each
    element's arithmetic is the same at any array length: ``tests/test_field_roots.py``)."""
    key = pair[:, 0] * (1 << 32) + (pair[:, 1] + 2)
    at = np.minimum(np.searchsorted(seen_key, key), max(len(seen_key) - 1, 0))
    hit = seen_key[at] == key if len(seen_key) else np.zeros(len(key), dtype=bool)
    val = np.empty(len(key))
    val[hit] = seen_val[at[hit]]
    new = np.flatnonzero(~hit)
    if len(new):
        val[new] = field._key_values(ids[pair[new, 0]], pair[new, 1])
        seen_key = np.concatenate([seen_key, key[new]])
        seen_val = np.concatenate([seen_val, val[new]])
        order = np.argsort(seen_key, kind="stable")
        seen_key, seen_val = seen_key[order], seen_val[order]
    return val, seen_key, seen_val


def _unique_pairs(cells: NDArray[np.int64], roots: NDArray[np.int64]) -> NDArray[np.int64]:
    """The distinct ``(cell, root)`` pairs, sorted by cell then root: an ``(N, 2)`` int array.

    The rows of ``np.unique(np.stack([cells, roots], 1), axis=0)``, found by sorting one
    int64 key per pair (``cell * span + root + 2``) instead of the pairs as structured rows,
    which sorts several times slower. Same order, so ties later keep their order.

    Parameters
    ----------
    cells : ndarray of int, shape (N,)
        Cell indices, >= 0.
    roots : ndarray of int, shape (N,)
        Roots, >= -2 (-2: none, -1: the goal directly, else a label).
    """
    cells = np.asarray(cells, dtype=np.int64)
    roots = np.asarray(roots, dtype=np.int64)
    if not len(cells):
        return np.zeros((0, 2), dtype=np.int64)
    span = int(roots.max()) + 3
    key = np.unique(cells * span + (roots + 2))
    cell, root = np.divmod(key, span)
    return np.stack([cell, root - 2], axis=1)


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
