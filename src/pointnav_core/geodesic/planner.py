"""Exact geodesics of a disc robot in a floor's collision geometry (the tangent graph).

This is the planner behind :class:`~pointnav_core.scenes.Scene`'s shortest paths, geodesic
distances and goal fields (the model, its accuracy and cost: ``docs/geodesic.md``).

The robot's centre may go wherever its disc of radius ``r`` misses the blocked set of
:class:`~pointnav_core.floor.collision.FloorCollision`. A shortest path in that space is taut: a
chain of straight segments, each tangent to circles of radius ``r`` centred at convex
corners of the blocked set, joined by arcs of those circles. The planner therefore works
on the *tangent graph*:

- a **node** is a convex corner (a grid vertex with one blocked cell of four, or a convex
  polygon vertex) with the arc of its circle that faces free space; nodes whose arc is
  entirely within ``r`` of something else are dropped;
- an **edge** is a common tangent of two nodes' circles (outer tangents keep the winding
  side, inner tangents cross over) whose tangent points lie on the arcs and whose segment
  is clear for ``r`` (exact test, see ``collision``); edges are found lazily, per node and
  winding side, among the nodes within that node's sight radius;
- a path wraps each node clockwise or counter-clockwise, entering and leaving on its arc;
  the arc between costs ``r * angle``.

Search is label-setting (Dijkstra, or A* with the straight-line heuristic for a single
pair): a label is a node, a winding side, the arc position where the path arrived and its
cost; a label is dropped when an earlier label on the same arc reaches its position more
cheaply. Distances are exact in the geometry; paths keep at least ``r`` from the blocked set
(within 1e-9 m), and arcs are drawn as polylines that circumscribe the circle, so that the
drawn path never cuts the clearance.

A goal field (:class:`~pointnav_core.geodesic.field.GoalField`) holds a whole Dijkstra run from one goal (exact distance of every
node) and answers exact point queries by the tangents a point sees. For the per-step hot
path it keeps a root table, each cell's centre's exact root, settled a block of cells at a
time; a lookup is the tangent length from the point to its cell's root plus the root's arc
and distance. Everything is in world metres.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage
from scipy.spatial import cKDTree
from tqdm.auto import tqdm

from pointnav_core.errors import ArgumentError
from pointnav_core.floor.collision import FloorCollision
from pointnav_core.geodesic import cache
from pointnav_core.geodesic.arc_graph import ArcGraph
from pointnav_core.geodesic.arcs import ARC_PIECE
from pointnav_core.geodesic.cache import edge_arrays
from pointnav_core.geodesic.edge_store import EdgeStore
from pointnav_core.geodesic.cell_links import CellLinks
from pointnav_core.geodesic.edges import build_edges
from pointnav_core.geodesic.field import GoalField
from pointnav_core.geodesic.links import point_links
from pointnav_core.geodesic.nodes import corner_arcs
from pointnav_core.geodesic.point_search import shortest_path
from pointnav_core.geodesic.sight import NodeBalls, node_sights
from pointnav_core.geodesic.tangents import ANG_TOL
from pointnav_core.geodesic.usable import nearest_usable, usable_cells
from pointnav_core.utils.frozen import ThawOnUnpickle
from pointnav_core.utils.validation import is_real

if TYPE_CHECKING:
    from pointnav_core.floor.maps import TraversableMap

__all__ = ["Planner", "planner_for"]

#: Nodes whose tangent edges are found together by build_all_edges.
_EDGE_BATCH = 256

#: Nodes whose edges a build finds before it shows a progress bar (about 2 s of work).
_PROGRESS_NODES = 20_000
#: Side (cells) of the square tiles whose nodes get their edges built together.
_TILE = 32
#: Floors with at most this many nodes get their whole graph at the first point-to-point
#: query, which then searches it in compiled code (a house has a few hundred nodes; its
#: whole graph builds in tens of milliseconds, as much as a few lazy queries).
WHOLE_GRAPH_NODES = 4096
#: Smallest radius (m) the planner uses.
MIN_RADIUS = 1e-6
#: Byte budget of the goal fields a planner keeps.
FIELD_CACHE_BYTES = 256 * 2**20
#: Byte budget of a floor's geometry for one radius (nodes, sight bounds, tangent edges,
#: the arc graph and the cell links; the goal fields have their own).
GEOMETRY_BYTES = 1 * 2**30
#: Approximate bytes one tangent edge holds, in the planner's lists and the arc graph's arrays
#: (440-450 measured with tracemalloc on ``scenes.clutter``).
_EDGE_BYTES = 450


def planner_for(tmap: TraversableMap, radius: float) -> Planner:
    """Return the cached tangent-graph :class:`Planner` of ``tmap`` for ``radius`` metres."""
    key = ("tangent", round(float(radius), 12))
    return tmap.planner_cache.get_or_create(key, lambda: Planner(FloorCollision.from_map(tmap), radius))


class Planner(ThawOnUnpickle):
    """Tangent graph of one floor's collision geometry for one robot radius.

    Parameters
    ----------
    collision : FloorCollision
        The floor's blocked set (every non-FREE cell, off the map, and its polygons).
    radius : float
        Robot radius in metres, >= 0.

    Attributes
    ----------
    field_cache_bytes : int
        Byte budget of the goal fields a planner keeps (default :data:`FIELD_CACHE_BYTES`,
        256 MiB); set it on the class for every planner (``Planner.field_cache_bytes =
        64 * 2**20``) or on one planner.
    geometry_bytes : int
        Byte budget of the floor's geometry for this radius (default :data:`GEOMETRY_BYTES`,
        1 GiB): building tangent edges past it raises ``ValueError``, and cell links that
        would pass it are not kept. Set it as ``field_cache_bytes``.
    whole_graph_search : bool
        Whether :meth:`shortest_path` searches the whole graph in compiled code once it
        exists (default True); False keeps the lazy search, tile by tile.
    """

    field_cache_bytes: int = FIELD_CACHE_BYTES
    geometry_bytes: int = GEOMETRY_BYTES
    # The fast path; False keeps the general one, which a property test compares with it.
    whole_graph_search: bool = True

    def __init__(self, collision: FloorCollision, radius: float) -> None:
        self.geo = collision
        # A point robot plans as a disc of 1 micrometre, so that paths wrap corners
        # rather than pass through the vertex two diagonal squares share.
        self.radius = max(float(radius), MIN_RADIUS)
        started = time.perf_counter()
        self._build_nodes()
        # (node, side) -> departure positions, targets, target sides, arrivals, lengths.
        self.edge_store = EdgeStore()
        # The per-floor build from the disk cache, if an earlier process kept it (geodesic.cache).
        self._cache_key = cache.floor_key(collision, self.radius) if cache.cache_dir() is not None else None
        stored = cache.load(self._cache_key, self.n_nodes) if self._cache_key is not None else None
        self._in_cache = stored is not None
        # Every cell's clear links (geodesic.cell_links): None until asked for, False where
        # the floor gets none.
        self._cell_links: CellLinks | None | bool = None
        self._roots_seconds = 0.0
        self._links_estimate: float | None = None
        if stored is not None:
            self.sights = stored["sights"].astype(np.float64)
            self.sight_profile = stored["sight_profile"].astype(np.float32)
            self.edge_store.attach(stored)  # each node's lists made when first read
            self._check_geometry_bytes()
            self._cell_links = CellLinks.stored(stored, collision.shape[0] * collision.shape[1], self.n_nodes)
        else:
            # Strict bounds (m) on every clear segment leaving a node's arc (geodesic.sight).
            # and per direction bin (geodesic.sight.blocked_by_profile).
            self.sights, self.sight_profile = node_sights(collision, self.radius, self.cx, self.cy, self.phi0, self.span)
        self._build_seconds = time.perf_counter() - started
        self._balls = NodeBalls(self.cx, self.cy, self.sights + self.radius)
        self._arc_graph: ArcGraph | None = None
        self._fb_edt: NDArray[np.float64] | None = None
        self._fb_mask: NDArray[np.bool_] | None = None
        self._usable: NDArray[np.bool_] | None = None
        self._near: NDArray[np.int32] | None = None
        self._fields: dict[tuple[float, float], GoalField] = {}
        # The cached fields' bytes, kept as they enter, grow and leave (a sum over the
        # cache on every insert cost a tenth of a reset).
        self._field_bytes = 0

    # ------------------------------------------------------------------ nodes
    def __setstate__(self, state: dict[str, Any]) -> None:
        super().__setstate__(state)
        if not isinstance(self.edge_store, EdgeStore):  # thawing copies dicts as plain ones
            self.edge_store = EdgeStore.of(self.edge_store)

    def _build_nodes(self) -> None:
        geo = self.geo
        res = geo.resolution
        ox, oy = geo.origin
        self.cx, self.cy, self.phi0, self.span, self.arc_clear, k = corner_arcs(geo, self.radius)
        self.n_nodes = len(self.cx)
        # The same numbers as Python lists: the package's scalar loops (arcs, fields, point
        # search) index them one node at a time, where a numpy scalar costs ten times more.
        self.cx_list, self.cy_list = self.cx.tolist(), self.cy.tolist()
        self.phi0_list, self.span_list = self.phi0.tolist(), self.span.tolist()
        # Blocked sample positions (ccw, rad) per node; empty for almost every node.
        self.blocked_ccw: list[list[float]] = [[] for _ in range(self.n_nodes)]
        for i, j in zip(*np.nonzero(~self.arc_clear)):
            self.blocked_ccw[int(i)].append(float(self.span[i] * k[j]))
        # Node centres for nearest-node queries (edge building).
        self.tree = cKDTree(np.stack([self.cx, self.cy], axis=1)) if self.n_nodes else None
        # Nodes grouped by tile, so that a lazy search builds a tile's edges in one batch.
        tcol = np.floor((self.cx - ox) / (res * _TILE)).astype(np.int64)
        trow = np.floor((self.cy - oy) / (res * _TILE)).astype(np.int64)
        tile = (trow + 1) * (geo.shape[1] // _TILE + 3) + (tcol + 1)
        order = np.argsort(tile, kind="stable")
        self._tile_of = tile
        self._tile_nodes = {int(t): order[i:j] for t, i, j in _runs(tile[order])}

    def node_point(self, node: int, s: int, pos: float) -> tuple[float, float]:
        """World point at arc position ``pos`` (rad, along winding ``s``) of ``node``."""
        ccw = pos if s > 0 else self.span_list[node] - pos
        a = self.phi0_list[node] + ccw
        return (self.cx_list[node] + self.radius * math.cos(a), self.cy_list[node] + self.radius * math.sin(a))

    def arc_free(self, node: int, s: int, p1: float, p2: float) -> bool:
        """Whether the arc of ``node`` between positions ``p1 <= p2`` (winding ``s``) is clear."""
        blocked = self.blocked_ccw[node]
        if not blocked:
            return True
        if s > 0:
            lo, hi = p1, p2
        else:
            sp = self.span_list[node]
            lo, hi = sp - p2, sp - p1
        return not any(lo + ANG_TOL < b < hi - ANG_TOL for b in blocked)

    def blocked_arcs(self) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """Each node's blocked arc samples (ccw positions, rad) as a row, NaN padded (NaN
        compares false), and which nodes have any; built once."""
        if getattr(self, "_blocked", None) is None:
            widest = max((len(b) for b in self.blocked_ccw), default=0)
            self._blocked = np.full((self.n_nodes, max(widest, 1)), np.nan)
            for n, b in enumerate(self.blocked_ccw):
                self._blocked[n, : len(b)] = b
            self._has_blocked = np.fromiter((bool(b) for b in self.blocked_ccw), dtype=bool, count=self.n_nodes)
        return self._blocked, self._has_blocked

    def arcs_free(
        self, nodes: NDArray[np.int64], sides: NDArray[np.int64], p1: NDArray[np.float64], p2: NDArray[np.float64]
    ) -> NDArray[np.bool_]:
        """Vectorised :meth:`arc_free`, with its expressions (only nodes with a blocked arc
        sample are looked at)."""
        blocked, has_blocked = self.blocked_arcs()
        out = np.ones(len(nodes), dtype=bool)
        k = np.flatnonzero(has_blocked[nodes])
        if len(k):
            node = nodes[k]
            sp = self.span[node]
            ccw = sides[k] > 0
            lo = np.where(ccw, p1[k], sp - p2[k])
            hi = np.where(ccw, p2[k], sp - p1[k])
            b = blocked[node]
            with np.errstate(invalid="ignore"):
                out[k] = ~((lo[:, None] + ANG_TOL < b) & (b < hi[:, None] - ANG_TOL)).any(axis=1)
        return out

    # ------------------------------------------------------------------ sight
    def _fully_blocked_edt(self) -> NDArray[np.float64]:
        """Distance (cells) from each cell centre to the nearest cell no disc point can use."""
        if self._fb_edt is None:
            geo = self.geo
            pad = 1
            blocked = np.pad(geo.blocked, pad, constant_values=geo.outside_blocked)
            edt = ndimage.distance_transform_edt(~blocked)
            # Clearance anywhere in a cell < (edt - 0.5 + sqrt(1/2)) cells.
            full = blocked | ((edt - 0.5 + math.sqrt(0.5)) * geo.resolution < self.radius)
            self._fb_edt = np.asarray(ndimage.distance_transform_edt(~full))
        return self._fb_edt

    def fully_blocked_mask(self) -> NDArray[np.bool_]:
        """Cells (padded by one ring) where no point is clear for the robot's disc."""
        if self._fb_mask is None:
            self._fb_mask = self._fully_blocked_edt() < 0.5
        return self._fb_mask

    # ------------------------------------------------------------------ edges
    def edges(self, node: int, s: int) -> tuple[list[float], NDArray[Any]]:
        """Tangent edges leaving ``node`` winding ``s``, sorted by departure position.

        Returns the departure positions (rad) and a record array with fields ``to``,
        ``side``, ``arr`` (arrival position at ``to``), ``length`` (m).
        """
        dep, to, side, arr, length = self.edge_lists(node, s)
        rec = np.empty(len(dep), dtype=_EDGE_DTYPE)
        rec["to"], rec["side"], rec["arr"], rec["length"] = to, side, arr, length
        return list(dep), rec

    def edge_lists(self, node: int, s: int) -> tuple[list[float], list[int], list[int], list[float], list[float]]:
        got = self.edge_store.get((node, s))
        if got is None:
            # Build the whole tile: the search will want the neighbours next.
            tile = self._tile_nodes[int(self._tile_of[node])]
            todo = np.array([n for n in tile.tolist() if (n, 1) not in self.edge_store], dtype=np.int64)
            build_edges(self, todo)
            got = self.edge_store[(node, s)]
        return got

    def build_all_edges(self) -> None:
        """Build the edges of every node (a goal field needs them all), and keep a slow build
        in the disk cache (:mod:`pointnav_core.geodesic.cache`)."""
        todo = np.array([n for n in range(self.n_nodes) if (n, 1) not in self.edge_store], dtype=np.int64)
        if not len(todo):
            return
        started = time.perf_counter()
        # Batches of nodes, each with all its candidates in memory at once: a few hundred
        # keep that near 0.5 GB on a map of thousands of obstacles (4,096 took 7 GB).
        batches = range(0, len(todo), _EDGE_BATCH)
        with tqdm(total=len(todo), desc="tangent edges", unit="node", leave=False,
                  disable=len(todo) < _PROGRESS_NODES or None) as bar:
            for i in batches:
                build_edges(self, todo[i : i + _EDGE_BATCH])
                bar.update(min(_EDGE_BATCH, len(todo) - i))
                self._check_geometry_bytes()
        self._build_seconds += time.perf_counter() - started
        if self._cache_key is not None and self._build_seconds >= cache.MIN_SECONDS:
            links = self._cell_links.arrays() if isinstance(self._cell_links, CellLinks) else {}
            self._in_cache = cache.save(self._cache_key, {**self._edge_arrays(), **links}) is not None

    @property
    def geometry_nbytes(self) -> int:
        """Approximate memory (bytes) of this floor's geometry for this radius: nodes, sight
        bounds, tangent edges, arc graph and cell links (the goal fields not included)."""
        arrays = sum(a.nbytes for a in (self.cx, self.cy, self.phi0, self.span, self.sights, self.sight_profile))
        n_edges = self.edge_store.n_edges()
        links = self._cell_links.nbytes if isinstance(self._cell_links, CellLinks) else 0
        return int(arrays + n_edges * _EDGE_BYTES + links)

    def _check_geometry_bytes(self) -> None:
        used = self.geometry_nbytes
        if used > self.geometry_bytes:
            h, w = self.geo.shape
            raise ArgumentError(
                f"the geometry of this {h} x {w}-cell floor ({self.n_nodes} corners) for a robot of radius "
                f"{self.radius} m needs more than Planner.geometry_bytes = {self.geometry_bytes / 2**20:.0f} MiB "
                f"({used / 2**20:.0f} MiB so far); raise the budget (pointnav_core.geodesic.Planner.geometry_bytes "
                f"= n_bytes) or use a coarser map"
            )

    @property
    def sight_reach(self) -> NDArray[np.float64]:
        """Per node, the radius (m) of its sight ball: no point further from the node's centre
        sees its arc by a clear tangent."""
        return self._balls.reach

    def cell_links(self, build: bool = True) -> CellLinks | None:
        """Every usable cell centre's clear links (:class:`~pointnav_core.geodesic.cell_links.
        CellLinks`), or None where the floor gets none (its roots are then settled link by
        link, as fast for a few goals).

        With ``build`` they are built now where the floor is small enough
        (:meth:`CellLinks.fits`) and kept in the disk cache; without, they are returned only
        when already built, loaded from the cache, or once the roots settled without them
        have cost as much as building them would (:meth:`spent_on_roots`).
        """
        if self._cell_links is None and build:
            self._cell_links = False
            if CellLinks.fits(self):
                self.build_all_edges()
                started = time.perf_counter()
                self._cell_links = CellLinks.build(self)
                self._build_seconds += time.perf_counter() - started
                if self.geometry_nbytes > self.geometry_bytes:
                    self._cell_links = False  # optional: not kept past the budget
                if self._cache_key is not None and self._build_seconds >= cache.MIN_SECONDS:
                    arrays = {**self._edge_arrays(), **self._cell_links.arrays()}
                    self._in_cache = cache.save(self._cache_key, arrays) is not None
        return self._cell_links or None

    def spent_on_roots(self, seconds: float) -> None:
        """Count ``seconds`` of roots settled without the cell links; once they add up to the
        links' estimated build (:data:`~pointnav_core.geodesic.cell_links.BUILD_SECONDS_PER_PAIR`
        per candidate pair), build them: a floor that serves many goals pays at most twice
        the cheaper of the two ways, and one that serves few never builds them."""
        self._roots_seconds += seconds
        if self._cell_links is None:
            if self._links_estimate is None:
                self._links_estimate = CellLinks.build_estimate(self)
            if self._roots_seconds >= self._links_estimate:
                self.cell_links()

    @property
    def cached(self) -> bool:
        """Whether this floor's build is in the disk cache (read from it, or written to it)."""
        return self._in_cache

    def _edge_arrays(self) -> dict[str, NDArray[Any]]:
        """The sights and every edge as flat arrays (what the disk cache keeps)."""
        return {"sights": self.sights, "sight_profile": self.sight_profile, **edge_arrays(self.edge_store)}

    def arc_graph(self) -> ArcGraph:
        """The whole tangent graph as a plain digraph (built on first use, then cached)."""
        if self._arc_graph is None:
            self._arc_graph = ArcGraph(self)
        return self._arc_graph

    def nodes_seeing(self, xs: NDArray[np.float64], ys: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """The nodes each point ``(xs[i], ys[i])`` may see (m): ``(owner, node)`` pairs, sorted.

        A node further from a point than its sight plus the radius cannot be reached from it
        by a clear tangent (:mod:`pointnav_core.geodesic.sight`); the rest are candidates.
        """
        return self._balls.query(xs, ys)

    def point_links(
        self, x: float, y: float
    ) -> list[tuple[int, int, float, float]]:
        """Tangents from point ``(x, y)`` to the nodes it sees: ``(node, side, arrival, length)``.

        ``side`` is the winding of a path that leaves the point and wraps the node; the
        reverse path (node to point) winds ``-side`` and leaves at ``span - arrival``.
        """
        return point_links(self, x, y)

    # ------------------------------------------------------------------ queries
    def is_clear(self, x: float, y: float) -> bool:
        """Whether the robot's disc fits at world point ``(x, y)``."""
        return self.geo.segment_clear(x, y, x, y, self.radius)

    def segment_clear(self, a: ArrayLike, b: ArrayLike) -> bool:
        """Whether the robot's disc can move straight from ``a`` to ``b``."""
        a = np.asarray(a, dtype=np.float64).reshape(-1)
        b = np.asarray(b, dtype=np.float64).reshape(-1)
        return self.geo.segment_clear(float(a[0]), float(a[1]), float(b[0]), float(b[1]), self.radius)

    def has_field(self, goal: ArrayLike) -> bool:
        """Whether the goal field of world point ``goal`` is cached."""
        g = np.asarray(goal, dtype=np.float64).reshape(-1)[:2]
        return (float(g[0]), float(g[1])) in self._fields

    def goal_field(self, goal: ArrayLike) -> GoalField:
        """Return the cached :class:`GoalField` rooted at world point ``goal``.

        The cache is bounded by :attr:`field_cache_bytes`; the least recently used fields
        are dropped beyond it.
        """
        g = np.asarray(goal, dtype=np.float64).reshape(-1)[:2]
        key = (float(g[0]), float(g[1]))
        field = self._fields.pop(key, None)
        if field is None:
            field = GoalField(self, g)
            self._field_bytes += field.nbytes
        self._fields[key] = field  # most recently used last
        self._trim_fields()
        return field

    def field_resized(self, field: GoalField, before: int) -> None:
        """Count a cached ``field`` whose size changed from ``before`` bytes (its root table
        was made), and keep the cache within :attr:`field_cache_bytes`."""
        if self._fields.get((float(field.goal[0]), float(field.goal[1]))) is field:
            self._field_bytes += field.nbytes - before
            self._trim_fields()

    def _trim_fields(self) -> None:
        while self._field_bytes > self.field_cache_bytes and len(self._fields) > 1:
            key = next(iter(self._fields))
            self._field_bytes -= self._fields.pop(key).nbytes

    def shortest_path(
        self, source: ArrayLike, target: ArrayLike, piece: float = ARC_PIECE
    ) -> tuple[NDArray[np.float64], float] | tuple[None, None]:
        """Exact shortest path between two world points by A*, without building a field.

        Once the floor's whole graph exists (:meth:`arc_graph`; a goal field builds it, and
        so does this on floors of at most :data:`WHOLE_GRAPH_NODES` nodes), the search runs
        on it in compiled code (:mod:`pointnav_core.geodesic.arc_search`); before, it
        builds the edges it needs tile by tile (:mod:`.point_search`). Returns the drawn
        path (N, 2), its arcs in pieces of at most ``piece`` (rad, in (0, pi / 2]), and its
        exact length in metres, or ``(None, None)``.
        """
        if not (is_real(piece) and 0.0 < piece <= math.pi / 2):
            raise ArgumentError(f"piece must be a number of radians in (0, pi / 2], got {piece!r}")
        whole = self.whole_graph_search and (self._arc_graph is not None or self.n_nodes <= WHOLE_GRAPH_NODES)
        return shortest_path(self, source, target, self.arc_graph() if whole else None, float(piece))

    @property
    def usable(self) -> NDArray[np.bool_]:
        """Cells whose centre the robot's disc fits at (read-only)."""
        if self._usable is None:
            self._usable = usable_cells(self.geo, self.radius)
        return self._usable

    @property
    def near_usable(self) -> NDArray[np.int32]:
        """Flat index of each cell's nearest usable cell (-1 where none is), int32."""
        if self._near is None:
            self._near = nearest_usable(self.usable)
        return self._near


_EDGE_DTYPE = np.dtype([("to", np.int64), ("side", np.int8), ("arr", np.float64), ("length", np.float64)])


def _runs(sorted_keys: NDArray[np.int64]) -> list[tuple[int, int, int]]:
    """``(key, start, end)`` of each run of equal values in a sorted array."""
    if not len(sorted_keys):
        return []
    cut = np.flatnonzero(np.diff(sorted_keys)) + 1
    starts = np.concatenate([[0], cut])
    ends = np.concatenate([cut, [len(sorted_keys)]])
    return list(zip(sorted_keys[starts].tolist(), starts.tolist(), ends.tolist()))

