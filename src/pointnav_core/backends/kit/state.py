"""One robot's state, its command, and the exact motion of its drive.

Everything here is plain Python floats: a backend runs it once per robot and step (or
sub-step), where numpy's per-call overhead would cost more than the arithmetic.
"""

from __future__ import annotations

import math

from numpy.typing import ArrayLike

from pointnav_core.backends.robot_spec import RobotSpec

__all__ = ["RobotState", "body_command", "drive_arc"]

#: The velocity of a robot at rest, ``(vx, vy, vz, wz)``, and its command ``(vx, vy, w)``.
_STILL = (0.0, 0.0, 0.0, 0.0)
_NO_COMMAND = (0.0, 0.0, 0.0)


class RobotState:
    """What a backend keeps for one robot besides its pose: spec, floor, flags, velocity.

    :class:`~pointnav_core.backends.kit.RobotStateBackend` reads and writes these
    attributes; a backend subclasses this class to add its own (its pose, a physics body),
    with ``__slots__`` of its own.

    Parameters
    ----------
    spec : RobotSpec
        The robot's size, speed limits and drive.

    Attributes
    ----------
    spec : RobotSpec
        As given.
    radius : float
        ``spec.radius``, in metres.
    holonomic : bool
        Whether ``spec.drive`` is ``"holonomic"``.
    floor : int
        The floor the robot was last landed on (0 until then).
    z : float
        World z in metres (a falling robot's drops below its floor's height).
    present : bool
        In the world (see :meth:`Backend.set_present`).
    placed : bool
        Landed or posed since the last load or reset; an unplaced robot collides with
        nothing and does not move.
    falling : bool
        Its centre went over VOID: it no longer moves in x, y and drops.
    fall_speed : float
        Downward speed of the fall in m/s.
    contact : bool
        Hit or pushed against an obstacle or a robot in the last step.
    vel : tuple of float
        World velocity of the last step, ``(vx, vy, vz, wz)`` in m/s and rad/s.
    cmd : tuple of float
        Body-frame command of the current step, ``(vx, vy, w)`` (see :func:`body_command`).
    travel : float
        Length in metres of the current step's commanded motion, ``|(vx, vy)|`` times
        the step's duration (set by ``RobotStateBackend._start_step``).

    Examples
    --------
    >>> rb = RobotState(RobotSpec(radius=0.2))
    >>> rb.radius, rb.solid()  # present but not placed yet
    (0.2, False)
    >>> rb.placed = True
    >>> rb.solid()
    True
    """

    __slots__ = (
        "spec",
        "radius",
        "holonomic",
        "floor",
        "z",
        "present",
        "placed",
        "falling",
        "fall_speed",
        "contact",
        "vel",
        "cmd",
        "travel",
    )

    def __init__(self, spec: RobotSpec) -> None:
        self.spec = spec
        self.radius = spec.radius
        self.holonomic = spec.drive == "holonomic"
        self.floor = 0
        self.z = 0.0
        self.present = True
        self.placed = False
        self.falling = False
        self.fall_speed = 0.0
        self.contact = False
        self.vel = _STILL
        self.cmd = _NO_COMMAND
        self.travel = 0.0

    def solid(self) -> bool:
        """Whether other robots can collide with this one: present, placed, not falling."""
        return self.present and self.placed and not self.falling

    def at_rest(self) -> None:
        """Stop the robot where it is: no fall, no contact, zero velocity and command.

        A subclass with more per-step state extends this (calling ``super().at_rest()``).
        """
        self.falling = False
        self.fall_speed = 0.0
        self.contact = False
        self.vel = _STILL
        self.cmd = _NO_COMMAND


def body_command(spec: RobotSpec, action: ArrayLike) -> tuple[float, float, float]:
    """Return an action's body-frame velocity ``(vx, vy, w)`` in m/s and rad/s.

    The action is checked and scaled by :meth:`RobotSpec.scale_action_floats`; a
    differential drive's ``(v, w)`` becomes ``(v, 0, w)``, so both drives integrate alike
    (:func:`drive_arc`).

    Raises
    ------
    ValueError
        If the action has the wrong shape for the drive or is not finite.

    Examples
    --------
    >>> body_command(RobotSpec(), [1.0, -0.5])
    (0.5, 0.0, -0.75)
    >>> body_command(RobotSpec(drive="holonomic"), [0.0, 2.0, 0.0])  # clipped to 1
    (0.0, 0.5, 0.0)
    """
    v = spec.scale_action_floats(action)
    return v if len(v) == 3 else (v[0], 0.0, v[1])


def drive_arc(
    yaw: float, vx: float, vy: float, w: float, h: float, velocity: bool = False
) -> tuple[float, float]:
    """The exact world motion over ``h`` seconds of a constant body-frame command.

    A robot heading ``yaw`` (rad) that holds body velocity ``(vx, vy)`` (m/s, +x ahead,
    +y left) while turning at ``w`` rad/s moves by the integral of
    ``R(yaw + w t) (vx, vy)`` over ``[0, h]``: an arc of a circle, or a straight line when
    ``w = 0``. Written with ``sin(a) / a``, ``a = w h / 2`` (the chord turns by half the
    heading change), so it stays accurate as ``w -> 0``.

    Parameters
    ----------
    yaw, vx, vy, w, h : float
        Start heading (rad), body velocity (m/s), yaw rate (rad/s), duration (s).
    velocity : bool
        False: return the displacement ``(dx, dy)`` in metres. True: return the constant
        world velocity (m/s) whose straight motion over ``h`` ends where the arc ends
        (the displacement over ``h``; for a physics engine that moves bodies straight).

    Returns
    -------
    tuple of float
        ``(dx, dy)`` in metres, or ``(ux, uy)`` in m/s.

    Examples
    --------
    >>> [round(v, 9) for v in drive_arc(0.0, 1.0, 0.0, math.pi, 1.0)]  # a half turn
    [0.0, 0.636619772]
    >>> drive_arc(0.0, 0.5, 0.0, 0.0, 2.0), drive_arc(0.0, 0.5, 0.0, 0.0, 2.0, True)
    ((1.0, 0.0), (0.5, 0.0))
    """
    a = 0.5 * w * h
    s = math.sin(a) / a if a != 0.0 else 1.0
    if not velocity:
        s = h * s
    mid = yaw + a
    c = math.cos(mid)
    sn = math.sin(mid)
    return s * (vx * c - vy * sn), s * (vx * sn + vy * c)
