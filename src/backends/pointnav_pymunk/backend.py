"""The pymunk backend: robots as rigid discs with real contacts in a 2D physics engine."""

from __future__ import annotations

import math
import weakref
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pymunk
from numpy.typing import ArrayLike

from pointnav_core.backends.kit import (
    RobotState,
    RobotStateBackend,
    check_load,
    drive_arc,
)
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import VOID
from pointnav_pymunk.floor import (
    _ROBOT,
    _WALL_SKIN,
    TOUCH_TOLERANCE,
    _Floor,
)
from pointnav_pymunk.velocity import closest_feasible

__all__ = ["OVERLAP_TOLERANCE", "PymunkBackend"]

#: Largest overlap (m) with an obstacle or another robot that a robot may have at the end
#: of a control step (the conformance kit's bound). In practice a robot ends clear of the
#: floor's blocked set, and overlaps another robot by at most :data:`TOUCH_TOLERANCE`.
OVERLAP_TOLERANCE = 1e-3

_SETTLE_DEPTH = 0.5 * _WALL_SKIN  # m: deeper overlaps at the end of a step are settled
_MAX_SETTLE = 8  # settling sub-steps per control step, at most
_MAX_SUBSTEPS = 4096
_SUBSTEP_FRACTION = 0.4  # of the thinnest wall / smallest robot pair, travel per sub-step
_MIN_SIZE = 1e-3  # m: walls and robot pairs thinner than this count as this thick
_PUSH_EPS = 1e-9  # m/s: a command into a contact faster than this is a hit
_MASS = 1.0  # kg, a driving robot
_HOLD_MASS = 1e6  # kg, a robot told to stand still (braked: it is not shoved)
_MOTOR_MARGIN = 4.0  # motor force lets a robot reverse at full speed within a sub-step, x2

class _Robot(RobotState):
    """One robot: the shared state, its pymunk parts and what a step needs."""

    __slots__ = ("body", "shape", "control", "joint", "space", "touching", "start")

    def __init__(self, spec: RobotSpec) -> None:
        super().__init__(spec)
        self.space: pymunk.Space | None = None
        # Contacts found by the last pymunk step: (nx, ny, other robot or None), the
        # normal pointing from the obstacle towards this robot.
        self.touching: list[tuple[float, float, Any]] = []
        self.start = (0.0, 0.0, 0.0)
        self.build(0.0, 0.0, 0.0)

    def build(self, x: float, y: float, yaw: float) -> None:
        """(Re)create the pymunk parts at pose (x, y, yaw), outside any space."""
        body = pymunk.Body(_MASS, math.inf)
        body.position = (x, y)
        body.angle = yaw
        shape = pymunk.Circle(body, self.radius)
        shape.collision_type = _ROBOT
        shape.filter = pymunk.ShapeFilter(categories=_ROBOT)
        shape.friction = 0.0
        shape.elasticity = 0.0
        control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        control.position = (x, y)
        joint = pymunk.PivotJoint(control, body, (0.0, 0.0), (0.0, 0.0))
        joint.max_bias = 0.0  # a velocity motor: it never pulls towards a position
        joint.max_force = 0.0
        self.body, self.shape, self.control, self.joint = body, shape, control, joint
        self.space = None

    def at_rest(self) -> None:
        super().at_rest()
        self.touching = []
        self.body.velocity = (0.0, 0.0)
        self.body.angular_velocity = 0.0


def _empty_spaces(spaces: list[pymunk.Space]) -> None:
    """Take everything out of the spaces and drop them.

    pymunk frees a space by walking its contents with callbacks that no longer work once
    the interpreter is shutting down (it then prints errors); an empty space has nothing
    to walk. Run when the backend is collected, at exit, and when spaces are rebuilt.
    """
    for space in spaces:
        space.remove(*space.constraints, *space.shapes, *space.bodies)
    spaces.clear()


def _depth(arbiter: pymunk.Arbiter) -> float:
    """How deep (m) the two shapes of ``arbiter`` overlap; 0 when they only touch."""
    return max((-p.distance for p in arbiter.contact_point_set.points), default=0.0)


class PymunkBackend(RobotStateBackend):
    """2D rigid-body backend on pymunk: discs with real contacts against walls and robots.

    Each floor is one pymunk ``Space`` holding the floor's obstacles as static convex
    shapes (OBSTACLE cells merged into rectangles, and the floor plan's shapely obstacle
    polygons cut into convex pieces, so both stop a robot; see
    :mod:`pointnav_pymunk.geometry`), grown by a skin of half :data:`TOUCH_TOLERANCE`, and the
    robots standing on it. A robot is a dynamic disc of its spec's radius (frictionless, inelastic, never
    spun by contacts) pulled towards its commanded velocity by a velocity motor: a pivot
    joint to a kinematic control body with no position correction and a finite force, as
    in pymunk's own examples, so the solver resolves motors and contacts together. One
    control step of ``1 / action_frequency`` seconds is split into sub-steps short enough
    that no robot moves more than 0.4 of the thinnest wall (one map cell, or the thinnest
    obstacle polygon) or of the smallest sum of two robots' radii per sub-step, so a robot
    at full speed cannot pass through a wall one cell thick, nor through another robot.

    Semantics follow the kinematic backend. A robot's contact flag says that it hit or
    pushed against an obstacle or a robot during the step: pymunk found a contact and the
    robot's command drove into it (into a robot: into that robot's actual motion, so the
    robot that is hit is flagged too); touching while driving along a wall or backing
    away is not a hit. Rotation is never blocked. A robot whose centre moves over VOID or
    off the map stops moving in x, y and falls (its z drops by at least 0.05 m on that
    step, then under gravity). :meth:`get_velocity` reports the effective velocities of
    the last step (displacement over its duration). No robot ends a step overlapping an
    obstacle or another robot by more than :data:`OVERLAP_TOLERANCE` (1 mm); in practice
    a robot ends clear of the blocked set (it rests on the skin, overlapping it by pymunk's
    slop, :data:`CONTACT_SLOP`), and overlaps another robot by at most
    :data:`TOUCH_TOLERANCE` (1e-6 m). :meth:`is_valid_pose` accepts a robot that overlaps
    another by up to :data:`TOUCH_TOLERANCE`, so two robots resting in contact stand
    validly, and a robot resting against a wall stays valid: the static shapes are grown
    by a skin of half :data:`TOUCH_TOLERANCE`, so it rests clear of the blocked set.

    Parameters
    ----------
    min_substeps : int
        Fewest pymunk steps per control step, >= 1; more are used automatically when a
        robot is fast compared with the walls and robots it could hit.
    fall_speed : float
        Downward speed in m/s with which a fall starts, > 0; gravity (9.81 m/s^2) then
        accelerates it.

    Notes
    -----
    How a step runs. A robot touching nothing gets its commanded velocity outright (the
    exact arc of its drive, sub-step by sub-step), so open-space motion equals the
    kinematic backend's. A robot in contact at the start of a step gets its new command
    less the part that points into its contacts (into a robot: less what that robot is
    itself commanded to move away); after that its velocity is the solver's, which slides
    it along walls (contacts are frictionless). The motors are strong enough to reverse
    full speed within one sub-step, so a robot keeps to its command unless a contact stops
    it. A robot told to stand still is braked (its mass becomes 1e6 kg instead of 1 kg),
    so a robot that drives into it stops rather than shoving it: the braked robot moves by
    micrometres at most. At the end of a step, overlaps deeper than a
    quarter of :data:`TOUCH_TOLERANCE` (left by a hit in the last sub-step) are removed by pymunk's own
    position correction in extra sub-steps in which nothing moves. The step is
    deterministic: the same calls give the same results, and :meth:`reset` rebuilds every
    space, so an episode does not depend on earlier ones.

    Examples
    --------
    >>> import types
    >>> from pointnav_core.floor.maps import TraversableMap
    >>> floor = TraversableMap([[0, 0, 0, 0, 1]], resolution=1.0)
    >>> scene = types.SimpleNamespace(floors=[floor], n_floors=1, get_floor_height=lambda f=0: 0.0)
    >>> backend = PymunkBackend()
    >>> backend.load(scene, [RobotSpec(radius=0.25)], action_frequency=1.0)
    >>> backend.land(0, 0, (1.5, 0.5, 0.0), (0.0, 0.0, 0.0, 1.0))
    >>> backend.step({0: np.array([1.0, 0.0])})  # 0.5 m/s for 1 s
    >>> backend.get_pose(0)[0].round(9).tolist(), backend.in_contact(0)
    ([2.0, 0.5, 0.0], False)
    >>> for _ in range(6):
    ...     backend.step({0: np.array([1.0, 0.0])})
    >>> round(float(backend.get_pose(0)[0][0]), 3), backend.in_contact(0)  # at the wall
    (3.75, True)
    """

    touch_tolerance = TOUCH_TOLERANCE

    def __init__(self, min_substeps: int = 1, fall_speed: float = 1.0) -> None:
        if (
            isinstance(min_substeps, bool)
            or not isinstance(min_substeps, (int, np.integer))
            or not 1 <= min_substeps <= _MAX_SUBSTEPS
        ):
            raise ArgumentError(
                f"min_substeps must be an int in [1, {_MAX_SUBSTEPS}], got {min_substeps!r}"
            )
        super().__init__(fall_speed=fall_speed)
        self.min_substeps = int(min_substeps)
        self._floors: list[_Floor] = []
        self._robots: list[_Robot] = []
        self._by_shape: dict[pymunk.Shape, _Robot] = {}
        self._measuring = False
        # The live spaces, emptied when this backend is collected or at interpreter exit.
        self._spaces: list[pymunk.Space] = []
        weakref.finalize(self, _empty_spaces, self._spaces)

    # ------------------------------------------------------------------ lifecycle
    def load(
        self, scene: Any, robots: Sequence[RobotSpec], action_frequency: float = 10.0
    ) -> None:
        """Build one pymunk space per floor of ``scene`` and one robot per spec.

        See :meth:`Backend.load`. Robots collide with each floor's OBSTACLE cells and with
        the obstacle polygons of its collision geometry (``tmap.collision``, from the
        floor plan the map was built from, if any); they start present, unplaced, at rest
        at x = y = 0 on floor 0.
        """
        specs, n_floors, dt = check_load(scene, robots, action_frequency)
        self._floors = [
            _Floor(scene.floors[f], float(scene.get_floor_height(f))) for f in range(n_floors)
        ]
        self._robots = [_Robot(spec) for spec in specs]
        for rb in self._robots:
            rb.z = self._floors[0].height
        self._dt = dt
        self._rebuild()

    def _rebuild(self) -> None:
        """Fresh spaces with the static obstacles; robots' parts rebuilt, in no space."""
        _empty_spaces(self._spaces)
        for floor in self._floors:
            floor.build_space(self._hit_wall, self._hit_robot)
            self._spaces.append(floor.space)
        self._by_shape = {}
        for rb in self._robots:
            x, y = rb.body.position
            rb.build(x, y, rb.body.angle)
            self._by_shape[rb.shape] = rb

    def reset(self) -> None:
        """As :meth:`RobotStateBackend.reset`, and every space is rebuilt.

        So what happens next does not depend on what happened before.
        """
        super().reset()
        self._rebuild()

    # ------------------------------------------------------------------ membership
    def _sync_space(self, rb: _Robot) -> None:
        """Put the robot's parts in its floor's space when solid, else in no space."""
        want = self._floors[rb.floor].space if rb.solid() else None
        if rb.space is want:
            return
        parts = (rb.body, rb.shape, rb.control, rb.joint)
        if rb.space is not None:
            rb.space.remove(*parts)
        if want is not None:
            want.add(*parts)
        rb.space = want
        self._forget(rb)

    def _forget(self, rb: _Robot) -> None:
        """Drop the contacts known for and against a robot that moved or left."""
        rb.touching = []
        for other in self._robots:
            if other.touching:
                other.touching = [t for t in other.touching if t[2] is not rb]

    def _teleport(self, rb: _Robot, x: float, y: float, yaw: float) -> None:
        rb.body.position = (x, y)
        rb.body.angle = yaw
        rb.control.position = (x, y)
        if rb.space is not None:
            rb.space.reindex_shapes_for_body(rb.body)
        self._forget(rb)

    # ------------------------------------------------------------------ poses
    def _pose(self, rb: _Robot) -> tuple[float, float, float]:
        x, y = rb.body.position
        return x, y, rb.body.angle

    def _place(self, rb: _Robot, x: float, y: float, yaw: float) -> None:
        self._teleport(rb, x, y, yaw)
        self._sync_space(rb)

    def set_present(self, idn: int, present: bool) -> None:
        """Take robot ``idn`` out of the world (``False``) or bring it back (``True``).

        As :meth:`RobotStateBackend.set_present`; the robot's body also stops, and leaves
        or rejoins its floor's space.
        """
        super().set_present(idn, present)
        rb = self._robots[idn]
        rb.body.velocity = (0.0, 0.0)
        self._sync_space(rb)

    # ------------------------------------------------------------------ contacts
    def _hit_wall(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: Any) -> None:
        rb = self._by_shape[arbiter.shapes[0]]
        n = arbiter.normal  # from the robot towards the wall
        nx, ny = -n.x, -n.y
        rb.touching.append((nx, ny, None))
        u = rb.control.velocity  # the commanded velocity of this sub-step
        # A hit: the command drives into the wall, or the sub-step ended deeper in it than
        # a resting contact ever is (a sub-step that ends just past a corner can leave the
        # normal square to the motion, though the robot ran into the corner on the way).
        if u.x * nx + u.y * ny < -_PUSH_EPS or _depth(arbiter) > TOUCH_TOLERANCE:
            rb.contact = True
        if self._measuring:
            self._measure(rb, arbiter)

    def _hit_robot(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: Any) -> None:
        a_shape, b_shape = arbiter.shapes
        a, b = self._by_shape[a_shape], self._by_shape[b_shape]
        n = arbiter.normal  # from a towards b
        a.touching.append((-n.x, -n.y, b))
        b.touching.append((n.x, n.y, a))
        # A hit when either robot's command drives into the other one's actual motion.
        ua, ub = a.control.velocity, b.control.velocity
        va, vb = a.body.velocity, b.body.velocity
        if (
            (ua.x - vb.x) * n.x + (ua.y - vb.y) * n.y > _PUSH_EPS
            or (va.x - ub.x) * n.x + (va.y - ub.y) * n.y > _PUSH_EPS
        ):
            a.contact = b.contact = True
        if self._measuring:
            self._measure(a, arbiter)

    def _measure(self, rb: _Robot, arbiter: pymunk.Arbiter) -> None:
        floor = self._floors[rb.floor]
        for point in arbiter.contact_point_set.points:
            if -point.distance > floor.depth:
                floor.depth = -point.distance

    # ------------------------------------------------------------------ stepping
    def step(self, actions: Mapping[int, ArrayLike]) -> None:
        """Apply each given robot's action and advance one control step for all robots.

        See :meth:`Backend.step`; how a step runs is told in the class's notes. A bad
        action or robot index raises (ValueError) before any robot has moved.
        """
        free = self._start_step(actions)
        dt = self._dt
        moving: list[_Robot] = []
        travel = 0.0  # the most sub-steps' worth of travel of any robot
        reach = self._reach()
        for rb in free:
            x, y = rb.body.position
            rb.start = (x, y, rb.body.angle)
            if self._floors[rb.floor].code(x, y) == VOID:
                self._start_fall(rb)  # standing over nothing: falls without moving
                continue
            travel = max(travel, rb.travel / reach[rb.floor])
            moving.append(rb)
        if not moving:
            return
        n_sub = min(max(self.min_substeps, math.ceil(travel)), _MAX_SUBSTEPS)
        h = dt / n_sub
        spaces = []
        for rb in moving:
            space = rb.space
            if space is not None and space not in spaces:
                spaces.append(space)
            vx, vy, w = rb.cmd
            mass = _HOLD_MASS if vx == 0.0 and vy == 0.0 else _MASS
            if rb.body.mass != mass:
                rb.body.mass = mass
            rb.joint.max_force = mass * _MOTOR_MARGIN * rb.spec.max_linear_velocity / h
            rb.body.angular_velocity = w  # infinite moment: contacts never change it
        self._substeps(moving, spaces, n_sub, h)
        self._settle(moving, spaces, h)
        for rb in moving:
            if rb.falling:
                continue
            x0, y0, yaw0 = rb.start
            x, y = rb.body.position
            rb.vel = ((x - x0) / dt, (y - y0) / dt, 0.0, (rb.body.angle - yaw0) / dt)

    def _reach(self) -> list[float]:
        """Longest safe motion (m) per sub-step on each floor.

        0.4 of the thinnest wall, and of the smallest sum of radii of two robots standing
        there that can touch (two point robots never do): between two collision checks no
        robot gets past a wall's middle, nor two robots past each other's centres.
        """
        sizes = [floor.thickness for floor in self._floors]
        radii: list[list[float]] = [[] for _ in self._floors]
        for rb in self._robots:
            if rb.solid():
                radii[rb.floor].append(rb.radius)
        for f, rs in enumerate(radii):
            if len(rs) >= 2:
                rs.sort()
                pair = rs[0] + rs[1] if rs[1] > 0.0 else next((r for r in rs if r > 0.0), math.inf)
                sizes[f] = min(sizes[f], pair)
        return [_SUBSTEP_FRACTION * max(size, _MIN_SIZE) for size in sizes]

    def _substeps(
        self, moving: list[_Robot], spaces: list[pymunk.Space], n_sub: int, h: float
    ) -> None:
        floors = self._floors
        for k in range(n_sub):
            last = k == n_sub - 1
            velocities = []
            for rb in moving:
                if rb.falling:
                    velocities.append(None)
                    continue
                vx, vy, w = rb.cmd
                u = drive_arc(rb.body.angle, vx, vy, w, h, True)
                rb.control.velocity = u
                velocities.append(u)
            for rb, u in zip(moving, velocities):
                if u is None:
                    continue
                if not rb.touching:
                    rb.body.velocity = u  # nothing to push against: exact motion
                elif k == 0:
                    rb.body.velocity = self._predict(rb, u)
                rb.touching = []
            self._measuring = last
            if last:
                for floor in floors:
                    floor.depth = 0.0
            for space in spaces:
                space.step(h)
            self._measuring = False
            for rb in moving:
                if not rb.falling:
                    x, y = rb.body.position
                    if floors[rb.floor].code(x, y) == VOID:
                        self._start_fall(rb)

    def _predict(self, rb: _Robot, u: tuple[float, float]) -> tuple[float, float]:
        """Command ``u`` less what points into the robot's current contacts."""
        limits = []
        for nx, ny, other in rb.touching:
            c = 0.0
            if other is not None:  # the other robot's command for this sub-step
                ov = other.control.velocity
                c = min(0.0, nx * ov.x + ny * ov.y)
            limits.append((nx, ny, c))
        return closest_feasible(u[0], u[1], limits)

    def _settle(self, moving: list[_Robot], spaces: list[pymunk.Space], h: float) -> None:
        """Resolve overlaps left by the last sub-step, with nothing else moving."""
        floors = self._floors
        for _ in range(_MAX_SETTLE):
            deep = [f.space for f in floors if f.depth > _SETTLE_DEPTH and f.space in spaces]
            if not deep:
                return
            for rb in moving:
                if rb.space in deep:
                    rb.body.velocity = (0.0, 0.0)
                    rb.touching = []
            for floor in floors:
                floor.depth = 0.0
            self._measuring = True
            for space in deep:
                space.step(h)
            self._measuring = False
            for rb in moving:
                if not rb.falling and rb.space in deep:
                    x, y = rb.body.position
                    if floors[rb.floor].code(x, y) == VOID:
                        self._start_fall(rb)

    def _start_fall(self, rb: _Robot) -> None:
        """Take a robot whose centre is over VOID out of the physics and start its fall."""
        x0, y0, yaw0 = rb.start
        x, y = rb.body.position
        rb.falling = True
        rb.touching = []
        self._sync_space(rb)
        rb.body.velocity = (0.0, 0.0)
        rb.body.angular_velocity = 0.0
        dt = self._dt
        planar = ((x - x0) / dt, (y - y0) / dt, (rb.body.angle - yaw0) / dt)
        self._fall(rb, first=True, planar=planar)
