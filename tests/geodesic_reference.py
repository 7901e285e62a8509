"""Exact continuous geodesics from polygons, independent of the library's planner.

Grow the obstacles by the robot radius with shapely, shrink the outline by it, build the
visibility graph over the free space's reflex vertices, and run Dijkstra. Used by the
accuracy test and by ``benchmarks/bench_geodesic.py``.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.sparse import csgraph, csr_matrix
from shapely.geometry import Polygon, box
from shapely.affinity import rotate


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
        verts = []
        for poly in getattr(free, "geoms", [free]):
            for ring in [poly.exterior, *poly.interiors]:
                pts = np.asarray(ring.coords)[:-1]
                verts.append(pts)
        self.vertices = np.vstack(verts)
        n = len(self.vertices)
        i, j = np.triu_indices(n, k=1)
        lines = shapely.linestrings(np.stack([self.vertices[i], self.vertices[j]], axis=1))
        ok = shapely.covers(free, lines)
        d = np.hypot(*(self.vertices[i[ok]] - self.vertices[j[ok]]).T)
        graph = csr_matrix((d, (i[ok], j[ok])), shape=(n, n))
        self.all_pairs = csgraph.shortest_path(graph, directed=False)

    def visible_from(self, p: np.ndarray) -> np.ndarray:
        lines = shapely.linestrings(
            np.stack([np.broadcast_to(p, self.vertices.shape), self.vertices], axis=1)
        )
        return shapely.covers(self.free, lines)

    def distance(self, s: np.ndarray, t: np.ndarray) -> float:
        s, t = np.asarray(s, float), np.asarray(t, float)
        if shapely.covers(self.free, shapely.linestrings([s, t])):
            return float(np.hypot(*(s - t)))
        vs, vt = self.visible_from(s), self.visible_from(t)
        ds = np.hypot(*(self.vertices[vs] - s).T)
        dt = np.hypot(*(self.vertices[vt] - t).T)
        total = ds[:, None] + self.all_pairs[np.ix_(vs, vt)] + dt[None, :]
        return float(total.min()) if total.size else float("inf")
