"""The pymunk backend: static geometry, motion, contacts, tolerances and determinism.

The behaviour every backend shares is checked by the conformance kit (test_conformance);
this file checks what is particular to pymunk: how the world is built from a scene, the
motor controller, the stated overlap tolerance, sub-stepping and rebuilding on reset.
"""

from __future__ import annotations

import math
import subprocess
import sys
import types

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from pointnav_kinematic import KinematicBackend
from pointnav_pymunk import OVERLAP_TOLERANCE, TOUCH_TOLERANCE, PymunkBackend
from pointnav_pymunk.geometry import convex_pieces, floor_pieces, merge_cells
from pointnav_pymunk.velocity import closest_feasible
from shapely.geometry import Point, Polygon, box

from pointnav_core import floorplans, scenes
from pointnav_core.backends.protocol import get_backend, make_backend
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.floor.maps import OBSTACLE, VOID, TraversableMap
from pointnav_core.scenes import Scene
from pointnav_core.testing import strategies

IDENTITY = (0.0, 0.0, 0.0, 1.0)


def quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def room(size: int = 60, res: float = 0.1) -> Scene:
    grid = np.zeros((size, size), np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, res)


def loaded(scene, specs, freq: float = 10.0, **kwargs) -> PymunkBackend:
    backend = PymunkBackend(**kwargs)
    backend.load(scene, list(specs), action_frequency=freq)
    return backend


def position(backend, idn: int = 0) -> np.ndarray:
    return backend.get_pose(idn)[0]


def static_shapes(backend: PymunkBackend, floor: int = 0) -> list:
    space = backend._floors[floor].space
    return [s for s in space.shapes if s.body.body_type == s.body.STATIC]


# ----------------------------------------------------------------------- geometry


@given(strategies.code_grids(max_side=16))
def test_merged_rectangles_cover_exactly_the_obstacle_cells(grid):
    mask = grid == OBSTACLE
    cover = np.zeros(mask.shape, int)
    rects = merge_cells(mask)
    for r0, c0, r1, c1 in rects:
        assert 0 <= r0 < r1 <= mask.shape[0] and 0 <= c0 < c1 <= mask.shape[1]
        cover[r0:r1, c0:c1] += 1
    assert np.array_equal(cover, mask.astype(int))  # disjoint, and exactly the cells
    padded = np.pad(mask.astype(int), ((0, 0), (1, 1)))
    runs = int(np.sum(np.diff(padded, axis=1) == 1))
    assert len(rects) <= runs


def test_merge_cells_rejects_non_2d_masks():
    with pytest.raises(ValueError, match=r"mask must be a 2D array, got shape \(3,\)"):
        merge_cells([1, 0, 1])


def _is_convex(ring) -> bool:
    poly = Polygon(ring)
    return poly.convex_hull.area - poly.area <= 1e-9 * poly.convex_hull.area


@pytest.mark.parametrize(
    "polygon",
    [
        box(0, 0, 2, 1),
        Point(1, 1).buffer(0.5),
        box(0, 0, 2, 1).union(box(0, 0, 1, 2)),
        box(0, 0, 4, 4).difference(box(1, 1, 3, 3)),
        Polygon([(0, 0), (4, 0), (4, 3), (2, 1), (0, 3)]),
        Point(0, 0).buffer(2).difference(Point(0.5, 0).buffer(0.7)),
    ],
    ids=["box", "disc", "ell", "frame", "notch", "crescent"],
)
def test_convex_pieces_are_convex_and_tile_the_polygon(polygon):
    pieces = convex_pieces(polygon)
    assert all(_is_convex(p) for p in pieces)
    union = shapely.union_all([Polygon(p) for p in pieces])
    assert union.symmetric_difference(polygon).area <= 1e-9 * polygon.area
    assert sum(Polygon(p).area for p in pieces) == pytest.approx(polygon.area, rel=1e-9)
    if _is_convex(list(polygon.exterior.coords)) and not polygon.interiors:
        assert len(pieces) == 1


@given(strategies.floor_plans())
def test_generated_floor_plans_become_few_convex_pieces(plan):
    tmap = TraversableMap(np.zeros((2, 2), np.uint8), 0.1, geometry=plan)  # no OBSTACLE cell
    pieces, thickness = floor_pieces(tmap)
    assert all(_is_convex(p) for p in pieces)
    union = shapely.union_all([Polygon(p) for p in pieces])
    obstacles = shapely.union_all(plan.obstacles)
    assert union.symmetric_difference(obstacles).area <= 1e-6 * obstacles.area
    assert 0.0 < thickness <= 0.1


def test_a_grid_wall_is_one_shape_not_one_per_cell():
    grid = np.zeros((50, 80), np.uint8)
    grid[10, 5:75] = OBSTACLE  # a 70-cell wall
    grid[20:30, 20:40] = OBSTACLE  # a 200-cell block
    backend = loaded(Scene.from_array(grid, 0.1), [RobotSpec()])
    assert len(static_shapes(backend)) == 2


def test_a_generated_house_uses_its_polygons_and_few_shapes():
    scene = scenes.rooms(0)
    tmap = scene.floors[0]
    backend = loaded(scene, [RobotSpec()])
    n_shapes = len(static_shapes(backend))
    assert n_shapes == len(floor_pieces(tmap)[0])
    rects = len(merge_cells(tmap.codes == OBSTACLE))
    assert n_shapes <= 2 * len(scene.floor_plans[0].obstacles) + rects
    assert n_shapes < (tmap.codes == OBSTACLE).sum() / 20


def test_polygon_scene_collides_with_the_polygon_and_its_raster():
    # A disc obstacle on a coarse 0.25 m grid: its raster squares stick out of the circle
    # in a staircase. The blocked set is both, so the robot stops touching their union.
    outline = box(0, 0, 6, 6)
    pillar = Point(3.0, 3.0).buffer(0.5, quad_segs=64)
    scene = Scene.from_polygons(outline, [pillar], resolution=0.25)
    tmap = scene.floors[0]
    (ox, oy), res = tmap.origin, tmap.resolution
    cells = [
        box(ox + c * res, oy + r * res, ox + (c + 1) * res, oy + (r + 1) * res)
        for r, c in zip(*np.nonzero(tmap.codes == OBSTACLE))
    ]
    blocked = shapely.union_all([pillar, *cells])
    assert blocked.area > pillar.area + 0.02  # the raster does stick out
    spec = RobotSpec(radius=0.2)
    backend = loaded(scene, [spec])
    corners = np.array(blocked.exterior.coords)
    cx, cy = corners[np.argmax([pillar.distance(Point(c)) for c in corners])]
    outermost = math.atan2(cy - 3.0, cx - 3.0)  # the square corner farthest out
    beyond_the_circle = []
    for yaw in (0.0, 0.7, 2.0, -2.5, outermost):
        start = (3.0 - 2.0 * math.cos(yaw), 3.0 - 2.0 * math.sin(yaw))
        backend.land(0, 0, start, quat(yaw))
        for _ in range(40):
            backend.step({0: [1.0, 0.0]})
        x, y, _ = position(backend)
        assert blocked.distance(Point(x, y)) == pytest.approx(0.2, abs=2 * TOUCH_TOLERANCE)
        assert blocked.distance(Point(x, y)) >= 0.2
        assert backend.in_contact(0)
        beyond_the_circle.append(pillar.distance(Point(x, y)) - 0.2)
    assert beyond_the_circle[-1] > 0.01  # stopped by a square, not the circle


def test_floor_geometry_comes_from_the_maps_own_collision_geometry():
    # A scene without floor_plans: the map's FloorCollision still brings its polygons.
    plan = floorplans.FloorPlan(outline=box(0, 0, 4, 4), obstacles=[box(2.0, 0.0, 2.02, 4.0)])
    tmap = Scene.from_polygons(plan.outline, plan.obstacles, resolution=0.1).floors[0]
    assert not (tmap.codes == OBSTACLE).any()  # too thin to cover a cell centre
    bare = types.SimpleNamespace(floors=[tmap], n_floors=1, get_floor_height=lambda f=0: 0.0)
    backend = loaded(bare, [RobotSpec()])
    assert len(static_shapes(backend)) == 1


# ----------------------------------------------------------------------- construction


def test_registered_under_pymunk():
    assert get_backend("pymunk") is PymunkBackend
    assert make_backend("pymunk", min_substeps=3).min_substeps == 3


@pytest.mark.parametrize("bad", [0, -1, 1.5, True, 10**6])
def test_min_substeps_must_be_a_positive_int(bad):
    with pytest.raises(ValueError, match="min_substeps must be an int in"):
        PymunkBackend(min_substeps=bad)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
def test_fall_speed_must_be_positive(bad):
    with pytest.raises(ValueError, match="fall_speed"):
        PymunkBackend(fall_speed=bad)


def test_load_validates_its_arguments():
    with pytest.raises(ValueError, match="action_frequency must be a finite number > 0"):
        loaded(room(), [RobotSpec()], freq=0.0)
    with pytest.raises(TypeError, match=r"robots\[1\] must be a RobotSpec, got float"):
        loaded(room(), [RobotSpec(), 0.3])
    bad = types.SimpleNamespace(floors=[], n_floors=0, get_floor_height=lambda f=0: 0.0)
    with pytest.raises(ValueError, match="scene must have n_floors >= 1"):
        loaded(bad, [RobotSpec()])


def test_index_errors_name_the_parameter_and_range():
    backend = PymunkBackend()
    with pytest.raises(RuntimeError, match="call load"):
        backend.get_pose(0)
    backend = loaded(room(), [RobotSpec()])
    with pytest.raises(ValueError, match=r"idn must be in \[0, 1\), got 3"):
        backend.get_pose(3)
    with pytest.raises(TypeError, match="idn must be an int"):
        backend.in_contact("robot_0")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"floor must be in \[0, 1\), got 2"):
        backend.land(0, 2, (1.0, 1.0), IDENTITY)
    with pytest.raises(ValueError, match=r"position must be finite \(x, y, z\)"):
        backend.set_pose(0, (1.0, 2.0), IDENTITY)
    with pytest.raises(ValueError, match="non-zero quaternion"):
        backend.land(0, 0, (1.0, 1.0), (0.0, 0.0, 0.0, 0.0))


# ----------------------------------------------------------------------- motion


@given(
    drive=st.sampled_from(["differential", "holonomic"]),
    data=st.data(),
    yaw=strategies.yaws(),
)
def test_open_space_motion_equals_the_kinematic_backend(drive, data, yaw):
    spec = RobotSpec(drive=drive, max_linear_velocity=1.0, max_angular_velocity=3.0)
    actions = data.draw(strategies.action_sequences(spec, max_steps=8, overshoot=0.5))
    grid = np.zeros((100, 100), np.uint8)
    results = []
    for backend in (PymunkBackend(), KinematicBackend()):
        backend.load(Scene.from_array(grid, 0.1), [spec])
        backend.land(0, 0, (5.0, 5.0), quat(yaw))
        trace = []
        for action in actions:
            backend.step({0: action})
            trace.append(np.concatenate([*backend.get_pose(0), *backend.get_velocity(0)]))
        results.append(np.array(trace).reshape(len(actions), 13))
    np.testing.assert_allclose(results[0], results[1], atol=1e-9)


def test_sliding_into_a_wall_keeps_the_tangential_part():
    backend = loaded(room(), [RobotSpec()])
    backend.land(0, 0, (5.72, 3.0), quat(math.pi / 4))  # touching the x = 5.9 wall at 45 deg
    backend.step({0: [1.0, 0.0]})
    assert backend.in_contact(0)
    x, y, _ = position(backend)
    assert y == pytest.approx(3.0 + 0.05 * math.sqrt(0.5), abs=1e-6)
    assert x == pytest.approx(5.72, abs=TOUCH_TOLERANCE)


def test_driving_along_a_wall_or_away_from_it_is_no_contact():
    backend = loaded(room(), [RobotSpec(drive="holonomic")])
    backend.land(0, 0, (5.6, 3.0), IDENTITY)
    for _ in range(4):
        backend.step({0: [1.0, 0.0, 0.0]})
    assert backend.in_contact(0)
    for _ in range(4):
        backend.step({0: [0.0, 1.0, 0.0]})  # along the wall, touching it
        assert not backend.in_contact(0)
    assert position(backend)[1] == pytest.approx(3.2, abs=1e-9)
    backend.step({0: [-1.0, 0.0, 0.0]})
    assert not backend.in_contact(0)
    assert position(backend)[0] == pytest.approx(5.67, abs=1e-5)


def test_rotation_is_never_blocked():
    backend = loaded(room(), [RobotSpec()])
    backend.land(0, 0, (5.72, 3.0), IDENTITY)
    backend.step({0: [1.0, 1.0]})
    q = backend.get_pose(0)[1]
    assert 2 * math.atan2(q[2], q[3]) == pytest.approx(0.15, abs=1e-12)


def test_a_standing_robot_is_braked_not_shoved():
    backend = loaded(room(), [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (2.0, 3.0), IDENTITY)
    backend.land(1, 0, (2.36, 3.1), IDENTITY)  # a glancing hit
    for _ in range(10):
        backend.step({0: [1.0, 0.0]})
    assert np.linalg.norm(position(backend, 1) - (2.36, 3.1, 0.0)) < 1e-5
    assert position(backend, 0)[0] > 2.1  # robot 0 slid past


def test_a_robot_driving_behind_a_slower_one_is_held_back_and_both_are_flagged():
    backend = loaded(room(), [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (2.0, 3.0), IDENTITY)
    backend.land(1, 0, (2.4, 3.0), IDENTITY)
    for _ in range(10):
        backend.step({0: [1.0, 0.0], 1: [0.2, 0.0]})
    assert backend.in_contact(0) and backend.in_contact(1)
    assert position(backend, 1)[0] == pytest.approx(2.5, abs=1e-4)  # at its own speed
    gap = np.linalg.norm(position(backend, 0) - position(backend, 1))
    assert 0.36 - TOUCH_TOLERANCE <= gap <= 0.36 + 1e-4


# ----------------------------------------------------------------------- tolerance and sub-steps


@pytest.mark.parametrize("kind", ["rooms", "maze", "clutter"])
def test_stated_overlap_tolerance_holds_for_eight_robots_in_a_house(kind):
    scene = getattr(scenes, kind)(1)
    tmap = scene.floors[0]
    (ox, oy), res = tmap.origin, tmap.resolution
    cells = [
        box(ox + c * res, oy + r * res, ox + (c + 1) * res, oy + (r + 1) * res)
        for r, c in zip(*np.nonzero(tmap.codes == OBSTACLE))
    ]
    obstacles = shapely.union_all([*scene.floor_plans[0].obstacles, *cells])
    specs = [RobotSpec(drive=("holonomic", "differential")[i % 2]) for i in range(8)]
    backend = loaded(scene, specs)
    rng = np.random.default_rng(1)
    for idn in range(8):
        while True:
            _, xyz = scene.get_random_point(0, robot=0.18, rng=rng)
            if backend.is_valid_pose(idn, xyz):
                break
        backend.land(idn, 0, xyz, quat(rng.uniform(-math.pi, math.pi)))
    worst = worst_wall = 0.0
    hits = 0
    for step in range(150):
        forward = step % 30 < 24
        actions = {}
        for idn, spec in enumerate(specs):
            action = rng.uniform(-1.0, 1.0, spec.action_dim)
            action[0] = abs(action[0]) if forward else action[0]
            actions[idn] = action
        backend.step(actions)
        xy = np.array([position(backend, i)[:2] for i in range(8)])
        hits += sum(backend.in_contact(i) for i in range(8))
        for i in range(8):
            p = Point(xy[i])
            depth = 0.18 - (obstacles.distance(p) if not obstacles.contains(p) else -1.0)
            worst_wall = max(worst_wall, depth)
            for j in range(i + 1, 8):
                worst = max(worst, 0.36 - float(np.linalg.norm(xy[i] - xy[j])))
    assert hits > 50  # the robots did run into things
    assert worst_wall <= 1e-9  # clear of the walls: they rest on the skin
    assert worst <= TOUCH_TOLERANCE + 1e-9 <= OVERLAP_TOLERANCE


@pytest.mark.parametrize("radius", [0.0, 0.001, 0.02])
def test_no_tunnelling_through_a_one_cell_wall_at_1000_m_per_s(radius):
    grid = np.zeros((5, 40), np.uint8)
    grid[:, 20] = OBSTACLE  # wall x in [2.0, 2.1)
    spec = RobotSpec(radius=radius, max_linear_velocity=1000.0, drive="holonomic")
    backend = loaded(Scene.from_array(grid, 0.1), [spec])
    backend.land(0, 0, (1.0, 0.25), IDENTITY)
    backend.step({0: [1.0, 0.01, 0.0]})  # 100 m in one step
    assert backend.in_contact(0)
    assert position(backend)[0] <= 2.0 - radius + TOUCH_TOLERANCE


def test_small_fast_robots_do_not_pass_through_each_other():
    spec = RobotSpec(radius=0.01, max_linear_velocity=20.0)
    backend = loaded(Scene.from_array(np.zeros((5, 60), np.uint8), 0.1), [spec, spec])
    backend.land(0, 0, (1.0, 0.25), IDENTITY)
    backend.land(1, 0, (5.0, 0.25), quat(math.pi))
    for _ in range(2):
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})  # closing at 4 m per step
    x0, x1 = position(backend, 0)[0], position(backend, 1)[0]
    assert x0 < x1 and x1 - x0 >= 0.02 - TOUCH_TOLERANCE
    assert backend.in_contact(0) and backend.in_contact(1)


def test_is_valid_pose_accepts_a_resting_contact_and_a_touching_point_robot():
    backend = loaded(room(), [RobotSpec(), RobotSpec(radius=0.0)])
    backend.land(0, 0, (5.6, 3.0), IDENTITY)
    backend.land(1, 0, (3.0, 5.8), quat(math.pi / 2))
    for _ in range(5):
        backend.step({0: [1.0, 0.0], 1: [1.0, 0.0]})
    assert backend.in_contact(0) and backend.in_contact(1)
    for idn in range(2):
        assert backend.is_valid_pose(idn, position(backend, idn))
    assert not backend.is_valid_pose(1, (3.0, 5.9 + 1e-4))  # a point inside the wall


# ----------------------------------------------------------------------- determinism and lifecycle


def test_reset_makes_an_episode_independent_of_earlier_ones():
    scene = scenes.rooms(2, size=(8.0, 8.0))
    specs = [RobotSpec(), RobotSpec(drive="holonomic"), RobotSpec(radius=0.25)]
    rng = np.random.default_rng(3)
    starts = []
    probe = loaded(scene, specs)
    for idn in range(3):
        while True:
            _, xyz = scene.get_random_point(0, robot=specs[idn].radius, rng=rng)
            if probe.is_valid_pose(idn, xyz):
                probe.land(idn, 0, xyz, IDENTITY)
                starts.append(xyz)
                break
    episode = [
        {i: rng.uniform(-1, 1, s.action_dim) for i, s in enumerate(specs)} for _ in range(60)
    ]

    def play(backend) -> list:
        for idn, xyz in enumerate(starts):
            backend.land(idn, 0, xyz, IDENTITY)
        out = []
        for actions in episode:
            backend.step(actions)
            out.append([(position(backend, i).tolist(), backend.in_contact(i)) for i in range(3)])
        return out

    fresh = play(loaded(scene, specs))
    used = loaded(scene, specs)
    play(used)
    for actions in episode[::-1]:  # some other history, with collisions
        used.step(actions)
    used.reset()
    assert play(used) == fresh


def test_falling_robot_leaves_the_physics_and_land_brings_it_back():
    grid = np.zeros((20, 40), np.uint8)
    grid[:, 25:] = VOID
    backend = loaded(Scene.from_array(grid, 0.1, heights=[1.0]), [RobotSpec(), RobotSpec()])
    backend.land(0, 0, (2.47, 1.0), IDENTITY)
    backend.land(1, 0, (1.0, 1.0), IDENTITY)
    backend.step({0: [1.0, 0.0]})
    assert position(backend)[2] <= 1.0 - 0.05
    assert backend._robots[0].space is None
    assert backend.is_valid_pose(1, (2.5, 1.0)) is False  # over VOID, whoever is there
    backend.land(0, 0, (1.0, 1.5), IDENTITY)
    assert backend._robots[0].space is backend._floors[0].space
    assert not backend.is_valid_pose(1, (1.0, 1.4))


def test_no_pymunk_noise_when_a_backend_lives_until_interpreter_exit(tmp_path):
    # A failing doctest keeps its globals (and our spaces) alive until shutdown, when
    # pymunk can no longer run the callbacks it frees spaces with; the backend empties
    # its spaces at exit so there is nothing left to walk.
    (tmp_path / "keeps_backend.py").write_text(
        '"""\n'
        ">>> import numpy as np\n"
        ">>> from pointnav_core.scenes import Scene\n"
        ">>> from pointnav_core.backends.protocol import RobotSpec\n"
        ">>> from pointnav_pymunk import PymunkBackend\n"
        ">>> b = PymunkBackend()\n"
        ">>> b.load(Scene.from_array(np.ones((20, 20), bool), 0.1), [RobotSpec()])\n"
        ">>> b.land(0, 0, (1.0, 1.0), (0.0, 0.0, 0.0, 1.0)); b.step({0: [1.0, 0.0]})\n"
        ">>> 1\n"
        "2\n"
        '"""\n'
    )
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--doctest-modules",
         "keeps_backend.py"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert "1 failed" in done.stdout
    assert "extern" not in done.stdout + done.stderr


# ----------------------------------------------------------------------- helpers


@given(
    u=st.tuples(st.floats(-2, 2), st.floats(-2, 2)),
    limits=st.lists(
        st.tuples(st.floats(-math.pi, math.pi), st.floats(-1.0, 0.0)), min_size=1, max_size=4
    ),
)
def test_projection_is_feasible_and_no_worse_than_stopping(u, limits):
    constraints = [(math.cos(a), math.sin(a), c) for a, c in limits]
    vx, vy = closest_feasible(u[0], u[1], constraints)
    for nx, ny, c in constraints:
        assert nx * vx + ny * vy >= c - 1e-9
    assert (vx - u[0]) ** 2 + (vy - u[1]) ** 2 <= u[0] ** 2 + u[1] ** 2 + 1e-12
    if all(nx * u[0] + ny * u[1] >= c for nx, ny, c in constraints):
        assert (vx, vy) == u
