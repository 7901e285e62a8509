"""Exact geodesics of a disc robot in a floor's collision geometry (the tangent graph).

This planner replaces the corner graph of :mod:`pointnav_core.geodesic`, whose usable
cells are decided at their centres (see ``docs/geodesic.md``); it is tested on its own
and not yet what :class:`~pointnav_core.scenes.Scene` calls.

The robot's centre may go wherever its disc of radius ``r`` misses the blocked set of
:class:`~pointnav_core.collision.FloorCollision`. A shortest path in that space is taut: a
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

A :class:`GoalField` holds a whole Dijkstra run from one goal (exact distance of every
node) and answers exact point queries by the tangents a point sees. For the per-step hot
path it also builds a root table on first use: a seeded multi-source Dijkstra on the grid
proposes each cell's root node, every proposal is checked (the tangent from the root to the
cell centre is clear and leaves the arc forward), and a lookup is the tangent length from
the root plus the root's arc and distance. Everything is in world metres.
"""

from __future__ import annotations

import bisect
import heapq
import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage, sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from pointnav_core.collision import FloorCollision, convex_corners
from pointnav_core.geodesic import path_length, resample_path

if TYPE_CHECKING:
    from pointnav_core.maps import TraversableMap

__all__ = ["Planner", "GoalField", "planner_for", "resample_path", "path_length"]

_TWO_PI = 2.0 * math.pi
_ANG_TOL = 1e-9
_COST_TOL = 1e-12
#: Samples along a node's arc used to find the parts of it within ``r`` of something else.
_ARC_SAMPLES = 9
#: Rays cast to bound how far a node can see.
_SIGHT_RAYS = 128
#: Largest angle (rad) of one piece of a drawn arc.
_ARC_PIECE = math.radians(2.0)
#: Smallest radius (m) the planner uses.
MIN_RADIUS = 1e-6
#: Byte budget of the goal fields a planner keeps.
FIELD_CACHE_BYTES = 256 * 2**20


def planner_for(tmap: TraversableMap, radius: float) -> Planner:
    """Return the cached tangent-graph :class:`Planner` of ``tmap`` for ``radius`` metres."""
    key = ("tangent", round(float(radius), 12))
    return tmap.planner_cache.get_or_create(key, lambda: Planner(FloorCollision.from_map(tmap), radius))


# --------------------------------------------------------------------------- tangents
def _tangent_from_point(
    px: Any, py: Any, cx: Any, cy: Any, r: float, s: Any
) -> tuple[Any, Any, Any, Any]:
    """Tangent from point ``p`` to the circle at ``c`` that arrives winding on side ``s``.

    Returns the arrival angle on the circle (rad), the tangent length, the tangent point
    and a validity mask (``p`` outside the circle). ``s = +1`` winds counter-clockwise (the
    corner on the path's left).
    """
    dx = cx - px
    dy = cy - py
    L = np.hypot(dx, dy)
    ok = L >= r * (1 + 1e-12) if r > 0 else L > 0
    safe = np.where(ok, L, 1.0)
    theta = -s * np.arcsin(np.clip(r / safe, -1.0, 1.0))
    heading = np.arctan2(dy, dx) + theta
    ang = heading - s * (math.pi / 2)
    length = np.sqrt(np.maximum(L * L - r * r, 0.0))
    return ang, length, heading, ok


def _ccw_pos(ang: Any, phi0: Any, span: Any) -> tuple[Any, Any]:
    """Counter-clockwise position of angles on arcs ``[phi0, phi0 + span]``, and validity."""
    ccw = np.mod(ang - phi0, _TWO_PI)
    ccw = np.where(ccw > _TWO_PI - _ANG_TOL, 0.0, ccw)
    ok = ccw <= span + _ANG_TOL
    return np.minimum(ccw, span), ok


class Planner:
    """Tangent graph of one floor's collision geometry for one robot radius.

    Parameters
    ----------
    collision : FloorCollision
        The floor's blocked set (every non-FREE cell, off the map, and its polygons).
    radius : float
        Robot radius in metres, >= 0.
    """

    def __init__(self, collision: FloorCollision, radius: float) -> None:
        self.geo = collision
        # A point robot plans as a disc of 1 micrometre, so that paths wrap corners
        # rather than pass through the vertex two diagonal squares share.
        self.radius = max(float(radius), MIN_RADIUS)
        self._build_nodes()
        self._edges: dict[tuple[int, int], tuple[list[float], NDArray[Any]]] = {}
        self._sight_cache: dict[int, float] = {}
        self._fb_edt: NDArray[np.float64] | None = None
        self._usable: NDArray[np.bool_] | None = None
        self._fields: dict[tuple[float, float], GoalField] = {}
        self._field_bytes = 0

    # ------------------------------------------------------------------ nodes
    def _build_nodes(self) -> None:
        geo, r = self.geo, self.radius
        res = geo.resolution
        ox, oy = geo.origin
        rows, cols, quad = convex_corners(geo.blocked, geo.outside_blocked)
        xs = [ox + cols * res]
        ys = [oy + rows * res]
        phi0 = [quad * (math.pi / 2)]
        span = [np.full(len(rows), math.pi / 2)]
        for poly in geo.polygons:
            for ring in _rings(poly):
                pts = np.asarray(ring.coords)[:-1]
                if len(pts) < 3:
                    continue
                e1 = pts - np.roll(pts, 1, axis=0)
                e2 = np.roll(pts, -1, axis=0) - pts
                cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
                dot = (e1 * e2).sum(axis=1)
                convex = cross > 1e-12
                a1 = np.arctan2(-e1[:, 0], e1[:, 1])  # outward normal of the edge before
                turn = np.arctan2(cross, dot)
                xs.append(pts[convex, 0])
                ys.append(pts[convex, 1])
                phi0.append(a1[convex])
                span.append(turn[convex])
        cx = np.concatenate(xs).astype(np.float64)
        cy = np.concatenate(ys).astype(np.float64)
        phi0_all = np.mod(np.concatenate(phi0).astype(np.float64), _TWO_PI)
        span_all = np.concatenate(span).astype(np.float64)
        # Which samples of each arc are clear of everything else.
        k = np.linspace(0.0, 1.0, _ARC_SAMPLES)
        ang = phi0_all[:, None] + span_all[:, None] * k[None, :]
        pts = np.stack([cx[:, None] + r * np.cos(ang), cy[:, None] + r * np.sin(ang)], axis=-1)
        clear = geo.points_clear(pts, r) if len(cx) else np.zeros((0, _ARC_SAMPLES), bool)
        keep = clear.any(axis=1)
        self.cx, self.cy = cx[keep], cy[keep]
        self.phi0, self.span = phi0_all[keep], span_all[keep]
        self.arc_clear = clear[keep]
        self.n_nodes = int(keep.sum())
        self._cx, self._cy = self.cx.tolist(), self.cy.tolist()
        self._phi0, self._span = self.phi0.tolist(), self.span.tolist()
        # Blocked sample positions (ccw, rad) per node; empty for almost every node.
        self._blocked_ccw: list[list[float]] = [[] for _ in range(self.n_nodes)]
        for i, j in zip(*np.nonzero(~self.arc_clear)):
            self._blocked_ccw[int(i)].append(float(self.span[i] * k[j]))
        self._tree = cKDTree(np.stack([self.cx, self.cy], axis=1)) if self.n_nodes else None

    def node_point(self, node: int, s: int, pos: float) -> tuple[float, float]:
        """World point at arc position ``pos`` (rad, along winding ``s``) of ``node``."""
        ccw = pos if s > 0 else self._span[node] - pos
        a = self._phi0[node] + ccw
        return (self._cx[node] + self.radius * math.cos(a), self._cy[node] + self.radius * math.sin(a))

    def _arc_free(self, node: int, s: int, p1: float, p2: float) -> bool:
        """Whether the arc of ``node`` between positions ``p1 <= p2`` (winding ``s``) is clear."""
        blocked = self._blocked_ccw[node]
        if not blocked:
            return True
        if s > 0:
            lo, hi = p1, p2
        else:
            sp = self._span[node]
            lo, hi = sp - p2, sp - p1
        return not any(lo + _ANG_TOL < b < hi - _ANG_TOL for b in blocked)

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

    def sight_radius(self, x: float, y: float) -> float:
        """An upper bound (m) on how far a disc at ``(x, y)`` can move in a straight line.

        Cast as :data:`_SIGHT_RAYS` rays marched through cells no disc can use; the bound
        is the longest ray plus two cells.
        """
        geo = self.geo
        res = geo.resolution
        edt = self._fully_blocked_edt()
        h, w = edt.shape
        ang = np.linspace(0.0, _TWO_PI, _SIGHT_RAYS, endpoint=False)
        ux, uy = np.cos(ang), np.sin(ang)
        gx0 = (x - geo.origin[0]) / res + 1.0  # +1: the padding ring
        gy0 = (y - geo.origin[1]) / res + 1.0
        t = np.zeros(_SIGHT_RAYS)
        active = np.ones(_SIGHT_RAYS, bool)
        start = self.radius / res + 2.0
        limit = math.hypot(h, w) + 2.0
        for _ in range(4 * (h + w)):
            if not active.any():
                break
            gx = gx0 + t * ux
            gy = gy0 + t * uy
            col = np.floor(gx).astype(np.int64)
            row = np.floor(gy).astype(np.int64)
            inside = (col >= 0) & (col < w) & (row >= 0) & (row < h)
            d = np.where(inside, edt[np.clip(row, 0, h - 1), np.clip(col, 0, w - 1)], 0.0)
            # Stop inside a cell no disc can use; advance by what the nearest such cell
            # leaves free (or a quarter cell, which can only overestimate the reach).
            stop = active & ((~inside) | ((d < 0.5) & (t > start)) | (t > limit))
            active &= ~stop
            t = np.where(active, t + np.maximum(d - math.sqrt(2.0), 0.25), t)
        return float(t.max() + 2.0) * res

    # ------------------------------------------------------------------ edges
    def edges(self, node: int, s: int) -> tuple[list[float], NDArray[Any]]:
        """Tangent edges leaving ``node`` winding ``s``, sorted by departure position.

        Returns the departure positions (rad) and a record array with fields ``to``,
        ``side``, ``arr`` (arrival position at ``to``), ``length`` (m).
        """
        key = (node, s)
        got = self._edges.get(key)
        if got is None:
            got = self._make_edges(node, s)
            self._edges[key] = got
        return got

    def _node_sight(self, node: int) -> float:
        got = self._sight_cache.get(node)
        if got is None:
            mid = self._phi0[node] + self._span[node] / 2
            x = self._cx[node] + self.radius * math.cos(mid)
            y = self._cy[node] + self.radius * math.sin(mid)
            got = self.sight_radius(x, y) + self.radius
            self._sight_cache[node] = got
        return got

    def _make_edges(self, a: int, s: int) -> tuple[list[float], NDArray[Any]]:
        r = self.radius
        cand = np.asarray(self._tree.query_ball_point((self._cx[a], self._cy[a]), self._node_sight(a)), dtype=np.int64)
        cand = cand[cand != a]
        out_dep: list[NDArray[np.float64]] = []
        recs: list[NDArray[Any]] = []
        ax, ay = self._cx[a], self._cy[a]
        for sb in (s, -s):
            bx, by = self.cx[cand], self.cy[cand]
            dx, dy = bx - ax, by - ay
            L = np.hypot(dx, dy)
            if sb == s:
                ok = L > 0
                theta = np.zeros_like(L)
                seg = L
            else:
                ok = L > 2 * r * (1 + 1e-12) if r > 0 else L > 0
                theta = s * np.arcsin(np.clip(2 * r / np.where(ok, L, 1.0), -1.0, 1.0))
                seg = np.sqrt(np.maximum(L * L - 4 * r * r, 0.0))
            heading = np.arctan2(dy, dx) + theta
            dep_ang = heading - s * (math.pi / 2)
            arr_ang = heading - sb * (math.pi / 2)
            dep_ccw, ok_a = _ccw_pos(dep_ang, self._phi0[a], self._span[a])
            arr_ccw, ok_b = _ccw_pos(arr_ang, self.phi0[cand], self.span[cand])
            ok &= ok_a & ok_b
            idx = np.flatnonzero(ok)
            if not len(idx):
                continue
            pa = np.stack([ax + r * np.cos(dep_ang[idx]), ay + r * np.sin(dep_ang[idx])], axis=1)
            pb = np.stack([bx[idx] + r * np.cos(arr_ang[idx]), by[idx] + r * np.sin(arr_ang[idx])], axis=1)
            clear = self.geo.segments_clear(pa, pb, r)
            idx = idx[clear]
            if not len(idx):
                continue
            dep = dep_ccw[idx] if s > 0 else self._span[a] - dep_ccw[idx]
            arr = arr_ccw[idx] if sb > 0 else self.span[cand[idx]] - arr_ccw[idx]
            rec = np.empty(len(idx), dtype=_EDGE_DTYPE)
            rec["to"] = cand[idx]
            rec["side"] = sb
            rec["arr"] = arr
            rec["length"] = seg[idx]
            out_dep.append(dep)
            recs.append(rec)
        if not recs:
            return [], np.empty(0, dtype=_EDGE_DTYPE)
        dep_all = np.concatenate(out_dep)
        rec_all = np.concatenate(recs)
        order = np.argsort(dep_all, kind="stable")
        return dep_all[order].tolist(), rec_all[order]

    def point_links(
        self, x: float, y: float
    ) -> list[tuple[int, int, float, float]]:
        """Tangents from point ``(x, y)`` to the nodes it sees: ``(node, side, arrival, length)``.

        ``side`` is the winding of a path that leaves the point and wraps the node; the
        reverse path (node to point) winds ``-side`` and leaves at ``span - arrival``.
        """
        if not self.n_nodes:
            return []
        r = self.radius
        cand = np.asarray(self._tree.query_ball_point((x, y), self.sight_radius(x, y) + r), dtype=np.int64)
        links: list[tuple[int, int, float, float]] = []
        if not len(cand):
            return links
        for s in (1, -1):
            ang, length, _, ok = _tangent_from_point(x, y, self.cx[cand], self.cy[cand], r, s)
            ccw, ok_arc = _ccw_pos(ang, self.phi0[cand], self.span[cand])
            ok &= ok_arc
            idx = np.flatnonzero(ok)
            if not len(idx):
                continue
            q = np.stack([self.cx[cand[idx]] + r * np.cos(ang[idx]), self.cy[cand[idx]] + r * np.sin(ang[idx])], axis=1)
            clear = self.geo.segments_clear(np.array([x, y]), q, r)
            for i in idx[clear].tolist():
                c = int(cand[i])
                pos = float(ccw[i]) if s > 0 else self._span[c] - float(ccw[i])
                links.append((c, s, pos, float(length[i])))
        return links

    # ------------------------------------------------------------------ queries
    def is_clear(self, x: float, y: float) -> bool:
        """Whether the robot's disc fits at world point ``(x, y)``."""
        return bool(self.geo.points_clear(np.array([x, y]), self.radius))

    def segment_clear(self, a: ArrayLike, b: ArrayLike) -> bool:
        """Whether the robot's disc can move straight from ``a`` to ``b``."""
        return bool(self.geo.segments_clear(np.asarray(a, float), np.asarray(b, float), self.radius))

    def has_field(self, goal: ArrayLike) -> bool:
        """Whether the goal field of world point ``goal`` is cached."""
        g = np.asarray(goal, dtype=np.float64).reshape(-1)[:2]
        return (float(g[0]), float(g[1])) in self._fields

    def goal_field(self, goal: ArrayLike) -> GoalField:
        """Return the cached :class:`GoalField` rooted at world point ``goal``.

        The cache is bounded by :data:`FIELD_CACHE_BYTES`; the least recently used fields
        are dropped beyond it.
        """
        g = np.asarray(goal, dtype=np.float64).reshape(-1)[:2]
        key = (float(g[0]), float(g[1]))
        field = self._fields.pop(key, None)
        if field is None:
            field = GoalField(self, g)
        self._fields[key] = field  # most recently used last
        self._trim_fields()
        return field

    def _trim_fields(self) -> None:
        total = sum(f.nbytes for f in self._fields.values())
        while total > FIELD_CACHE_BYTES and len(self._fields) > 1:
            key = next(iter(self._fields))
            total -= self._fields.pop(key).nbytes

    def shortest_path(
        self, source: ArrayLike, target: ArrayLike
    ) -> tuple[NDArray[np.float64], float] | tuple[None, None]:
        """Exact shortest path between two world points by A*, without building a field.

        Returns the drawn path (N, 2) and its exact length in metres, or ``(None, None)``.
        """
        src = np.asarray(source, dtype=np.float64)[:2]
        tgt = np.asarray(target, dtype=np.float64)[:2]
        sx, sy, tx, ty = float(src[0]), float(src[1]), float(tgt[0]), float(tgt[1])
        if not (self.is_clear(sx, sy) and self.is_clear(tx, ty)):
            return None, None
        if self.segment_clear(src, tgt):
            return np.array([src, tgt]), math.hypot(tx - sx, ty - sy)
        # Links into the target, seen from the target: reversed, they leave a node.
        finish: dict[tuple[int, int], list[tuple[float, float]]] = {}
        for c, s, pos, length in self.point_links(tx, ty):
            finish.setdefault((c, -s), []).append((self._span[c] - pos, length))
        search = _Search(self, heuristic_to=(tx, ty))
        for c, s, pos, length in self.point_links(sx, sy):
            search.push(length, c, s, pos, -1, 0.0)
        best = search.run(finish)
        if best is None:
            return None, None
        cost, label, dep = best
        pts = [np.array([tx, ty])]
        pts += search.trace(label, dep)
        pts.append(np.array([sx, sy]))
        return np.array(pts[::-1]), cost

    @property
    def usable(self) -> NDArray[np.bool_]:
        """Cells whose centre the robot's disc fits at (read-only)."""
        if self._usable is None:
            geo = self.geo
            h, w = geo.shape
            rows, cols = np.mgrid[0:h, 0:w]
            centres = np.stack(
                [geo.origin[0] + (cols + 0.5) * geo.resolution, geo.origin[1] + (rows + 0.5) * geo.resolution],
                axis=-1,
            )
            mask = ~geo.blocked
            sub = geo.points_clear(centres[mask], self.radius)
            usable = np.zeros((h, w), dtype=bool)
            usable[mask] = sub
            usable.flags.writeable = False
            self._usable = usable
        return self._usable


_EDGE_DTYPE = np.dtype([("to", np.int64), ("side", np.int8), ("arr", np.float64), ("length", np.float64)])


def _rings(poly: Any) -> list[Any]:
    """Exterior rings of a polygon's parts, counter-clockwise (the blocked side on the left)."""
    parts = getattr(poly, "geoms", [poly])
    rings = []
    for part in parts:
        ext = part.exterior
        if not ext.is_ccw:
            ext = type(ext)(list(ext.coords)[::-1])
        rings.append(ext)
    return rings


class _Search:
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
            if lp <= pos + _ANG_TOL and self.cost[lab] + r * max(pos - lp, 0.0) <= g + _COST_TOL:
                if self.p._arc_free(node, s, lp, pos):
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
                    if fdep >= pos - _ANG_TOL and p._arc_free(node, s, pos, fdep):
                        total = g + r * max(fdep - pos, 0.0) + flen
                        self.count += 1
                        heapq.heappush(heap, (total, total, self.count, -1, 0, 0.0, lab, fdep))
            deps, recs = p.edges(node, s)
            start = bisect.bisect_left(deps, pos - _ANG_TOL)
            if start >= len(deps):
                continue
            blocked = p._blocked_ccw[node]
            for i in range(start, len(deps)):
                d = deps[i]
                if blocked and not p._arc_free(node, s, pos, d):
                    break
                rec = recs[i]
                self.push(g + r * max(d - pos, 0.0) + float(rec["length"]), int(rec["to"]), int(rec["side"]), float(rec["arr"]), lab, d)
        return None

    def trace(self, label: int, dep: float) -> list[NDArray[np.float64]]:
        """Points from the departure at ``dep`` on ``label``'s arc back to the first node."""
        p = self.p
        pts: list[NDArray[np.float64]] = []
        while label >= 0:
            node, s = self.node[label], self.side[label]
            pts += _arc_points(p, node, s, dep, self.pos[label])
            dep = self.parent_dep[label]
            label = self.parent[label]
        return pts


def _arc_points(p: Planner, node: int, s: int, pos_from: float, pos_to: float) -> list[NDArray[np.float64]]:
    """Drawn arc of ``node`` from position ``pos_from`` back to ``pos_to`` (both ends on it).

    Intermediate vertices lie outside the circle, so that every drawn piece is tangent to
    it and keeps the full radius from the corner.
    """
    a = p.node_point(node, s, pos_from)
    delta = pos_from - pos_to
    out = [np.array(a)]
    if delta <= _ANG_TOL or p.radius == 0.0:
        return out
    n = max(1, math.ceil(delta / _ARC_PIECE))
    piece = delta / n
    reach = p.radius / math.cos(piece / 2)
    cx, cy = p._cx[node], p._cy[node]
    for k in range(n):
        pos = pos_from - piece * (k + 0.5)
        ccw = pos if s > 0 else p._span[node] - pos
        ang = p._phi0[node] + ccw
        out.append(np.array([cx + reach * math.cos(ang), cy + reach * math.sin(ang)]))
    out.append(np.array(p.node_point(node, s, pos_to)))
    return out


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
        self._search = _Search(planner)
        if self.goal_usable:
            for c, s, pos, length in planner.point_links(gx, gy):
                self._search.push(length, c, s, pos, -1, 0.0)
            self._search.run()
        self._table: dict[str, Any] | None = None

    @property
    def reachable_from_anywhere(self) -> bool:
        """False when the robot does not fit at the goal (nothing reaches it)."""
        return self.goal_usable

    @property
    def nbytes(self) -> int:
        """Approximate memory held by this field, in bytes."""
        labels = len(self._search.node) * 6 * 8
        # The table holds six Python lists of one entry per cell (8-byte pointers to
        # mostly shared small objects).
        table = 0 if self._table is None else 6 * 8 * len(self._table["kind"])
        return labels + table

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
            for lab in search.settled.get((c, side), ()):
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
        i = t["near"][row * w + col]
        if i < 0:
            return math.inf
        kind = t["kind"][i]
        if kind == 0:
            return math.inf
        if kind == 1:  # straight to the goal
            return math.hypot(x - t["gx"], y - t["gy"])
        if kind == 3:  # grid fallback from the cell centre
            return t["value"][i] + math.hypot(x - t["px"][i], y - t["py"][i])
        lab = t["label"][i]
        p = self.planner
        search = self._search
        c, side = search.node[lab], search.side[lab]
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

    def _adopt_roots(self, kind, label, value, cx_all, cy_all, usable, gx, gy) -> None:  # type: ignore[no-untyped-def]
        """Let cells whose proposed root failed its check try their neighbours' roots.

        A neighbour's root is usually visible from a cell too (as Theta* inherits parents);
        a few passes settle almost every cell exactly.
        """
        p = self.planner
        h, w = usable.shape
        for _ in range(16):
            todo = np.flatnonzero(usable.ravel() & ((kind == 3) | (kind == 0)))
            if not len(todo):
                return
            best = np.full(len(todo), np.inf)
            best_lab = np.full(len(todo), -1)
            best_kind = np.zeros(len(todo), dtype=np.int8)
            rows, cols = np.divmod(todo, w)
            px, py = cx_all[todo], cy_all[todo]
            for dr in (-1, 0, 1):
                for dc in (-1, 0, 1):
                    if not (dr or dc):
                        continue
                    nr, nc = rows + dr, cols + dc
                    inside = (nr >= 0) & (nr < h) & (nc >= 0) & (nc < w)
                    nb = np.where(inside, nr * w + nc, 0)
                    k = np.where(inside, kind[nb], 0)
                    sel = np.flatnonzero(k == 2)
                    if len(sel):
                        val = self._root_values(todo[sel], label[nb[sel]], px[sel], py[sel])
                        better = val < best[sel]
                        best[sel[better]] = val[better]
                        best_lab[sel[better]] = label[nb[sel[better]]]
                        best_kind[sel[better]] = 2
                    sel = np.flatnonzero((k == 1) & (best_kind != 1))
                    if len(sel):
                        clear = p.geo.segments_clear(np.stack([px[sel], py[sel]], 1), np.array([gx, gy]), p.radius)
                        sel = sel[clear]
                        best[sel] = np.hypot(px[sel] - gx, py[sel] - gy)
                        best_kind[sel] = 1
            found = best_kind > 0
            if not found.any():
                return
            cells = todo[found]
            kind[cells] = best_kind[found]
            label[cells] = best_lab[found]

    def _build_table(self) -> dict[str, Any]:
        p = self.planner
        geo = p.geo
        h, w = geo.shape
        res = geo.resolution
        usable = p.usable
        n_cells = h * w
        flat = usable.ravel()
        idx = np.flatnonzero(flat)
        kind = np.zeros(n_cells, dtype=np.int8)
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
            # Seeds: the goal and every settled label's arrival point, at their cells.
            search = self._search
            n_lab = len(search.node)
            # Seed each label at points along its arc ahead of the arrival, so that a cell
            # behind the corner is proposed the arc point it leaves from.
            xs, ys, costs, owner = [gx], [gy], [0.0], [0]
            for j in range(n_lab):
                node, side, pos = search.node[j], search.side[j], search.pos[j]
                rest = p._span[node] - pos
                for f in (0.0, 0.25, 0.5, 0.75, 1.0):
                    q = pos + f * rest
                    if f > 0 and (rest <= _ANG_TOL or not p._arc_free(node, side, pos, q)):
                        break
                    x, y = p.node_point(node, side, q)
                    xs.append(x)
                    ys.append(y)
                    costs.append(search.cost[j] + p.radius * (q - pos))
                    owner.append(j + 1)
            seed_x, seed_y, seed_cost = np.array(xs), np.array(ys), np.array(costs)
            seed_owner = np.array(owner)
            scol = np.floor((seed_x - geo.origin[0]) / res).astype(np.int64)
            srow = np.floor((seed_y - geo.origin[1]) / res).astype(np.int64)
            inside = (scol >= 0) & (scol < w) & (srow >= 0) & (srow < h)
            scell = np.where(inside, srow * w + scol, 0)
            ok = inside & flat[scell]
            seeds = np.flatnonzero(ok)
            seed_val = seed_cost[seeds] + np.hypot(cx_all[scell[seeds]] - seed_x[seeds], cy_all[scell[seeds]] - seed_y[seeds])
            graph = _cell_graph(usable, res)
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
                nodes = np.asarray(search.node)[lab]
                sides = np.asarray(search.side)[lab]
                lpos = np.asarray(search.pos)[lab]
                ang, _, _, ok = _tangent_from_point(cx_all[c], cy_all[c], p.cx[nodes], p.cy[nodes], p.radius, -sides)
                ccw, in_arc = _ccw_pos(ang, p.phi0[nodes], p.span[nodes])
                dep = np.where(sides > 0, ccw, p.span[nodes] - ccw)
                ok &= in_arc & (dep >= lpos - _ANG_TOL)
                q = np.stack([p.cx[nodes] + p.radius * np.cos(ang), p.cy[nodes] + p.radius * np.sin(ang)], 1)
                good = np.zeros(len(c), dtype=bool)
                if ok.any():
                    sub = np.flatnonzero(ok)
                    good[sub] = geo.segments_clear(np.stack([cx_all[c[sub]], cy_all[c[sub]]], 1), q[sub], p.radius)
                kind[c[good]] = 2
                label[c[good]] = lab[good]
                value[c[good]] = 0.0
            self._adopt_roots(kind, label, value, cx_all, cy_all, usable, gx, gy)
        # Cells the disc does not fit at read their nearest usable cell.
        if len(idx):
            _, (nr, nc) = ndimage.distance_transform_edt(~usable, return_indices=True)
            near = (nr * w + nc).ravel()
        else:
            near = np.full(n_cells, -1)
        table = {
            "kind": kind.tolist(),
            "label": label.tolist(),
            "value": value.tolist(),
            "px": cx_all.tolist(),
            "py": cy_all.tolist(),
            "near": near.tolist(),
            "gx": gx,
            "gy": gy,
        }
        self._table = table
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
