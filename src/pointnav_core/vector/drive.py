"""The drive of the batched engines: commands, arcs and sub-steps, as the kinematic backend.

Both drives of :class:`~pointnav_core.backends.robot_spec.RobotSpec` run here as arrays: an action
in ``[-1, 1]`` becomes the body-frame command ``(vx, vy, w)`` (m/s, m/s, rad/s) exactly as
:meth:`RobotSpec.scale_action` clips and scales it (a differential drive's ``(v, w)`` is
``(v, 0, w)``, as :func:`~pointnav_core.backends.kit.body_command` makes it), and the
command moves the robot by the exact arc of
:func:`~pointnav_core.backends.kit.drive_arc`.

A robot near something (the engine's slow path) advances as the backend's ``_slow_step``
does: in ``n`` equal sub-steps, ``n`` the backend's count (the step's travel over half a
cell, its turn over 0.25 rad, the most of any slow robot of the world), each one chord
resolved for contacts, the robot's heading turned after it, and a robot whose centre is
over VOID after a sub-step out of the later ones (it begins to fall). At any control
rate: a 0.5 m/s robot at 10 Hz on a 0.05 m map takes two sub-steps near a wall, on a
0.03 m map four, as the backend does.

Examples
--------
>>> import numpy as np
>>> vx, vy, w = body_command(np, np.array([[1.0, 0.0, 0.0]]), 0.5, 1.5, holonomic=True)
>>> [round(float(v[0]), 12) for v in arc(np, np.array([np.pi / 2]), vx, vy, w, 0.1)]  # +y at yaw 90 deg
[0.0, 0.05]
>>> body_command(np, np.array([[2.0, -0.5]]), 0.5, 1.5, holonomic=False)[2].tolist()
[-0.75]
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import ArgumentError

__all__ = ["MAX_TURN", "arc", "body_command", "drive_of", "sub_steps", "substep_drive", "travel"]

#: rad per sub-step, the kinematic backend's: a control step may turn this much without sub-steps.
MAX_TURN = 0.25
_MAX_SUBSTEPS = 1024  # the kinematic backend's cap


def drive_of(specs: Sequence[RobotSpec], name: str = "robot") -> str:
    """The one drive of ``specs``; ValueError naming ``name`` when they mix drives.

    The batched engines take one action array, of one ``action_dim``, for all robots.

    Examples
    --------
    >>> drive_of([RobotSpec(drive="holonomic")] * 2)
    'holonomic'
    >>> drive_of([RobotSpec(), RobotSpec(drive="holonomic")])
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: robot: every robot must have the same drive in the batched engine (one action array), got ['differential', 'holonomic']
    """
    drives = sorted({spec.drive for spec in specs})
    if len(drives) > 1:
        raise ArgumentError(
            f"{name}: every robot must have the same drive in the batched engine (one action array), got {drives}"
        )
    return drives[0]


def body_command(xp: Any, act: Any, vmax: Any, wmax: Any, holonomic: bool) -> tuple[Any, Any, Any]:
    """The body-frame command of actions ``act`` (``(..., 2)`` or ``(..., 3)``, in ``[-1, 1]``).

    Parameters
    ----------
    xp : module
        numpy or torch.
    act : float array (..., action_dim)
        ``(v, w)`` or ``(vx, vy, w)``; values beyond ``[-1, 1]`` are clipped.
    vmax, wmax : float or float array broadcasting over ``act[..., 0]``
        Top speed (m/s) and yaw rate (rad/s).
    holonomic : bool
        Whether ``act`` holds ``(vx, vy, w)``.

    Returns
    -------
    vx, vy, w : float arrays
        Velocities ahead and to the left (m/s, robot frame) and the yaw rate (rad/s), as
        :meth:`RobotSpec.scale_action` gives them (``vy`` zero for a differential drive).
    """

    def scale(v: Any, top: Any) -> Any:
        return xp.where(v >= 1.0, top, xp.where(v <= -1.0, -top, v * top))

    vx = scale(act[..., 0], vmax)
    if holonomic:
        return vx, scale(act[..., 1], vmax), scale(act[..., 2], wmax)
    return vx, xp.zeros_like(vx), scale(act[..., 1], wmax)


def arc(xp: Any, yaw: Any, vx: Any, vy: Any, w: Any, h: Any) -> tuple[Any, Any]:
    """The displacement (m) of ``h`` seconds of body command ``(vx, vy, w)`` from heading ``yaw``.

    :func:`~pointnav_core.backends.kit.drive_arc` as arrays: the integral of
    ``R(yaw + w t) (vx, vy)`` over ``[0, h]``, with the same expressions in the same order.
    """
    half = 0.5 * w * h
    safe = xp.where(half != 0.0, half, 1.0)
    s = h * xp.where(half != 0.0, xp.sin(safe) / safe, 1.0)
    mid = yaw + half
    c, sn = xp.cos(mid), xp.sin(mid)
    return s * (vx * c - vy * sn), s * (vx * sn + vy * c)


def travel(xp: Any, vx: Any, vy: Any, dt: float) -> Any:
    """The length (m) of a command's motion over ``dt`` s: the backend's ``rb.travel``."""
    return xp.where(vy != 0.0, xp.hypot(vx, vy), xp.abs(vx)) * dt


def sub_steps(xp: Any, length: Any, w: Any, dt: float, res: Any) -> Any:
    """The backend's sub-step count of each robot's slow step, float array >= 1.

    ``length`` is the step's travel (m, :func:`travel`), ``w`` the yaw rate (rad/s) and
    ``res`` the cell size (m) of the robot's floor; a world of several slow robots takes
    the most of theirs.
    """
    need = xp.maximum(length / (0.5 * res), xp.abs(w) * dt / MAX_TURN)
    return xp.minimum(xp.maximum(xp.ceil(need), xp.ones_like(need)), xp.zeros_like(need) + _MAX_SUBSTEPS)


def substep_drive(
    xp: Any,
    start: tuple[Any, Any, Any],
    command: tuple[Any, Any, Any],
    n_sub: Any,
    dt: float,
    move: Callable[[Any, Any, Any, Any, Any], tuple[Any, Any, Any]],
    is_void: Callable[[Any, Any], Any],
    whole: tuple[Any, Any] | None = None,
) -> tuple[Any, Any, Any, Any, Any]:
    """Advance slow robots in their sub-steps, as the backend's ``_slow_step``.

    Parameters
    ----------
    xp : module
        numpy or torch.
    start : tuple of float arrays
        ``x``, ``y`` (m) and ``yaw`` (rad) at the start of the step, all of one shape.
    command : tuple of float arrays
        ``vx``, ``vy`` (m/s, robot frame) and ``w`` (rad/s), same shape.
    n_sub : float array, same shape
        Each robot's sub-steps (its world's count, :func:`sub_steps`); 0 for a robot that
        does not take part (it neither moves nor is moved).
    dt : float
        The control step (s).
    move : callable
        ``move(x, y, mx, my, part) -> (x, y, contact)``: the contact resolver, moving the
        robots of mask ``part`` together by their chords ``(mx, my)`` (m); the others
        neither move nor block.
    is_void : callable
        ``is_void(x, y)``: whether each position is over VOID or off the map.
    whole : tuple of float arrays, optional
        The chord ``arc(yaw, vx, vy, w, dt)`` of the whole step, if the caller has it: when
        no robot takes more than one sub-step it is the first sub-step's (the same
        expressions on the same numbers), so it is not computed again.

    Returns
    -------
    x, y, yaw : float arrays
        The pose after the step (m, rad).
    fell : bool array
        The robots that began to fall (they stopped at the end of their sub-step).
    contact : bool array
        Whether a robot was blocked, or blocked another, in any sub-step.
    """
    x, y, yaw = start
    vx, vy, w = command
    h = dt / xp.where(n_sub > 0.0, n_sub, 1.0)
    still = (vx == 0.0) & (vy == 0.0)
    fell = xp.zeros_like(x) > 1.0
    contact = fell
    k = 0
    while True:
        part = (n_sub > k) & ~fell
        if not bool(part.any()):
            break
        one = k == 0 and whole is not None and bool((n_sub <= 1.0).all())
        mx, my = whole if one else arc(xp, yaw, vx, vy, w, h)
        zero = xp.zeros_like(mx)
        mx, my = xp.where(part & ~still, mx, zero), xp.where(part & ~still, my, zero)
        nx, ny, c = move(x, y, mx, my, part)
        x, y = xp.where(part, nx, x), xp.where(part, ny, y)
        contact = contact | (c & part)
        fell = fell | (part & is_void(x, y))
        yaw = xp.where(part, yaw + w * h, yaw)
        k += 1
    return x, y, yaw, fell, contact
