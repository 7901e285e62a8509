"""The base class of a backend that keeps one state object per robot."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core.backends.kit.checks import (
    _is_index,
    check_index,
    parse_orientation,
    parse_position,
    planar_quat,
    planar_quat_floats,
)
from pointnav_core.backends.kit.state import _NO_COMMAND, _STILL
from pointnav_core.backends.kit.world import robots_overlap
from pointnav_core.errors import ArgumentError, TaskStateError
from pointnav_core.floor.collision import TOUCH_TOL

__all__ = ["RobotStateBackend"]

_GRAVITY = 9.81  # m/s^2
_MIN_FIRST_DROP = 0.05  # m: a fall must be visible on the step it starts, at any rate


class RobotStateBackend:
    """Base class for a backend that keeps one :class:`RobotState` per robot.

    It implements every :class:`~pointnav_core.backends.protocol.Backend` method but ``load`` and
    ``step``, and the float twins ``get_pose_floats`` and ``get_velocity_floats``: the
    robot and floor index checks, the argument checks of ``land``, ``set_pose`` and
    ``is_valid_pose``, the accessors, presence, :meth:`reset`, and the fall of a robot
    whose centre is over VOID (:meth:`_fall`). A subclass writes what is its own:

    ``load(scene, robots, action_frequency)``
        Check the arguments with :func:`check_load` (it returns ``_dt``), build one
        :class:`FloorGrid` (or subclass) per floor into ``_floors`` and one
        :class:`RobotState` (or subclass) per spec into ``_robots``.
    ``step(actions)``
        Start with ``free = self._start_step(actions)`` (:meth:`_start_step`: actions
        checked and turned into each robot's ``cmd`` and ``travel``, falls advanced), move
        the robots in
        ``free`` and set each one's ``vel`` (and ``contact``); call
        ``self._fall(rb, first=True, planar=...)`` for one whose centre went over VOID.
    ``_pose(rb)`` and ``_place(rb, x, y, yaw)``
        Read and write a robot's planar pose, wherever the backend keeps it (attributes of
        its state, a physics body).

    :func:`~pointnav_core.backends.protocol.check_backend` still checks that ``load`` and ``step``
    exist. A subclass that overrides ``get_pose`` or ``get_velocity`` should override
    its float twin too, or the task reads the override instead of the twin (see
    :data:`~pointnav_core.backends.protocol.FLOAT_TWINS`).

    Parameters
    ----------
    fall_speed : float
        Downward speed in m/s with which a fall starts, > 0; gravity (9.81 m/s^2) then
        accelerates it.

    Attributes
    ----------
    touch_tolerance : float
        Overlap in metres up to which two robots count as touching in
        :meth:`is_valid_pose` (a class attribute, 1e-9 m unless a subclass sets another).

    Notes
    -----
    The subclass's ``load`` fills these attributes (empty, and ``0.1`` s, until then):

    ``_robots`` : list of RobotState
        One state per robot, index ``idn``.
    ``_floors`` : list of FloorGrid
        One per floor, index ``floor``: its ``height`` and ``clear(x, y, r)`` are used.
    ``_dt`` : float
        Duration of one control step in seconds.

    Examples
    --------
    A backend whose robots ignore each other and the walls, but fall into holes; see the
    package's guide, :mod:`pointnav_core.backends.kit`, for the walk-through:

    >>> from pointnav_core.backends.kit import FloorGrid, RobotState, check_load, drive_arc
    >>> class Walker(RobotState):
    ...     __slots__ = ("x", "y", "yaw")
    >>> class Ghosts(RobotStateBackend):
    ...     def load(self, scene, robots, action_frequency=10.0):
    ...         specs, n_floors, self._dt = check_load(scene, robots, action_frequency)
    ...         self._floors = [
    ...             FloorGrid(scene.floors[f], scene.get_floor_height(f)) for f in range(n_floors)
    ...         ]
    ...         self._robots = [Walker(spec) for spec in specs]
    ...         for rb in self._robots:
    ...             rb.x = rb.y = rb.yaw = 0.0
    ...             rb.z = self._floors[0].height
    ...     def _pose(self, rb):
    ...         return rb.x, rb.y, rb.yaw
    ...     def _place(self, rb, x, y, yaw):
    ...         rb.x, rb.y, rb.yaw = x, y, yaw
    ...     def step(self, actions):
    ...         dt = self._dt
    ...         for rb in self._start_step(actions):
    ...             vx, vy, w = rb.cmd
    ...             dx, dy = drive_arc(rb.yaw, vx, vy, w, dt)
    ...             rb.x, rb.y, rb.yaw = rb.x + dx, rb.y + dy, rb.yaw + w * dt
    ...             rb.vel = (dx / dt, dy / dt, 0.0, w)
    ...             if self._floors[rb.floor].is_void(rb.x, rb.y):
    ...                 self._fall(rb, first=True, planar=(dx / dt, dy / dt, w))
    >>> from pointnav_core.backends.protocol import RobotSpec
    >>> from pointnav_core.scenes import Scene
    >>> backend = Ghosts()
    >>> backend.load(Scene.from_array(np.zeros((10, 10), np.uint8), 0.5), [RobotSpec()])
    >>> backend.land(0, 0, (1.0, 1.0), (0.0, 0.0, 0.0, 1.0))
    >>> backend.step({0: [1.0, 0.0]})
    >>> backend.get_pose(0)[0].tolist(), backend.get_velocity_floats(0)
    ([1.05, 1.0, 0.0], (0.5, 0.0, 0.0, 0.0, 0.0, 0.0))
    >>> backend.in_contact(1)
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: idn must be in [0, 1), got 1
    """

    #: Overlap (m) up to which two robots count as touching in is_valid_pose.
    touch_tolerance: float = TOUCH_TOL

    _robots: list[Any]
    _floors: list[Any]
    _dt: float

    def __init__(self, *, fall_speed: float = 1.0) -> None:
        fall_speed_f = float(fall_speed)
        if not math.isfinite(fall_speed_f) or fall_speed_f <= 0.0:
            raise ArgumentError(f"fall_speed must be a finite number > 0 (m/s), got {fall_speed!r}")
        self.fall_speed = fall_speed_f
        self._floors = []
        self._robots = []
        self._dt = 0.1

    @property
    def n_robots(self) -> int:
        """Number of robots loaded (0 before :meth:`load`)."""
        return len(self._robots)

    @property
    def action_frequency(self) -> float:
        """Control steps per second (Hz)."""
        return 1.0 / self._dt

    def _robot(self, idn: int) -> Any:
        """Robot ``idn``'s state; raises naming ``idn`` (RuntimeError before :meth:`load`)."""
        robots = self._robots
        if type(idn) is int and 0 <= idn < len(robots):
            return robots[idn]  # the common case, checked without a call
        if not robots and _is_index(idn):
            raise TaskStateError("no robots: call load(scene, robots) first")
        return robots[check_index(idn, len(robots), name="idn", what="robot")]

    def _floor(self, floor: int) -> Any:
        """Floor ``floor``'s object from ``_floors``; raises naming ``floor``."""
        return self._floors[check_index(floor, len(self._floors), name="floor", what="floor")]

    def _pose(self, rb: Any) -> tuple[float, float, float]:
        """Robot ``rb``'s planar pose ``(x, y, yaw)``, in metres and radians (a hook)."""
        raise NotImplementedError(f"{type(self).__name__} must implement _pose(rb)")

    def _place(self, rb: Any, x: float, y: float, yaw: float) -> None:
        """Put robot ``rb`` at ``(x, y)`` heading ``yaw`` (a hook).

        Called by :meth:`land` and :meth:`set_pose` after ``rb``'s ``floor``, ``z`` and
        ``placed`` are set and :meth:`RobotState.at_rest` has stopped it.
        """
        raise NotImplementedError(
            f"{type(self).__name__} must implement _place(rb, x, y, yaw)"
        )

    def reset(self) -> None:
        """Return every robot to its state after :meth:`load`, keeping its pose.

        Velocities and contact flags become zero, falls end, and every robot is present
        again but unplaced: it takes part in no collision until :meth:`land` or
        :meth:`set_pose` places it, so that the task can place robots one by one.
        """
        for rb in self._robots:
            rb.present = True
            rb.placed = False
            rb.at_rest()

    def land(self, idn: int, floor: int, position: ArrayLike, orientation: ArrayLike) -> None:
        """Place robot ``idn`` at rest on ``floor`` (see :meth:`Backend.land`).

        x, y come from ``position`` (a z is ignored: z becomes the floor's height), and
        only the heading (yaw) of ``orientation`` matters.
        """
        rb = self._robot(idn)
        fl = self._floor(floor)
        xy = parse_position(position, allow_2d=True)
        yaw = parse_orientation(orientation)
        rb.floor = int(floor)
        rb.z = fl.height
        rb.placed = True
        rb.at_rest()
        self._place(rb, xy[0], xy[1], yaw)

    def set_pose(self, idn: int, position: ArrayLike, orientation: ArrayLike) -> None:
        """Teleport robot ``idn`` (at rest) to world ``position`` and ``orientation``.

        ``position`` is world (x, y, z) in metres; the robot stays on its floor (use
        :meth:`land` to change floors). The backend is planar, so only the heading (yaw)
        of the ``(x, y, z, w)`` quaternion ``orientation`` is kept.
        """
        rb = self._robot(idn)
        x, y, z = parse_position(position)
        yaw = parse_orientation(orientation)
        rb.z = z
        rb.placed = True
        rb.at_rest()
        self._place(rb, x, y, yaw)

    def get_pose(self, idn: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Return robot ``idn``'s world position (3,) in metres and orientation (4,).

        The orientation is the planar quaternion ``(0, 0, sin(yaw/2), cos(yaw/2))`` with
        yaw in [-pi, pi], so its w is >= 0.
        """
        rb = self._robot(idn)
        x, y, yaw = self._pose(rb)
        return np.array((x, y, rb.z)), planar_quat(yaw)

    def planar_pose(self, idn: int) -> tuple[float, float, float]:
        """Robot ``idn``'s planar pose ``(x, y, yaw)`` (m, m, rad) as the backend holds it,
        without the quaternion round trip of :meth:`get_pose` (the batched engine's pools)."""
        return self._pose(self._robot(idn))

    def get_pose_floats(self, idn: int) -> tuple[float, ...]:
        """Return :meth:`get_pose`'s seven numbers as a tuple of floats, without arrays.

        ``(x, y, z, qx, qy, qz, qw)``: the float twin of :meth:`get_pose` (see
        :data:`~pointnav_core.backends.protocol.FLOAT_TWINS`), which the task reads on every step.
        """
        rb = self._robot(idn)
        x, y, yaw = self._pose(rb)
        return (x, y, rb.z, *planar_quat_floats(yaw))

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
            True when the disc misses the floor's blocked set (``FloorGrid.clear``: every
            OBSTACLE and VOID cell square, everything off the map and the floor plan's
            obstacle polygons; touching within 1e-9 m is fine), exactly as the task and
            the planner decide, and it overlaps no other present, placed, non-falling
            robot on that floor by more than :attr:`touch_tolerance`.
        """
        rb = self._robot(idn)
        fl = self._floors[rb.floor] if floor is None else self._floor(floor)
        xy = parse_position(position, allow_2d=True)
        if orientation is not None:
            parse_orientation(orientation)
        x, y = xy[0], xy[1]
        if not fl.clear(x, y, rb.radius):
            return False
        index = rb.floor if floor is None else int(floor)
        others = []
        for other in self._robots:
            if other is not rb and other.floor == index and other.solid():
                ox, oy, _ = self._pose(other)
                others.append((ox, oy, other.radius))
        return not robots_overlap(x, y, rb.radius, others, self.touch_tolerance)

    def _start_step(self, actions: Mapping[int, ArrayLike]) -> list[Any]:
        """The start of every :meth:`step`; returns the robots free to move, in order.

        Sets each robot's ``cmd`` from its action (:func:`body_command`; zero without
        one) and clears its contact flag; a robot that is absent or unplaced gets zero
        velocity, a falling one falls one more step (:meth:`_fall`). The others (present,
        placed and not falling) get their ``travel``, the length of their commanded
        motion over the step, and are returned, for the subclass to move. A bad action or
        index raises (ValueError, TypeError) before any of that but the commands.
        """
        robots = self._robots
        for rb in robots:
            rb.cmd = _NO_COMMAND
        for idn, action in actions.items():
            rb = self._robot(idn)
            v = rb.spec.scale_action_floats(action)  # body_command, inlined: a hot path
            rb.cmd = v if len(v) == 3 else (v[0], 0.0, v[1])
        dt = self._dt
        free = []
        for rb in robots:
            rb.contact = False
            if not (rb.present and rb.placed):
                rb.vel = _STILL
            elif rb.falling:
                self._fall(rb, first=False)
            else:
                vx, vy, _ = rb.cmd
                rb.travel = (math.hypot(vx, vy) if vy else abs(vx)) * dt
                free.append(rb)
        return free

    def get_velocity(self, idn: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Return robot ``idn``'s world linear (3,) m/s and angular (3,) rad/s velocity.

        These are the effective velocities of the last step: displacement and yaw change
        divided by the step's duration (zero after load, reset, land and set_pose).
        """
        rb = self._robot(idn)
        vx, vy, vz, wz = rb.vel
        return np.array((vx, vy, vz)), np.array((0.0, 0.0, wz))

    def get_velocity_floats(self, idn: int) -> tuple[float, ...]:
        """Return :meth:`get_velocity`'s six numbers as a tuple of floats, without arrays.

        ``(vx, vy, vz, wx, wy, wz)``: the float twin of :meth:`get_velocity` (see
        :data:`~pointnav_core.backends.protocol.FLOAT_TWINS`), which the task reads on every step.
        """
        vx, vy, vz, wz = self._robot(idn).vel
        return vx, vy, vz, 0.0, 0.0, wz

    def get_robot_floor(self, idn: int) -> int:
        """The floor robot ``idn`` was last landed on (0 until then)."""
        return self._robot(idn).floor

    def in_contact(self, idn: int) -> bool:
        """Whether robot ``idn`` hit or pushed against an obstacle or robot in the last step."""
        return self._robot(idn).contact

    def set_present(self, idn: int, present: bool) -> None:
        """Take robot ``idn`` out of the world (``False``) or bring it back (``True``).

        An absent robot keeps its pose (and a fall in progress) but is not moved by
        :meth:`step`, has no velocity and collides with nothing; bringing it back does not
        check whether its pose is still free.
        """
        rb = self._robot(idn)
        rb.present = bool(present)
        if not rb.present:
            rb.contact = False
            rb.vel = _STILL

    def is_present(self, idn: int) -> bool:
        """Whether robot ``idn`` is in the world."""
        return self._robot(idn).present

    def _fall(
        self, rb: Any, *, first: bool, planar: tuple[float, float, float] = (0.0, 0.0, 0.0)
    ) -> None:
        """Advance robot ``rb``'s fall by one control step: z drops, ``vel`` is the drop's.

        On the ``first`` step the robot starts falling at ``fall_speed`` and drops at
        least 0.05 m (so the fall shows at any rate); then gravity accelerates it.
        ``planar`` is the step's ``(vx, vy, wz)`` before the fall began (zero on the later
        steps of a fall), kept in ``vel`` beside the drop's vz.
        """
        dt = self._dt
        if first:
            rb.falling = True
            rb.fall_speed = self.fall_speed
        v0 = rb.fall_speed
        drop = v0 * dt + 0.5 * _GRAVITY * dt * dt
        if first and drop < _MIN_FIRST_DROP:
            drop = _MIN_FIRST_DROP
        rb.fall_speed = v0 + _GRAVITY * dt
        rb.z -= drop
        rb.vel = (planar[0], planar[1], -drop / dt, planar[2])
