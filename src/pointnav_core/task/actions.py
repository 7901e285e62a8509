"""Discrete actions, Habitat style: MOVE_FORWARD, TURN_LEFT, TURN_RIGHT and STOP.

With ``action_space="discrete"`` the environments take an integer action instead of a
velocity command:

===  ================  ==========================================================
int  name              what the robot does
===  ================  ==========================================================
0    ``MOVE_FORWARD``  drives ``forward_step`` metres straight ahead (default 0.25)
1    ``TURN_LEFT``     turns in place by ``turn_angle`` radians (default 10 deg)
2    ``TURN_RIGHT``    turns in place by ``-turn_angle``
3    ``STOP``          stands still and ends the episode (only with ``stop=True``)
===  ================  ==========================================================

How a discrete action moves the robot
-------------------------------------
Backends drive with velocities held for one control step of ``1 / action_frequency``
seconds. A discrete action is executed honestly as such commands: the fewest control steps
``n`` in which the robot can cover the move at its top speed, at the constant command that
covers it exactly in ``n`` steps (:meth:`DiscreteActions.commands`). With the default robot
(0.5 m/s, 1.5 rad/s) at 10 Hz, MOVE_FORWARD is 5 steps at full speed and a 10 deg turn 2
steps at 58 % of the top yaw rate; a kinematic backend then moves exactly 0.25 m and turns
exactly 10 deg. A move that touches something ends at that control step (the robot does not
keep pushing), and it counts as one collision for the task, whichever of its control steps
touched. STOP is one control step at rest. The task sees one step per discrete action:
``max_steps`` counts actions, as in Habitat.

Success with STOP
-----------------
With STOP in the action set, reaching the goal does not end the episode. The robot must
call STOP: the episode then ends, a success when the robot is within ``goal_tolerance`` of
the goal (Habitat's ``success_distance``), a failure otherwise
(:class:`StopAtGoal`, which replaces the task's ``pointgoal`` condition, so the
``pointgoal`` reward is paid on a successful STOP). Without STOP (``stop=False``) the
seed's rule holds: the episode succeeds the moment the robot is within tolerance.

Examples
--------
>>> from pointnav_core.backends.protocol import RobotSpec
>>> acts = DiscreteActions()
>>> acts.names
('MOVE_FORWARD', 'TURN_LEFT', 'TURN_RIGHT', 'STOP')
>>> [(cmd.round(4).tolist(), n) for cmd, n in acts.commands(RobotSpec(), 10.0)]
[([1.0, 0.0], 5), ([0.0, 0.5818], 2), ([0.0, -0.5818], 2), ([0.0, 0.0], 1)]
>>> DiscreteActions(forward_step=0.0)
Traceback (most recent call last):
...
pointnav_core.errors.ArgumentError: forward_step must be a finite number > 0 (m), got 0.0
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError
from pointnav_core.task.terminations import TerminationCondition
from pointnav_core.utils import validation

__all__ = [
    "ACTION_SPACES",
    "MOVE_FORWARD",
    "STOP",
    "TURN_LEFT",
    "TURN_RIGHT",
    "DiscreteActions",
    "StopAtGoal",
    "check_discrete_action",
    "make_discrete_actions",
]

#: The values of the envs' ``action_space`` argument.
ACTION_SPACES = ("continuous", "discrete")
MOVE_FORWARD, TURN_LEFT, TURN_RIGHT, STOP = 0, 1, 2, 3
_NAMES = ("MOVE_FORWARD", "TURN_LEFT", "TURN_RIGHT", "STOP")
# Relative slack when counting control steps, so that 0.25 m at 0.05 m per step is 5 steps.
_SLACK = 1e-9


class DiscreteActions:
    """The discrete action set and how each action becomes velocity commands.

    Parameters
    ----------
    forward_step : float
        Metres MOVE_FORWARD drives, > 0 (default 0.25, Habitat's).
    turn_angle : float
        Radians TURN_LEFT / TURN_RIGHT turn, in ``(0, pi]`` (default 10 deg, Habitat's).
    stop : bool
        Whether STOP is an action (default True); with it, success needs STOP.

    Attributes
    ----------
    names : tuple of str
        Action names by index.
    n : int
        Number of actions (4 with STOP, else 3).
    """

    def __init__(
        self, forward_step: float = 0.25, turn_angle: float = math.radians(10.0), stop: bool = True
    ) -> None:
        self.forward_step = validation.real("forward_step", forward_step, minimum=0.0, strict=True, unit="m")
        self.turn_angle = validation.real(
            "turn_angle", turn_angle, minimum=0.0, strict=True, maximum=math.pi, unit="rad"
        )
        if not isinstance(stop, (bool, np.bool_)):
            raise ArgumentError(f"stop must be True or False, got {stop!r}")
        self.stop = bool(stop)
        self.n = 4 if self.stop else 3
        self.names = _NAMES[: self.n]

    def commands(self, robot: Any, action_frequency: float) -> tuple[tuple[NDArray[np.float64], int], ...]:
        """Per action: the command in ``[-1, 1]`` units and the control steps it is held.

        Parameters
        ----------
        robot : RobotSpec
            Its top speeds and drive (a holonomic command is ``(vx, 0, w)``).
        action_frequency : float
            Control steps per second (Hz).
        """
        dt = 1.0 / float(action_frequency)
        dim = robot.action_dim
        out = []
        for distance, top, axis, sign in (
            (self.forward_step, robot.max_linear_velocity, 0, 1.0),
            (self.turn_angle, robot.max_angular_velocity, dim - 1, 1.0),
            (self.turn_angle, robot.max_angular_velocity, dim - 1, -1.0),
        ):
            per_step = top * dt
            steps = max(1, math.ceil(distance / per_step * (1.0 - _SLACK)))
            command = np.zeros(dim)
            command[axis] = sign * min(distance / (steps * per_step), 1.0)
            out.append((command, steps))
        if self.stop:
            out.append((np.zeros(dim), 1))
        return tuple(out)

    def __repr__(self) -> str:
        return (
            f"DiscreteActions(forward_step={self.forward_step:g}, "
            f"turn_angle={self.turn_angle:g}, stop={self.stop})"
        )


def make_discrete_actions(
    action_space: Any, discrete_actions: Mapping[str, Any] | DiscreteActions | None
) -> DiscreteActions | None:
    """The discrete action set of an env's arguments, or None for continuous actions.

    Raises
    ------
    ValueError
        For an ``action_space`` other than ``"continuous"`` or ``"discrete"``, an unknown
        key in ``discrete_actions``, a bad value (naming it), or ``discrete_actions`` with
        continuous actions.
    """
    if not isinstance(action_space, str) or action_space not in ACTION_SPACES:
        raise ArgumentError(f"action_space must be one of {list(ACTION_SPACES)}, got {action_space!r}")
    if action_space == "continuous":
        if discrete_actions is not None:
            raise ArgumentError('discrete_actions needs action_space="discrete"')
        return None
    if discrete_actions is None:
        return DiscreteActions()
    if isinstance(discrete_actions, DiscreteActions):
        return discrete_actions
    if not isinstance(discrete_actions, Mapping):
        raise ArgumentError(f"discrete_actions must be None or a dict, got {discrete_actions!r}")
    valid = ["forward_step", "turn_angle", "stop"]
    validation.known_keys("discrete_actions", discrete_actions, valid)
    return DiscreteActions(**discrete_actions)


def check_discrete_action(action: Any, n: int, name: str = "action") -> int:
    """Return ``action`` as an int in ``[0, n)``, or raise ArgumentError (a ValueError) naming ``name``.

    Takes a Python or numpy integer, or an integer array holding one value (as vectorised
    learners pass it); a bool, a float or anything else is an error.
    """
    value = action
    if isinstance(value, np.ndarray) and value.size == 1 and value.dtype.kind in "iu":
        value = value.reshape(()).item()
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or not 0 <= value < n:
        raise ArgumentError(f"{name} must be an integer in [0, {n}) (a discrete action), got {action!r}")
    return int(value)


class StopAtGoal(TerminationCondition):
    """Ends the episode when the robot calls STOP: a success within ``goal_tolerance``.

    Replaces the task's ``pointgoal`` condition when STOP is an action (Habitat's rule:
    ``success_distance`` is checked when the agent stops). Reads the tolerance from the task.

    Parameters
    ----------
    stop_action : int
        The action index that is STOP (default :data:`STOP`).
    """

    name = "pointgoal"
    is_success = True

    def __init__(self, stop_action: int = STOP) -> None:
        super().__init__()
        self.stop_action = int(stop_action)

    def step(self, task: Any, env: Any, action: Any) -> tuple[bool, bool]:
        stopped = isinstance(action, (int, np.integer)) and int(action) == self.stop_action
        if not stopped:
            self.done = self.success = False
            return False, False
        x, y, _ = task.robot_xyz
        gx, gy = task.goal_xy
        self.done = True
        self.success = math.hypot(gx - x, gy - y) < task.goal_tolerance
        return True, self.success

    def __repr__(self) -> str:
        return f"StopAtGoal(stop_action={self.stop_action})"
