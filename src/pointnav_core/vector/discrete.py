"""Discrete actions in the batched engine: Habitat's actions as batched control steps.

A discrete action (:mod:`pointnav_core.actions`) is a velocity command held for a number
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
>>> from pointnav_core.actions import DiscreteActions
>>> from pointnav_core.backend import RobotSpec
>>> from pointnav_core.vector.xp import make_arrays
>>> plan = DiscretePlan(DiscreteActions(), RobotSpec(), 10.0, make_arrays("numpy"))
>>> plan.steps.tolist(), plan.n, plan.max_steps
([5, 2, 2, 1], 4, 5)
>>> plan.check(np.array([0, 3]), 2).tolist()
[0, 3]
>>> plan.check(np.array([0.0, 3.0]), 2)
Traceback (most recent call last):
...
ValueError: actions must be integers in [0, 4) (discrete actions), got dtype float64
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pointnav_core.actions import STOP, DiscreteActions
from pointnav_core.vector.xp import Arrays

__all__ = ["DiscretePlan"]

_GRAVITY = 9.81  # m/s^2, the kinematic backend's
_FALL_SPEED = 1.0  # m/s at the start of a fall, the kinematic backend's default fall_speed
# The state a control step changes: pose, height and the backend's velocities.
MOVED = ("x", "y", "yaw", "z", "vx", "vy", "w", "vz")


class DiscretePlan:
    """The discrete action set of a batched engine, as arrays indexed by action.

    Parameters
    ----------
    actions : DiscreteActions
        The action set (as the single env's ``discrete_actions`` makes it).
    robot : RobotSpec
        The robot (top speeds and drive; a holonomic command is ``(vx, 0, w)``).
    action_frequency : float
        Control steps per second (Hz).
    arrays : Arrays
        The engine's array namespace and device.

    Attributes
    ----------
    commands : array, shape (n, action_dim)
        Each action's command in ``[-1, 1]`` units (forward, yaw rate; a holonomic robot's
        has a zero sideways speed between them).
    steps : array of int, shape (n,)
        Each action's control steps.
    n : int
        Number of actions.
    max_steps : int
        The most control steps any action takes.
    stop : int or None
        The index of STOP, or None when STOP is not an action.
    """

    def __init__(self, actions: DiscreteActions, robot: Any, action_frequency: float, arrays: Arrays) -> None:
        plan = actions.commands(robot, action_frequency)
        self.arrays = arrays
        self.actions = actions
        self.commands = arrays.asarray(np.stack([command for command, _ in plan]))
        self.steps = arrays.asarray([steps for _, steps in plan], arrays.i64)
        self.n = len(plan)
        self.max_steps = max(steps for _, steps in plan)
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
            raise ValueError(f"actions must have shape {words} (discrete actions), got {shape}")
        dtype = getattr(actions, "dtype", None)
        if not _is_integer_dtype(dtype):
            raise ValueError(f"actions must be integers in [0, {n}) (discrete actions), got dtype {dtype}")
        arr = a.asarray(actions, a.i64).reshape(want[0])
        if bool(((arr < 0) | (arr >= n)).any()):
            bad = a.numpy(arr)
            bad = bad[(bad < 0) | (bad >= n)]
            raise ValueError(f"actions must be integers in [0, {n}) (discrete actions), got {bad[:5].tolist()}")
        return arr

    def run(self, env: Any, index: Any, acting: Any = None) -> tuple[dict[str, Any], Any, Any]:
        """Run each world's action (or each robot's) as batched control steps, from ``env``'s state.

        Parameters
        ----------
        env : VectorPointNavEnv
            The engine; its ``_drive(commands, state)`` advances every world one control
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
        state : dict of arrays
            The worlds' (robots') pose, height and velocities after their actions (keys ``MOVED``).
        contact : array of bool
            Whether any of a world's (robot's) control steps touched something.
        stopped : array of bool or None
            The worlds (robots) that called STOP, or None without STOP.
        """
        a, xp = self.arrays, self.arrays.xp
        command, steps = self.commands[index], self.steps[index]
        state = {key: env._state[key] for key in MOVED}
        contact = xp.zeros_like(index) > 0
        z_start, dt = state["z"], env.dt
        fall_speed = xp.zeros_like(z_start)  # m/s, of the worlds that fell in an earlier sub-step
        zero = xp.zeros_like(z_start)
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
            falling = state["z"] < z_start
            moved, touched = env._drive(xp.where(running[..., None], command, 0.0 * command), state)
            # A falling robot no longer drives: it only drops, faster each step (the backend's _fall).
            drop = fall_speed * dt + 0.5 * _GRAVITY * dt * dt
            fell = {"x": state["x"], "y": state["y"], "yaw": state["yaw"], "z": state["z"] - drop,
                    "vx": zero, "vy": zero, "w": zero, "vz": -drop / dt}
            moved = {key: xp.where(falling, fell[key], moved[key]) for key in MOVED}
            state = {key: xp.where(active, moved[key], state[key]) for key in MOVED}
            began = active & ~falling & (state["z"] < z_start)
            fall_speed = xp.where(began, _FALL_SPEED + _GRAVITY * dt,
                                  xp.where(active & falling, fall_speed + _GRAVITY * dt, fall_speed))
            contact = contact | (active & touched & ~falling)
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
