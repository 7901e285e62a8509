"""Properties of the tangent-graph planner on random small floors, each against shapely.

Floors are grids of 6-14 cells a side at 0.05-1 m per cell with random blocked cells and
short walls, or a polygon floor with one thin rotated wall; the robot radius is 0.05-3
cells. End points are drawn where shapely says the disc fits (distance to the blocked cell
boxes and the map frame >= r). Every check is against an independent shapely or brute
force reference, never the library's own clearance predicates:

- every drawn segment keeps ``r`` (1e-6 m) from the blocked set;
- distances are symmetric and obey the triangle inequality (1e-6 m);
- the drawn polyline is as long as the reported distance, within the arc drawing: arcs are
  circumscribed polylines of pieces of at most 2 degrees, each ``tan(t/2) / (t/2)`` times
  its arc, so ``d <= length <= d * tan(1 deg) / (1 deg)``;
- a pair joined by a straight segment that shapely finds clear is no further apart than
  the segment;
- reachability agrees with two one-sided references: a flood fill over a fine lattice of
  points and segments shapely finds clear proves a pair reachable, and separate parts of
  the free space with inscribed (so slightly too small) grown obstacles prove it is not.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from shapely.affinity import rotate
from shapely.geometry import box

from pointnav_core.floor.maps import TraversableMap
from pointnav_core.geodesic.planner import planner_for
from pointnav_core.scenes import Scene

#: Largest drawn-length to distance ratio: an arc piece of 2 degrees, circumscribed.
ARC_RATIO = math.tan(math.radians(1.0)) / math.radians(1.0)
#: Lattice points per cell of the flood-fill reference.
FILL_PER_CELL = 3


class Reference:
    """The blocked set of a floor rebuilt with shapely: cell boxes, polygons, the frame."""

    def __init__(self, tmap: TraversableMap, radius: float, polygons=()) -> None:
        h, w = tmap.shape
        res = tmap.resolution
        ox, oy = tmap.origin
        self.radius = radius
        self.frame = box(ox, oy, ox + w * res, oy + h * res)
        rows, cols = np.nonzero(np.asarray(tmap.codes) != 0)
        self.obstacles = [box(ox + c * res, oy + r * res, ox + (c + 1) * res, oy + (r + 1) * res)
                          for r, c in zip(rows, cols)] + list(polygons)
        self.blocked = shapely.union_all(self.obstacles + [self.frame.exterior])
        shapely.prepare(self.blocked)

    def clearance(self, geoms) -> np.ndarray:
        """Distance (m) from each geometry to the blocked set (0 outside the frame)."""
        d = shapely.distance(self.blocked, geoms)
        return np.where(shapely.covered_by(geoms, self.frame), d, 0.0)

    def fits(self, points: np.ndarray) -> np.ndarray:
        return self.clearance(shapely.points(points)) >= self.radius

    def segment_clear(self, a, b, margin: float = 0.0) -> bool:
        return bool(self.clearance(shapely.linestrings([a, b])) >= self.radius + margin)

    def surely_separate(self, a, b) -> bool:
        """True when ``a`` and ``b`` lie in different parts of a free space that contains the
        true one (corners grown as inscribed polygons, radius a hair smaller)."""
        r = self.radius - 1e-7
        grown = shapely.union_all([o.buffer(r, quad_segs=16) for o in self.obstacles]) if self.obstacles else None
        free = self.frame.buffer(-r, join_style="mitre")
        if grown is not None:
            free = free.difference(grown)
        parts = list(getattr(free, "geoms", [free]))
        pa = [i for i, p in enumerate(parts) if p.covers(shapely.Point(a))]
        pb = [i for i, p in enumerate(parts) if p.covers(shapely.Point(b))]
        return len(pa) == 1 and len(pb) == 1 and pa != pb

    def surely_connected(self, a, b, step: float) -> bool:
        """True when a chain of lattice points, each segment clear by shapely, joins ``a`` to ``b``."""
        x0, y0, x1, y1 = self.frame.bounds
        xs = np.arange(x0 + step / 2, x1, step)
        ys = np.arange(y0 + step / 2, y1, step)
        gx, gy = np.meshgrid(xs, ys)
        pts = np.stack([gx.ravel(), gy.ravel()], axis=1)
        margin = 1e-7  # strictly clear: the certificate must not rest on touching
        ok = self.clearance(shapely.points(pts)) >= self.radius + margin
        idx = np.full(len(pts), -1)
        idx[ok] = np.arange(ok.sum())
        shape = gx.shape
        src, dst = [], []
        for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
            r0, c0 = np.nonzero(ok.reshape(shape))
            r1, c1 = r0 + dr, c0 + dc
            inside = (r1 >= 0) & (r1 < shape[0]) & (c1 >= 0) & (c1 < shape[1])
            r0, c0, r1, c1 = r0[inside], c0[inside], r1[inside], c1[inside]
            i0, i1 = r0 * shape[1] + c0, r1 * shape[1] + c1
            both = ok[i1]
            i0, i1 = i0[both], i1[both]
            lines = shapely.linestrings(np.stack([pts[i0], pts[i1]], axis=1))
            clear = self.clearance(lines) >= self.radius + margin
            src.append(idx[i0[clear]])
            dst.append(idx[i1[clear]])
        n = int(ok.sum())
        if n == 0:
            return False
        src, dst = np.concatenate(src), np.concatenate(dst)
        _, label = connected_components(coo_matrix((np.ones(len(src)), (src, dst)), shape=(n, n)), directed=False)
        kept = pts[ok]

        def components(p) -> set[int]:
            near = np.argsort(np.hypot(*(kept - p).T))[:12]
            lines = shapely.linestrings(np.stack([np.broadcast_to(p, (len(near), 2)), kept[near]], axis=1))
            clear = self.clearance(lines) >= self.radius + margin
            return set(label[near[clear]].tolist())

        return bool(components(a) & components(b))


def check_path(ref: Reference, path, dist, a, b) -> None:
    """Path ends, clearance and drawn length against the reported distance."""
    assert isinstance(dist, float)
    np.testing.assert_allclose(path[0], a, atol=1e-12)
    np.testing.assert_allclose(path[-1], b, atol=1e-12)
    line = shapely.LineString(path) if len(path) > 1 and dist > 0 else shapely.Point(path[0])
    gap = float(ref.clearance(line))
    assert gap >= ref.radius - 1e-6, f"path comes {gap} m from the blocked set, r = {ref.radius}"
    length = float(np.hypot(*np.diff(path, axis=0).T).sum())
    assert length >= dist - 1e-9 - 1e-12 * dist
    assert length <= dist * ARC_RATIO + 1e-9


def check_floor(ref: Reference, planner, unit_points, step: float) -> None:
    x0, y0, x1, y1 = ref.frame.bounds
    pts = np.asarray(unit_points) * (x1 - x0, y1 - y0) + (x0, y0)
    pts = pts[ref.fits(pts)]
    assume(len(pts) >= 3)
    # The farthest pair of the drawn points: more bends and more walls between them.
    far = np.hypot(*(pts[:, None] - pts[None]).T)
    i, j = np.unravel_index(np.argmax(far), far.shape)
    k = next(k for k in range(len(pts)) if k not in (i, j))
    a, b, c = pts[i], pts[j], pts[k]
    results = []
    for p, q in ((a, b), (b, a), (b, c), (a, c)):
        path, dist = planner.shortest_path(p, q)
        if path is None:
            assert dist is None
        else:
            check_path(ref, path, dist, p, q)
        results.append(dist)
    d_ab, d_ba, d_bc, d_ac = results
    # Symmetry, including reachability.
    assert (d_ab is None) == (d_ba is None)
    if d_ab is not None:
        assert abs(d_ab - d_ba) <= 1e-6
        # Triangle inequality, and reachability is transitive.
        if d_bc is not None:
            assert d_ac is not None
            assert d_ac <= d_ab + d_bc + 1e-6
    if d_ab is None:
        event("a, b unreachable")
    else:
        event("a, b straight" if d_ab <= float(np.hypot(*(b - a))) + 1e-9 else "a, b bends")
    # A segment shapely finds clear bounds the distance.
    if ref.segment_clear(a, b):
        assert d_ab is not None and d_ab <= float(np.hypot(*(b - a))) + 1e-9
    # Reachability, in the direction each reference can prove.
    if d_ab is None:
        assert not ref.surely_connected(a, b, step), f"{a} -> {b} joined by a clear lattice chain"
    else:
        assert not ref.surely_separate(a, b), f"{a} -> {b} planned across parts the reference separates"


@st.composite
def grid_floors(draw):
    h = draw(st.integers(6, 14))
    w = draw(st.integers(6, 14))
    res = draw(st.floats(0.05, 1.0))
    ratio = draw(st.floats(0.05, 3.0))
    radius = min(ratio, 0.3 * min(h, w)) * res
    blocked = np.zeros((h, w), bool)
    for r, c in draw(st.lists(st.tuples(st.integers(0, h - 1), st.integers(0, w - 1)), max_size=20)):
        blocked[r, c] = True
    walls = st.tuples(st.integers(0, h - 1), st.integers(0, w - 1), st.booleans(), st.integers(2, 5))
    for r, c, horizontal, n in draw(st.lists(walls, max_size=4)):
        if horizontal:
            blocked[r, c:c + n] = True
        else:
            blocked[r:r + n, c] = True
    # Maybe a wall across the whole floor with a door of 0-3 cells (0: two closed halves).
    if draw(st.booleans()):
        horizontal = draw(st.booleans())
        at = draw(st.integers(2, (h if horizontal else w) - 3))
        span = w if horizontal else h
        door = draw(st.integers(0, 3))
        start = draw(st.integers(0, span - door))
        line = np.ones(span, bool)
        line[start:start + door] = False
        if horizontal:
            blocked[at, :] = line
        else:
            blocked[:, at] = line
    return TraversableMap(~blocked, res), radius


unit_points = st.lists(st.tuples(st.floats(0, 1), st.floats(0, 1)), min_size=16, max_size=16)


@settings(suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(grid_floors(), unit_points)
def test_grid_floors(floor, points):
    tmap, radius = floor
    ref = Reference(tmap, radius)
    planner = planner_for(tmap, radius)
    step = tmap.resolution / FILL_PER_CELL
    check_floor(ref, planner, points, step)


@st.composite
def thin_wall_floors(draw):
    res = draw(st.floats(0.05, 0.5))
    cells = draw(st.integers(8, 14))
    size = cells * res
    ratio = draw(st.floats(0.05, 2.0))
    radius = ratio * res
    # A wall thinner than a cell, rotated about a point off the lattice, with its ends loose.
    thick = draw(st.floats(0.05, 0.9)) * res
    length = draw(st.floats(0.3, 0.8)) * size
    cx = draw(st.floats(0.3, 0.7)) * size
    cy = draw(st.floats(0.3, 0.7)) * size
    angle = draw(st.floats(0, 180))
    wall = rotate(box(cx - length / 2, cy - thick / 2, cx + length / 2, cy + thick / 2), angle, origin=(cx, cy))
    outline = box(0, 0, size, size)
    wall = wall.intersection(outline)
    assume(wall.geom_type == "Polygon" and not wall.is_empty)
    scene = Scene.from_polygons(outline, [wall], resolution=res)
    return scene.floors[0], radius, wall


@settings(suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(thin_wall_floors(), unit_points)
def test_thin_rotated_polygon_walls(floor, points):
    tmap, radius, wall = floor
    ref = Reference(tmap, radius, polygons=[wall])
    planner = planner_for(tmap, radius)
    step = tmap.resolution / FILL_PER_CELL
    check_floor(ref, planner, points, step)
