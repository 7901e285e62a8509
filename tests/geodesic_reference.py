"""Exact continuous geodesics from polygons, independent of the library's planner.

Grow the obstacles by the robot radius with shapely, shrink the outline by it, build the
visibility graph over the free space's reflex vertices, and run Dijkstra. Used by the
accuracy tests and by ``benchmarks/bench_geodesic.py``.

Error model. ``buffer(r, quad_segs=q)`` replaces each rounded corner by a polygon whose
vertices lie on the true circle, so the grown obstacles are *inscribed* in the true ones:
the reference free space contains the true free space and is contained in the free space of
the smaller radius ``r * cos(pi / (4 q))``. Hence the reference distance is never longer
than the exact one (up to float noise), and it is shorter only where the path wraps a
corner: a chord of angle ``t`` is ``sin(t/2) / (t/2)`` of its arc, so the shortfall is at
most ``(pi / 4q)**2 / 6`` of the wrapped arc length (6e-5 of the arc for q = 16, 2.4e-4 for
q = 8), unless a passage narrower than ``2r`` but wider than ``2r cos(pi / 4q)`` opens.

The graph keeps only *bitangent* edges: a segment whose line leaves both end vertices'
neighbours on one side. A shortest path bends only at reflex vertices and only on tangent
segments, so the pruning drops no shortest path; it only skips the expensive
``covers`` tests.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.sparse import csgraph, csr_matrix
from shapely.affinity import rotate
from shapely.geometry import Polygon, box
from shapely.geometry.polygon import orient

#: Relative tolerance of the collinearity and tangency tests (unit vectors).
_TANGENT_TOL = 1e-9


def blocked_cells(blocked: np.ndarray, resolution: float, origin: tuple[float, float] = (0.0, 0.0)) -> list[Polygon]:
    """Boxes of the blocked cells of a grid (row grows with +y), one box per run of a row.

    ``blocked[row, col]`` covers ``[col, col + 1) x [row, row + 1)`` times ``resolution``
    from ``origin``. Runs are merged per row only to keep the union cheap.
    """
    ox, oy = origin
    boxes = []
    for row in range(blocked.shape[0]):
        padded = np.concatenate([[False], np.asarray(blocked[row], bool), [False]])
        edges = np.flatnonzero(np.diff(padded.astype(np.int8)))
        for c0, c1 in zip(edges[::2], edges[1::2]):
            boxes.append(box(ox + c0 * resolution, oy + row * resolution,
                             ox + c1 * resolution, oy + (row + 1) * resolution))
    return boxes


def _tangent(vertices: np.ndarray, prev: np.ndarray, nxt: np.ndarray, other: np.ndarray) -> np.ndarray:
    """Whether the line from each vertex to ``other`` leaves both its neighbours on one side."""
    d = other - vertices
    d = d / np.maximum(np.hypot(d[..., 0], d[..., 1]), 1e-300)[..., None]
    c1 = d[..., 0] * prev[..., 1] - d[..., 1] * prev[..., 0]
    c2 = d[..., 0] * nxt[..., 1] - d[..., 1] * nxt[..., 0]
    return c1 * c2 >= -_TANGENT_TOL


def house_plan(seed: int) -> tuple[Polygon, list[Polygon]]:
    """A 12 x 9 m floor: outer walls, a grid of rooms with door gaps, rotated furniture."""
    rng = np.random.default_rng(seed)
    w, h, t = 12.0, 9.0, 0.12
    outline = box(0, 0, w, h)
    walls = [box(0, 0, w, t), box(0, h - t, w, h), box(0, 0, t, h), box(w - t, 0, w, h)]
    xs = [0.0, 4.0 + rng.uniform(-0.5, 0.5), 8.0 + rng.uniform(-0.5, 0.5), w]
    ys = [0.0, 4.5 + rng.uniform(-0.5, 0.5), h]
    for x in xs[1:-1]:
        for y0, y1 in zip(ys[:-1], ys[1:]):
            door = rng.uniform(y0 + 0.6, y1 - 1.6)
            walls += [box(x - t / 2, y0, x + t / 2, door), box(x - t / 2, door + 1.0, x + t / 2, y1)]
    for y in ys[1:-1]:
        for x0, x1 in zip(xs[:-1], xs[1:]):
            door = rng.uniform(x0 + 0.6, x1 - 1.6)
            walls += [box(x0, y - t / 2, door, y + t / 2), box(door + 1.0, y - t / 2, x1, y + t / 2)]
    furniture = []
    for x0, x1 in zip(xs[:-1], xs[1:]):
        for y0, y1 in zip(ys[:-1], ys[1:]):
            for _ in range(2):
                cx, cy = rng.uniform(x0 + 1.3, x1 - 1.3), rng.uniform(y0 + 1.3, y1 - 1.3)
                bw, bh = rng.uniform(0.3, 0.9), rng.uniform(0.3, 0.7)
                piece = rotate(box(cx - bw / 2, cy - bh / 2, cx + bw / 2, cy + bh / 2),
                               rng.uniform(0, 180), origin="centroid")
                furniture.append(piece)
    return outline, walls + furniture


class ContinuousGeodesic:
    """Exact shortest paths for a disc robot among polygons (visibility graph + Dijkstra)."""

    def __init__(self, outline: Polygon, obstacles: list[Polygon], radius: float, quad_segs: int = 4):
        grown = shapely.union_all([o.buffer(radius, quad_segs=quad_segs) for o in obstacles])
        free = outline.buffer(-radius, quad_segs=quad_segs, join_style="mitre").difference(grown)
        self.free = free
        shapely.prepare(free)
        verts, prevs, nexts = [], [], []
        for poly in getattr(free, "geoms", [free]):
            poly = orient(poly, 1.0)  # free space on the left of every ring
            for ring in [poly.exterior, *poly.interiors]:
                pts = np.asarray(ring.coords)[:-1]
                if len(pts) < 3:
                    continue
                e_in = pts - np.roll(pts, 1, axis=0)
                e_out = np.roll(pts, -1, axis=0) - pts
                e_in /= np.hypot(*e_in.T)[:, None]
                e_out /= np.hypot(*e_out.T)[:, None]
                # Reflex (a right turn) or straight: the only places a shortest path bends.
                keep = e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0] <= _TANGENT_TOL
                verts.append(pts[keep])
                prevs.append(-e_in[keep])
                nexts.append(e_out[keep])
        self.vertices = np.vstack(verts) if verts else np.zeros((0, 2))
        self._prev = np.vstack(prevs) if prevs else np.zeros((0, 2))
        self._next = np.vstack(nexts) if nexts else np.zeros((0, 2))
        n = len(self.vertices)
        rows, cols, lengths = [], [], []
        chunk = max(1, 2_000_000 // max(n, 1))
        for start in range(0, n, chunk):
            i = np.arange(start, min(start + chunk, n))
            ii, jj = np.meshgrid(i, np.arange(n), indexing="ij")
            m = jj > ii
            ii, jj = ii[m], jj[m]
            v, w = self.vertices[ii], self.vertices[jj]
            cand = _tangent(v, self._prev[ii], self._next[ii], w) & _tangent(w, self._prev[jj], self._next[jj], v)
            ii, jj = ii[cand], jj[cand]
            lines = shapely.linestrings(np.stack([self.vertices[ii], self.vertices[jj]], axis=1))
            ok = shapely.covers(free, lines)
            rows.append(ii[ok])
            cols.append(jj[ok])
            lengths.append(np.hypot(*(self.vertices[ii[ok]] - self.vertices[jj[ok]]).T))
        if n:
            graph = csr_matrix((np.concatenate(lengths), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
            self.all_pairs = csgraph.shortest_path(graph, directed=False)
        else:
            self.all_pairs = np.zeros((0, 0))

    def visible_from(self, p: np.ndarray) -> np.ndarray:
        """Vertices a straight segment from ``p`` reaches tangentially inside the free space."""
        p = np.asarray(p, float)
        seen = _tangent(self.vertices, self._prev, self._next, np.broadcast_to(p, self.vertices.shape))
        idx = np.flatnonzero(seen)
        lines = shapely.linestrings(
            np.stack([np.broadcast_to(p, (len(idx), 2)), self.vertices[idx]], axis=1)
        )
        seen[idx] = shapely.covers(self.free, lines)
        return seen

    def distance(self, s: np.ndarray, t: np.ndarray) -> float:
        s, t = np.asarray(s, float), np.asarray(t, float)
        if shapely.covers(self.free, shapely.linestrings([s, t])):
            return float(np.hypot(*(s - t)))
        vs, vt = self.visible_from(s), self.visible_from(t)
        ds = np.hypot(*(self.vertices[vs] - s).T)
        dt = np.hypot(*(self.vertices[vt] - t).T)
        total = ds[:, None] + self.all_pairs[np.ix_(vs, vt)] + dt[None, :]
        return float(total.min()) if total.size else float("inf")
