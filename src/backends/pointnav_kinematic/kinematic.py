"""The kinematic backend: exact drive integration and swept-disc collisions, no physics."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.collision import TOUCH_TOL
from pointnav_core.backend import (
    RobotSpec,
    RobotStateBackend,
    _planar_quat_floats,
    check_load,
    parse_orientation,
    parse_position,
    planar_quat,
)
from pointnav_kinematic.contacts import advance
from pointnav_kinematic.geometry import FloorGeometry

__all__ = ["COLLISION_MODES", "KinematicBackend"]

#: Valid values of ``collision_mode``.
COLLISION_MODES = ("slide", "stop")

# Accepted overlap between robots in is_valid_pose (touching is allowed), as for walls.
_TOUCH = TOUCH_TOL
_MAX_TURN = 0.25  # rad per sub-step: the chord stays close to the arc
_MAX_SUBSTEPS = 1024  # beyond this, segments grow; collisions stay exact regardless


class _Robot:
    """Mutable state of one robot, as plain floats for the per-step hot path."""

    __slots__ = (
        "spec",
        "radius",
        "holonomic",
        "x",
        "y",
        "z",
        "yaw",
        "floor",
        "geom",
        "fast",
        "present",
        "placed",
        "falling",
        "fall_speed",
        "contact",
        "vel",
        "cmd",
        "travel",
        "stopped",
        "mx",
        "my",
        "walls",
    )

    def __init__(self, spec: RobotSpec, geom: FloorGeometry) -> None:
        self.spec = spec
        self.radius = spec.radius
        self.holonomic = spec.drive == "holonomic"
        self.x = self.y = self.yaw = 0.0
        self.z = geom.height
        self.floor = 0
        self.geom = geom
        self.fast = geom.fast_clearance(spec.radius)
        self.present = True
        self.placed = False
        self.falling = False
        self.fall_speed = 0.0
        self.contact = False
        # World velocity of the last step: (vx, vy, vz) in m/s and yaw rate in rad/s.
        self.vel = (0.0, 0.0, 0.0, 0.0)
        # Commanded body-frame velocity (vx, vy, w) for the current step.
        self.cmd = (0.0, 0.0, 0.0)
        self.travel = 0.0
        self.stopped = False
        # This sub-step's chord (m) and the walls near it, for contacts.advance.
        self.mx = self.my = 0.0
        self.walls: list[tuple[float, ...]] = []

    def solid(self) -> bool:
        """Whether other robots can collide with this one."""
        return self.present and self.placed and not self.falling


def _arc(
    yaw: float, vx: float, vy: float, w: float, h: float
) -> tuple[float, float]:
    """World displacement over ``h`` s of body velocity (vx, vy) turning at ``w`` rad/s.

    Exact for a constant command: the integral of R(yaw + w t) (vx, vy) over [0, h].
    Written with sin(a)/a, a = w h / 2, so it stays accurate as w -> 0 (straight line).
    """
    a = 0.5 * w * h
    s = h * (math.sin(a) / a if a != 0.0 else 1.0)
    mid = yaw + a
    c = math.cos(mid)
    sn = math.sin(mid)
    return s * (vx * c - vy * sn), s * (vx * sn + vy * c)


class KinematicBackend(RobotStateBackend):
    """Physics-free backend: robots are discs that follow their commands exactly.

    Each :meth:`step` integrates every robot's drive in closed form over one control
    step of ``1 / action_frequency`` seconds (an exact arc for differential drive; exact
    rotation of the body-frame velocity for holonomic drive). A motion that would make a
    robot's disc overlap an OBSTACLE cell square, an obstacle polygon of the floor plan
    or another robot on the same floor is cut at the first contact, found exactly by
    sweeping the discs (no tunnelling at any speed); then the robot slides along the
    contact (``"slide"``) or stops there for the rest of the step (``"stop"``), and both
    parties' contact flags are set. Robots move simultaneously: two that close on each
    other stop where they first touch. A motion that does not go into an obstacle, such
    as driving along a wall the disc touches, is not a contact. No robot ever ends a
    step overlapping an obstacle or another robot. A robot whose centre
    moves over VOID (or off the map) stops moving in x, y and falls: its z drops by at
    least 0.05 m on that step, then under gravity.

    Parameters
    ----------
    collision_mode : {"slide", "stop"}
        What a blocked robot does with the rest of its motion: ``"slide"`` keeps the part
        tangent to the contact, ``"stop"`` stays at the contact point. Rotation is never
        blocked (a disc can always turn in place).
    fall_speed : float
        Downward speed in m/s with which a fall starts, > 0; gravity (9.81 m/s^2) then
        accelerates it.

    Notes
    -----
    Open space is the fast path: a per-floor, per-radius clearance grid says in one
    lookup that nothing is within reach of the step, and the robot just moves. Contact
    resolution runs only near obstacles, VOID or other robots.

    Examples
    --------
    >>> import types
    >>> from pointnav_core.maps import TraversableMap
    >>> floor = TraversableMap([[0, 0, 0, 0, 1]], resolution=1.0)
    >>> scene = types.SimpleNamespace(floors=[floor], n_floors=1, get_floor_height=lambda f=0: 0.0)
    >>> backend = KinematicBackend()
    >>> backend.load(scene, [RobotSpec(radius=0.25)], action_frequency=1.0)
    >>> backend.land(0, 0, (1.5, 0.5, 0.0), (0.0, 0.0, 0.0, 1.0))
    >>> backend.step({0: np.array([1.0, 0.0])})  # 0.5 m/s for 1 s
    >>> backend.get_pose(0)[0].tolist(), backend.in_contact(0)
    ([2.0, 0.5, 0.0], False)
    >>> for _ in range(6):
    ...     backend.step({0: np.array([1.0, 0.0])})
    >>> round(float(backend.get_pose(0)[0][0]), 6), backend.in_contact(0)  # at the wall
    (3.75, True)
    """

    def __init__(self, collision_mode: str = "slide", fall_speed: float = 1.0) -> None:
        if collision_mode not in COLLISION_MODES:
            raise ValueError(
                f"collision_mode must be one of {list(COLLISION_MODES)}, got {collision_mode!r}"
            )
        super().__init__(fall_speed=fall_speed)
        self.collision_mode = collision_mode
        self._stop = collision_mode == "stop"
        self._floors: list[FloorGeometry] = []
        self._robots: list[_Robot] = []

    # ------------------------------------------------------------------ lifecycle
    def load(
        self, scene: Any, robots: Sequence[RobotSpec], action_frequency: float = 10.0
    ) -> None:
        """Build the world from ``scene.floors`` and one robot per spec.

        Parameters
        ----------
        scene : Scene
            Uses only ``floors`` (list of TraversableMap), ``n_floors`` and
            ``get_floor_height(floor)``.
        robots : sequence of RobotSpec
            Robot ``idn`` is ``robots[idn]``.
        action_frequency : float
            Control steps per second (Hz), > 0.

        Notes
        -----
        Robots start present, unplaced, at rest at x = y = 0 on floor 0.
        """
        specs, n_floors, dt = check_load(scene, robots, action_frequency)
        self._floors = [
            FloorGeometry(scene.floors[f], float(scene.get_floor_height(f)))
            for f in range(n_floors)
        ]
        self._robots = [_Robot(spec, self._floors[0]) for spec in specs]
        self._dt = dt

    def reset(self) -> None:
        """Return every robot to its state after :meth:`load`, keeping its pose.

        Velocities and contact flags become zero, falls end, and every robot is present
        again but unplaced: it takes part in no collision until :meth:`land` or
        :meth:`set_pose` places it, so that the task can place robots one by one.
        """
        for rb in self._robots:
            rb.present = True
            rb.placed = False
            self._at_rest(rb)

    @staticmethod
    def _at_rest(rb: _Robot) -> None:
        rb.falling = False
        rb.fall_speed = 0.0
        rb.contact = False
        rb.stopped = False
        rb.vel = (0.0, 0.0, 0.0, 0.0)
        rb.cmd = (0.0, 0.0, 0.0)

    # ------------------------------------------------------------------ poses
    def land(self, idn: int, floor: int, position: ArrayLike, orientation: ArrayLike) -> None:
        """Place robot ``idn`` at rest on ``floor``: x, y from ``position``, z = floor height.

        Parameters
        ----------
        idn : int
            Robot index.
        floor : int
            Floor index.
        position : array_like, shape (2,) or (3,)
            World x, y in metres; a z is ignored.
        orientation : array_like, shape (4,)
            ``(x, y, z, w)`` quaternion; only its yaw matters.
        """
        rb = self._robot(idn)
        geom = self._floor(floor)
        xy = parse_position(position, allow_2d=True)
        yaw = parse_orientation(orientation)
        rb.floor = int(floor)
        rb.geom = geom
        rb.fast = geom.fast_clearance(rb.radius)
        rb.x, rb.y, rb.z, rb.yaw = xy[0], xy[1], geom.height, yaw
        rb.placed = True
        self._at_rest(rb)

    def set_pose(self, idn: int, position: ArrayLike, orientation: ArrayLike) -> None:
        """Teleport robot ``idn`` (at rest) to world ``position`` and ``orientation``.

        Parameters
        ----------
        idn : int
            Robot index.
        position : array_like, shape (3,)
            World x, y, z in metres. The robot stays on its floor (use :meth:`land` to
            change floors).
        orientation : array_like, shape (4,)
            ``(x, y, z, w)`` quaternion; the backend is planar, so only its yaw is kept.
        """
        rb = self._robot(idn)
        x, y, z = parse_position(position)
        yaw = parse_orientation(orientation)
        rb.x, rb.y, rb.z, rb.yaw = x, y, z, yaw
        rb.placed = True
        self._at_rest(rb)

    def get_pose(self, idn: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Return robot ``idn``'s world position (3,) in metres and orientation (4,).

        The orientation is the planar quaternion ``(0, 0, sin(yaw/2), cos(yaw/2))`` with
        yaw in [-pi, pi], so its w is >= 0.
        """
        rb = self._robot(idn)
        return np.array((rb.x, rb.y, rb.z)), planar_quat(rb.yaw)

    def get_pose_floats(self, idn: int) -> tuple[float, ...]:
        """Return :meth:`get_pose`'s seven numbers as a tuple of floats, without arrays.

        ``(x, y, z, qx, qy, qz, qw)``. Not part of the :class:`~pointnav_core.backend.Backend`
        protocol: an optional fast path that the task reads on every step instead of
        :meth:`get_pose`, only when no subclass has overridden ``get_pose``.
        """
        rb = self._robot(idn)
        return (rb.x, rb.y, rb.z, *_planar_quat_floats(rb.yaw))

    def is_valid_pose(
        self,
        idn: int,
        position: ArrayLike,
        orientation: ArrayLike | None = None,
        *,
        floor: int | None = None,
    ) -> bool:
        """Whether robot ``idn`` could stand at ``position``.

        Parameters
        ----------
        idn : int
            Robot index.
        position : array_like, shape (2,) or (3,)
            World x, y (and an ignored z) in metres.
        orientation : array_like, shape (4,), optional
            Ignored (a disc looks the same in every heading); validated when given.
        floor : int, optional
            Floor to test on; default: the robot's floor (:meth:`get_robot_floor`).

        Returns
        -------
        bool
            True when the disc misses the floor's blocked set (``tmap.collision``: every
            OBSTACLE and VOID cell square, everything off the map and the floor plan's
            obstacle polygons; touching within 1e-9 m is fine), exactly as the task and
            the planner decide, and it overlaps no other present, placed, non-falling
            robot on that floor by more than 1e-9 m. (Motion is more lenient about VOID: a
            disc may overhang it, and a robot falls only once its centre is over it.)
        """
        rb = self._robot(idn)
        geom = rb.geom if floor is None else self._floor(floor)
        fl = rb.floor if floor is None else int(floor)
        xy = parse_position(position, allow_2d=True)
        if orientation is not None:
            parse_orientation(orientation)
        x, y = xy[0], xy[1]
        r = rb.radius
        if not geom.collision.points_clear((x, y), r):
            return False
        for other in self._robots:
            if other is rb or other.floor != fl or not other.solid():
                continue
            reach = r + other.radius - _TOUCH
            if (x - other.x) ** 2 + (y - other.y) ** 2 < reach * reach and reach > 0.0:
                return False
        return True

    # ------------------------------------------------------------------ stepping
    def step(self, actions: Mapping[int, ArrayLike]) -> None:
        """Apply each given robot's action and advance one control step for all robots.

        Parameters
        ----------
        actions : mapping of int to array_like
            Robot index -> action in ``[-1, 1]`` (see :meth:`RobotSpec.scale_action`).
            Robots without an entry get a zero command.
        """
        robots = self._robots
        zero = (0.0, 0.0, 0.0)
        for rb in robots:
            rb.cmd = zero
        for idn, action in actions.items():
            rb = self._robot(idn)
            cmd = rb.spec._scaled(action)
            rb.cmd = cmd if rb.holonomic else (cmd[0], 0.0, cmd[1])
        dt = self._dt
        moving = []
        for rb in robots:
            rb.contact = False
            if not (rb.present and rb.placed):
                rb.vel = (0.0, 0.0, 0.0, 0.0)
            elif rb.falling:
                self._fall(rb, first=False)
            else:
                vx, vy, _ = rb.cmd
                rb.travel = (math.hypot(vx, vy) if vy else abs(vx)) * dt
                moving.append(rb)
        if not moving:
            return
        slow = []
        for rb in moving:
            # Fast path: the clearance grid vouches for everything within reach.
            geom = rb.geom
            col = math.floor((rb.x - geom.ox) * geom.inv_res)
            row = math.floor((rb.y - geom.oy) * geom.inv_res)
            if not (0 <= col < geom.width and 0 <= row < geom.rows) or not (
                rb.fast[row * geom.width + col] > rb.travel
            ):
                slow.append(rb)
                continue
            if len(moving) > 1:
                reach = rb.radius + rb.travel
                for other in moving:
                    if other is not rb and other.floor == rb.floor:
                        gap = reach + other.radius + other.travel
                        if (rb.x - other.x) ** 2 + (rb.y - other.y) ** 2 <= gap * gap:
                            slow.append(rb)
                            break
        if slow and len(slow) < len(moving):
            fast = [rb for rb in moving if rb not in slow]
        elif slow:
            fast = []
        else:
            fast = moving
        for rb in fast:
            vx, vy, w = rb.cmd
            dx, dy = _arc(rb.yaw, vx, vy, w, dt)
            rb.x += dx
            rb.y += dy
            rb.yaw += w * dt
            rb.vel = (dx / dt, dy / dt, 0.0, w)
        if slow:
            self._slow_step(slow, dt)

    def _slow_step(self, slow: list[_Robot], dt: float) -> None:
        # All slow robots advance together in sub-steps; within each, contacts.advance moves
        # them simultaneously, so robots meeting head-on share the gap by their speeds.
        # Collisions are exact for any chord; sub-steps keep the chord near the arc and the
        # search boxes small.
        n_sub = 1
        for rb in slow:
            res = rb.geom.res
            need = max(rb.travel / (0.5 * res), abs(rb.cmd[2]) * dt / _MAX_TURN)
            if need > n_sub:
                n_sub = min(math.ceil(need), _MAX_SUBSTEPS)
        h = dt / n_sub
        start = []
        for rb in slow:
            start.append((rb.x, rb.y, rb.yaw))
            rb.stopped = False
            if rb.geom.is_void(rb.x, rb.y):
                rb.falling = True  # standing over nothing: falls without moving
        stop = self._stop
        for _ in range(n_sub):
            standing = []
            for rb in slow:
                if rb.falling:
                    continue
                vx, vy, w = rb.cmd
                if rb.stopped or (vx == 0.0 and vy == 0.0):
                    rb.mx = rb.my = 0.0
                else:
                    rb.mx, rb.my = _arc(rb.yaw, vx, vy, w, h)
                standing.append(rb)
            advance(standing, stop)
            for rb in standing:
                if rb.geom.is_void(rb.x, rb.y):
                    rb.falling = True
                rb.yaw += rb.cmd[2] * h
        for rb, (x0, y0, yaw0) in zip(slow, start):
            if rb.falling:
                vel_x, vel_y, wz = (rb.x - x0) / dt, (rb.y - y0) / dt, (rb.yaw - yaw0) / dt
                self._fall(rb, first=True)
                rb.vel = (vel_x, vel_y, rb.vel[2], wz)
            else:
                rb.vel = ((rb.x - x0) / dt, (rb.y - y0) / dt, 0.0, (rb.yaw - yaw0) / dt)
