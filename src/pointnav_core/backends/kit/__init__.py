"""The backend author's kit: what the shipped backends are built from, for a new one too.

A backend is anything that implements :class:`~pointnav_core.backends.protocol.Backend` (see
:mod:`pointnav_core.backends.protocol` for the protocol, its units and the registry). This package
holds the parts that the two shipped backends, ``kinematic`` and ``pymunk``, share, so that
a new backend writes only what is its own: how its robots move and collide.

============================  =============================================================
Name                          What it is
============================  =============================================================
:class:`RobotStateBackend`    base class: every protocol method but ``load`` and ``step``
:class:`RobotState`           one robot's spec, floor, flags, velocity and command
:class:`FloorGrid`            one floor's cells as plain numbers: point lookups, disc test
:func:`body_command`          an action as a body-frame velocity ``(vx, vy, w)``
:func:`drive_arc`             the exact motion of a constant command (both drives)
:func:`robots_overlap`        whether a disc overlaps any of some other robots' discs
:func:`check_load`            the checks of ``load``'s arguments; returns the step duration
:func:`check_index`           an index checked against a count, the error naming it
:func:`parse_position`        a world position checked, as floats
:func:`parse_orientation`     a quaternion checked, as its yaw
:func:`planar_quat`           a yaw as the quaternion ``get_pose`` returns (``w >= 0``)
:func:`planar_quat_floats`    the same as four floats, for ``get_pose_floats``
============================  =============================================================

Writing a backend with :class:`RobotStateBackend`
-------------------------------------------------
1. Subclass :class:`RobotState` for what the backend keeps per robot beyond the shared
   state: its pose (or a physics body holding it), with ``__slots__``. Extend
   :meth:`RobotState.at_rest` if that state has velocities or per-step flags of its own.
2. Subclass :class:`RobotStateBackend` and write

   - ``load(scene, robots, action_frequency)``: ``specs, n_floors, self._dt =
     check_load(...)``; ``self._floors``, one :class:`FloorGrid` (or a subclass) per
     floor of ``scene``; ``self._robots``, one robot state per spec, with ``z`` at floor
     0's height;
   - ``_pose(rb)`` returning ``(x, y, yaw)`` and ``_place(rb, x, y, yaw)``: where the
     pose lives;
   - ``step(actions)``: ``for rb in self._start_step(actions)`` (the robots free to
     move, each with its checked, scaled body-frame ``rb.cmd`` and its ``rb.travel``),
     move the robot over ``self._dt`` seconds (:func:`drive_arc` is the exact motion in
     open space), resolve contacts (setting ``rb.contact`` on both parties), set
     ``rb.vel`` to the step's displacement and yaw change over its duration, and call
     ``self._fall(rb, first=True, planar=...)`` for a robot whose centre ended over
     VOID (``FloorGrid.is_void``); robots that are absent, unplaced or already falling
     are handled by ``_start_step``.

   The base class then gives ``reset``, ``land``, ``set_pose``, ``get_pose``,
   ``get_velocity``, ``in_contact``, ``is_valid_pose`` (the floor's ``clear`` and
   :func:`robots_overlap`), presence, ``get_robot_floor`` and the float twins
   ``get_pose_floats`` and ``get_velocity_floats``. Override ``is_valid_pose`` or a
   floor's ``clear`` if the backend's obstacles are not the floor's collision geometry;
   override ``get_pose`` and ``get_pose_floats`` together, never one alone.
3. Register the class in the entry-point group ``pointnav_core.backends`` and run the
   conformance kit on it: ``python -m pointnav_core.testing NAME``, or
   :func:`pointnav_core.testing.conformance.assert_conforms` from a test.

The helpers work on plain Python floats: a backend's ``step`` runs for every robot on
every control step, and for two or three numbers numpy's per-call overhead costs more
than the arithmetic. The example backend of :class:`RobotStateBackend` (robots that
drive through walls and fall into holes) is the smallest complete one; it passes every
conformance check but those of contacts. ``pointnav_kinematic`` and ``pointnav_pymunk``
are the full ones.

>>> from pointnav_core.backends.protocol import RobotSpec
>>> body_command(RobotSpec(drive="holonomic"), [0.5, -0.5, 1.0])
(0.25, -0.25, 1.5)
"""

from pointnav_core.backends.kit.base import RobotStateBackend
from pointnav_core.backends.kit.checks import (
    check_index,
    check_load,
    parse_orientation,
    parse_position,
    planar_quat,
    planar_quat_floats,
)
from pointnav_core.backends.kit.state import RobotState, body_command, drive_arc
from pointnav_core.backends.kit.world import FloorGrid, robots_overlap

__all__ = [
    "FloorGrid",
    "RobotState",
    "RobotStateBackend",
    "body_command",
    "check_index",
    "check_load",
    "drive_arc",
    "parse_orientation",
    "parse_position",
    "planar_quat",
    "planar_quat_floats",
    "robots_overlap",
]
