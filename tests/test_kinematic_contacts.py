"""The kinematic backend on the one collision geometry: polygons, touching walls, robots meeting.

References are independent of the backend: shapely distances to the floor plan's polygons
and to the blocked cell squares, and hand-computed positions.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
import shapely.ops
from pointnav_kinematic import KinematicBackend
from shapely import affinity
from shapely.geometry import Point

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene

R = 0.18
TOUCH = 1e-9


def quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def loaded(scene, specs, mode: str = "slide") -> KinematicBackend:
    backend = KinematicBackend(collision_mode=mode)
    backend.load(scene, specs)
    return backend


def xy(backend: KinematicBackend, idn: int = 0) -> np.ndarray:
    return backend.get_pose(idn)[0][:2]


def blocked_geometry(scene: Scene, floor: int = 0):
    """Shapely union of every non-FREE cell square, the polygons and everything off the map."""
    tmap = scene.floors[floor]
    res, (ox, oy) = tmap.resolution, tmap.origin
    rows, cols = np.nonzero(np.asarray(tmap.codes) != FREE)
    squares = shapely.box(
        ox + cols * res, oy + rows * res, ox + (cols + 1) * res, oy + (rows + 1) * res
    )
    h, w = tmap.codes.shape
    frame = shapely.box(ox - 50, oy - 50, ox + w * res + 50, oy + h * res + 50).difference(
        shapely.box(ox, oy, ox + w * res, oy + h * res)
    )
    return shapely.union_all([*squares, frame, *polygons(scene, floor)])


def obstacle_geometry(scene: Scene, floor: int = 0):
    """What a robot collides with while moving: OBSTACLE squares and the polygons."""
    tmap = scene.floors[floor]
    res, (ox, oy) = tmap.resolution, tmap.origin
    rows, cols = np.nonzero(np.asarray(tmap.codes) == OBSTACLE)
    squares = shapely.box(
        ox + cols * res, oy + rows * res, ox + (cols + 1) * res, oy + (rows + 1) * res
    )
    return shapely.union_all([*squares, *polygons(scene, floor)])


def polygons(scene: Scene, floor: int = 0) -> tuple:
    plans = scene.floor_plans
    return () if plans is None or plans[floor] is None else tuple(plans[floor].obstacles)


# ----------------------------------------------------------------------- polygon walls


@pytest.mark.parametrize("mode", ["slide", "stop"])
def test_a_polygon_wall_thinner_than_a_cell_stops_the_robot(mode):
    thin = shapely.box(2.99, 0.0, 3.02, 3.0)
    scene = Scene.from_polygons(shapely.box(0, 0, 6, 3), [thin], resolution=0.1)
    assert not (scene.floors[0].codes == OBSTACLE).any()  # the raster alone has no wall
    backend = loaded(scene, [RobotSpec(radius=R)], mode)
    backend.land(0, 0, (2.0, 1.5), quat(0.0))
    flags = []
    for _ in range(30):
        backend.step({0: [1.0, 0.0]})
        flags.append(backend.in_contact(0))
        assert Point(*xy(backend)).distance(thin) >= R - TOUCH
    assert xy(backend)[0] == pytest.approx(2.99 - R, abs=1e-8)
    assert flags[:16] == [False] * 16 and all(flags[17:])


def rotated_wall(angle: float, centre=(3.0, 3.0)):
    """A 4 m long, 2 cm thick wall through ``centre`` along direction ``angle``."""
    wall = shapely.box(centre[0] - 2.0, centre[1] - 0.01, centre[0] + 2.0, centre[1] + 0.01)
    return affinity.rotate(wall, angle, origin=centre, use_radians=True)


def wall_scene(wall) -> Scene:
    """A 6 m square room holding only ``wall``, on cells too coarse to raster it.

    Cell centres are 0.5 m apart, none within the 2 cm wall, so its sides are exactly the
    polygon's and not a staircase of cell squares.
    """
    scene = Scene.from_polygons(shapely.box(0, 0, 6, 6), [wall], resolution=0.5)
    assert not (scene.floors[0].codes == OBSTACLE).any()
    return scene


@pytest.mark.parametrize("angle", [0.0, 0.3, 1.0, math.pi / 2, 2.2, -0.7])
def test_sliding_along_a_polygon_edge_at_any_angle_keeps_the_tangential_motion(angle):
    wall = rotated_wall(angle)
    scene = wall_scene(wall)
    backend = loaded(scene, [RobotSpec(radius=R)])
    along = np.array([math.cos(angle), math.sin(angle)])
    normal = np.array([-along[1], along[0]])  # the wall's left side
    start = np.array([3.0, 3.0]) + (0.01 + R + 0.02) * normal - 0.5 * along
    heading = along - normal  # 45 degrees into the wall
    yaw = math.atan2(heading[1], heading[0])
    backend.land(0, 0, start, quat(yaw))
    step = 0.05  # 0.5 m/s for 0.1 s
    for k in range(12):
        before = xy(backend)
        backend.step({0: [1.0, 0.0]})
        after = xy(backend)
        clearance = Point(*after).distance(wall)
        assert clearance >= R - TOUCH
        if k >= 1:  # 2 cm from contact, 3.5 cm of approach per step: touching from step 1
            assert backend.in_contact(0)
            assert clearance == pytest.approx(R, abs=1e-8)
        if k >= 2:  # a full step against the wall: only the part along it survives
            moved = after - before
            assert moved @ along == pytest.approx(step * math.sqrt(0.5), abs=1e-9)
            assert moved @ normal == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("angle", [0.0, 0.3, 1.0, 2.2])
def test_stop_mode_stays_where_a_polygon_edge_is_met(angle):
    wall = rotated_wall(angle)
    scene = wall_scene(wall)
    backend = loaded(scene, [RobotSpec(radius=R)], mode="stop")
    along = np.array([math.cos(angle), math.sin(angle)])
    normal = np.array([-along[1], along[0]])
    start = np.array([3.0, 3.0]) + (0.01 + R + 0.1) * normal
    backend.land(0, 0, start, quat(math.atan2(-normal[1], -normal[0])))  # facing the wall
    for _ in range(3):
        backend.step({0: [1.0, 0.0]})
    met = xy(backend)
    assert backend.in_contact(0)
    assert Point(*met).distance(wall) == pytest.approx(R, abs=1e-8)
    backend.step({0: [1.0, 0.0]})
    assert backend.in_contact(0) and xy(backend).tolist() == met.tolist()


@pytest.mark.parametrize("radius", [0.0, 0.05])
@pytest.mark.parametrize("mode", ["slide", "stop"])
def test_no_tunnelling_through_a_thin_polygon_at_any_speed(radius, mode):
    # 1 cm thick, tilted by 0.2 rad, and met head on: sliding has nowhere to go.
    thin = shapely.box(2.99, -1.0, 3.0, 4.0)
    thin = affinity.rotate(thin, 0.2, origin=(3.0, 1.5), use_radians=True)
    scene = Scene.from_polygons(shapely.box(0, 0, 6, 3), [thin], resolution=0.1)
    spec = RobotSpec(radius=radius, max_linear_velocity=500.0)
    backend = loaded(scene, [spec], mode)
    start = np.array([3.0, 1.5]) - 2.0 * np.array([math.cos(0.2), math.sin(0.2)])
    backend.land(0, 0, start, quat(0.2))
    backend.step({0: [1.0, 0.0]})  # 50 m in one step
    x, y = xy(backend)
    assert backend.in_contact(0)
    assert Point(x, y).distance(thin) >= radius - TOUCH
    assert Point(x, y).distance(thin) == pytest.approx(radius, abs=1e-8)
    assert (x - 3.0) * math.cos(0.2) + (y - 1.5) * math.sin(0.2) < 0.0  # still on its side


def test_a_concave_polygon_corner_holds_a_robot_pushed_into_it():
    vee = shapely.Polygon([(2.0, 1.0), (4.0, 1.0), (4.0, 5.0), (3.0, 1.6), (2.0, 5.0)])
    scene = Scene.from_polygons(shapely.box(0, 0, 6, 6), [vee], resolution=0.1)
    backend = loaded(scene, [RobotSpec(radius=R)])
    backend.land(0, 0, (3.0, 4.0), quat(-math.pi / 2))  # inside the notch, facing its tip
    for _ in range(60):
        backend.step({0: [1.0, 0.0]})
        assert Point(*xy(backend)).distance(vee) >= R - TOUCH
    final = xy(backend)
    backend.step({0: [1.0, 0.0]})
    assert backend.in_contact(0)
    np.testing.assert_allclose(xy(backend), final, atol=1e-9)
    assert abs(final[0] - 3.0) < 1e-6  # held on the notch's axis of symmetry


# ----------------------------------------------------------------------- touching walls


def room(size: int = 60, res: float = 0.1) -> Scene:
    grid = np.full((size, size), FREE, np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, res)


@pytest.mark.parametrize(
    ("start", "yaw", "action"),
    [
        ((5.9 - R, 1.0), math.pi / 2, [1.0, 0.0]),  # along the right wall, differential
        ((0.1 + R, 5.0), -math.pi / 2, [1.0, 0.0]),  # along the left wall
        ((1.0, 5.9 - R), 0.0, [1.0, 0.0]),  # along the top wall
        ((1.0, 0.1 + R), math.pi, [-1.0, 0.0]),  # along the bottom wall, reversing
    ],
)
@pytest.mark.parametrize("mode", ["slide", "stop"])
def test_driving_parallel_along_a_touched_wall_is_never_a_collision(start, yaw, action, mode):
    backend = loaded(room(), [RobotSpec(radius=R)], mode)
    backend.land(0, 0, start, quat(yaw))
    for _ in range(50):
        before = xy(backend)
        backend.step({0: action})
        assert not backend.in_contact(0)
        assert np.linalg.norm(xy(backend) - before) == pytest.approx(0.05, abs=1e-12)


def test_holonomic_sideways_along_a_touched_wall_is_never_a_collision():
    backend = loaded(room(), [RobotSpec(radius=R, drive="holonomic")])
    backend.land(0, 0, (5.9 - R, 1.0), quat(0.0))  # facing the wall, moving to its left
    for _ in range(50):
        backend.step({0: [0.0, 1.0, 0.0]})
        assert not backend.in_contact(0)
    assert xy(backend) == pytest.approx([5.9 - R, 3.5], abs=1e-9)


def test_driving_parallel_along_a_touched_polygon_edge_is_never_a_collision():
    angle = 0.45
    wall = rotated_wall(angle)
    scene = wall_scene(wall)
    backend = loaded(scene, [RobotSpec(radius=R)])
    along = np.array([math.cos(angle), math.sin(angle)])
    normal = np.array([-along[1], along[0]])
    backend.land(0, 0, np.array([3.0, 3.0]) + (0.01 + R) * normal - 1.5 * along, quat(angle))
    for _ in range(50):
        backend.step({0: [1.0, 0.0]})
        assert not backend.in_contact(0)
        assert Point(*xy(backend)).distance(wall) >= R - TOUCH
    assert (xy(backend) - [3.0, 3.0]) @ along == pytest.approx(1.0, abs=1e-9)


def test_a_robot_exactly_as_wide_as_a_passage_slides_into_it_past_the_far_corner():
    # Blocks at x 0.6-0.8, y 0.5-0.7 and x 0.7-0.9, y 1.0-1.2 leave a passage (x 0.7-0.8)
    # exactly 0.3 m wide. A 0.15 m robot touching the lower block, drifting up by 1e-9 m a
    # step as float32 actions do, meets the upper block's corner: its own slide would take
    # it into the lower block, and it used to stop there for good. The slide along the
    # lower block it touches is clear.
    grid = np.zeros((16, 19), dtype=np.uint8)
    grid[5:7, 6:8] = OBSTACLE
    grid[10:12, 7:9] = OBSTACLE
    scene = Scene.from_array(grid, 0.1)
    backend = loaded(scene, [RobotSpec(radius=0.15, drive="holonomic")])
    backend.land(0, 0, (0.69998013, 0.85 + 3e-10), quat(0.0))
    blocks = shapely.union_all([shapely.box(0.6, 0.5, 0.8, 0.7), shapely.box(0.7, 1.0, 0.9, 1.2)])
    for _ in range(2):
        backend.step({0: [1.0, 2e-8, 0.0]})
        assert Point(*xy(backend)).distance(blocks) >= 0.15 - 2 * TOUCH
    assert xy(backend)[0] > 0.79


@pytest.mark.parametrize("scene_kind", ["grid", "polygon"])
def test_pushing_diagonally_into_a_wall_is_a_collision_on_every_blocked_step(scene_kind):
    if scene_kind == "grid":
        scene = room()
        wall = obstacle_geometry(scene)
    else:
        wall = rotated_wall(math.pi / 2, centre=(5.0, 3.0))  # x in [4.99, 5.01]
        scene = wall_scene(wall)
    backend = loaded(scene, [RobotSpec(radius=R)])
    face = 5.9 if scene_kind == "grid" else 4.99
    backend.land(0, 0, (face - R, 2.0), quat(math.pi / 4))  # touching, heading into it
    for _ in range(30):
        backend.step({0: [1.0, 0.0]})
        assert backend.in_contact(0)
        assert Point(*xy(backend)).distance(wall) >= R - TOUCH
    assert xy(backend)[1] == pytest.approx(2.0 + 30 * 0.05 * math.sqrt(0.5), abs=1e-9)


# ----------------------------------------------------------------------- robots meeting


@pytest.mark.parametrize("first", [0, 1])
def test_robots_driven_head_on_meet_in_the_middle_whatever_their_order(first):
    backend = loaded(room(), [RobotSpec(radius=R), RobotSpec(radius=R)])
    left, right = first, 1 - first
    backend.land(left, 0, (2.0, 3.0), quat(0.0))
    backend.land(right, 0, (4.0, 3.0), quat(math.pi))
    for _ in range(25):
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
        a, b = xy(backend, left), xy(backend, right)
        assert (a[0] - 3.0) == pytest.approx(-(b[0] - 3.0), abs=1e-9)  # symmetric
        assert b[0] - a[0] >= 2 * R - TOUCH
    assert backend.in_contact(0) and backend.in_contact(1)
    assert a[0] == pytest.approx(3.0 - R, abs=1e-8)
    assert b[0] == pytest.approx(3.0 + R, abs=1e-8)


@pytest.mark.parametrize("first", [0, 1])
def test_a_half_speed_robot_covers_a_third_of_the_gap(first):
    backend = loaded(room(), [RobotSpec(radius=R), RobotSpec(radius=R)])
    fast, slow = first, 1 - first
    backend.land(fast, 0, (2.0, 3.0), quat(0.0))
    backend.land(slow, 0, (4.0, 3.0), quat(math.pi))
    for _ in range(40):
        backend.step({fast: [1.0, 0.0], slow: [0.5, 0.0]})
    a, b = xy(backend, fast)[0], xy(backend, slow)[0]
    assert backend.in_contact(0) and backend.in_contact(1)
    assert b - a == pytest.approx(2 * R, abs=1e-8)
    gap = 2.0 - 2 * R
    assert a - 2.0 == pytest.approx(gap * 2 / 3, abs=1e-8)
    assert 4.0 - b == pytest.approx(gap / 3, abs=1e-8)
    assert (a - 2.0) == pytest.approx(2 * (4.0 - b), abs=1e-8)


@pytest.mark.parametrize("leader", [0, 1])
def test_a_robot_following_another_at_its_speed_is_not_blocked_by_where_it_was(leader):
    # 3 cm apart and both driving 5 cm the same way: the gap never closes, whichever robot
    # is processed first.
    backend = loaded(room(), [RobotSpec(radius=R), RobotSpec(radius=R)])
    follower = 1 - leader
    backend.land(follower, 0, (2.0, 3.0), quat(0.0))
    backend.land(leader, 0, (2.0 + 2 * R + 0.03, 3.0), quat(0.0))
    for k in range(1, 6):
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
        assert xy(backend, follower).tolist() == pytest.approx([2.0 + 0.05 * k, 3.0], abs=1e-12)
        assert not backend.in_contact(0) and not backend.in_contact(1)


# ----------------------------------------------------------------------- valid poses


def test_is_valid_pose_is_the_disc_missing_blocked_cells_void_off_map_and_polygons():
    outline = shapely.Polygon([(0, 0), (6, 0), (6, 4), (3, 4), (3, 6), (0, 6)])
    walls = [rotated_wall(0.5, centre=(2.0, 2.0)), shapely.box(4.0, 1.0, 4.015, 3.0)]
    scene = Scene.from_polygons(outline, walls, resolution=0.1)
    blocked = blocked_geometry(scene)
    backend = loaded(scene, [RobotSpec(radius=R)])
    rng = np.random.default_rng(5)
    points = rng.uniform((-0.3, -0.3), (6.3, 6.3), size=(3000, 2))
    decided = 0
    for p in points:
        clearance = Point(*p).distance(blocked)
        if abs(clearance - R) < 1e-6:
            continue  # too close to call without the 1e-9 tolerance
        assert backend.is_valid_pose(0, p) == (clearance >= R), p
        decided += 1
    assert decided > 2900
    # The thin wall covers no cell centre, yet a disc across it is refused.
    assert not backend.is_valid_pose(0, (4.0075, 2.0))
    assert backend.is_valid_pose(0, (4.0 - R, 2.0))  # touching it


def test_is_valid_pose_also_refuses_overlap_with_present_robots_on_a_polygon_floor():
    scene = Scene.from_polygons(shapely.box(0, 0, 6, 6), [rotated_wall(0.3)], resolution=0.1)
    backend = loaded(scene, [RobotSpec(radius=R), RobotSpec(radius=0.1)])
    backend.land(1, 0, (1.0, 1.0), quat(0.0))
    assert not backend.is_valid_pose(0, (1.2, 1.0))
    assert backend.is_valid_pose(0, (1.0 + R + 0.1, 1.0))
    backend.set_present(1, False)
    assert backend.is_valid_pose(0, (1.2, 1.0))


# ----------------------------------------------------------------------- capsule geometry


def test_capsule_entry_and_segment_distance_agree_with_shapely():
    from pointnav_kinematic.geometry import enter_capsule, segment_distance

    rng = np.random.default_rng(11)
    entered = 0
    for _ in range(400):
        a, b, p = rng.uniform(-2, 2, size=(3, 2))
        d = rng.normal(size=2)
        radius = rng.uniform(0.0, 0.8)
        length = float(np.hypot(*(b - a)))
        u = (b - a) / length
        seg = (*a, *b, *u, length)
        line = shapely.LineString([a, b])
        dist, nx, ny = segment_distance(*p, seg)
        assert dist == pytest.approx(Point(*p).distance(line), abs=1e-12)
        nearest = np.array(shapely.ops.nearest_points(line, Point(*p))[0].coords[0])
        if dist > 1e-9:
            np.testing.assert_allclose([nx, ny], (p - nearest) / dist, atol=1e-9)
        t = enter_capsule(*p, *d, seg, radius)
        inside = Point(*p).distance(line) < radius
        if inside:
            assert t == 0.0
            continue
        # Before t the disc is clear; at t it touches (where t is finite).
        for s in np.linspace(0.0, min(t, 10.0), 50)[:-1]:
            assert Point(*(p + s * d)).distance(line) >= radius - 1e-9
        if math.isfinite(t):
            entered += 1
            assert Point(*(p + t * d)).distance(line) == pytest.approx(radius, abs=1e-9)
    assert entered > 50
