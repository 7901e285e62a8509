"""Goal fields on the tangent graph: exact point queries and the per-step lookup table.

A :class:`GoalField` is one Dijkstra run of :mod:`pointnav_core.geodesic.planner` from a goal:
the exact distance of every node it reaches. :meth:`GoalField.point_distance` and
:meth:`GoalField.path` are exact for any point (the tangents the point sees, then the
settled labels). :meth:`GoalField.distance` is the per-step lookup through a root table:
each cell holds the exact root of its centre (the goal directly, or the label its best path
leaves by, :func:`pointnav_core.geodesic.roots.cell_roots`), settled one block of cells at a
time when a lookup first lands in the block; a lookup is the tangent from the exact point to
its cell's root. Everything is in world metres.
"""

from __future__ import annotations

import math
import weakref
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.geodesic.arc_graph import FieldLabels
from pointnav_core.geodesic.cell_links import centre_cell
from pointnav_core.geodesic.roots import (
    ArcTables,
    cell_roots,
    compiled,
    compiled_roots,
    table_roots,
)
from pointnav_core.geodesic.tangents import ANG_TOL, TWO_PI
from pointnav_core.utils.frozen import ThawOnUnpickle

if TYPE_CHECKING:
    from pointnav_core.geodesic.planner import Planner

__all__ = ["BLOCK", "GoalField", "LOOKUP_BOUND", "UNSETTLED", "block_cells"]

#: Side (cells) of the square blocks of the root table, each settled on its first lookup
#: (4: a reset's first lookup settles 16 cells; a path of L cells settles about 4 L, against 8 L at 8).
BLOCK = 4
#: A block's row (or column) offsets, for :func:`block_cells`.
_STEP = np.arange(BLOCK)
#: Table kind of a cell not settled yet.
UNSETTLED = 4
#: The lookup's documented bound: ``|distance(p) - point_distance(p)| <= LOOKUP_BOUND * |p - c|``,
#: ``c`` the centre of the cell whose root the lookup uses, where the segment from ``p`` to ``c``
#: is clear (both values are within ``|p - c|`` of the exact value at ``c``).
LOOKUP_BOUND = 2.0


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
        self._nbytes: int | None = None
        self._arc_tables: ArcTables | None = None

    @property
    def reachable_from_anywhere(self) -> bool:
        """False when the robot does not fit at the goal (nothing reaches it)."""
        return self.goal_usable

    @property
    def nbytes(self) -> int:
        """Approximate memory held by this field, in bytes."""
        if self._nbytes is None:  # counted once, again after the root table is made
            table = 0 if self._table is None else sum(v.nbytes for v in self._table.values() if isinstance(v, np.ndarray))
            self._nbytes = self._search.nbytes + table
        return self._nbytes

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
            dep = p.span_list[c] - pos
            for lab in search.on_arc(c, side):
                lp = search.pos[lab]
                if lp <= dep + ANG_TOL and p.arc_free(c, side, lp, dep):
                    total = search.cost[lab] + r * max(dep - lp, 0.0) + length
                    if total < best[0]:
                        best = (total, lab, dep)
        return best

    def _way(self, x: float, y: float) -> tuple[float, int, float]:
        """:meth:`_best`'s ``(cost, label, departure)``, in compiled code where numba is
        installed: the same cost within rounding, and the same root wherever two do not tie
        (a property test)."""
        p = self.planner
        if compiled(p, "best_links") is None:
            return self._best(x, y)
        if not self.goal_usable or not p.is_clear(x, y):
            return math.inf, -2, 0.0
        kind, label, value, dep = compiled_roots(self, self.arc_tables(), np.array([x]), np.array([y]), departures=True)
        if kind[0] == 0:
            return math.inf, -2, 0.0
        if kind[0] == 1:
            return float(value[0]), -1, 0.0
        return float(value[0]), int(label[0]), float(dep[0])

    def point_distance(self, xy: ArrayLike) -> float:
        """Exact geodesic distance (m) from world point ``xy`` to the goal (inf if none).

        With numba the one-point query runs compiled (``geodesic.roots.compiled_roots``):
        the same value as :meth:`_best`'s within rounding (a property test)."""
        x, y = (float(v) for v in np.asarray(xy, dtype=np.float64).reshape(-1)[:2])
        p = self.planner
        if compiled(p, "best_links") is not None:
            if not self.goal_usable or not p.is_clear(x, y):
                return math.inf
            links = p.cell_links(build=False)
            cell = -1 if links is None else centre_cell(p, x, y)
            if cell >= 0:  # a cell centre (a sampled start): its links are known
                one = np.array([cell])
                return float(table_roots(self, self.arc_tables(), links, one, np.array([x]), np.array([y]))[2][0])
            return float(compiled_roots(self, self.arc_tables(), np.array([x]), np.array([y]))[2][0])
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
        cost, label, dep = self._way(x, y)
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

    def arc_tables(self) -> ArcTables:
        """The reached labels grouped by arc, as the cell roots read them (built once)."""
        if self._arc_tables is None:
            self._arc_tables = ArcTables(self.planner, self._search)
        return self._arc_tables

    # ------------------------------------------------------------- lookup table
    @property
    def labels(self) -> FieldLabels:
        """The Dijkstra run from the goal: every reached label's node, side, position and cost."""
        return self._search

    def distance(self, x: float, y: float) -> float:
        """Per-step geodesic lookup (m) from world point ``(x, y)``; ``inf`` if unreachable.

        The tangent from ``(x, y)`` to the exact root of its cell's centre (the nearest usable
        cell where the point's own is not): within ``LOOKUP_BOUND * |p - c|`` of
        :meth:`point_distance`, ``c`` that centre.
        """
        t = self._table if self._table is not None else self._new_table()
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
        if kind == UNSETTLED:
            self._settle_block(i)
            kind = t["kind"][i]
        if kind == 0:
            return math.inf
        if kind == 1:  # straight to the goal
            return math.hypot(x - t["gx"], y - t["gy"])
        lab = int(t["label"][i])
        p = self.planner
        search = self._search
        c, side = int(search.node[lab]), int(search.side[lab])
        r = p.radius
        dx = p.cx_list[c] - x
        dy = p.cy_list[c] - y
        L = math.hypot(dx, dy)
        if L > r:
            # The tangent from (x, y) arriving winding -side is the one leaving the node.
            heading = math.atan2(dy, dx) + side * math.asin(r / L) if r > 0 else math.atan2(dy, dx)
            ccw = (heading + side * (math.pi / 2) - p.phi0_list[c]) % TWO_PI
            if ccw > TWO_PI - ANG_TOL:
                ccw = 0.0
            span = p.span_list[c]
            if ccw <= span + ANG_TOL:
                dep = min(ccw, span) if side > 0 else span - min(ccw, span)
                lp = search.pos[lab]
                if dep >= lp - ANG_TOL:
                    return search.cost[lab] + r * max(dep - lp, 0.0) + math.sqrt(L * L - r * r)
        qx, qy = p.node_point(c, side, search.pos[lab])
        return search.cost[lab] + around_disc(x, y, p.cx_list[c], p.cy_list[c], r, qx, qy)

    def settle(self, cells: ArrayLike | None = None) -> tuple[NDArray[np.int8], NDArray[np.int32]]:
        """Settle the blocks of the root table that hold ``cells`` (default: every block).

        Returns the whole table, read-only: per cell (row-major) its kind (0: no path,
        1: straight to the goal, 2: by a label, 4: not settled) and label (-1 where none).

        Parameters
        ----------
        cells : array_like of int, shape (N,), optional
            Flat cell indices (``row * width + col``), each in ``[0, height * width)``.
        """
        t = self._table if self._table is not None else self._new_table()
        h, w = self.planner.geo.shape
        if cells is None:
            idx = np.flatnonzero(t["kind"] == UNSETTLED)
        else:
            idx = np.asarray(cells)
            if idx.ndim != 1 or (idx.size and not np.issubdtype(idx.dtype, np.integer)):
                raise ArgumentError(f"cells must be a 1D array of integer cell indices, got shape {idx.shape} of {idx.dtype}")
            idx = idx.astype(np.int64)
            if idx.size and (idx.min() < 0 or idx.max() >= h * w):
                raise ArgumentError(f"cells must lie in [0, {h * w}), got {idx.min()} to {idx.max()}")
        blocks = np.unique((idx // w) // BLOCK * t["blocks_w"] + (idx % w) // BLOCK)
        todo = blocks[~t["done"][blocks]]
        if len(todo):
            t["done"][todo] = True
            cells = block_cells(todo, h, w)
            # Many blocks (a pool's window) in row-major order, as a mask over the grid gave
            # them (the order changes no root: a property test; kept to keep tables byte-equal).
            self._settle_cells(np.sort(cells) if len(todo) > 16 else cells)
        kind, label = t["kind"].view(), t["label"].view()
        kind.flags.writeable = label.flags.writeable = False
        return kind, label

    def _settle_block(self, i: int) -> None:
        """Settle the block of the root table that holds cell ``i``."""
        t = self._table
        assert t is not None
        w = self.planner.geo.shape[1]
        k = (i // w) // BLOCK * t["blocks_w"] + (i % w) // BLOCK
        t["done"][k] = True
        self._settle_cells(block_cells(np.array([k]), *self.planner.geo.shape))

    def _settle_cells(self, cells: NDArray[np.int64]) -> None:
        """Give the usable ``cells`` their centres' exact roots (the others have kind 0)."""
        t = self._table
        assert t is not None
        cells = cells[t["kind"][cells] == UNSETTLED]
        kind, label = cell_roots(self, cells)
        t["kind"][cells] = kind
        t["label"][cells] = label

    def _new_table(self) -> dict[str, Any]:
        """An empty root table: every usable cell unsettled, the rest with no path."""
        p = self.planner
        h, w = p.geo.shape
        kind = _unsettled(p) if self.goal_usable else np.zeros(h * w, dtype=np.int8)
        blocks_w = -(-w // BLOCK)
        table = {
            "kind": kind,
            "label": np.full(h * w, -1, dtype=np.int32),
            # Whether each block (row-major, BLOCK cells square) has been settled.
            "done": np.zeros(-(-h // BLOCK) * blocks_w, dtype=bool),
            "blocks_w": blocks_w,
            "gx": float(self.goal[0]),
            "gy": float(self.goal[1]),
        }
        before = self.nbytes
        self._table = table
        self._nbytes = None
        # The table made this field bigger: keep the planner's cache within its budget.
        self.planner.field_resized(self, before)
        return table


#: Each planner's empty root table (every usable cell unsettled), copied by each new table.
_EMPTY_KINDS: weakref.WeakKeyDictionary[Planner, NDArray[np.int8]] = weakref.WeakKeyDictionary()


def _unsettled(planner: Planner) -> NDArray[np.int8]:
    """A fresh copy of ``planner``'s empty root table kinds: UNSETTLED on usable cells, 0
    elsewhere (made once per planner: a ``where`` over the grid was 6 % of a reset)."""
    empty = _EMPTY_KINDS.get(planner)
    if empty is None:
        empty = _EMPTY_KINDS[planner] = np.where(planner.usable.ravel(), UNSETTLED, 0).astype(np.int8)
    return empty.copy()


def around_disc(x: float, y: float, cx: float, cy: float, r: float, qx: float, qy: float) -> float:
    """Length (m) of the shortest path from ``(x, y)`` to ``q`` on the circle of radius ``r``
    at ``c`` that keeps out of its disc: straight where ``q`` is in sight, else the tangent
    and the shorter arc. The lookup's value where the tangent to its root's arc does not
    apply: it joins that value where the two meet, so the lookup moves no faster than the
    point (the bound :data:`LOOKUP_BOUND` rests on that)."""
    L = math.hypot(x - cx, y - cy)
    if L <= r:
        return math.hypot(x - qx, y - qy)
    seen = math.acos(min(r / L, 1.0))
    turn = abs((math.atan2(qy - cy, qx - cx) - math.atan2(y - cy, x - cx) + math.pi) % TWO_PI - math.pi)
    if turn <= seen:
        return math.hypot(x - qx, y - qy)
    return math.sqrt(L * L - r * r) + r * (turn - seen)


def block_cells(blocks: NDArray[np.int64], h: int, w: int) -> NDArray[np.int64]:
    """Flat indices (``row * w + col``) of the cells of ``blocks`` (row-major blocks of
    ``BLOCK`` cells square over an ``h`` x ``w`` grid), block by block."""
    blocks_w = -(-w // BLOCK)
    if len(blocks) == 1:  # a lookup's one block: a few small aranges (44 us as arrays against 6)
        r0, c0 = (int(blocks[0]) // blocks_w) * BLOCK, (int(blocks[0]) % blocks_w) * BLOCK
        rows, cols = np.arange(r0, min(r0 + BLOCK, h)), np.arange(c0, min(c0 + BLOCK, w))
        return (rows[:, None] * w + cols[None, :]).ravel().astype(np.int64)
    rows = (blocks // blocks_w * BLOCK)[:, None] + _STEP
    cols = (blocks % blocks_w * BLOCK)[:, None] + _STEP
    inside = (rows < h)[:, :, None] & (cols < w)[:, None, :]
    return (rows[:, :, None] * w + cols[:, None, :])[inside].astype(np.int64)

