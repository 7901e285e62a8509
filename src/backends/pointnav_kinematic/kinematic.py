"""The kinematic backend: exact drive integration and swept-disc collisions, no physics."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from numpy.typing import ArrayLike

from pointnav_core.backends.kit import (
    RobotState,
    RobotStateBackend,
    check_load,
    drive_arc,
)
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import ArgumentError
from pointnav_kinematic.contacts import advance
from pointnav_kinematic.geometry import FloorGeometry

__all__ = ["COLLISION_MODES", "KinematicBackend"]

#: Valid values of ``collision_mode``.
COLLISION_MODES = ("slide", "stop")

_MAX_TURN = 0.25  # rad per sub-step: the chord stays close to the arc
_MAX_SUBSTEPS = 1024  # beyond this, segments grow; collisions stay exact regardless


class _Robot(RobotState):
    """One robot: the shared state, its pose and what a step needs, as plain floats."""

    __slots__ = ("x", "y", "yaw", "geom", "fast", "stopped", "mx", "my", "walls")

    def __init__(self, spec: RobotSpec, geom: FloorGeometry) -> None:
        super().__init__(spec)
        self.x = self.y = self.yaw = 0.0
        self.z = geom.height
        self.geom = geom
        self.fast = geom.fast_clearance(spec.radius)
        self.stopped = False
        # This sub-step's chord (m) and the walls near it, for contacts.advance.
        self.mx = self.my = 0.0
        self.walls: list[tuple[float, ...]] = []

    def at_rest(self) -> None:
        super().at_rest()
        self.stopped = False


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
    >>> import numpy as np
    >>> from pointnav_core.floor.maps import TraversableMap
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
            raise ArgumentError(
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
        """Build the world (see :meth:`Backend.load`): the floors' geometry, the robots.

        Uses only the scene's ``floors``, ``n_floors`` and ``get_floor_height(floor)``.
        Robots start present, unplaced, at rest at x = y = 0 on floor 0.
        """
        specs, n_floors, dt = check_load(scene, robots, action_frequency)
        self._floors = [
            FloorGeometry(scene.floors[f], float(scene.get_floor_height(f)))
            for f in range(n_floors)
        ]
        self._robots = [_Robot(spec, self._floors[0]) for spec in specs]
        self._dt = dt

    def floor_geometry(self, floor: int) -> FloorGeometry:
        """The loaded world's floor ``floor`` as this backend collides with it (read only:
        the batched engine shares it rather than building it again)."""
        return self._floors[floor]

    # ------------------------------------------------------------------ poses
    def _pose(self, rb: _Robot) -> tuple[float, float, float]:
        return rb.x, rb.y, rb.yaw

    def _place(self, rb: _Robot, x: float, y: float, yaw: float) -> None:
        rb.x, rb.y, rb.yaw = x, y, yaw
        geom = self._floors[rb.floor]
        if rb.geom is not geom:  # landed on another floor
            rb.geom = geom
            rb.fast = geom.fast_clearance(rb.radius)

    # ------------------------------------------------------------------ stepping
    def step(self, actions: Mapping[int, ArrayLike]) -> None:
        """Apply each given robot's action and advance one control step for all robots.

        See :meth:`Backend.step`. A robot with nothing within reach of its step (the
        clearance grid says so in one lookup) moves by its exact arc; the others advance
        together in sub-steps with exact, swept contacts (:func:`contacts.advance`). A
        bad action or robot index raises (ValueError) before any robot has moved.
        """
        moving = self._start_step(actions)
        if not moving:
            return
        dt = self._dt
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
            dx, dy = drive_arc(rb.yaw, vx, vy, w, dt)
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
                    rb.mx, rb.my = drive_arc(rb.yaw, vx, vy, w, h)
                standing.append(rb)
            advance(standing, stop)
            for rb in standing:
                if rb.geom.is_void(rb.x, rb.y):
                    rb.falling = True
                rb.yaw += rb.cmd[2] * h
        for rb, (x0, y0, yaw0) in zip(slow, start):
            planar = ((rb.x - x0) / dt, (rb.y - y0) / dt, (rb.yaw - yaw0) / dt)
            if rb.falling:
                self._fall(rb, first=True, planar=planar)
            else:
                rb.vel = (planar[0], planar[1], 0.0, planar[2])
