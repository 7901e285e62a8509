"""The stepping rules of :class:`~pointnav_core.envs.multi_pointnav.MultiPointNavEnv`: checking actions.

A parallel step takes exactly one action for every alive agent. :func:`check_actions`
checks them all before anything moves, so a rejected step changes nothing; its errors name
the agent (a missing action, one for an agent whose episode ended or for an unknown agent,
one of the wrong shape). Finiteness of continuous actions is left to the backend's step,
which moves nothing when it refuses one; :func:`named_action_error` then names the agent.
:func:`no_agents_error` says why a step with no alive agent is refused, and
:func:`step_discrete` runs one step of discrete actions.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from pointnav_core.envs import common as _envcommon
from pointnav_core.errors import ArgumentError
from pointnav_core.task import TaskStateError
from pointnav_core.task.actions import check_discrete_action

__all__ = [
    "bad_keys_error",
    "check_actions",
    "named_action_error",
    "no_agents_error",
    "step_discrete",
]

#: Per agent: robot index, action shape, drive, the task's step and its observation function.
Slot = tuple[int, tuple[int], str, Callable[..., Any], Callable[..., Any]]
#: Per acting agent: agent, robot index, checked action, the task's step and observation.
Todo = tuple[str, int, Any, Callable[..., Any], Callable[..., Any]]


def no_agents_error(started: bool, void: bool) -> TaskStateError:
    """Why ``step()`` cannot run with no alive agent.

    Parameters
    ----------
    started : bool
        Whether ``reset()`` was ever called.
    void : bool
        Whether the last reset or step failed half-way.
    """
    if not started:
        reason = "no episode has started: call reset() first"
    elif void:
        reason = (
            "the last reset or step failed half-way, so there is no valid episode: "
            "call reset()"
        )
    else:
        reason = "every agent's episode has ended: call reset() to start new ones"
    return TaskStateError(f"step() needs alive agents, but env.agents is empty: {reason}")


def bad_keys_error(
    agents: Sequence[str], actions: Mapping[str, Any], known: Mapping[str, int]
) -> ValueError:
    """The error for ``actions`` whose keys are not exactly the alive ``agents``.

    Parameters
    ----------
    agents : sequence of str
        The alive agents (``env.agents``).
    actions : Mapping
        The actions given to ``step()``.
    known : Mapping
        Every possible agent (alive or not), to tell an ended agent from an unknown one.
    """
    alive = set(agents)
    for agent in agents:
        if agent not in actions:
            return ArgumentError(
                f"missing action for {agent}: every agent in env.agents {agents} must "
                f"act (agents whose episode ended must not)"
            )
    for key in actions:
        if key in alive:
            continue
        if key in known:
            return ArgumentError(
                f"got an action for {key}, which is not alive: its episode has ended; step() "
                f"takes actions only for the agents in env.agents {agents}"
            )
        return ArgumentError(
            f"got an action for unknown agent {key!r}; step() takes actions only for the "
            f"agents in env.agents {agents}"
        )
    return ArgumentError(  # only a Mapping whose len() disagrees with its keys gets here
        f"actions must hold exactly one action per agent in env.agents {agents}, "
        f"got {len(actions)} for keys {list(actions)}"
    )


def check_actions(
    agents: Sequence[str],
    actions: Any,
    slots: Mapping[str, Slot],
    plans: Sequence[Sequence[Any]] | None,
    known: Mapping[str, int],
) -> tuple[dict[int, Any], list[Todo]]:
    """Check one action per alive agent, before anything moves.

    Parameters
    ----------
    agents : sequence of str
        The alive agents, in order.
    actions : Mapping
        Agent -> action, as given to ``step()``.
    slots : Mapping
        Agent -> its :data:`Slot`.
    plans : sequence or None
        Per robot, its discrete actions' plans; None for continuous actions.
    known : Mapping
        Every possible agent.

    Returns
    -------
    commands : dict
        Robot index -> checked action (a float array in ``[-1, 1]``, its finiteness not
        yet checked, or a discrete action's index).
    todo : list
        One :data:`Todo` per agent, in ``agents`` order.

    Raises
    ------
    ValueError
        For actions that are not a dict, a missing, extra or None action, or an action of
        the wrong shape or value, naming the agent.
    """
    if type(actions) is not dict and not isinstance(actions, Mapping):
        raise ArgumentError(
            f"actions must be a dict of agent -> action for the agents in env.agents "
            f"{agents}, got {type(actions).__name__}"
        )
    if len(actions) != len(agents):
        raise bad_keys_error(agents, actions, known)
    check = _envcommon.check_action
    commands: dict[int, Any] = {}
    todo: list[Todo] = []
    for agent in agents:
        i, shape, drive, task_step, observe = slots[agent]
        try:
            action = actions[agent]
        except KeyError:  # as many keys as agents, so one is missing and one is extra
            raise bad_keys_error(agents, actions, known)
        if action is None:
            raise ArgumentError(
                f"missing action for {agent}: got None, but {agent} is alive; every agent "
                f"in env.agents must act"
            )
        try:
            if plans is None:  # finiteness: the backend's step checks it
                action = check(action, shape, drive, finite=False)
            else:
                action = check_discrete_action(action, len(plans[i]))
        except ValueError as err:
            raise ArgumentError(f"{agent}: {err}") from None
        commands[i] = action
        todo.append((agent, i, action, task_step, observe))
    return commands, todo


def named_action_error(err: ValueError, todo: Sequence[Todo]) -> ValueError:
    """The backend's refusal of a step, prefixed with the first agent whose action is not
    finite (the backend refuses the first bad action it meets, in the agents' order)."""
    for agent, _, action, *_ in todo:
        if not np.isfinite(action).all():
            return ArgumentError(f"{agent}: {err}")
    return err


def step_discrete(
    backend: Any, plans: Sequence[Any], actions: dict[int, int], after: Callable[[], None] | None = None
) -> dict[int, bool]:
    """Run each robot's discrete action for its control steps, all robots together; a
    robot's action ends at its first contact. ``plans[i][a]`` is robot ``i``'s command and
    control steps for action ``a``; ``after`` is called after every control step (the
    pedestrians walk). Returns whether each robot touched something
    (:mod:`pointnav_core.task.actions`)."""
    todo = {i: plans[i][a] for i, a in actions.items()}
    contacts = dict.fromkeys(todo, False)
    for k in range(max(steps for _, steps in todo.values())):
        backend.step({i: cmd for i, (cmd, steps) in todo.items() if k < steps and not contacts[i]})
        if after is not None:
            after()
        for i in todo:
            if not contacts[i] and backend.in_contact(i):
                contacts[i] = True
    return contacts
