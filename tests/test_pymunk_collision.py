"""The pymunk backend on the floor's one collision geometry.

Robots collide with every OBSTACLE cell square and every obstacle polygon of the floor
plan, and ``is_valid_pose`` accepts a disc exactly where it misses the blocked set (every
non-FREE cell square, everything off the map, the polygons). Each test builds its own
reference from shapely boxes and polygons, not from the library's predicates.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
import shapely.ops
from hypothesis import assume, given
from hypothesis import strategies as st
from pointnav_pymunk import TOUCH_TOLERANCE, PymunkBackend
from shapely.geometry import Point, box

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.scenes import Scene

IDENTITY = (0.0, 0.0, 0.0, 1.0)
R = 0.18  # the default robot's radius, m


def loaded(scene: Scene, specs: list[RobotSpec]) -> PymunkBackend:
    backend = PymunkBackend()
    backend.load(scene, specs, action_frequency=10.0)
    return backend


def cell_squares(tmap: TraversableMap, codes: tuple[int, ...]) -> list:
    """The world squares of the cells whose code is in ``codes``."""
    (ox, oy), res = tmap.origin, tmap.resolution
    rows, cols = np.nonzero(np.isin(tmap.codes, codes))
    return [
        box(ox + c * res, oy + r * res, ox + (c + 1) * res, oy + (r + 1) * res)
        for r, c in zip(rows.tolist(), cols.tolist())
    ]


def reference_blocked(tmap: TraversableMap, polygons=()) -> shapely.Geometry:
    """Standing is blocked by non-FREE squares, the polygons and everything off the map."""
    x0, x1, y0, y1 = tmap.extent
    off_map = box(x0 - 100, y0 - 100, x1 + 100, y1 + 100).difference(box(x0, y0, x1, y1))
    return shapely.union_all([*cell_squares(tmap, (OBSTACLE, VOID)), *polygons, off_map])


def edited(tmap: TraversableMap, cells: dict[tuple[int, int], int]) -> Scene:
    """A copy of a one-floor scene with some cells set by hand, keeping its floor plan."""
    codes = np.array(tmap.codes)
    for (row, col), code in cells.items():
        codes[row, col] = code
    new = TraversableMap(codes, tmap.resolution, tmap.origin, geometry=tmap.geometry)
    return Scene([new])


THIN_WALL = box(2.99, 0.0, 3.02, 3.0)


def thin_wall_scene() -> Scene:
    return Scene.from_polygons(box(0.0, 0.0, 6.0, 3.0), [THIN_WALL], resolution=0.1)


# ----------------------------------------------------------------------- is_valid_pose


def test_a_wall_thinner_than_a_cell_decides_validity_by_its_true_clearance():
    scene = thin_wall_scene()
    assert not (scene.floors[0].codes == OBSTACLE).any()  # no cell centre under it
    backend = loaded(scene, [RobotSpec()])
    for x, clearance in [(2.80, 0.19), (2.82, 0.17), (3.21, 0.19), (3.19, 0.17)]:
        assert THIN_WALL.distance(Point(x, 1.5)) == pytest.approx(clearance)
        assert backend.is_valid_pose(0, (x, 1.5)) is (clearance >= R), (x, clearance)


def test_an_obstacle_cell_with_no_polygon_under_it_makes_a_pose_invalid():
    plain = thin_wall_scene()
    # Cell (15, 40) covers x in [4.0, 4.1], y in [1.5, 1.6]: drawn by hand, no polygon.
    scene = edited(plain.floors[0], {(15, 40): OBSTACLE})
    square = box(4.0, 1.5, 4.1, 1.6)
    p = (3.85, 1.55)  # 0.15 m from the square: its disc overlaps only that square
    assert square.distance(Point(p)) == pytest.approx(0.15)
    assert THIN_WALL.distance(Point(p)) > 0.5
    assert loaded(plain, [RobotSpec()]).is_valid_pose(0, p)
    assert not loaded(scene, [RobotSpec()]).is_valid_pose(0, p)


def test_a_disc_overhanging_void_is_not_a_valid_pose():
    grid = np.zeros((10, 10), np.uint8)
    grid[:, 7:] = VOID  # x >= 0.7
    backend = loaded(Scene.from_array(grid, 0.1), [RobotSpec(radius=0.05)])
    assert backend.is_valid_pose(0, (0.64, 0.5))  # 0.06 m from the drop
    assert not backend.is_valid_pose(0, (0.66, 0.5))  # the centre is on the floor
    assert not backend.is_valid_pose(0, (0.95, 0.5))


def mixed_scene() -> tuple[Scene, list]:
    """An L-shaped outline (VOID outside), a thin wall, a round pillar, hand-drawn cells."""
    outline = box(0.0, 0.0, 6.0, 4.0).difference(box(4.0, 2.5, 6.0, 4.0))
    pillar = Point(1.5, 2.5).buffer(0.4, quad_segs=16)
    wall = box(2.99, 0.5, 3.02, 3.5)
    base = Scene.from_polygons(outline, [wall, pillar], resolution=0.1).floors[0]
    scene = edited(base, {(10, 50): OBSTACLE, (11, 50): OBSTACLE, (30, 10): VOID})
    return scene, [wall, pillar]


MIXED, MIXED_POLYGONS = mixed_scene()
MIXED_BLOCKED = reference_blocked(MIXED.floors[0], MIXED_POLYGONS)


@given(
    x=st.floats(-0.5, 6.5),
    y=st.floats(-0.5, 4.5),
    radius=st.sampled_from([0.0, 0.05, R, 0.3]),
)
def test_is_valid_pose_agrees_with_a_shapely_reference(x, y, radius):
    p = Point(x, y)
    distance = 0.0 if MIXED_BLOCKED.contains(p) else MIXED_BLOCKED.distance(p)
    assume(abs(distance - radius) > 1e-7)  # not on the fence, where rounding decides
    backend = loaded(MIXED, [RobotSpec(radius=radius)])
    assert backend.is_valid_pose(0, (x, y)) is (distance > radius)


@pytest.mark.parametrize("radius", [0.0, R])
def test_is_valid_pose_agrees_with_a_shapely_reference_over_a_sweep(radius):
    # Brute force over a lattice that is not aligned with the cells, plus points just in
    # and just out of reach of the blocked set along random directions.
    xs, ys = np.meshgrid(np.arange(-0.213, 6.3, 0.0931), np.arange(-0.177, 4.3, 0.0931))
    points = np.column_stack([xs.ravel(), ys.ravel()])
    rng = np.random.default_rng(7)
    near = []
    for p in points[rng.choice(len(points), 300, replace=False)]:
        q = shapely.ops.nearest_points(MIXED_BLOCKED, Point(p))[0]
        d = np.subtract(p, (q.x, q.y))
        if np.hypot(*d) > 1e-9:
            u = d / np.hypot(*d)
            near += [(q.x, q.y) + u * (radius + 1e-6), (q.x, q.y) + u * (radius - 1e-6)]
    points = np.vstack([points, near])
    distance = shapely.distance(MIXED_BLOCKED, shapely.points(points))
    want = (distance > radius + 1e-7).tolist()
    keep = np.abs(distance - radius) > 1e-7
    backend = loaded(MIXED, [RobotSpec(radius=radius)])
    got = [backend.is_valid_pose(0, p) for p in points]
    wrong = [tuple(p) for p, g, w, k in zip(points, got, want, keep) if k and g != w]
    assert wrong == []
    assert 0.2 < np.mean(want) < 0.9  # both answers are well represented


def test_the_shapely_reference_sees_the_hand_drawn_cells_and_the_void():
    # The property above is only as good as its reference: it must hold both edits.
    for p in [(5.05, 1.05), (5.05, 1.15), (1.05, 3.05)]:
        assert MIXED_BLOCKED.contains(Point(p))
    assert not MIXED_BLOCKED.contains(Point(5.05, 1.25))


def test_other_robots_still_block_and_absent_ones_do_not():
    backend = loaded(thin_wall_scene(), [RobotSpec(), RobotSpec()])
    backend.land(1, 0, (1.5, 1.5), IDENTITY)
    assert not backend.is_valid_pose(0, (1.8, 1.5))  # 0.3 m apart, radii sum 0.36 m
    assert backend.is_valid_pose(0, (1.87, 1.5))
    backend.set_present(1, False)
    assert backend.is_valid_pose(0, (1.8, 1.5))


# ----------------------------------------------------------------------- motion


@pytest.mark.parametrize("speed", [0.5, 5.0])
def test_a_robot_driven_into_a_thin_wall_stops_clear_of_it(speed):
    spec = RobotSpec(max_linear_velocity=speed)
    backend = loaded(thin_wall_scene(), [spec])
    backend.land(0, 0, (1.5, 1.3), IDENTITY)
    hits = []
    for _ in range(int(math.ceil(2.0 / (speed * 0.1))) + 3):  # long enough to reach it
        backend.step({0: [1.0, 0.0]})
        hits.append(backend.in_contact(0))
    x, y, _ = backend.get_pose(0)[0]
    clearance = THIN_WALL.distance(Point(x, y))
    assert x < 2.99  # still on the near side
    assert clearance >= R - 1e-3  # the backend's stated bound
    assert R <= clearance <= R + 2 * TOUCH_TOLERANCE  # in practice: touching, not into it
    assert hits[-1] and not hits[0]
    assert backend.is_valid_pose(0, (x, y))


def test_a_hand_drawn_obstacle_cell_under_a_plan_stops_a_robot():
    scene = edited(thin_wall_scene().floors[0], {(15, 40): OBSTACLE})
    square = box(4.0, 1.5, 4.1, 1.6)
    backend = loaded(scene, [RobotSpec()])
    backend.land(0, 0, (3.5, 1.55), IDENTITY)
    for _ in range(10):
        backend.step({0: [1.0, 0.0]})
    x, y, _ = backend.get_pose(0)[0]
    assert R <= square.distance(Point(x, y)) <= R + 2 * TOUCH_TOLERANCE
    assert backend.in_contact(0)


MOVINGAI = """type octile
height 4
width 8
map
........
...@@...
...@@...
........
"""


def test_a_robot_on_a_movingai_map_collides_with_its_cells_and_its_frame(tmp_path):
    path = tmp_path / "tiny.map"
    path.write_text(MOVINGAI)
    scene = Scene.from_movingai(path, resolution=0.5)
    assert set(np.unique(scene.floors[0].codes).tolist()) == {FREE, OBSTACLE}
    block = box(1.5, 0.5, 2.5, 1.5)  # characters (1..2, 3..4) at 0.5 m each
    inside = box(0.0, 0.0, 4.0, 2.0)  # the map; outside it is a wall, not a drop
    backend = loaded(scene, [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (0.5, 1.0), IDENTITY)  # drives +x into the block
    backend.land(1, 0, (3.5, 1.0), IDENTITY)  # drives +x into the map's edge
    for _ in range(25):  # 1.25 m at 0.5 m/s: far enough for both
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
    (x0, y0, _), (x1, y1, z1) = backend.get_pose(0)[0], backend.get_pose(1)[0]
    assert R <= block.distance(Point(x0, y0)) <= R + 2 * TOUCH_TOLERANCE
    assert R <= inside.exterior.distance(Point(x1, y1)) <= R + 2 * TOUCH_TOLERANCE
    assert inside.contains(Point(x1, y1)) and z1 == 0.0  # did not fall off
    assert backend.in_contact(0) and backend.in_contact(1)


def test_a_step_that_ends_square_over_a_corner_it_ran_into_is_a_contact():
    # A holonomic robot (r = 0.0546875 m) drives +x at 0.375 m/s along y = 0.55, 5 cm above
    # the top face (y = 0.5) of a block whose left edge is x = 0.4: the disc reaches the
    # block's corner at x = 0.4 - sqrt(r^2 - 0.05^2), and its fourth step ends with the
    # centre exactly above the corner, where the contact normal is square to the motion.
    grid = np.full((16, 16), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    grid[3:5, 4:6] = OBSTACLE
    scene = Scene.from_array(grid, 0.1)
    radius = 0.0546875
    backend = loaded(scene, [RobotSpec(radius=radius, drive="holonomic")])
    backend.land(0, 0, (0.25, 0.55, 0.0), IDENTITY)
    block = box(0.4, 0.3, 0.6, 0.5)
    flagged = []
    for _ in range(4):
        start = backend.get_pose(0)[0][:2].copy()
        backend.step({0: np.array([0.75, 0.0, 0.0])})
        end = backend.get_pose(0)[0][:2]
        # The reference: the straight drive of this step comes within r of the block.
        ran_into = shapely.LineString([start, (end[0], start[1])]).distance(block) < radius - 1e-9
        flagged.append((backend.in_contact(0), ran_into))
    assert flagged[:3] == [(False, False)] * 3
    assert flagged[3] == (True, True)
