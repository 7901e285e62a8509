"""Discrete actions in the batched engine: Habitat's actions as batched control steps.

A discrete action (:mod:`pointnav_core.task.actions`) is a velocity command held for a number
of control steps, cut short by a contact. The single env runs these control steps one by
one for its one robot; here every world runs its action's control steps together: sub-step
``k`` advances, with one batched control step, the worlds whose action has more than ``k``
steps and that have not touched anything yet. The others do not move in that sub-step
(their pose, height and velocities are kept as they are), so that every world ends exactly
where its single env ends. The loop is over sub-steps (at most five with the defaults),
never over worlds.

With several robots per world (``run(..., acting=...)``) the rule is the multi-robot
env's: a world takes as many control steps as its robots' longest action; in each, the
robots whose action lasts and that have touched nothing drive, the others get no command
(they stand, still block, and can be touched).

Examples
--------
>>> from pointnav_core.task.actions import DiscreteActions
>>> from pointnav_core.backends.protocol import RobotSpec
>>> from pointnav_core.vector.xp import make_arrays
>>> plan = DiscretePlan(DiscreteActions(), RobotSpec(), 10.0, make_arrays("numpy"))
>>> plan.steps.tolist(), plan.n, plan.max_steps
([5, 2, 2, 1], 4, 5)
>>> plan.check(np.array([0, 3]), 2).tolist()
[0, 3]
>>> plan.check(np.array([0.0, 3.0]), 2)
Traceback (most recent call last):
...
pointnav_core.errors.ArgumentError: actions must be integers in [0, 4) (discrete actions), got dtype float64
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pointnav_core.errors import ArgumentError
from pointnav_core.task.actions import STOP, DiscreteActions
from pointnav_core.vector.state import Motion, motion_where
from pointnav_core.vector.xp import Arrays

__all__ = ["DiscretePlan"]


class DiscretePlan:
    """The discrete action set of a batched engine, as arrays indexed by action.

    Parameters
    ----------
    actions : DiscreteActions
        The action set (as the single env's ``discrete_actions`` makes it).
    robot : RobotSpec or sequence of RobotSpec
        The robot (top speeds and drive; a holonomic command is ``(vx, 0, w)``), or one
        per robot of a world: then every robot has its own commands and control steps per
        action (a slower robot holds MOVE_FORWARD for more steps), as in the multi-robot env.
    action_frequency : float
        Control steps per second (Hz).
    arrays : Arrays
        The engine's array namespace and device.

    Attributes
    ----------
    commands : array, shape (n, action_dim), or (R, n, action_dim) with one robot spec per robot
        Each action's command in ``[-1, 1]`` units (forward, yaw rate; a holonomic robot's
        has a zero sideways speed between them).
    steps : array of int, shape (n,), or (R, n) with one robot spec per robot
        Each action's control steps.
    n : int
        Number of actions.
    max_steps : int
        The most control steps any action takes (of any robot).
    stop : int or None
        The index of STOP, or None when STOP is not an action.

    Examples
    --------
    >>> from pointnav_core.backends.protocol import RobotSpec
    >>> from pointnav_core.vector.xp import make_arrays
    >>> slow = RobotSpec(max_linear_velocity=0.25)
    >>> DiscretePlan(DiscreteActions(), [RobotSpec(), slow], 10.0, make_arrays("numpy")).steps.tolist()
    [[5, 2, 2, 1], [10, 2, 2, 1]]
    """

    def __init__(self, actions: DiscreteActions, robot: Any, action_frequency: float, arrays: Arrays) -> None:
        per_robot = isinstance(robot, (list, tuple))
        plans = [actions.commands(spec, action_frequency) for spec in (robot if per_robot else [robot])]
        self.arrays = arrays
        self.actions = actions
        commands = np.stack([np.stack([command for command, _ in plan]) for plan in plans])
        steps = np.array([[n_steps for _, n_steps in plan] for plan in plans], np.int64)
        self.commands = arrays.asarray(commands if per_robot else commands[0])
        self.steps = arrays.asarray(steps if per_robot else steps[0], arrays.i64)
        # Gathers (robot, action) with several robots: robot ids (1, R) beside the actions (W, R).
        self._robots = arrays.asarray(np.arange(len(plans)).reshape(1, -1), arrays.i64) if per_robot else None
        self.n = len(plans[0])
        self.max_steps = int(steps.max())
        self.stop = STOP if actions.stop else None

    def check(self, actions: Any, num_envs: int, n_robots: int | None = None) -> Any:
        """``actions`` as an int64 array ``(num_envs,)``, or ``(num_envs, n_robots)`` with
        several robots per world; ValueError naming ``actions`` if bad.

        Takes shape ``(num_envs,)`` or ``(num_envs, 1)`` (``(num_envs, n_robots)`` when
        ``n_robots`` is given), of an integer dtype (numpy, torch or a list of Python ints),
        every value in ``[0, n)``.
        """
        a, n = self.arrays, self.n
        if isinstance(actions, (list, tuple)):
            actions = np.asarray(actions)
        shape = tuple(getattr(actions, "shape", ()))
        if n_robots is None:
            want: tuple[tuple[int, ...], ...] = ((num_envs,), (num_envs, 1))
            words = f"({num_envs},) or ({num_envs}, 1)"
        else:
            want, words = ((num_envs, n_robots),), f"({num_envs}, {n_robots})"
        if shape not in want:
            raise ArgumentError(f"actions must have shape {words} (discrete actions), got {shape}")
        dtype = getattr(actions, "dtype", None)
        if not _is_integer_dtype(dtype):
            raise ArgumentError(f"actions must be integers in [0, {n}) (discrete actions), got dtype {dtype}")
        arr = a.asarray(actions, a.i64).reshape(want[0])
        if bool(((arr < 0) | (arr >= n)).any()):
            bad = a.numpy(arr)
            bad = bad[(bad < 0) | (bad >= n)]
            raise ArgumentError(f"actions must be integers in [0, {n}) (discrete actions), got {bad[:5].tolist()}")
        return arr

    def run(self, env: Any, index: Any, acting: Any = None) -> tuple[dict[str, Any], Any, Any]:
        """Run each world's action (or each robot's) as batched control steps, from ``env``'s state.

        Parameters
        ----------
        env : VectorPointNavEnv
            The engine; its ``drive(commands, state)`` advances every world one control
            step from ``state`` without committing it (commands in ``[-1, 1]`` units, one
            per world, or per robot with several robots per world).
        index : array of int, shape (num_envs,) or (num_envs, n_robots)
            Each world's (robot's) action (checked by :meth:`check`).
        acting : array of bool, shape (num_envs, n_robots), optional
            With several robots per world: the robots that are agents. Then, as in the
            multi-robot env, a world runs as many control steps as its longest action;
            in each, the robots whose action lasts and has touched nothing get its
            command, the others none (they stand, and can still be touched), and a
            robot's contact counts in any of them.

        Returns
        -------
        state : Motion
            The worlds' (robots') pose, height and velocities after their actions.
        contact : array of bool
            Whether any of a world's (robot's) control steps touched something.
        stopped : array of bool or None
            The worlds (robots) that called STOP, or None without STOP.
        """
        a, xp = self.arrays, self.arrays.xp
        if self._robots is None:
            command, steps = self.commands[index], self.steps[index]
        else:  # one plan per robot: (robot, action) pairs
            command, steps = self.commands[self._robots, index], self.steps[self._robots, index]
        state: Motion = env.state
        contact = xp.zeros_like(index) > 0
        for k in range(self.max_steps):
            lasts = steps > k
            if acting is None:
                # A world moves in sub-step k while its action lasts and it has touched nothing.
                active = running = lasts & ~contact
            else:
                # A world steps while any robot's action lasts; only those not yet in contact drive.
                lasts = lasts & acting
                running = lasts & ~contact
                active = lasts.any(-1)[:, None]
            if not a.any(active):
                break
            # A falling robot ignores its command and drops, faster each step (env.drive, vector.falls).
            moved, touched = env.drive(xp.where(running[..., None], command, 0.0 * command), state)
            state = motion_where(xp, active, moved, state)
            contact = contact | (active & touched)
            if env.crowd is not None:  # the crowd walks each control step of the worlds still stepping
                env.crowd.step(state, env.dt, active.reshape(active.shape[0], -1).any(-1))
        stopped = None if self.stop is None else index == self.stop
        return state, contact, stopped


def _is_integer_dtype(dtype: Any) -> bool:
    if dtype is None:
        return False
    if isinstance(dtype, np.dtype):
        return dtype.kind in "iu"
    # torch: an integer dtype is neither floating, complex nor bool.
    is_float = getattr(dtype, "is_floating_point", True)
    is_complex = getattr(dtype, "is_complex", True)
    return not is_float and not is_complex and str(dtype) != "torch.bool"
