"""The lifecycle of a task's episode: states, events and the transition table (h11 style).

A task is a small state machine. Its states are :class:`TaskState`; the events are what
its ``reset`` and ``step`` end with (:class:`Event`); the legal moves are the table
:data:`TRANSITIONS`, and nothing else decides them. The diagram in ``docs/lifecycle.md``
is :func:`diagram` of that table (a test keeps the two equal):

- a reset may start an episode from any state;
- a reset or a step that raises leaves the task in ERROR, from any state;
- a step happens only in RUNNING, and stays there or moves to DONE when a termination
  condition fires.

A pair missing from the table is an illegal move: :func:`move` raises
:class:`TaskStateError` and the state is unchanged.

Examples
--------
>>> move(TaskState.IDLE, Event.RESET)
<TaskState.RUNNING: 'running'>
>>> move(TaskState.DONE, Event.STEP)
Traceback (most recent call last):
...
pointnav_core.errors.TaskStateError: step() is not allowed while the task is DONE: the episode has ended (terminated or truncated): call reset(env) to start another
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from types import MappingProxyType

from pointnav_core.errors import TaskStateError

__all__ = ["TaskState", "Event", "TRANSITIONS", "move", "allows", "diagram"]


class TaskState(enum.Enum):
    """States of a task's episode lifecycle."""

    #: Built, no episode yet: call ``reset(env)``.
    IDLE = "idle"
    #: An episode is in progress: ``step`` is legal.
    RUNNING = "running"
    #: The episode ended (terminated or truncated): call ``reset(env)`` to start another.
    DONE = "done"
    #: A reset or a step raised half-way; no valid episode: call ``reset(env)``.
    ERROR = "error"

    # Members are singletons compared by identity: hash them so too (Enum's default hash
    # is a Python-level function, and the transition table is consulted on every step).
    __hash__ = object.__hash__


class Event(enum.Enum):
    """What a ``reset`` or ``step`` of the task ended with."""

    #: A reset succeeded.
    RESET = "reset"
    #: A step ended with no termination condition done.
    STEP = "step"
    #: A step ended with some termination condition done.
    END = "end"
    #: A reset or a step raised.
    FAIL = "fail"

    __hash__ = object.__hash__


IDLE, RUNNING, DONE, ERROR = TaskState.IDLE, TaskState.RUNNING, TaskState.DONE, TaskState.ERROR

#: The lifecycle: ``(state, event) -> next state``.
TRANSITIONS: Mapping[tuple[TaskState, Event], TaskState] = MappingProxyType(
    {
        **{(state, Event.RESET): RUNNING for state in TaskState},
        **{(state, Event.FAIL): ERROR for state in TaskState},
        (RUNNING, Event.STEP): RUNNING,
        (RUNNING, Event.END): DONE,
    }
)

#: Why a step is illegal in each state where it is, and what to do.
ILLEGAL_HINT: Mapping[TaskState, str] = MappingProxyType(
    {
        IDLE: "no episode has started: call reset(env) first",
        DONE: "the episode has ended (terminated or truncated): call reset(env) to start another",
        ERROR: "the last reset or step failed, so there is no valid episode: call reset(env)",
    }
)

#: The method whose call each event stands for, in error messages.
_CALL = MappingProxyType({Event.RESET: "reset()", Event.STEP: "step()", Event.END: "step()", Event.FAIL: "reset()"})


def allows(state: TaskState, event: Event) -> bool:
    """Whether the table has a move for ``event`` in ``state``."""
    return (state, event) in TRANSITIONS


def move(state: TaskState, event: Event) -> TaskState:
    """The state after ``event`` in ``state``; :class:`TaskStateError` if the move is illegal."""
    try:
        return TRANSITIONS[(state, event)]
    except KeyError:
        hint = ILLEGAL_HINT.get(state, "")
        raise TaskStateError(f"{_CALL[event]} is not allowed while the task is {state.name}: {hint}") from None


def diagram() -> str:
    """The transition table as a Mermaid state diagram (``docs/lifecycle.md`` shows it).

    Moves from every state on one event are drawn once, from "any state"; the start
    state is IDLE.
    """
    lines = ["stateDiagram-v2", f"    [*] --> {IDLE.name}"]
    for event in Event:
        targets = {TRANSITIONS.get((state, event)) for state in TaskState}
        if len(targets) == 1 and None not in targets:
            (target,) = targets
            lines.append(f"    any_state --> {target.name}: {event.value}")
            continue
        for state in TaskState:
            target = TRANSITIONS.get((state, event))
            if target is not None:
                lines.append(f"    {state.name} --> {target.name}: {event.value}")
    lines.append('    state "any state" as any_state')
    return "\n".join(lines)
