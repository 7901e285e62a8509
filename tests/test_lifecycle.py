"""The lifecycle table against the rules written out by hand, and the docs diagram."""

import itertools
from pathlib import Path

import pytest

from pointnav_core.errors import TaskStateError
from pointnav_core.task.lifecycle import (
    TRANSITIONS,
    Event,
    TaskState,
    allows,
    diagram,
    move,
)

DOCS = Path(__file__).resolve().parents[1] / "docs" / "lifecycle.md"


def expected(state: TaskState, event: Event) -> TaskState | None:
    """The rules of the lifecycle, written independently of the table."""
    if event is Event.RESET:
        return TaskState.RUNNING
    if event is Event.FAIL:
        return TaskState.ERROR
    if state is not TaskState.RUNNING:
        return None
    return TaskState.RUNNING if event is Event.STEP else TaskState.DONE


@pytest.mark.parametrize(("state", "event"), list(itertools.product(TaskState, Event)))
def test_every_move_follows_the_rules(state, event):
    want = expected(state, event)
    assert allows(state, event) is (want is not None)
    if want is None:
        with pytest.raises(TaskStateError, match=f"while the task is {state.name}: .*call reset"):
            move(state, event)
    else:
        assert move(state, event) is want


def test_the_table_has_exactly_the_legal_moves():
    legal = {(s, e) for s, e in itertools.product(TaskState, Event) if expected(s, e) is not None}
    assert set(TRANSITIONS) == legal


def test_the_docs_diagram_is_drawn_from_the_table():
    assert f"```mermaid\n{diagram()}\n```" in DOCS.read_text()
