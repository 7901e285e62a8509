"""Falls in the batched engine: the kinematic backend's fall, carried over control steps.

A robot whose centre ends a control step over VOID (or off the map) begins to fall: in
that step it drops by the backend's first drop, ``max(fall_speed dt + g dt^2 / 2,
0.05 m)`` with ``fall_speed`` 1 m/s, and keeps the step's planar velocities beside the
drop's ``vz``. From then on it no longer drives or blocks: every control step it drops by
``v dt + g dt^2 / 2`` at its current fall speed ``v`` (which then grows by ``g dt``), with
zero planar velocities (``RobotStateBackend._fall``). Nothing stops a fall; the task ends
the episode once ``z < floor height - fall_height``, however many steps that takes.

The engines keep each robot's fall speed in their state (``WorldState.fall_speed``, m/s;
0 while it stands). :func:`apply_falls` turns one control step of the standing robots into
the step of all of them, as arrays of any shape (numpy or torch).

Examples
--------
>>> import numpy as np
>>> from pointnav_core.vector.state import Motion
>>> zero = np.zeros(3)
>>> start = Motion(zero, zero, zero, zero, zero, zero, zero, zero, np.array([0.0, 0.0, 1.0]))
>>> standing = {"x": np.array([0.1, 0.1, 0.5]), "y": zero, "yaw": zero,
...             "vx": np.ones(3), "vy": zero, "yaw_rate": zero}
>>> began = np.array([False, True, False])  # robot 1 went over VOID, robot 2 was falling
>>> out = apply_falls(np, start, standing, began, 0.1)
>>> out.z.round(5).tolist(), out.x.tolist(), out.fall_speed.round(3).tolist()
([0.0, -0.14905, -0.14905], [0.1, 0.1, 0.0], [0.0, 1.981, 1.981])
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pointnav_core.backends.kit.base import _GRAVITY, _MIN_FIRST_DROP
from pointnav_core.vector.state import Motion

__all__ = ["FALL_SPEED", "GRAVITY", "MIN_FIRST_DROP", "apply_falls", "first_drop"]

#: m/s^2, the kinematic backend's gravity.
GRAVITY = _GRAVITY
#: m/s, the kinematic backend's default ``fall_speed`` (a fall's speed as it begins).
FALL_SPEED = 1.0
#: m, the least a robot drops in the step it begins to fall (so that a fall shows at any rate).
MIN_FIRST_DROP = _MIN_FIRST_DROP


def first_drop(dt: float) -> float:
    """How far (m) a robot drops in the control step of ``dt`` (s) in which it begins to
    fall: the kinematic backend's ``max(fall_speed dt + g dt^2 / 2, 0.05 m)``.

    Examples
    --------
    >>> round(first_drop(0.1), 5), first_drop(1 / 30)
    (0.14905, 0.05)
    """
    return max(FALL_SPEED * dt + 0.5 * GRAVITY * dt * dt, MIN_FIRST_DROP)


def apply_falls(xp: Any, start: Motion, standing: Mapping[str, Any], began: Any, dt: float) -> Motion:
    """One control step of every robot, falls included, from the standing robots' step.

    Parameters
    ----------
    xp : module
        ``numpy`` or ``torch``.
    start : Motion
        The state before the step (a :class:`~.state.WorldState` will do): its ``x``, ``y``
        (m), ``yaw`` (rad), ``z`` (m) and ``fall_speed`` (m/s, > 0 for a robot already
        falling, 0 otherwise) are read.
    standing : dict of arrays
        The step as the drive and contacts give it: ``x``, ``y``, ``yaw``, ``vx``, ``vy``
        (m/s) and ``yaw_rate`` (rad/s); entries of falling robots are ignored.
    began : array of bool
        The robots that were standing and whose centre ended this step over VOID.
    dt : float
        The control step (s).

    Returns
    -------
    Motion
        ``x``, ``y``, ``yaw``, ``vx``, ``vy``, ``yaw_rate``: the standing step, except that
        a robot already falling keeps its pose and has zero planar velocities; ``z`` (m),
        ``vz`` (m/s, the drop over ``dt``, negative) and ``fall_speed`` (m/s) after the step.
    """
    fs0, z0 = start.fall_speed, start.z
    falling = fs0 > 0.0
    zero = xp.zeros_like(z0)
    # The backend's _fall, in its own expression order: drop = v dt + g dt^2 / 2.
    drop = fs0 * dt + 0.5 * GRAVITY * dt * dt
    first = first_drop(dt)
    return Motion(
        x=xp.where(falling, start.x, standing["x"]),
        y=xp.where(falling, start.y, standing["y"]),
        yaw=xp.where(falling, start.yaw, standing["yaw"]),
        z=xp.where(falling, z0 - drop, xp.where(began, z0 - first, z0)),
        vx=xp.where(falling, zero, standing["vx"]),
        vy=xp.where(falling, zero, standing["vy"]),
        yaw_rate=xp.where(falling, zero, standing["yaw_rate"]),
        vz=xp.where(falling, -drop / dt, xp.where(began, zero - first / dt, zero)),
        fall_speed=xp.where(falling, fs0 + GRAVITY * dt, xp.where(began, zero + (FALL_SPEED + GRAVITY * dt), zero)),
    )
