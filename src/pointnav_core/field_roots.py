"""Exact roots of many cell centres of a goal field at once (``GoalField._best`` on arrays).

A goal field's root table leaves a few cells (kind 3) to be settled exactly: the best way
to the goal from the cell centre, as :meth:`GoalField._best
<pointnav_core.tangent_field.GoalField._best>` finds it one point at a time. :func:`cell_roots`
makes the same decision for whole arrays of cells, in chunks of :data:`CHUNK` cells, with
the same floating-point expressions, so that each cell gets exactly the kind and label
the one-point code gives it:

- the candidate nodes are the kd-tree's ball around each centre (radius: the centre's sight
  bound plus the robot radius), in the order the one-point query returns them;
- each (centre, node) pair gets its tangent and arc position, on both winding sides;
- the one-point code keeps, of the direct segment to the goal first and then every visible
  link's labels in order, the first with the smallest total (strict ``<``): the smallest
  ``(total, order)`` over the visible candidates, the direct segment ordered first;
- a link's total is at least the cheapest reached label on its arc plus its tangent's
  length, in floats too (rounding is monotone). Links are taken in the order of that bound,
  in rounds of growing size per cell: each is expanded to the reached labels on the arc it
  departs along (``FieldLabels.on_arc``'s order, from a table built once per call; a label
  counts where it lies at or before the departure and the arc between is clear), its total
  is its best label's (the first of equal totals), and only a link that beats the cell's
  best so far has its segment tested. A cell is done when its next bound exceeds its best:
  no link further on can win, so neither their labels nor their segments are looked at.

Everything is in world metres and radians.
"""

from __future__ import annotations

import itertools
import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from pointnav_core.tangent_graph import _ANG_TOL, Planner, _ccw_pos, _tangent_from_point

if TYPE_CHECKING:
    from pointnav_core.arc_graph import FieldLabels
    from pointnav_core.tangent_field import GoalField

__all__ = ["CHUNK", "cell_roots"]

#: Cells settled together: bounds the (cell, node) and (link, label) arrays of one pass.
CHUNK = 256
#: Links per cell that the first round evaluates; each later round doubles it.
_FIRST_ROUND = 8


class _ArcTables:
    """What the one-point search reads per arc and per node, as flat arrays.

    ``labels[start[g]:start[g + 1]]`` are ``search.on_arc(node, side)`` for the arc group
    ``g = 2 * node + (side < 0)``, in its order (graph vertices, then the field's own
    arrivals); ``blocked[n]`` holds node ``n``'s blocked arc samples (NaN padded).
    """

    def __init__(self, planner: Planner, search: FieldLabels) -> None:
        labs = np.flatnonzero(np.isfinite(search.cost))
        group = search.group[labs]
        order = np.argsort(group, kind="stable")
        self.labels = labs[order]
        self.start = np.searchsorted(group[order], np.arange(2 * planner.n_nodes + 1), side="left")
        # The cheapest reached label of each arc group (inf where none is reached).
        self.cheapest = np.full(2 * planner.n_nodes, math.inf)
        some = np.flatnonzero(self.start[1:] > self.start[:-1])
        if len(some):
            self.cheapest[some] = np.minimum.reduceat(search.cost[self.labels], self.start[some])
        lists = planner._blocked_ccw
        widest = max((len(b) for b in lists), default=0)
        self.blocked = np.full((planner.n_nodes, max(widest, 1)), np.nan)
        for n, b in enumerate(lists):
            if b:
                self.blocked[n, : len(b)] = b
        self.has_blocked = np.fromiter((bool(b) for b in lists), dtype=bool, count=planner.n_nodes)

    def arcs_free(
        self,
        planner: Planner,
        node: NDArray[np.int64],
        s: NDArray[np.int64],
        p1: NDArray[np.float64],
        p2: NDArray[np.float64],
    ) -> NDArray[np.bool_]:
        """:meth:`Planner._arc_free` of each ``(node, s, p1, p2)``, with its expressions."""
        out = np.ones(len(node), dtype=bool)
        k = np.flatnonzero(self.has_blocked[node])
        if len(k):
            sp = planner.span[node[k]]
            ccw_side = s[k] > 0
            lo = np.where(ccw_side, p1[k], sp - p2[k])
            hi = np.where(ccw_side, p2[k], sp - p1[k])
            b = self.blocked[node[k]]
            with np.errstate(invalid="ignore"):
                out[k] = ~((lo[:, None] + _ANG_TOL < b) & (b < hi[:, None] - _ANG_TOL)).any(axis=1)
        return out


def cell_roots(field: GoalField, cells: NDArray[np.int64]) -> tuple[NDArray[np.int8], NDArray[np.int32]]:
    """Table kind and label of each cell's centre, exactly as ``GoalField._settle_cell`` sets them.

    Parameters
    ----------
    field : GoalField
    cells : ndarray of int, shape (N,)
        Flat cell indices (``row * width + col``) of the field's grid.

    Returns
    -------
    kind : ndarray of int8, shape (N,)
        0: the goal is not reachable from the centre, 1: straight to the goal, 2: by a label.
    label : ndarray of int32, shape (N,)
        The label for kind 2, else -1.
    """
    p = field.planner
    geo = p.geo
    n = len(cells)
    kind = np.zeros(n, dtype=np.int8)
    label = np.full(n, -1, dtype=np.int32)
    if not n or not field.goal_usable:
        return kind, label
    rows, cols = np.divmod(cells, geo.shape[1])
    xs = geo.origin[0] + (cols + 0.5) * geo.resolution
    ys = geo.origin[1] + (rows + 0.5) * geo.resolution
    clear = np.flatnonzero(geo.points_clear(np.stack([xs, ys], axis=1), p.radius))
    tables = _ArcTables(p, field._search) if p.n_nodes else None
    for i in range(0, len(clear), CHUNK):
        sub = clear[i : i + CHUNK]
        kind[sub], label[sub] = _chunk_roots(field, tables, xs[sub], ys[sub])
    return kind, label


def _chunk_roots(
    field: GoalField, tables: _ArcTables | None, x: NDArray[np.float64], y: NDArray[np.float64]
) -> tuple[NDArray[np.int8], NDArray[np.int32]]:
    """Kinds and labels of clear centres ``(x, y)``: the direct segment, then the links."""
    p = field.planner
    geo = p.geo
    r = p.radius
    n = len(x)
    pts = np.stack([x, y], axis=1)
    gx, gy = float(field.goal[0]), float(field.goal[1])
    # The direct segment: math.hypot, as the one-point code (numpy's may differ in the last bit).
    direct = np.fromiter(
        (math.hypot(gx - a, gy - b) for a, b in zip(x.tolist(), y.tolist())), dtype=np.float64, count=n
    )
    direct[~geo.segments_clear(pts, np.array([gx, gy]), r)] = math.inf
    kind = np.where(np.isfinite(direct), 1, 0).astype(np.int8)
    label = np.full(n, -1, dtype=np.int32)
    if tables is None:
        return kind, label
    links = _links(p, x, y)
    if links is None:
        return kind, label
    cell, node, s, dep, length, ang, order = links
    # A link's total is at least its arc's cheapest reached label plus its tangent (rounding
    # is monotone, so in floats too); a link not below the direct segment cannot win.
    bound = tables.cheapest[2 * node + (s > 0)] + length
    keep = np.flatnonzero(bound < direct[cell])
    srt = keep[np.lexsort((order[keep], bound[keep], cell[keep]))]
    best, best_order, best_lab = direct.copy(), np.full(n, -1, dtype=np.int64), np.full(n, -1, dtype=np.int64)
    cell, bound = cell[srt], bound[srt]
    start = np.searchsorted(cell, np.arange(n), side="left")
    end = np.searchsorted(cell, np.arange(n), side="right")
    at = start.copy()
    live = np.flatnonzero(at < end)
    size = _FIRST_ROUND
    while len(live):
        # The next links of each live cell, in bound order: exact totals, then the
        # visibility of those that beat the cell's best so far.
        take = np.minimum(end[live] - at[live], size)
        owner = np.repeat(live, take)
        k = srt[np.repeat(at[live], take) + (np.arange(int(take.sum())) - np.repeat(np.cumsum(take) - take, take))]
        value, lab = _link_values(field, tables, node[k], s[k], dep[k], length[k])
        beat = np.flatnonzero((value < best[owner]) | ((value == best[owner]) & (order[k] < best_order[owner])))
        if len(beat):
            c = node[k[beat]]
            arrive = ang[k[beat]]
            q = np.stack([p.cx[c] + r * np.cos(arrive), p.cy[c] + r * np.sin(arrive)], axis=1)
            seen = beat[geo.segments_clear(pts[owner[beat]], q, r)]
            # Each cell's smallest (total, order) among its visible links of this round.
            seen = seen[np.lexsort((order[k[seen]], value[seen], owner[seen]))]
            seen = seen[_run_heads(owner[seen])]
            who = owner[seen]
            best[who], best_order[who], best_lab[who] = value[seen], order[k[seen]], lab[seen]
        at[live] += take
        # Links further on have totals of at least their bounds: stop past the best.
        more = at[live] < end[live]
        more[more] = bound[at[live[more]]] <= best[live[more]]
        live = live[more]
        size *= 2
    got = np.flatnonzero(best_lab >= 0)
    kind[got] = 2
    label[got] = best_lab[got]
    return kind, label


_Links = tuple[
    NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.float64], NDArray[np.float64],
    NDArray[np.float64], NDArray[np.int64],
]


def _links(p: Planner, x: NDArray[np.float64], y: NDArray[np.float64]) -> _Links | None:
    """Every tangent from the centres to a candidate node that lands on its arc (visible or not).

    Returns per link its centre, node, side ``s``, departure position of the reverse path
    ``dep`` (rad), tangent length (m), arrival angle (rad) and its rank in
    :meth:`Planner.point_links`'s order among the centre's links; None when there are none.
    """
    geo = p.geo
    res = geo.resolution
    r = p.radius
    # Planner.sight_radius of each centre: its cell's centre's rays, widened by a half diagonal.
    scx = geo.origin[0] + (np.floor((x - geo.origin[0]) / res) + 0.5) * res
    scy = geo.origin[1] + (np.floor((y - geo.origin[1]) / res) + 0.5) * res
    reach = (p._sight_radii(scx, scy) + res * math.sqrt(0.5)) + r
    # Unsorted, as a one-point query returns them (the same tree walk per point).
    balls = p._tree.query_ball_point(np.stack([x, y], axis=1), reach, return_sorted=False)
    counts = np.fromiter((len(b) for b in balls), dtype=np.int64, count=len(balls))
    total = int(counts.sum())
    if not total:
        return None
    cand = np.fromiter(itertools.chain.from_iterable(balls), dtype=np.int64, count=total)
    owner = np.repeat(np.arange(len(x)), counts)
    rank = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
    parts = []
    for side_rank, s in enumerate((1, -1)):
        ang, length, _, ok = _tangent_from_point(x[owner], y[owner], p.cx[cand], p.cy[cand], r, s)
        ccw, ok_arc = _ccw_pos(ang, p.phi0[cand], p.span[cand])
        ok &= ok_arc
        k = np.flatnonzero(ok)
        c = cand[k]
        pos = ccw[k] if s > 0 else p.span[c] - ccw[k]
        parts.append((owner[k], c, np.full(len(k), s), p.span[c] - pos, length[k], ang[k], side_rank * total + rank[k]))
    out = tuple(np.concatenate(v) for v in zip(*parts))
    return out if len(out[0]) else None  # type: ignore[return-value]


def _link_values(
    field: GoalField,
    tables: _ArcTables,
    node: NDArray[np.int64],
    s: NDArray[np.int64],
    dep: NDArray[np.float64],
    length: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Each link's best total (inf if no label counts) and its first label of that total."""
    p = field.planner
    search = field._search
    group = 2 * node + (s > 0)  # the reverse path winds -s
    first = tables.start[group]
    count = tables.start[group + 1] - first
    n_links = len(node)
    value = np.full(n_links, math.inf)
    lab = np.full(n_links, -1, dtype=np.int64)
    n_pairs = int(count.sum())
    if not n_pairs:
        return value, lab
    link = np.repeat(np.arange(n_links), count)
    begin = np.cumsum(count) - count
    labs = tables.labels[np.repeat(first, count) + (np.arange(n_pairs) - np.repeat(begin, count))]
    lp = search.pos[labs]
    d = dep[link]
    ok = lp <= d + _ANG_TOL
    k = np.flatnonzero(ok)
    ok[k] = tables.arcs_free(p, node[link[k]], -s[link[k]], lp[k], d[k])
    pair = np.where(ok, search.cost[labs] + p.radius * np.maximum(d - lp, 0.0) + length[link], math.inf)
    some = np.flatnonzero(count)
    value[some] = np.minimum.reduceat(pair, begin[some])
    hit = np.flatnonzero((pair == value[link]) & ok)
    hit = hit[_run_heads(link[hit])]
    lab[link[hit]] = labs[hit]
    return value, lab


def _run_heads(keys: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Where each run of equal consecutive ``keys`` begins."""
    head = np.ones(len(keys), dtype=bool)
    head[1:] = keys[1:] != keys[:-1]
    return head
