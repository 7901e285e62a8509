"""Properties of the kinematic backend on random small maps, robots and action sequences.

Every check here is computed independently of the backend's own geometry: overlap is the
signed distance from a robot's centre to every OBSTACLE square, and the commanded motion is
the textbook closed form of the drive.
"""

from __future__ import annotations

import math
import types
from dataclasses import dataclass

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, rule
from pointnav_kinematic import KinematicBackend
from shapely import affinity

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.scenes import Scene
from pointnav_core.testing.conformance import obstacle_distance
from pointnav_core.testing.strategies import robot_actions

TOUCH = 1e-9  # allowed overlap, metres


# ----------------------------------------------------------------------- strategies


@dataclass
class World:
    tmap: TraversableMap
    specs: list[RobotSpec]
    starts: list[tuple[float, float, float]]  # x, y, yaw
    frequency: float
    mode: str


@st.composite
def worlds(draw: st.DrawFn, max_robots: int = 3) -> World:
    """A small random map, 1..max_robots robots sized relative to its cells, and start poses.

    Start poses are not guaranteed valid: the test lands the robots whose start is valid
    and takes the others out of the world, which keeps drawing cheap and shrinking simple.
    """
    rows = draw(st.integers(2, 7))
    cols = draw(st.integers(2, 7))
    # Mostly FREE; shrinks to an all-free map.
    cell = st.integers(0, 9).map(lambda k: FREE if k < 6 else OBSTACLE if k < 9 else VOID)
    codes = np.array(draw(st.lists(cell, min_size=rows * cols, max_size=rows * cols)))
    res = draw(st.sampled_from((1.0, 0.5, 0.25, 0.1)))
    origin = (draw(st.floats(-3.0, 3.0)), draw(st.floats(-3.0, 3.0)))
    tmap = TraversableMap(codes.reshape(rows, cols).astype(np.uint8), res, origin=origin)
    frequency = draw(st.sampled_from((10.0, 1.0, 30.0)))
    n = draw(st.integers(1, max_robots))
    specs, starts = [], []
    for _ in range(n):
        radius = draw(st.sampled_from((0.0, 0.3, 0.5, 0.05, 1.3))) * res
        # Up to ~12 cells per step: fast enough to tunnel if collisions were not swept.
        speed = draw(st.floats(0.05, 12.0)) * res * frequency
        specs.append(
            RobotSpec(
                radius=radius,
                max_linear_velocity=speed,
                max_angular_velocity=draw(st.floats(0.1, 6.0)),
                drive=draw(st.sampled_from(("differential", "holonomic"))),
            )
        )
        fraction = st.floats(0.0, 1.0, exclude_max=True)
        x = origin[0] + (draw(st.integers(0, cols - 1)) + draw(fraction)) * res
        y = origin[1] + (draw(st.integers(0, rows - 1)) + draw(fraction)) * res
        starts.append((x, y, draw(st.floats(-math.pi, math.pi))))
    mode = draw(st.sampled_from(("slide", "stop")))
    return World(tmap, specs, starts, frequency, mode)


@st.composite
def episodes(draw: st.DrawFn) -> tuple[World, list[list[np.ndarray | None]]]:
    """A world and 1..10 steps of actions; a robot may get no action on a step."""
    world = draw(worlds())
    n_steps = draw(st.integers(1, 10))
    steps = [
        [draw(st.none() | robot_actions(spec, overshoot=0.5)) for spec in world.specs]
        for _ in range(n_steps)
    ]
    return world, steps


# ----------------------------------------------------------------------- independent checks


def scene_of(tmap: TraversableMap) -> types.SimpleNamespace:
    return types.SimpleNamespace(
        floors=[tmap], n_floors=1, get_floor_height=lambda floor=0: tmap.height
    )


def commanded_displacement(spec: RobotSpec, action, yaw: float, dt: float) -> tuple[float, float]:
    """Closed-form displacement of a constant command over dt (textbook formulas)."""
    a = np.clip(np.asarray(action, dtype=float), -1.0, 1.0)
    if spec.drive == "differential":
        vx, vy, w = a[0] * spec.max_linear_velocity, 0.0, a[1] * spec.max_angular_velocity
    else:
        vx, vy = a[0] * spec.max_linear_velocity, a[1] * spec.max_linear_velocity
        w = a[2] * spec.max_angular_velocity
    if abs(w * dt) < 1e-7:
        c, s = math.cos(yaw), math.sin(yaw)
        return (vx * c - vy * s) * dt, (vx * s + vy * c) * dt
    s0, c0 = math.sin(yaw), math.cos(yaw)
    s1, c1 = math.sin(yaw + w * dt), math.cos(yaw + w * dt)
    return (vx * (s1 - s0) + vy * (c1 - c0)) / w, (-vx * (c1 - c0) + vy * (s1 - s0)) / w


def yaw_of(q: np.ndarray) -> float:
    return 2.0 * math.atan2(q[2], q[3])


def quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def assert_no_overlap(
    backend: KinematicBackend, world: World, placed: set[int] | None = None
) -> None:
    """Check robots that are present and placed (landed); by default every present one."""
    solid = []
    for idn, spec in enumerate(world.specs):
        if not backend.is_present(idn) or (placed is not None and idn not in placed):
            continue
        pos = backend.get_pose(idn)[0]
        sd = obstacle_distance(world.tmap, pos[0], pos[1])
        assert sd >= spec.radius - TOUCH, (
            f"robot {idn} at {pos} overlaps an obstacle by {spec.radius - sd}"
        )
        if pos[2] == world.tmap.height:  # standing, not falling
            solid.append((idn, pos, spec.radius))
    for i, (a, pa, ra) in enumerate(solid):
        for b, pb, rb in solid[i + 1 :]:
            gap = math.hypot(pa[0] - pb[0], pa[1] - pb[1])
            assert gap >= ra + rb - TOUCH, f"robots {a} and {b} overlap by {ra + rb - gap}"


def start(world: World) -> KinematicBackend:
    backend = KinematicBackend(collision_mode=world.mode)
    backend.load(scene_of(world.tmap), world.specs, action_frequency=world.frequency)
    for idn, (x, y, yaw) in enumerate(world.starts):
        if backend.is_valid_pose(idn, (x, y)):
            backend.land(idn, 0, (x, y), quat(yaw))
        else:
            backend.set_present(idn, False)
    return backend


def snapshot(backend: KinematicBackend) -> list[tuple]:
    return [
        (
            backend.get_pose(i)[0].tolist(),
            backend.get_pose(i)[1].tolist(),
            backend.get_velocity(i)[0].tolist(),
            backend.in_contact(i),
        )
        for i in range(backend.n_robots)
    ]


# ----------------------------------------------------------------------- properties


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(episodes())
def test_no_robot_ever_overlaps_an_obstacle_or_another_robot(episode):
    world, steps = episode
    note(f"codes=\n{world.tmap.codes}\nres={world.tmap.resolution} origin={world.tmap.origin}")
    backend = start(world)
    assert_no_overlap(backend, world)
    for actions in steps:
        backend.step({i: a for i, a in enumerate(actions) if a is not None})
        assert_no_overlap(backend, world)


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(episodes())
def test_contact_is_flagged_whenever_the_motion_differs_from_the_command(episode):
    world, steps = episode
    backend = start(world)
    dt = 1.0 / world.frequency
    for actions in steps:
        before = [backend.get_pose(i) for i in range(backend.n_robots)]
        backend.step({i: a for i, a in enumerate(actions) if a is not None})
        for idn, spec in enumerate(world.specs):
            (p0, q0), (p1, q1) = before[idn], backend.get_pose(idn)
            if not backend.is_present(idn) or p1[2] < world.tmap.height:
                continue  # absent, or falling (a fall is not a contact)
            action = actions[idn] if actions[idn] is not None else np.zeros(spec.action_dim)
            yaw0 = yaw_of(q0)
            ex, ey = commanded_displacement(spec, action, yaw0, dt)
            error = math.hypot(p1[0] - p0[0] - ex, p1[1] - p0[1] - ey)
            if error > 1e-6 * (1.0 + math.hypot(ex, ey)):
                assert backend.in_contact(idn), f"robot {idn} deviated by {error} m without contact"
            # Turning is never blocked.
            w = float(np.clip(action[-1], -1, 1)) * spec.max_angular_velocity
            assert math.remainder(yaw_of(q1) - yaw0 - w * dt, 2 * math.pi) == pytest.approx(
                0.0, abs=1e-9
            )


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(episodes())
def test_same_world_and_actions_give_identical_results(episode):
    world, steps = episode

    def run() -> list:
        backend = start(world)
        trace = [snapshot(backend)]
        for actions in steps:
            backend.step({i: a for i, a in enumerate(actions) if a is not None})
            trace.append(snapshot(backend))
        return trace

    assert run() == run()


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(episodes())
def test_velocities_agree_with_displacement(episode):
    world, steps = episode
    backend = start(world)
    dt = 1.0 / world.frequency
    for actions in steps:
        before = [backend.get_pose(i)[0] for i in range(backend.n_robots)]
        backend.step({i: a for i, a in enumerate(actions) if a is not None})
        for idn in range(backend.n_robots):
            lin, ang = backend.get_velocity(idn)
            moved = backend.get_pose(idn)[0] - before[idn]
            np.testing.assert_allclose(lin * dt, moved, rtol=1e-9, atol=1e-12)
            assert ang[0] == ang[1] == 0.0


@st.composite
def walled_episodes(draw: st.DrawFn) -> tuple[World, float, list[list[np.ndarray | None]]]:
    """A map cut in two by a one-cell OBSTACLE column, fast robots left of it, and actions.

    Returns the world, the wall's left face x in metres, and the actions.
    """
    rows = draw(st.integers(1, 6))
    left = draw(st.integers(1, 5))
    right = draw(st.integers(1, 6))
    cell = st.integers(0, 9).map(lambda k: FREE if k < 7 else OBSTACLE if k < 9 else VOID)
    cols = left + 1 + right
    codes = np.array(draw(st.lists(cell, min_size=rows * cols, max_size=rows * cols)))
    codes = codes.reshape(rows, cols).astype(np.uint8)
    codes[:, left] = OBSTACLE
    codes[:, left + 1 :] = FREE  # land beyond the wall, so a robot that got there stands
    res = draw(st.sampled_from((1.0, 0.1, 0.25)))
    origin = (draw(st.floats(-3.0, 3.0)), draw(st.floats(-3.0, 3.0)))
    tmap = TraversableMap(codes, res, origin=origin)
    frequency = draw(st.sampled_from((10.0, 1.0)))
    specs, starts = [], []
    for _ in range(draw(st.integers(1, 2))):
        specs.append(
            RobotSpec(
                radius=draw(st.sampled_from((0.0, 0.01, 0.3, 1.3))) * res,
                # Up to 8 cells per step: far enough to jump the wall, near enough to land.
                max_linear_velocity=draw(st.floats(0.5, 8.0)) * res * frequency,
                max_angular_velocity=draw(st.floats(0.1, 3.0)),
                drive=draw(st.sampled_from(("differential", "holonomic"))),
            )
        )
        x = origin[0] + draw(st.floats(0.0, left, exclude_max=True)) * res
        y = origin[1] + draw(st.floats(0.0, rows, exclude_max=True)) * res
        starts.append((x, y, draw(st.floats(-1.5, 1.5))))  # facing the wall, roughly
    world = World(tmap, specs, starts, frequency, draw(st.sampled_from(("slide", "stop"))))
    steps = [
        [draw(st.none() | robot_actions(spec, overshoot=0.5)) for spec in specs]
        for _ in range(draw(st.integers(1, 6)))
    ]
    return world, origin[0] + left * res, steps


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(walled_episodes())
def test_no_robot_tunnels_through_a_one_cell_wall_at_any_speed(episode):
    world, wall_x, steps = episode
    backend = start(world)
    for actions in steps:
        backend.step({i: a for i, a in enumerate(actions) if a is not None})
        for idn, spec in enumerate(world.specs):
            pos = backend.get_pose(idn)[0]
            if backend.is_present(idn) and pos[2] == world.tmap.height:  # standing
                assert pos[0] <= wall_x - spec.radius + TOUCH, f"robot {idn} crossed the wall"


@st.composite
def polygon_episodes(draw: st.DrawFn) -> tuple[Scene, list, list, str, list]:
    """A 3 m room with a few thin walls at random angles, robots and their actions.

    Returns the scene, the specs, the start poses (x, y, yaw), the collision mode and the
    actions per step.
    """
    res = draw(st.sampled_from((0.1, 0.25, 0.5)))
    walls = []
    for _ in range(draw(st.integers(1, 3))):
        cx, cy = draw(st.floats(0.5, 2.5)), draw(st.floats(0.5, 2.5))
        length = draw(st.floats(0.2, 2.0))
        thick = draw(st.sampled_from((0.005, 0.02, 0.3)))
        wall = shapely.box(cx - length / 2, cy - thick / 2, cx + length / 2, cy + thick / 2)
        angle = draw(st.floats(-math.pi, math.pi))
        walls.append(affinity.rotate(wall, angle, origin=(cx, cy), use_radians=True))
    scene = Scene.from_polygons(shapely.box(0.0, 0.0, 3.0, 3.0), walls, resolution=res)
    specs, starts = [], []
    for _ in range(draw(st.integers(1, 3))):
        specs.append(
            RobotSpec(
                radius=draw(st.sampled_from((0.0, 0.05, 0.18))),
                max_linear_velocity=draw(st.floats(0.1, 20.0)),
                max_angular_velocity=draw(st.floats(0.1, 3.0)),
                drive=draw(st.sampled_from(("differential", "holonomic"))),
            )
        )
        xy = (draw(st.floats(0.0, 3.0)), draw(st.floats(0.0, 3.0)))
        starts.append((*xy, draw(st.floats(-4.0, 4.0))))
    steps = [
        [draw(st.none() | robot_actions(spec, overshoot=0.5)) for spec in specs]
        for _ in range(draw(st.integers(1, 8)))
    ]
    return scene, specs, starts, draw(st.sampled_from(("slide", "stop"))), steps


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(polygon_episodes())
def test_no_robot_ever_overlaps_a_polygon_and_deviations_are_contacts(episode):
    scene, specs, starts, mode, steps = episode
    tmap = scene.floors[0]
    walls = shapely.union_all(scene.floor_plans[0].obstacles)
    backend = KinematicBackend(collision_mode=mode)
    backend.load(scene, specs)
    for idn, (x, y, yaw) in enumerate(starts):
        if backend.is_valid_pose(idn, (x, y)):
            backend.land(idn, 0, (x, y), quat(yaw))
            # Independent reference: a valid pose is clear of the polygons by shapely.
            assert shapely.Point(x, y).distance(walls) >= specs[idn].radius - TOUCH
        else:
            backend.set_present(idn, False)
    dt = 0.1
    for actions in steps:
        before = [backend.get_pose(i) for i in range(len(specs))]
        backend.step({i: a for i, a in enumerate(actions) if a is not None})
        for idn, spec in enumerate(specs):
            (p0, q0), (p1, _) = before[idn], backend.get_pose(idn)
            if not backend.is_present(idn) or p1[2] < tmap.height:
                continue
            clearance = shapely.Point(p1[0], p1[1]).distance(walls)
            assert clearance >= spec.radius - TOUCH, f"robot {idn} overlaps a wall"
            assert obstacle_distance(tmap, p1[0], p1[1]) >= spec.radius - TOUCH
            action = actions[idn] if actions[idn] is not None else np.zeros(spec.action_dim)
            ex, ey = commanded_displacement(spec, action, yaw_of(q0), dt)
            error = math.hypot(p1[0] - p0[0] - ex, p1[1] - p0[1] - ey)
            if error > 1e-6 * (1.0 + math.hypot(ex, ey)):
                assert backend.in_contact(idn), f"robot {idn} deviated {error} m without contact"


# ----------------------------------------------------------------------- stateful


class MultiRobotEpisode(RuleBasedStateMachine):
    """Robots are stepped, teleported, removed and restored; nothing may ever overlap."""

    @initialize(world=worlds(max_robots=3))
    def load(self, world: World) -> None:
        self.world = world
        self.backend = start(world)
        # Robots never landed are present-but-unplaced once restored: not in the world.
        self.placed = {i for i in range(len(world.specs)) if self.backend.is_present(i)}

    @rule(data=st.data())
    def step(self, data: st.DataObject) -> None:
        actions = {}
        for idn, spec in enumerate(self.world.specs):
            action = data.draw(
                st.none() | robot_actions(spec, overshoot=0.5), label=f"action {idn}"
            )
            if action is not None:
                actions[idn] = action
        n = self.backend.n_robots
        absent = {i: self.backend.get_pose(i)[0] for i in range(n) if not self.backend.is_present(i)}
        self.backend.step(actions)
        for idn, pos in absent.items():
            assert self.backend.get_pose(idn)[0].tolist() == pos.tolist(), "absent robot moved"

    @rule(data=st.data())
    def teleport_to_a_valid_pose(self, data: st.DataObject) -> None:
        idn = data.draw(st.integers(0, len(self.world.specs) - 1), label="idn")
        xmin, xmax, ymin, ymax = self.world.tmap.extent
        x = data.draw(st.floats(xmin, xmax, exclude_max=True), label="x")
        y = data.draw(st.floats(ymin, ymax, exclude_max=True), label="y")
        if self.backend.is_present(idn) and self.backend.is_valid_pose(idn, (x, y)):
            self.backend.land(idn, 0, (x, y), quat(data.draw(st.floats(-4.0, 4.0), label="yaw")))
            self.placed.add(idn)

    @rule(data=st.data())
    def remove(self, data: st.DataObject) -> None:
        idn = data.draw(st.integers(0, len(self.world.specs) - 1), label="idn")
        self.backend.set_present(idn, False)
        assert not self.backend.is_present(idn)

    @rule(data=st.data())
    def restore_where_valid(self, data: st.DataObject) -> None:
        # Presence is restored only where the robot fits, as a task would do.
        idn = data.draw(st.integers(0, len(self.world.specs) - 1), label="idn")
        if self.backend.is_present(idn) or idn not in self.placed:
            return
        pos = self.backend.get_pose(idn)[0]
        self.backend.set_present(idn, True)
        falling = pos[2] < self.world.tmap.height
        if falling or not self.backend.is_valid_pose(idn, pos):
            self.backend.set_present(idn, False)

    @invariant()
    def nothing_overlaps(self) -> None:
        if hasattr(self, "backend"):
            assert_no_overlap(self.backend, self.world, self.placed)

    @invariant()
    def absent_robots_have_no_contact(self) -> None:
        if hasattr(self, "backend"):
            for idn in range(self.backend.n_robots):
                if not self.backend.is_present(idn):
                    assert not self.backend.in_contact(idn)


MultiRobotEpisode.TestCase.settings = settings(
    deadline=None, stateful_step_count=15, suppress_health_check=[HealthCheck.too_slow]
)
TestMultiRobotEpisode = MultiRobotEpisode.TestCase
