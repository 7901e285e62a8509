"""Termination conditions of a point-navigation episode: small objects the task composes.

A condition is asked once per control step, after the backend has moved the robots, whether
the episode is over. It answers ``(done, success)``. Conditions keep their own per-episode
state (counters), which :meth:`~TerminationCondition.reset` clears at the start of every
episode, so the first episode and later ones behave the same.

================  ===================  =======  ==========  ==================================
class             name                 success  truncation  done when
================  ===================  =======  ==========  ==================================
MaxCollision      ``"max_collision"``  no       no          contact steps > ``max_collisions``
Timeout           ``"timeout"``        no       yes         steps taken == ``max_steps``
Falling           ``"falling"``        no       no          z < floor height - ``fall_height``
PointGoal         ``"pointgoal"``      yes      no          xy distance < ``goal_tolerance``
================  ===================  =======  ==========  ==================================

:class:`PedestrianCollision` (``"pedestrian_collision"``, failure: the robot touched a
pedestrian) is not among the task's defaults; the envs add it for ``pedestrians={...,
"end_on_collision": True}``.

What a condition may read
-------------------------
The task refreshes a per-step snapshot *before* it asks any condition, so that the backend
is queried once per step however many conditions read it: ``task.robot_idn``,
``task.robot_xyz`` (the robot's position this step, a tuple of floats in metres),
``task.in_contact`` (``env.backend.in_contact(task.robot_idn)`` for this step),
``task.floor_height`` (m) and ``task.goal_xy`` (tuple of floats, m). A condition may also
use ``env.backend`` directly. To write your own, subclass :class:`TerminationCondition` and
override :meth:`~TerminationCondition.terminate`.

Examples
--------
>>> import types
>>> task = types.SimpleNamespace(robot_xyz=(1.0, 0.0, 0.0), goal_xy=(1.3, 0.4))
>>> goal = PointGoal(goal_tolerance=0.5)
>>> goal.reset(task, env=None)
>>> goal.step(task, env=None, action=None)  # 0.5 m away: not strictly below 0.5
(False, False)
>>> task.robot_xyz = (1.1, 0.1, 0.0)
>>> goal.step(task, env=None, action=None)
(True, True)
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from pointnav_core.utils import validation

__all__ = [
    "TerminationCondition",
    "MaxCollision",
    "Timeout",
    "Falling",
    "PointGoal",
    "PedestrianCollision",
]


def _check_count(name: str, value: Any, minimum: int) -> int:
    """Return ``value`` as an int ``>= minimum``, or raise ArgumentError (a ValueError) naming ``name``.

    Booleans and non-integral numbers are refused (``True`` is not a step count).

    Examples
    --------
    >>> _check_count("max_steps", 0, minimum=1)
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: max_steps must be an integer >= 1, got 0
    """
    return validation.integer(name, value, minimum=minimum)


def _check_length(name: str, value: Any, unit: str = "m") -> float:
    """Return ``value`` as a finite float ``>= 0``, or raise ArgumentError (a ValueError) naming ``name``.

    Examples
    --------
    >>> _check_length("fall_height", -1)
    Traceback (most recent call last):
    ...
    pointnav_core.errors.ArgumentError: fall_height must be a finite number >= 0 (m), got -1
    """
    return validation.real(name, value, minimum=0.0, unit=unit)


class TerminationCondition:
    """Base class: one reason an episode can end.

    Subclasses set the class attributes and implement :meth:`terminate` (a bool), or
    override :meth:`step` whole (the built-in conditions do, to keep the per-step path
    short); either way ``step`` must set ``done`` and ``success``.

    Attributes
    ----------
    name : str
        Key of the condition in the task's ``termination_conditions`` and in
        ``info["termination_conditions"]``.
    is_success : bool
        Whether the episode counts as a success when this condition ends it.
    is_truncation : bool
        Whether ending the episode here is a *truncation* (a time limit, not a terminal
        state of the task): it sets Gymnasium's ``truncated`` instead of ``terminated``.
    removes_robot : bool
        Whether the robot leaves the world when this condition ends its episode (it fell):
        a multi-robot env then takes it out of the backend even when finished robots
        otherwise stay as obstacles.
    done, success : bool
        This condition's result at the last step (False after :meth:`reset`).
    """

    name: ClassVar[str] = "termination"
    is_success: ClassVar[bool] = False
    is_truncation: ClassVar[bool] = False
    removes_robot: ClassVar[bool] = False

    def __init__(self) -> None:
        self.done = False
        self.success = False

    def reset(self, task: Any, env: Any) -> None:
        """Clear the per-episode state; called by the task at the end of its reset."""
        self.done = False
        self.success = False

    def terminate(self, task: Any, env: Any, action: Any) -> bool:
        """Whether the episode ends at this step (the backend has already moved)."""
        raise NotImplementedError(f"{type(self).__name__} must implement terminate() or step()")

    def step(self, task: Any, env: Any, action: Any) -> tuple[bool, bool]:
        """Evaluate the condition for this step.

        Returns
        -------
        done : bool
            Whether this condition ends the episode now.
        success : bool
            ``done and is_success``.
        """
        done = bool(self.terminate(task, env, action))
        self.done = done
        self.success = done and self.is_success
        return done, self.success

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class MaxCollision(TerminationCondition):
    """Ends the episode once the robot has touched something on too many steps (failure).

    A per-episode counter goes up by one on every step in which
    ``env.backend.in_contact(task.robot_idn)`` is True (an obstacle or another robot; the
    floor never counts). The episode ends on the step the counter *exceeds*
    ``max_collisions``: with ``max_collisions=0`` the first contact ends it.

    Parameters
    ----------
    max_collisions : int
        Contact steps tolerated, >= 0.

    The count is the task's own (``task.collisions``, which ``info["collisions"]``
    reports), so the two never disagree.
    """

    name = "max_collision"

    def __init__(self, max_collisions: int = 500) -> None:
        super().__init__()
        self.max_collisions = _check_count("max_collisions", max_collisions, minimum=0)

    @staticmethod
    def value(collisions: Any, max_collisions: Any) -> Any:
        """Whether one robot's episode ends, or a batch's (the batched engine calls it)."""
        return collisions > max_collisions

    def step(self, task: Any, env: Any, action: Any) -> tuple[bool, bool]:
        self.done = done = self.value(task.collisions, self.max_collisions)
        return done, False

    def __repr__(self) -> str:
        return f"MaxCollision(max_collisions={self.max_collisions})"


class Timeout(TerminationCondition):
    """Ends the episode after a fixed number of steps (failure, reported as truncation).

    The count starts at 0 on every reset, so the episode ends on step ``max_steps`` in the
    first episode and in every later one.

    Parameters
    ----------
    max_steps : int
        Steps per episode, >= 1.

    The count is the task's own (``task.episode_length``, which
    ``info["episode_length"]`` reports), so the two never disagree.
    """

    name = "timeout"
    is_truncation = True

    def __init__(self, max_steps: int = 500) -> None:
        super().__init__()
        self.max_steps = _check_count("max_steps", max_steps, minimum=1)

    @staticmethod
    def value(steps: Any, max_steps: Any) -> Any:
        """Whether one robot's episode is truncated, or a batch's (the batched engine calls it)."""
        return steps >= max_steps

    def step(self, task: Any, env: Any, action: Any) -> tuple[bool, bool]:
        self.done = done = self.value(task.episode_length, self.max_steps)
        return done, False

    def __repr__(self) -> str:
        return f"Timeout(max_steps={self.max_steps})"


class Falling(TerminationCondition):
    """Ends the episode when the robot drops below its floor (failure).

    Done when the robot's z is more than ``fall_height`` below the height of the task's
    floor: ``z < floor_height - fall_height``. (The kinematic backend drops a robot whose
    centre moves over VOID by at least 0.05 m on the first step of the fall.)

    Parameters
    ----------
    fall_height : float
        Tolerated drop in metres, >= 0.
    """

    name = "falling"
    removes_robot = True

    def __init__(self, fall_height: float = 0.03) -> None:
        super().__init__()
        self.fall_height = _check_length("fall_height", fall_height)

    @staticmethod
    def value(z: Any, floor_height: Any, fall_height: Any) -> Any:
        """Whether one robot fell (heights in metres), or a batch's (the batched engine calls it)."""
        return z < floor_height - fall_height

    def step(self, task: Any, env: Any, action: Any) -> tuple[bool, bool]:
        self.done = done = self.value(task.robot_xyz[2], task.floor_height, self.fall_height)
        return done, False

    def __repr__(self) -> str:
        return f"Falling(fall_height={self.fall_height})"


class PointGoal(TerminationCondition):
    """Ends the episode when the robot reaches the goal (success).

    Done when the planar (xy) Euclidean distance from the robot to the goal is strictly
    below ``goal_tolerance``.

    Parameters
    ----------
    goal_tolerance : float
        Success radius in metres, >= 0 (0 never succeeds).
    """

    name = "pointgoal"
    is_success = True

    def __init__(self, goal_tolerance: float = 0.5) -> None:
        super().__init__()
        self.goal_tolerance = validation.goal_tolerance("goal_tolerance", goal_tolerance)

    def step(self, task: Any, env: Any, action: Any) -> tuple[bool, bool]:
        x, y, _ = task.robot_xyz
        gx, gy = task.goal_xy
        self.done = self.success = done = math.hypot(gx - x, gy - y) < self.goal_tolerance
        return done, done

    def __repr__(self) -> str:
        return f"PointGoal(goal_tolerance={self.goal_tolerance})"


class PedestrianCollision(TerminationCondition):
    """Ends the episode when the robot touches a pedestrian (failure).

    Done on a step in which ``env.pedestrian_contact(task.robot_idn)`` is True: the robot's
    disc overlapped a pedestrian's after the step (:mod:`pointnav_core.crowds`). An env
    without pedestrians never ends an episode here. ``pedestrians={"end_on_collision":
    True}`` adds it to the env's task.
    """

    name = "pedestrian_collision"

    def terminate(self, task: Any, env: Any, action: Any) -> bool:
        contact = getattr(env, "pedestrian_contact", None)
        return bool(contact(task.robot_idn)) if contact is not None else False
