"""Exact roots of many cell centres of a goal field at once (``GoalField._best`` on arrays).

A goal field's root table holds, per cell, the exact root of its centre: the best way to
the goal from the cell centre, as :meth:`GoalField._best
<pointnav_core.geodesic.field.GoalField._best>` finds it one point at a time. :func:`cell_roots`
makes the same decision for whole arrays of cells, in chunks of at most :data:`CHUNK`
cells, with the same floating-point expressions, so that each cell gets exactly the kind
and label the one-point code gives it:

- the candidate nodes are those whose sight ball holds the centre (``Planner.nodes_seeing``),
  in the order the one-point query takes them;
- a link (a tangent from the centre landing on a node's arc, either winding side) is
  expanded to the reached labels on the arc it departs along (``FieldLabels.on_arc``'s
  order, from a table built once per call); a label counts where it lies at or before the
  departure and the arc between is clear, and the link's total is its best label's (the
  first of equal totals);
- the one-point code keeps, of the direct segment to the goal first and then every visible
  link's labels in order, the first with the smallest total (strict ``<``): the smallest
  ``(total, order)`` over the visible candidates, the direct segment ordered first;
- every link to a node totals at least the cheapest reached label on either of its arcs
  plus the distance to the node less the radius (loosened by :data:`_SLACK`, far above
  rounding; rounding is monotone, so the bound holds in floats). A cell's candidates are
  taken in bands of that bound, :data:`_FIRST_BAND` cells wide above the cell's lowest and
  doubling: their links get exact totals, and only a link that beats the cell's best so
  far has its segment tested. A cell is done once the band passes its best: no candidate
  further on can win, so neither its tangents, nor its labels, nor its segments are looked
  at.

With numba (the ``fast`` extra) :func:`compiled_roots` makes the same decision one point at
a time (:mod:`pointnav_core.geodesic._roots_kernel`), equal in value; it also serves the
exact one-point query (``GoalField.point_distance``).

Everything is in world metres and radians.
"""

from __future__ import annotations

import math
import time
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.floor.collision import TOUCH_TOL
from pointnav_core.geodesic.tangents import ANG_TOL, ccw_pos, tangent_from_point
from pointnav_core.utils import compiled as _compiled
from pointnav_core.utils import workers

if TYPE_CHECKING:
    from pointnav_core.geodesic.arc_graph import FieldLabels
    from pointnav_core.geodesic.cell_links import CellLinks
    from pointnav_core.geodesic.field import GoalField
    from pointnav_core.geodesic.planner import Planner

__all__ = ["CHUNK", "ArcTables", "cell_roots", "compiled", "compiled_roots", "table_roots"]

#: Most cells settled together: bounds the (cell, node) and (link, label) arrays of one pass.
CHUNK = 256
#: Most (cell, node) candidates a chunk may hold when every node falls in every ball.
_CANDIDATES = 2**20
#: Most nodes for which the compiled path scans every node per point (cheapest arcs first)
#: rather than ask the trees for each point's candidates.
_BRUTE_NODES = 1 << 15
#: Most (cell, node) pairs of one chunk of the compiled path.
_COMPILED_PAIRS = 2**22
#: Width (cells) of the first band of candidate bounds evaluated per cell; each round doubles it.
_FIRST_BAND = 8
#: Relative loosening of the candidate bounds (m per m), far above rounding error.
_SLACK = 1e-9
#: Cells per thread from which a settle (a pool's window) runs its kernel on several cores.
THREAD_CELLS = 2048


class ArcTables:
    """What the one-point search reads per arc and per node, as flat arrays.

    ``labels[start[g]:start[g + 1]]`` are ``search.on_arc(node, side)`` for the arc group
    ``g = 2 * node + (side < 0)``, in its order (graph vertices, then the field's own
    arrivals); ``cheapest[g]`` is the cheapest reached label's cost of group ``g``;
    ``labels[start[g]:graph_end[g]]`` are its graph vertices, in the order of their
    positions on the arc (``ArcGraph`` sorts them so), the rest the field's own arrivals.
    """

    def __init__(self, planner: Planner, search: FieldLabels) -> None:
        kernel = compiled(planner, "arc_tables")
        if kernel is not None:  # one pass in compiled code, the same arrays (a property test)
            self.labels, self.start, self.graph_end, self.cheapest, self.by_cheap = kernel(
                search.cost, search.group, search.graph.n_vertices, 2 * planner.n_nodes
            )
            return
        labs = np.flatnonzero(np.isfinite(search.cost))
        group = search.group[labs]
        order = np.argsort(group, kind="stable")
        self.labels = labs[order].astype(np.int64)
        self.start = np.searchsorted(group[order], np.arange(2 * planner.n_nodes + 1), side="left").astype(np.int64)
        graph = self.labels < search.graph.n_vertices
        self.graph_end = self.start[:-1] + np.bincount(search.group[self.labels[graph]], minlength=2 * planner.n_nodes)
        # The cheapest reached label of each arc group (inf where none is reached).
        self.cheapest = np.full(2 * planner.n_nodes, math.inf)
        some = np.flatnonzero(self.start[1:] > self.start[:-1])
        if len(some):
            self.cheapest[some] = np.minimum.reduceat(search.cost[self.labels], self.start[some])
        # The nodes with a reached arc, by their cheapest label.
        node_cheap = np.minimum(self.cheapest[0::2], self.cheapest[1::2])
        reached = np.flatnonzero(np.isfinite(node_cheap))
        self.by_cheap = reached[np.argsort(node_cheap[reached], kind="stable")].astype(np.int64)


def cell_roots(field: GoalField, cells: NDArray[np.int64]) -> tuple[NDArray[np.int8], NDArray[np.int32]]:
    """Table kind and label of each cell's centre, exactly as ``GoalField._best`` finds them.

    Parameters
    ----------
    field : GoalField
    cells : ndarray of int, shape (N,)
        Flat cell indices (``row * width + col``) of the field's grid.

    Returns
    -------
    kind : ndarray of int8, shape (N,)
        0: the robot does not fit at the centre or nothing reaches the goal from it, 1: straight
        to the goal, 2: by a label.
    label : ndarray of int32, shape (N,)
        The label for kind 2, else -1.

    See Also
    --------
    pointnav_core.geodesic.field.GoalField.settle : writes these into the root table.

    Examples
    --------
    A walled room cut by a wall with gaps at both ends; the goal is left of the wall. A cell
    on the left sees it (1), one on the right goes round an end of the wall (2), a wall
    cell gets none (0):

    >>> from pointnav_core.scenes import Scene
    >>> grid = np.zeros((12, 12), np.uint8)
    >>> grid[[0, -1], :] = grid[:, [0, -1]] = 1
    >>> grid[2:10, 6] = 1
    >>> field = Scene.from_array(grid, 0.1).planner(0, 0.0).goal_field((0.35, 0.65))
    >>> kind, label = cell_roots(field, np.array([6 * 12 + 2, 6 * 12 + 9, 0]))
    >>> kind.tolist()
    [1, 2, 0]
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
    # The planner's usable mask is this same exact test at these same centres, made once.
    clear = np.flatnonzero(p.usable.ravel()[cells])
    tables = field.arc_tables() if p.n_nodes else None
    if tables is not None and compiled(p, "best_links") is not None:
        links = p.cell_links(build=False)
        started = time.perf_counter()
        if links is not None:
            # The floor's clear links are known: no segment test beyond the direct one.
            def run(sub: NDArray[np.int64]) -> tuple[NDArray, ...]:
                return table_roots(field, tables, links, cells[sub], xs[sub], ys[sub])

            step = max(len(clear), 1)
        else:
            def run(sub: NDArray[np.int64]) -> tuple[NDArray, ...]:
                return compiled_roots(field, tables, xs[sub], ys[sub])

            # In chunks: the candidate lists of a chunk are held at once.
            step = max(len(clear), 1) if p.n_nodes <= _BRUTE_NODES else max(16, _COMPILED_PAIRS // p.n_nodes)
        threads = _threads(len(clear))
        pieces = np.array_split(clear, max(threads, -(-len(clear) // step)))
        for sub, (k, lab, _) in zip(pieces, _map(run, pieces, threads)):
            kind[sub], label[sub] = k, lab
        if links is None:
            p.spent_on_roots(time.perf_counter() - started)
        return kind, label
    # Fewer cells per chunk where many nodes could fall in a centre's ball.
    chunk = max(16, min(CHUNK, _CANDIDATES // max(p.n_nodes, 1)))
    for i in range(0, len(clear), chunk):
        sub = clear[i : i + chunk]
        kind[sub], label[sub] = _chunk_roots(field, tables, xs[sub], ys[sub])
    return kind, label


def _threads(n_cells: int) -> int:
    """Threads for settling ``n_cells`` cells: the process's cores from :data:`THREAD_CELLS`
    cells on, one in a worker process (its siblings use the other cores)."""
    if n_cells < THREAD_CELLS or workers.in_worker():
        return 1
    return max(1, min(workers.usable_cores(), n_cells // THREAD_CELLS))


def _map(run: Any, pieces: list[NDArray[np.int64]], threads: int) -> list[Any]:
    """``run`` over ``pieces``, in ``threads`` threads (the compiled kernels release the GIL
    and write only their own outputs), in order."""
    if threads <= 1:
        return [run(piece) for piece in pieces]
    with ThreadPoolExecutor(threads) as pool:
        return list(pool.map(run, pieces))


def _chunk_roots(
    field: GoalField, tables: ArcTables | None, x: NDArray[np.float64], y: NDArray[np.float64]
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
    found = _candidates(p, x, y)
    if found is None:
        return kind, label
    owner, cand, rank, total = found
    # Any link to a node totals at least the cheaper of its two arcs' cheapest reached labels
    # plus the tangent, and the tangent is at least the distance to the node less r: a lower
    # bound per candidate, loosened by far more than rounding can move either side.
    cheap = np.minimum(tables.cheapest[2 * cand], tables.cheapest[2 * cand + 1])
    k = np.flatnonzero(np.isfinite(cheap))
    owner, cand, rank, cheap = owner[k], cand[k], rank[k], cheap[k]
    dist = np.hypot(p.cx[cand] - x[owner], p.cy[cand] - y[owner])
    low = cheap + (dist - r) - _SLACK * (1.0 + cheap + dist)
    # A link that is not below the direct segment cannot win (the direct segment comes first).
    k = np.flatnonzero(low < direct[owner])
    owner, cand, rank, low = owner[k], cand[k], rank[k], low[k]
    best, best_order, best_lab = direct.copy(), np.full(n, -1, dtype=np.int64), np.full(n, -1, dtype=np.int64)
    floor = np.full(n, math.inf)
    np.minimum.at(floor, owner, low)
    band = _FIRST_BAND * geo.resolution
    while len(owner):
        # The candidates of each cell whose bound lies within the band above its lowest:
        # their links' exact totals, then the visibility of those that beat the best so far.
        top = floor + band
        now = low <= top[owner]
        k = np.flatnonzero(now)
        links = _tangents(p, x, y, owner[k], cand[k], rank[k], total) if len(k) else None
        if links is not None:
            cell, node, s, dep, length, ang, order = links
            value, lab = _link_values(field, tables, node, s, dep, length)
            beat = np.flatnonzero((value < best[cell]) | ((value == best[cell]) & (order < best_order[cell])))
            if len(beat):
                c = node[beat]
                q = np.stack([p.cx[c] + r * np.cos(ang[beat]), p.cy[c] + r * np.sin(ang[beat])], axis=1)
                seen = beat[geo.segments_clear(pts[cell[beat]], q, r)]
                # Each cell's smallest (total, order) among its visible links of this round.
                seen = seen[np.lexsort((order[seen], value[seen], cell[seen]))]
                seen = seen[_run_heads(cell[seen])]
                who = cell[seen]
                best[who], best_order[who], best_lab[who] = value[seen], order[seen], lab[seen]
        # What is left lies above the band: a cell whose best the band reached is done.
        rest = np.flatnonzero(~now & (top[owner] < best[owner]))
        owner, cand, rank, low = owner[rest], cand[rest], rank[rest], low[rest]
        band *= 2
    got = np.flatnonzero(best_lab >= 0)
    kind[got] = 2
    label[got] = best_lab[got]
    return kind, label


def compiled(planner: Planner, name: str) -> Any:
    """The compiled kernel ``name`` of :mod:`pointnav_core.geodesic._roots_kernel` for
    ``planner``'s floor, or None: without numba, without nodes, or with a floor part the
    compiled polygon test cannot read (the numpy paths then serve)."""
    if not planner.n_nodes or not planner.geo.compiled_polygons:
        return None
    return _compiled.kernel("pointnav_core.geodesic._roots_kernel", name)


def compiled_roots(
    field: GoalField, tables: ArcTables, x: NDArray[np.float64], y: NDArray[np.float64], departures: bool = False
) -> tuple[NDArray[np.int8], NDArray[np.int32], NDArray[np.float64]] | tuple[NDArray, ...]:
    """:func:`_chunk_roots`' decision for clear points (cell centres or any), one at a time
    in compiled code: kinds, labels and the exact distances (m), and with ``departures``
    where each path leaves its label's arc (rad, 0 for the direct segment). Needs numba."""
    p = field.planner
    search = field.labels
    best_links = compiled(p, "best_links")
    if p.n_nodes <= _BRUTE_NODES:
        # Every node, cheapest arcs first: the scan of a point stops where they pass its best.
        cand = tables.by_cheap
        lo, hi = np.zeros(len(x), np.int64), np.full(len(x), len(cand), np.int64)
    else:
        owner, cand = p.nodes_seeing(x, y)
        start = np.searchsorted(owner, np.arange(len(x) + 1)).astype(np.int64)
        lo, hi = start[:-1], start[1:]
    blocked, has_blocked = p.blocked_arcs()
    kind = np.zeros(len(x), dtype=np.int8)
    label = np.full(len(x), -1, dtype=np.int64)
    value = np.empty(len(x))
    dep = np.empty(len(x))
    best_links(
        x, y, float(field.goal[0]), float(field.goal[1]), cand, lo, hi, p.n_nodes <= _BRUTE_NODES, _SLACK,
        p.cx, p.cy, p.phi0, p.span, p.radius, ANG_TOL, TOUCH_TOL, p.sight_reach,
        p.sight_profile, tables.cheapest, tables.start, tables.graph_end, tables.labels, search.pos, search.cost,
        blocked, has_blocked, *p.geo.kernel_geometry(), kind, label, value, dep,
    )
    if departures:
        return kind, label.astype(np.int32), value, dep
    return kind, label.astype(np.int32), value


def table_roots(
    field: GoalField,
    tables: ArcTables,
    links: CellLinks,
    cells: NDArray[np.int64],
    x: NDArray[np.float64],
    y: NDArray[np.float64],
) -> tuple[NDArray[np.int8], NDArray[np.int32], NDArray[np.float64]]:
    """:func:`compiled_roots`' decision for the clear centres ``(x, y)`` of ``cells``, read
    from the floor's :class:`~pointnav_core.geodesic.cell_links.CellLinks`: kinds, labels and
    exact distances (m). Needs numba."""
    p = field.planner
    search = field.labels
    blocked, has_blocked = p.blocked_arcs()
    kind = np.zeros(len(x), dtype=np.int8)
    label = np.full(len(x), -1, dtype=np.int64)
    value = np.empty(len(x))
    compiled(p, "table_roots")(
        x, y, float(field.goal[0]), float(field.goal[1]), links.first[cells], links.count[cells], links.node,
        links.side, links.pos, links.length, p.n_nodes, p.span, p.radius, ANG_TOL, TOUCH_TOL,
        tables.start, tables.graph_end, tables.labels, search.pos, search.cost, blocked, has_blocked,
        *p.geo.kernel_geometry(), kind, label, value,
    )
    return kind, label.astype(np.int32), value


def _candidates(
    p: Planner, x: NDArray[np.float64], y: NDArray[np.float64]
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], int] | None:
    """The nodes each centre's one-point query finds: per candidate its centre, node and rank
    in the query's order, and their number; None when there are none."""
    owner, cand = p.nodes_seeing(x, y)
    total = len(cand)
    if not total:
        return None
    counts = np.bincount(owner, minlength=len(x))
    rank = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
    return owner, cand, rank, total


_Links = tuple[
    NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.float64], NDArray[np.float64],
    NDArray[np.float64], NDArray[np.int64],
]


def _tangents(
    p: Planner,
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    owner: NDArray[np.int64],
    cand: NDArray[np.int64],
    rank: NDArray[np.int64],
    total: int,
) -> _Links | None:
    """The tangents from centres to candidate nodes that land on the nodes' arcs (visible or not).

    Returns per link its centre, node, side ``s``, departure position of the reverse path
    ``dep`` (rad), tangent length (m), arrival angle (rad) and a key that orders a centre's
    links as :meth:`Planner.point_links` does (side +1 first, then the query's order,
    ``rank < total``); None when there are none.
    """
    r = p.radius
    parts = []
    for side_rank, s in enumerate((1, -1)):
        ang, length, _, ok = tangent_from_point(x[owner], y[owner], p.cx[cand], p.cy[cand], r, s)
        ccw, ok_arc = ccw_pos(ang, p.phi0[cand], p.span[cand])
        ok &= ok_arc
        k = np.flatnonzero(ok)
        c = cand[k]
        pos = ccw[k] if s > 0 else p.span[c] - ccw[k]
        parts.append((owner[k], c, np.full(len(k), s), p.span[c] - pos, length[k], ang[k], side_rank * total + rank[k]))
    out = tuple(np.concatenate(v) for v in zip(*parts))
    return out if len(out[0]) else None  # type: ignore[return-value]


def _link_values(
    field: GoalField,
    tables: ArcTables,
    node: NDArray[np.int64],
    s: NDArray[np.int64],
    dep: NDArray[np.float64],
    length: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Each link's best total (inf if no label counts) and its first label of that total."""
    p = field.planner
    search = field.labels
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
    ok = lp <= d + ANG_TOL
    k = np.flatnonzero(ok)
    ok[k] = p.arcs_free(node[link[k]], -s[link[k]], lp[k], d[k])
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
