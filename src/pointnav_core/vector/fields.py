"""Goal fields as arrays: every cell's root, so that a geodesic lookup is one gather.

:meth:`pointnav_core.geodesic.GoalField.distance` answers from a per-cell root
table that it fills lazily, a block of cells at a time. :meth:`GoalField.settle
<pointnav_core.geodesic.GoalField.settle>` fills the blocks a pool needs at once (the same
roots), and :class:`FieldTables` stores the
tables of many goals end to end: per grid cell its kind (0 unreachable, 1 straight to
the goal, 2 by a label of the Dijkstra search) and label, and per label the arc node
and cost. :meth:`FieldTables.distance` then evaluates ``GoalField.distance``'s formula
for every robot at once. Because the single env reads the same (now settled) table of
the same cached field, both give the same numbers.

A robot cannot leave the disc of an episode's reach around its start (its steps times its
longest chord per step), so with the episodes' ``starts`` and that ``reach`` a field keeps
only its window of cells (:func:`reach_window`), and only the blocks those cells look up
are checked: on a large map the settling and the memory scale with the episodes' reach,
not with the map.

Tables built in the stepping process are settled lazily, as the single env's field is: a
cell starts unsettled (kind 4) and its block is settled (``GoalField.settle``, the same
roots) the first time a robot's lookup lands in it, so that a pool's build costs its goals'
searches and not every cell of every window. Tables built in a worker process (a pool's
scenes, a refresh) are settled there, whole, since the worker has the time and the parent
would have to build the floor's geometry again.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from dataclasses import field as member
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pointnav_core.errors import ArgumentError
from pointnav_core.geodesic import GoalField
from pointnav_core.geodesic.field import BLOCK, UNSETTLED, block_cells
from pointnav_core.geodesic.tangents import ANG_TOL, TWO_PI
from pointnav_core.vector.xp import Arrays

__all__ = ["FIELD_TABLE_BYTES", "FieldPart", "FieldTables", "check_budget", "field_part", "reach_window", "window_cells"]

#: Byte budget of one set of goal-field tables (a pool's): the cells of the fields' windows
#: at 16 bytes each (kind and label). Building tables past it raises ``ValueError`` before
#: any field is settled. Change it by assigning ``pointnav_core.vector.fields.FIELD_TABLE_BYTES``.
FIELD_TABLE_BYTES = 2 * 2**30
_CELL_BYTES = 16

# Per Dijkstra label, in the order of the label table's columns.
_PER_LABEL = ("cost", "cx", "cy", "side", "phi0", "span", "pos", "qx", "qy")
_PER_FIELD_FLOAT = ("gx", "gy", "ox", "oy", "res", "radius")
_INDICES = ("kind", "label", "offset", "rows", "width", "row0", "col0")


def reach_window(field: GoalField, starts: ArrayLike, reach: float) -> tuple[int, int, int, int]:
    """The cells ``(row0, row1, col0, col1)`` (half-open) of ``field``'s grid that a robot
    centre within ``reach`` (m) of one of ``starts`` ``(n, 2)`` (m) can lie in, with a cell
    to spare each side; the whole grid when ``reach`` is infinite."""
    geo = field.planner.geo
    h, w = geo.shape
    xy = np.asarray(starts, dtype=np.float64).reshape(-1, 2)
    if not math.isfinite(reach) or not len(xy):
        return 0, h, 0, w
    res, (ox, oy) = geo.resolution, geo.origin[:2]
    lo = np.floor((xy.min(0) - reach - (ox, oy)) / res) - 1
    hi = np.floor((xy.max(0) + reach - (ox, oy)) / res) + 2
    c0, r0 = (int(min(max(v, 0), n)) for v, n in zip(lo, (w, h)))
    c1, r1 = (int(min(max(v, 0), n)) for v, n in zip(hi, (w, h)))
    return r0, max(r1, r0), c0, max(c1, c0)


@dataclass(frozen=True)
class FieldPart:
    """One settled goal field's share of :class:`FieldTables`, as plain numpy arrays (it
    pickles from a worker process).

    Attributes
    ----------
    window : (row0, row1, col0, col1)
        The cells kept, half-open, of the field's grid.
    kind, label : ndarray of int64
        Per kept cell, row by row: 0 unreachable, 1 straight to the goal, 2 by its label
        (an index into :attr:`labels`).
    labels : ndarray (n_labels, 9)
        Per label used, the columns of ``_PER_LABEL`` (cost and node in m, angles in rad).
    goal : (float, float)
        The goal (m).
    grid : (ox, oy, res, radius)
        The grid's origin and cell size and the robot radius (m).
    used : ndarray of int64
        Per row of :attr:`labels`, its label in the field's own search (``GoalField.labels``).
    source : GoalField, (scene, robot) or None
        Where cells are left unsettled (kind 4) to settle on their first lookup: the field
        itself, or, for a part built in a worker, the scene and robot whose sampler makes
        the same field again in the stepping process (:attr:`FieldTables.resolve`); None
        where every cell of the window is settled.
    """

    window: tuple[int, int, int, int]
    kind: np.ndarray
    label: np.ndarray
    labels: np.ndarray
    goal: tuple[float, float]
    grid: tuple[float, float, float, float]
    used: np.ndarray
    source: GoalField | tuple[int, int] | None = member(default=None, compare=False, repr=False)


def field_part(field: GoalField, window: tuple[int, int, int, int], lazy: bool = False,
               origin: tuple[int, int] | None = None) -> FieldPart:
    """``field``'s share of the tables over ``window`` (:func:`reach_window`): settled there,
    or with ``lazy`` only as far as the field is settled already (the rest kind 4, settled
    by :meth:`FieldTables.distance` as lookups land). With an ``origin`` (scene, robot) the
    part keeps that instead of the field, to pickle from a worker.

    Only the cells the window's cells look up are settled (every one for the whole grid),
    and only the labels the window's cells name are kept: a search labels every arc node of
    the floor's graph (millions on a large map), a window's cells name a few thousand.
    """
    p = field.planner
    h, w = p.geo.shape
    r0, r1, c0, c1 = window
    near = p.near_usable.reshape(h, w)[r0:r1, c0:c1].ravel().astype(np.int64)
    whole = (r0, r1, c0, c1) == (0, h, 0, w)
    if lazy and origin is not None:
        # For the stepping process, which makes the field again: every cell unsettled, no
        # labels (its search numbers its labels itself).
        kind_of, label_of = np.full(h * w, UNSETTLED, np.int8), np.zeros(h * w, np.int32)
    else:
        kind_of, label_of = field.settle(np.empty(0, np.int64) if lazy else None if whole else near[near >= 0])
    kind = np.where(near >= 0, kind_of[np.maximum(near, 0)], 0).astype(np.int64)
    label = np.where(kind == 2, label_of[np.maximum(near, 0)], 0).astype(np.int64)
    used = np.unique(label[kind == 2])
    label = np.where(kind == 2, np.searchsorted(used, label), 0).astype(np.int64)
    goal = (float(field.goal[0]), float(field.goal[1]))
    grid = (float(p.geo.origin[0]), float(p.geo.origin[1]), float(p.geo.resolution), float(p.radius))
    source = (field if origin is None else origin) if lazy else None
    return FieldPart(window, kind, label, label_rows(field, used), goal, grid, used, source)


def label_rows(field: GoalField, used: np.ndarray) -> np.ndarray:
    """The rows ``(n, 9)`` of the label table (the columns of ``_PER_LABEL``) for the labels
    ``used`` of ``field``'s search: cost and node in m, angles in rad."""
    p = field.planner
    s = field.labels
    node = np.asarray(s.node, dtype=np.int64)[used]
    side = np.asarray(s.side, dtype=np.float64)[used]
    pos = np.asarray(s.pos, dtype=np.float64)[used]
    n_lab = len(node)
    ccw = np.where(side > 0, pos, p.span[node] - pos) if n_lab else pos
    ang = p.phi0[node] + ccw if n_lab else pos
    return np.stack([
        np.asarray(s.cost, dtype=np.float64)[used], p.cx[node], p.cy[node], side, p.phi0[node],
        p.span[node], pos, p.cx[node] + p.radius * np.cos(ang), p.cy[node] + p.radius * np.sin(ang),
    ], 1).reshape(n_lab, 9)


class FieldTables:
    """The settled root tables of many goal fields, end to end, on one device.

    Parameters
    ----------
    fields : sequence of GoalField
        Each keeps its planner's robot radius (``radius``, per field), so fields of robots
        of different radii share the tables.
    arrays : Arrays
    starts : sequence of array_like (n_i, 2), optional
        Per field, the starts (m) of the episodes that use it. With ``reach``, each field
        keeps only the window of cells a robot from those starts can reach; a lookup
        outside it reads ``inf``. Default: every field keeps its whole grid.
    reach : float
        How far (m) a robot's centre can get from its start in one episode (``inf``: any
        distance, the whole grid).
    """

    #: Makes a worker-built part's field again here, from its ``(scene, robot)`` and goal
    #: ``(gx, gy)`` (m); set by the pool that holds the tables (its samplers' scenes).
    resolve: Callable[[tuple[int, int], tuple[float, float]], GoalField] | None = None
    # Per label (one spare row at the end of each field's labels): see _PER_LABEL.
    cost: Any
    cx: Any
    cy: Any
    side: Any
    phi0: Any
    span: Any
    pos: Any
    qx: Any
    qy: Any

    def __init__(
        self, fields: Sequence[GoalField], arrays: Arrays, starts: Sequence[ArrayLike] | None = None,
        reach: float = math.inf, lazy: bool = False,
    ) -> None:
        windows = [(0, f.planner.geo.shape[0], 0, f.planner.geo.shape[1]) if starts is None
                   else reach_window(f, starts[i], reach) for i, f in enumerate(fields)]
        check_budget(windows)
        self._assemble([field_part(f, w, lazy) for f, w in zip(fields, windows)], arrays)

    @classmethod
    def from_parts(cls, parts: Sequence[FieldPart], arrays: Arrays) -> FieldTables:
        """The tables of fields settled apart (:func:`field_part`, in worker processes, say),
        in order: the same arrays as the tables of those fields built here."""
        tables = cls.__new__(cls)
        cls._assemble(tables, parts, arrays)  # the class's own builder, on an instance without __init__
        return tables

    def _assemble(self, parts: Sequence[FieldPart], arrays: Arrays) -> None:
        kinds, labels, lab_arrays, goal, geo = [], [], [], [], []
        cell_off = lab_off = 0
        # Lazy settling's state, on the host: per field its GoalField (or None), and its
        # search's labels already in the table (rows lab_off on, or a map once settling adds more).
        self._sources = [part.source for part in parts]
        self._lazy = any(source is not None for source in self._sources)  # read every step
        self._known: list[Any] = []
        for part in parts:
            r0, r1, c0, c1 = part.window
            kinds.append(part.kind)
            labels.append(part.label + lab_off)
            lab_arrays.append(part.labels)
            goal.append(part.goal)
            geo.append((cell_off, r1 - r0, c1 - c0, *part.grid, r0, c0))
            self._known.append((part.used, lab_off))
            cell_off += (r1 - r0) * (c1 - c0)
            lab_off += len(part.labels)
        a = arrays
        g = np.array(geo, dtype=np.float64).reshape(-1, 9)
        self.kind = a.asarray(np.concatenate(kinds), a.i64)
        self.label = a.asarray(np.concatenate(labels), a.i64)
        # One spare row: cells with no label point at the end of their field's labels.
        lab = np.concatenate([*lab_arrays, np.zeros((1, 9))])
        for i, name in enumerate(_PER_LABEL):
            setattr(self, name, a.asarray(lab[:, i]))
        self._n_labels = lab_off
        gxy = np.array(goal, dtype=np.float64).reshape(-1, 2)
        self.gx, self.gy = a.asarray(gxy[:, 0]), a.asarray(gxy[:, 1])
        self.offset = a.asarray(g[:, 0], a.i64)
        # Each field's window of its grid: rows x width cells from (row0, col0).
        self.rows, self.width = a.asarray(g[:, 1], a.i64), a.asarray(g[:, 2], a.i64)
        self.row0, self.col0 = a.asarray(g[:, 7], a.i64), a.asarray(g[:, 8], a.i64)
        self.ox, self.oy, self.res, self.radius = (a.asarray(g[:, i]) for i in (3, 4, 5, 6))
        self._windows = g[:, (0, 1, 2, 7, 8)].astype(np.int64)
        self.arrays = a

    def __len__(self) -> int:
        return int(self.gx.shape[0])

    @property
    def lazy(self) -> bool:
        """Whether some cells may still be unsettled (kind 4), to settle on their first lookup."""
        return self._lazy

    def to(self, arrays: Arrays) -> FieldTables:
        """These tables on ``arrays``' device (numpy tables from a worker process, say)."""
        moved: FieldTables = FieldTables.__new__(FieldTables)
        moved.arrays = arrays
        for name in _PER_LABEL + _PER_FIELD_FLOAT:
            setattr(moved, name, arrays.asarray(self.arrays.numpy(getattr(self, name))))
        for name in _INDICES:
            setattr(moved, name, arrays.asarray(self.arrays.numpy(getattr(self, name)), arrays.i64))
        moved._lazy_state(self._sources, self._known, self._n_labels, self._windows, self.resolve)
        return moved

    @classmethod
    def concat(cls, first: FieldTables, second: FieldTables) -> FieldTables:
        """``first``'s fields followed by ``second``'s (field ``f`` of ``second`` becomes
        ``len(first) + f``), on ``first``'s device."""
        a = first.arrays
        cat = a.xp.concatenate
        joined: FieldTables = cls.__new__(cls)
        joined.arrays = a
        n1, n2 = first._n_labels, second._n_labels
        joined.kind = cat([first.kind, second.kind])
        joined.label = cat([first.label, second.label + n1])
        for name in _PER_LABEL:  # the labels in use, then one spare row
            setattr(joined, name, cat([getattr(first, name)[:n1], getattr(second, name)[:n2 + 1]]))
        for name in _PER_FIELD_FLOAT + ("rows", "width", "row0", "col0"):
            setattr(joined, name, cat([getattr(first, name), getattr(second, name)]))
        joined.offset = cat([first.offset, second.offset + first.kind.shape[0]])
        shifted = [np.where(k >= 0, k + n1, -1) if isinstance(k, np.ndarray) else (k[0], k[1] + n1) for k in second._known]
        windows = second._windows + np.array([first.kind.shape[0], 0, 0, 0, 0])
        joined._lazy_state(first._sources + second._sources, [*first._known, *shifted], n1 + n2,
                           np.concatenate([first._windows, windows]), first.resolve or second.resolve)
        return joined

    def _lazy_state(self, sources: list[Any], known: list[Any], n_labels: int, windows: np.ndarray,
                    resolve: Any = None) -> None:
        self._sources, self._n_labels, self._windows = list(sources), n_labels, windows
        # Each table its own label maps: they name rows of its own label arrays.
        self._known = [k.copy() if isinstance(k, np.ndarray) else k for k in known]
        self._lazy = any(source is not None for source in self._sources)
        self.resolve = resolve

    # ------------------------------------------------------------- lazy settling
    def _settle_cells(self, cells: np.ndarray) -> None:
        """Settle the blocks of the table cells ``cells`` (global indices, unsettled) in their
        fields, as ``GoalField.distance`` settles a lookup's block, and write them here."""
        a = self.arrays
        owner = np.searchsorted(self._windows[:, 0], cells, side="right") - 1
        where, kinds, labels = [], [], []
        for f in np.unique(owner).tolist():
            idx, kind, label = self._settle_blocks(f, cells[owner == f])
            where.append(idx)
            kinds.append(kind)
            labels.append(label)
        idx = a.asarray(np.concatenate(where), a.i64)
        self.label[idx] = a.asarray(np.concatenate(labels), a.i64)
        self.kind[idx] = a.asarray(np.concatenate(kinds), a.i64)

    def _settle_blocks(self, f: int, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Field ``f``'s grid blocks (``BLOCK`` cells square) that hold its table cells
        ``cells``: their window cells' global indices, kinds and global labels."""
        field = self._sources[f]
        if isinstance(field, tuple):  # built in a worker: the same field again, here, once
            if self.resolve is None:
                raise AssertionError(f"goal field {f} was built in a worker, and its tables have no resolve")
            goal = (float(self.arrays.numpy(self.gx[f])), float(self.arrays.numpy(self.gy[f])))
            field = self._sources[f] = self.resolve(field, goal)
        if field is None:  # settled whole: no cell of it is pending
            raise AssertionError(f"goal field {f} has unsettled cells but no field to settle them")
        off, rows, width, r0, c0 = (int(v) for v in self._windows[f])
        p = field.planner
        w = p.geo.shape[1]
        local = cells - off
        row, col = local // width + r0, local % width + c0
        blocks_w = -(-w // BLOCK)
        rr, cc = np.divmod(block_cells(np.unique(row // BLOCK * blocks_w + col // BLOCK), *p.geo.shape), w)
        keep = (rr >= r0) & (rr < r0 + rows) & (cc >= c0) & (cc < c0 + width)
        rr, cc = rr[keep], cc[keep]
        near = p.near_usable[rr * w + cc].astype(np.int64)  # the block's cells, not the grid, widened
        kind_of, label_of = field.settle(near[near >= 0])
        at = np.maximum(near, 0)
        kind = np.where(near >= 0, kind_of[at], 0).astype(np.int64)
        label = np.zeros(len(kind), dtype=np.int64)
        two = kind == 2
        label[two] = self._table_labels(f, field, label_of[at[two]].astype(np.int64))
        return off + (rr - r0) * width + (cc - c0), kind, label

    def _table_labels(self, f: int, field: GoalField, ids: np.ndarray) -> np.ndarray:
        """The table rows of field ``f``'s search labels ``ids``, appending those not in the table."""
        known = self._known[f]
        if not isinstance(known, np.ndarray):  # first growth: the part's labels as a map
            used, base = known
            known = np.full(len(field.labels.cost), -1, dtype=np.int64)
            known[used] = base + np.arange(len(used))
            self._known[f] = known
        new = np.unique(ids[known[ids] < 0])
        if len(new):
            known[new] = self._append_labels(label_rows(field, new))
        return known[ids]

    def _append_labels(self, rows: np.ndarray) -> np.ndarray:
        """Add ``rows`` (the columns of ``_PER_LABEL``) after the labels in use, growing the
        arrays by doubling (one spare row stays at the end); their indices."""
        a = self.arrays
        n, k = self._n_labels, len(rows)
        size = int(self.cost.shape[0])
        if n + k + 1 > size:
            grown = max(2 * size, n + k + 1)
            for name in _PER_LABEL:
                column = a.zeros(grown)
                column[:n] = getattr(self, name)[:n]
                setattr(self, name, column)
        for i, name in enumerate(_PER_LABEL):
            getattr(self, name)[n:n + k] = a.asarray(rows[:, i])
        self._n_labels = n + k
        return np.arange(n, n + k)

    def distance(self, field: Any, x: Any, y: Any) -> Any:
        """Geodesic distance (m) from each ``(x, y)`` to the goal of its ``field`` (index array); inf if none.

        ``GoalField.distance``'s formula on arrays: straight to the goal, or the cost of
        the cell's label plus the tangent (and arc) from the point to the label's node.
        """
        a = self.arrays
        xp = a.xp
        res = self.res[field]
        # The grid's cell, as the single env finds it, then its place in the field's window.
        col = a.to_int(xp.floor((x - self.ox[field]) / res)) - self.col0[field]
        row = a.to_int(xp.floor((y - self.oy[field]) / res)) - self.row0[field]
        inside = (row >= 0) & (row < self.rows[field]) & (col >= 0) & (col < self.width[field])
        cell = xp.where(inside, self.offset[field] + row * self.width[field] + col, 0)
        kind = xp.where(inside, self.kind[cell], 0)
        if self._lazy and a.any(kind == UNSETTLED):
            self._settle_cells(np.unique(a.numpy(cell[kind == UNSETTLED])))
            kind = xp.where(inside, self.kind[cell], 0)
        lab = self.label[cell]
        direct = xp.sqrt((x - self.gx[field]) ** 2 + (y - self.gy[field]) ** 2)
        r = self.radius[field]
        side = self.side[lab]
        dx, dy = self.cx[lab] - x, self.cy[lab] - y
        big = xp.sqrt(dx * dx + dy * dy)
        outside = big > r
        safe = xp.where(outside, big, 1.0)
        bend = xp.where(r > 0.0, side * xp.arcsin(xp.minimum(r / safe, xp.ones_like(safe))), 0.0)
        heading = xp.arctan2(dy, dx) + bend
        ccw = xp.remainder(heading + side * (math.pi / 2) - self.phi0[lab], TWO_PI)
        ccw = xp.where(ccw > TWO_PI - ANG_TOL, 0.0, ccw)
        span = self.span[lab]
        on_arc = ccw <= span + ANG_TOL
        clipped = xp.minimum(ccw, span)
        dep = xp.where(side > 0, clipped, span - clipped)
        lp = self.pos[lab]
        tangent_ok = outside & on_arc & (dep >= lp - ANG_TOL)
        tangent = self.cost[lab] + r * xp.maximum(dep - lp, xp.zeros_like(dep)) + xp.sqrt(
            xp.maximum(big * big - r * r, xp.zeros_like(big))
        )
        # GoalField's around_disc: straight to the label's point where it is in sight, else
        # the tangent and the shorter arc.
        qx, qy = self.qx[lab], self.qy[lab]
        straight = xp.sqrt((x - qx) ** 2 + (y - qy) ** 2)
        seen = xp.arccos(xp.minimum(r / safe, xp.ones_like(safe)))
        turn = xp.abs(xp.remainder(xp.arctan2(qy - self.cy[lab], qx - self.cx[lab]) - xp.arctan2(-dy, -dx) + math.pi, TWO_PI) - math.pi)
        wrap = xp.sqrt(xp.maximum(big * big - r * r, xp.zeros_like(big))) + r * (turn - seen)
        point = self.cost[lab] + xp.where(outside & (turn > seen), wrap, straight)
        via = xp.where(tangent_ok, tangent, point)
        return xp.where(kind == 1, direct, xp.where(kind == 2, via, math.inf))


def window_cells(windows: Sequence[tuple[int, int, int, int]]) -> int:
    """The cells of ``windows`` ``(row0, row1, col0, col1)`` (half-open), all together."""
    return sum((r1 - r0) * (c1 - c0) for r0, r1, c0, c1 in windows)


def check_budget(windows: Sequence[tuple[int, int, int, int]], cells_before: int = 0, goals_before: int = 0) -> None:
    """ValueError when the windows' cells, after ``cells_before`` of ``goals_before`` goals
    already kept (the scenes built before), would take more than :data:`FIELD_TABLE_BYTES`."""
    cells = cells_before + window_cells(windows)
    if cells * _CELL_BYTES > FIELD_TABLE_BYTES:
        raise ArgumentError(
            f"the goal fields of {goals_before + len(windows)} pool goals would take {cells * _CELL_BYTES / 2**20:.0f} MiB "
            f"({cells} cells within the episodes' reach), over FIELD_TABLE_BYTES = "
            f"{FIELD_TABLE_BYTES / 2**20:.0f} MiB: lower pool_size or max_episode_steps (the reach), "
            "or raise pointnav_core.vector.fields.FIELD_TABLE_BYTES"
        )

