"""Accuracy of the tangent-graph planner against the exact continuous reference.

The reference (``geodesic_reference.ContinuousGeodesic``) is rebuilt here from first
principles for every floor: one shapely box per blocked cell run, the floor plan's obstacle
polygons and the map frame, grown by the robot radius with ``quad_segs = 16``, and a
bitangent visibility graph with Dijkstra. It shares no code with the planner.

Its own error: the grown corners are inscribed polygons, so the reference free space
contains the true one and lies inside the free space of radius ``r cos(pi / 64)``. The
reference is therefore never longer than the exact geodesic, and shorter by at most
``(pi / 64)**2 / 6 = 4e-4`` of the arc length the path wraps (a few 1e-5 of a whole path),
unless a passage narrower than ``2r`` but wider than ``2r cos(pi / 64)`` (0.4 mm at
r = 0.18 m) opens. The floors below have no passage in that band: grid gaps are whole
cells, and the doors are built ``>= 2r + 1 mm`` wide. End points keep ``r + 1 mm`` from the
blocked set, so the reference's inscribed corners cannot change whether they fit.

Bounds asserted per floor, over the pairs whose reference path is not one straight
segment: median relative error <= 0.3 %, 95th percentile <= 1 %, no pair shorter than the
reference by more than 0.1 %; reachability equal to the reference's; every drawn segment
at least ``r`` (1e-6 m) from the blocked set by shapely.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
import shapely
from geodesic_reference import ContinuousGeodesic, blocked_cells
from shapely.affinity import rotate
from shapely.geometry import Polygon, box

from pointnav_core import scenes
from pointnav_core.floor.maps import TraversableMap
from pointnav_core.geodesic.planner import planner_for
from pointnav_core.scenes import Scene

#: Clearance margin (m) of sampled end points beyond the robot radius.
MARGIN = 1e-3
QUAD_SEGS = 16

# A 24 x 24 MovingAI map in the style of the game benchmarks: rooms, a diagonal wall,
# trees (T) and swamp (S).
GAME_MAP = """type octile
height 24
width 24
map
........................
..@@@@@@@@....TT........
..@......@....TT...@....
..@......@.........@@...
..@..............@@@@@..
..@@@@.@@@..........@@..
...........TT...........
..........TTT.....@.....
...@.......T.....@@.....
...@@...........@@......
....@@.........@@.......
.....@@.......@@....SS..
......@@.....@@.....SS..
.......@@...............
........@@..@@@@@@@@@...
.........@..@.......@...
............@..@@@..@...
..TT........@..@.@..@...
..TT........@..@....@...
............@@@@.@@@@...
....@@@@@...............
....@...@.......TTT.....
....@...........TTT.....
........................
"""


@dataclass
class Floor:
    """A planner's floor and the independent description of its blocked set."""

    tmap: TraversableMap
    radius: float
    polygons: tuple[Polygon, ...] = ()

    def __post_init__(self) -> None:
        t = self.tmap
        h, w = t.shape
        ox, oy = t.origin
        self.frame = box(ox, oy, ox + w * t.resolution, oy + h * t.resolution)
        self.obstacles = blocked_cells(np.asarray(t.codes) != 0, t.resolution, t.origin) + list(self.polygons)
        # The blocked set as one geometry: obstacles plus the frame's ring (off the map).
        self.blocked = shapely.union_all(self.obstacles + [self.frame.exterior])
        shapely.prepare(self.blocked)
        self.reference = ContinuousGeodesic(self.frame, self.obstacles, self.radius, quad_segs=QUAD_SEGS)
        self.planner = planner_for(t, self.radius)

    def clearance(self, points: np.ndarray) -> np.ndarray:
        return shapely.distance(self.blocked, shapely.points(points))

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """``n`` points at least ``r + MARGIN`` from the blocked set, inside the frame."""
        x0, y0, x1, y1 = self.frame.bounds
        out = []
        while sum(map(len, out)) < n:
            p = rng.uniform((x0, y0), (x1, y1), (4 * n, 2))
            ok = self.clearance(p) >= self.radius + MARGIN
            ok &= shapely.contains_xy(self.frame, p[:, 0], p[:, 1])
            out.append(p[ok])
        return np.vstack(out)[:n]

    def sample_near_walls(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """``n`` points whose clearance is within a few tenths of a millimetre of ``r + MARGIN``."""
        offset = shapely.union_all(self.obstacles).buffer(self.radius + MARGIN, quad_segs=64)
        ring = shapely.intersection(offset.boundary, self.frame.buffer(-(self.radius + MARGIN)))
        total = ring.length
        out = []
        while sum(map(len, out)) < n:
            p = shapely.get_coordinates(shapely.line_interpolate_point(ring, rng.uniform(0, total, 4 * n)))
            c = self.clearance(p)
            # Chords of the offset curve sit at most r (1 - cos(pi / 256)) inside it.
            ok = (c >= self.radius + MARGIN / 2) & (c <= self.radius + 2 * MARGIN)
            out.append(p[ok])
        return np.vstack(out)[:n]


def check_pairs(floor: Floor, pairs: list[tuple[np.ndarray, np.ndarray]], min_curved: int) -> dict[str, float]:
    """Plan every pair, check it against the reference, and return the error statistics."""
    r = floor.radius
    errors = []
    for a, b in pairs:
        want = floor.reference.distance(a, b)
        path, got = floor.planner.shortest_path(a, b)
        if not math.isfinite(want):
            assert path is None, f"reachable only for the planner: {a.tolist()} -> {b.tolist()}"
            continue
        assert path is not None, f"reference reaches {a.tolist()} -> {b.tolist()} ({want:.4f} m), planner does not"
        rel = (got - want) / want if want > 0 else 0.0
        assert rel >= -1e-3, f"{a.tolist()} -> {b.tolist()}: {got:.6f} m < reference {want:.6f} m"
        line = shapely.LineString(path)
        assert shapely.covered_by(line, floor.frame)
        gap = shapely.distance(floor.blocked, line)
        assert gap >= r - 1e-6, f"{a.tolist()} -> {b.tolist()}: path {gap:.7f} m from the blocked set, r = {r}"
        if want > np.hypot(*(b - a)) + 1e-9:
            errors.append(rel)
    errors = np.asarray(errors)
    assert len(errors) >= min_curved, f"only {len(errors)} pairs need a bend"
    stats = {
        "n": float(len(errors)),
        "median": float(np.median(errors)),
        "p95": float(np.percentile(errors, 95)),
        "min": float(errors.min()),
        "max": float(errors.max()),
    }
    assert stats["median"] <= 3e-3, stats
    assert stats["p95"] <= 1e-2, stats
    return stats


def random_pairs(floor: Floor, seed: int, n: int, near_walls: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """``n`` random pairs, of which ``near_walls`` have both ends at clearance ``r + 1 mm``."""
    rng = np.random.default_rng(seed)
    pts = floor.sample(rng, 2 * (n - near_walls))
    near = floor.sample_near_walls(rng, 2 * near_walls)
    pts = np.vstack([pts, near])
    return [(pts[2 * i], pts[2 * i + 1]) for i in range(n)]


# --------------------------------------------------------------------------- game maps
def perfect_maze(seed: int, cells: int = 10, corridor: int = 2) -> np.ndarray:
    """Blocked mask of a depth-first perfect maze: corridors ``corridor`` cells wide, walls one."""
    rng = np.random.default_rng(seed)
    step = corridor + 1
    n = cells * step + 1
    blocked = np.ones((n, n), bool)
    seen = np.zeros((cells, cells), bool)
    stack = [(0, 0)]
    seen[0, 0] = True
    while stack:
        i, j = stack[-1]
        r0, c0 = 1 + i * step, 1 + j * step
        blocked[r0:r0 + corridor, c0:c0 + corridor] = False
        nbrs = [(i + di, j + dj) for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1))
                if 0 <= i + di < cells and 0 <= j + dj < cells and not seen[i + di, j + dj]]
        if not nbrs:
            stack.pop()
            continue
        ni, nj = nbrs[rng.integers(len(nbrs))]
        seen[ni, nj] = True
        # Open the wall between the two cells.
        rr, cc = 1 + min(i, ni) * step, 1 + min(j, nj) * step
        if ni != i:
            blocked[rr + corridor - 1:rr + corridor + 2, cc:cc + corridor] = False
        else:
            blocked[rr:rr + corridor, cc + corridor - 1:cc + corridor + 2] = False
        stack.append((ni, nj))
    return blocked


def rooms_grid(seed: int, size: int = 30) -> np.ndarray:
    """Blocked mask of a grid of rooms with one- to three-cell doors and scattered pillars."""
    rng = np.random.default_rng(seed)
    blocked = np.zeros((size, size), bool)
    for k in range(0, size, 7):
        blocked[k, :] = True
        blocked[:, k] = True
    for k in range(0, size, 7):
        for lo in range(0, size - 1, 7):
            for horizontal in (True, False):
                door = lo + 1 + int(rng.integers(0, 4))
                width = int(rng.integers(1, 4))
                if horizontal:
                    blocked[k, door:door + width] = False
                else:
                    blocked[door:door + width, k] = False
    pillars = rng.random((size, size)) < 0.03
    blocked |= pillars
    return blocked


def game_floors(tmp_path) -> list[tuple[str, Scene]]:
    path = tmp_path / "game.map"
    path.write_text(GAME_MAP)
    return [
        ("movingai text map", Scene.from_movingai(path, resolution=0.5)),
        ("perfect maze", Scene.from_array(~perfect_maze(3), 0.5)),
        ("rooms grid", Scene.from_array(~rooms_grid(5), 0.5)),
    ]


@pytest.mark.parametrize("which", range(3))
def test_game_maps_at_half_a_metre_per_cell(which, tmp_path):
    name, scene = game_floors(tmp_path)[which]
    floor = Floor(scene.floors[0], 0.18)
    pairs = random_pairs(floor, seed=which, n=40, near_walls=10)
    check_pairs(floor, pairs, min_curved=25)


# --------------------------------------------------------------------------- houses
@pytest.mark.parametrize(
    "seed, resolution, radius",
    [(0, 0.1, 0.18), (1, 0.1, 0.18), (2, 0.05, 0.2), (3, 0.05, 0.2)],
)
def test_houses(seed, resolution, radius):
    scene = scenes.rooms(seed, resolution=resolution, size=(12.0, 9.0))
    tmap = scene.floors[0]
    floor = Floor(tmap, radius, tuple(scene.floor_plans[0].obstacles))
    pairs = random_pairs(floor, seed=seed, n=40, near_walls=10)
    check_pairs(floor, pairs, min_curved=20)


# --------------------------------------------------------------------------- narrow doors
def door_pairs(floor: Floor, seed: int, n: int, split) -> list[tuple[np.ndarray, np.ndarray]]:
    """``n`` pairs with one end on each side of the door wall (``split(p)`` says which side)."""
    rng = np.random.default_rng(seed)
    pts = np.vstack([floor.sample(rng, 6 * n), floor.sample_near_walls(rng, 2 * n)])
    side = split(pts)
    one, other = pts[side], pts[~side]
    k = min(len(one), len(other), n)
    assert k >= n // 2
    return [(one[i], other[i]) for i in range(k)]


@pytest.mark.parametrize("resolution", [0.05, 0.1])
@pytest.mark.parametrize("slack", ["1mm", "half cell", "one cell"])
def test_grid_doors_within_one_cell_of_the_diameter(resolution, slack):
    # A 3 x 2 m room split by a two-cell wall; the door is k cells wide and the robot's
    # diameter is the door width less the slack.
    res = resolution
    h, w = round(2.0 / res), round(3.0 / res)
    blocked = np.zeros((h, w), bool)
    row = h // 2
    blocked[row:row + 2, :] = True
    k = round(0.5 / res)
    col = round(1.1 / res)
    blocked[row:row + 2, col:col + k] = False
    door = k * res
    delta = {"1mm": 1e-3, "half cell": res / 2, "one cell": res}[slack]
    r = (door - delta) / 2
    tmap = TraversableMap(~blocked, res)
    floor = Floor(tmap, r)
    wall_y = row * res
    pairs = door_pairs(floor, seed=int(res * 100) + len(slack), n=30, split=lambda p: p[:, 1] < wall_y)
    check_pairs(floor, pairs, min_curved=15)


def _polygon_door_floor(res: float, angle: float, slack: float) -> tuple[Floor, Polygon]:
    """A 3 x 2.4 m floor split by a thin wall rotated by ``angle`` degrees about the centre,
    with a door off the cell lattice; the robot's diameter is the door's width in the
    blocked set (wall polygons and their raster cells) less ``slack``.
    """
    outline = box(0, 0, 3.0, 2.4)
    cx, cy = 1.5 + 0.37 * res, 1.2 + 0.29 * res
    t = 0.07
    x_door = 1.213
    pieces = [box(-1.0, cy - t / 2, x_door, cy + t / 2), box(x_door + 0.52, cy - t / 2, 4.0, cy + t / 2)]
    pieces = [rotate(p, angle, origin=(cx, cy)).intersection(outline) for p in pieces]
    scene = Scene.from_polygons(outline, pieces, resolution=res)
    tmap = scene.floors[0]
    codes = np.asarray(tmap.codes)
    # Each wall piece's part of the blocked set: the polygon and the cells its raster set.
    cells = blocked_cells(codes == 1, res, tmap.origin)
    cell_union = shapely.union_all(cells)
    parts = []
    for p in pieces:
        own = [c for c in getattr(cell_union, "geoms", [cell_union]) if shapely.distance(c, p) < res]
        parts.append(shapely.union_all([p, *own]))
    gap = shapely.distance(parts[0], parts[1])
    r = (gap - slack) / 2
    return Floor(tmap, r, tuple(pieces)), rotate(box(-1, cy - t / 2, 4, cy + t / 2), angle, origin=(cx, cy))


@pytest.mark.parametrize("res", [0.05, 0.1])
@pytest.mark.parametrize("angle", [0.0, 27.0])
@pytest.mark.parametrize("slack", [1e-3, "half cell"])
def test_polygon_doors_off_the_lattice(res, angle, slack):
    slack = res / 2 if slack == "half cell" else slack
    floor, wall_line = _polygon_door_floor(res, angle, slack)
    assert floor.radius > 0.1
    a = np.radians(angle)
    normal = np.array([-math.sin(a), math.cos(a)])
    c = np.asarray(wall_line.centroid.coords[0])
    pairs = door_pairs(floor, seed=int(angle) + int(res * 100), n=30, split=lambda p: (p - c) @ normal < 0)
    check_pairs(floor, pairs, min_curved=15)
