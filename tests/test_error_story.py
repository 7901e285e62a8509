"""One error story (issue 31, point 4).

Every deliberate error derives from ``PointNavError``; a refused argument is an
``ArgumentError``, which is also a ``ValueError``; a call out of order is a
``TaskStateError``, which is also a ``RuntimeError``. The source holds no ``raise`` of a
builtin ``ValueError``, ``RuntimeError`` or ``TypeError`` (checked on the syntax tree), and
the same misuse raises the same class in every engine: the single env, the PettingZoo
parallel env, the batched engine and its fleet.
"""

from __future__ import annotations

import ast
import importlib
import math
import pathlib

import numpy as np
import pytest

from pointnav_core import errors, scenes
from pointnav_core.datasets.format import PointNavEpisode
from pointnav_core.envs.multi_pointnav import parallel_env
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.errors import (
    ArgumentError,
    ArgumentTypeError,
    PointNavError,
    TaskStateError,
)
from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.vector import VectorPointNavEnv

SRC = pathlib.Path(__file__).resolve().parents[1] / "src"
BUILTINS = frozenset({"ValueError", "RuntimeError", "TypeError"})

#: (file relative to src/, builtin name) pairs that may stay builtin. Empty: nothing in
#: src/ needs one. An entry belongs here only where a protocol demands the builtin class
#: itself and a subclass would be wrong (as ``__getattr__`` must raise AttributeError,
#: which this scan does not cover); every entry must still match a raise (checked below).
ALLOWED: frozenset[tuple[str, str]] = frozenset()


def builtin_errors(source: str) -> list[tuple[int, str]]:
    """(line, name) of each builtin ValueError/RuntimeError/TypeError that ``source``
    raises or builds: ``raise ValueError``, ``raise ValueError(...)`` and ``ValueError(...)``
    (an error built to be raised elsewhere). Names in ``except`` clauses are not calls."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in BUILTINS:
            found.append((node.lineno, node.func.id))
        elif isinstance(node, ast.Raise) and isinstance(node.exc, ast.Name) and node.exc.id in BUILTINS:
            found.append((node.lineno, node.exc.id))
    return found


def test_the_scan_finds_every_form_of_a_builtin_raise() -> None:
    source = (
        "def f(x):\n"
        "    try:\n"
        "        g()\n"
        "    except (ValueError, TypeError):\n"  # a catch, not a raise
        "        raise ValueError('x must be 1')\n"
        "    if x:\n"
        "        raise RuntimeError\n"
        "    return TypeError(f'{x}')\n"
        "def g():\n"
        "    raise ArgumentError('fine')  # ValueError('in a comment')\n"
        "    s = 'raise ValueError(\"in a string\")'\n"
    )
    assert sorted(builtin_errors(source)) == [(5, "ValueError"), (7, "RuntimeError"), (8, "TypeError")]


def test_no_builtin_value_runtime_or_type_error_is_raised_in_src() -> None:
    seen, bad = set(), []
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        for line, name in builtin_errors(path.read_text(encoding="utf-8")):
            seen.add((rel, name))
            if (rel, name) not in ALLOWED:
                bad.append(f"{rel}:{line}: {name}")
    assert not bad, "raise a pointnav_core.errors class instead (ArgumentError is a ValueError):\n" + "\n".join(bad)
    assert ALLOWED <= seen, f"stale allow-list entries: {sorted(ALLOWED - seen)}"


def defined_exceptions() -> list[tuple[str, str]]:
    """(module, class) of every class in src/ whose name ends in Error."""
    found = []
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).with_suffix("")
        module = ".".join(rel.parts[1:] if rel.parts[0] == "backends" else rel.parts)
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.ClassDef) and node.name.endswith("Error"):
                found.append((module, node.name))
    return found


def test_every_error_class_of_the_library_is_a_pointnav_error() -> None:
    classes = defined_exceptions()
    assert ("pointnav_core.utils.workers", "WorkerError") in classes  # the scan sees outside errors.py
    for module, name in classes:
        cls = getattr(importlib.import_module(module), name)
        assert issubclass(cls, PointNavError), f"{module}.{name} does not derive from PointNavError"


def test_each_error_is_also_the_builtin_old_code_catches() -> None:
    # (class, builtins it must also be): old ``except ValueError`` code keeps working.
    table = {
        errors.ArgumentError: (ValueError,),
        errors.ArgumentTypeError: (ValueError, TypeError, errors.ArgumentError),
        errors.TaskStateError: (RuntimeError,),
        errors.SamplingError: (RuntimeError,),
        errors.BackendError: (TypeError,),
        errors.EpisodeError: (RuntimeError,),
    }
    assert set(table) == {getattr(errors, n) for n in errors.__all__} - {PointNavError}
    for cls, bases in table.items():
        assert issubclass(cls, PointNavError) and all(issubclass(cls, b) for b in bases), cls
    from pointnav_core import task
    from pointnav_core.task import lifecycle

    assert lifecycle.TaskStateError is task.TaskStateError is TaskStateError  # one class, not three


# The same misuse in every engine. A walled 3 x 2 m room keeps the engines small.
def room() -> scenes.Scene:
    grid = np.zeros((20, 30), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    return scenes.Scene.from_array(grid, 0.1, scene_id="box")


def episode(scene_id: str, start=(0.6, 0.6), goal=(2.2, 1.2)) -> PointNavEpisode:
    return PointNavEpisode(
        episode_id="e", scene_id=scene_id, floor=0, start_position=(*start, 0.0),
        start_rotation=(0.0, 0.0, 0.0, 1.0), goal_position=(*goal, 0.0),
        goal_radius=0.3, geodesic_distance=math.dist(start, goal), robot_radius=0.18,
    )


ENGINES = {
    "single": lambda **kw: PointNavEnv(scene=room(), **kw),
    "parallel": lambda **kw: parallel_env(scene=room(), n_robots=2, **kw),
    "vector": lambda **kw: VectorPointNavEnv(1, scene=room(), pool_size=1, seed=0, **kw),
    "fleet": lambda **kw: VectorPointNavEnv(1, n_robots=2, scene=room(), pool_size=1, seed=0, **kw),
}


def step(kind: str, env, action) -> None:
    """One step of ``action`` for every robot (per engine, in its own shape)."""
    if kind == "single":
        env.step(action)
    elif kind == "parallel":
        env.step({agent: action for agent in env.possible_agents})
    elif kind == "vector":
        env.step([action])
    else:
        env.step([[action, action]])


def reset_into(kind: str, env, scene_id: str) -> None:
    """Reset ``env`` into a dataset episode of scene ``scene_id`` (one per robot)."""
    ep, other = episode(scene_id), episode(scene_id, start=(2.4, 0.5), goal=(0.5, 1.5))
    if kind == "single":
        env.reset(options={"episode": ep})
    elif kind == "parallel":
        env.reset(options={"episodes": [ep, other]})
    else:
        env.reset(options={"episodes": [ep] if kind == "vector" else [[ep, other]]})


def misuse(kind: str, what: str) -> None:
    if what == "step before reset":
        step(kind, ENGINES[kind](), [0.5, 0.0])
    elif what == "unknown scene id":
        reset_into(kind, ENGINES[kind](), "house_b")
    elif what == "bool as a number":
        ENGINES[kind](robot={"radius": True})
    else:
        env = ENGINES[kind]()
        env.reset(seed=0)
        step(kind, env, {"non-number action": ["a", "b"], "bool action": [True, False]}[what])


EXPECTED = {
    "step before reset": TaskStateError,
    "unknown scene id": ArgumentError,
    "non-number action": ArgumentError,
    "bool action": ArgumentError,
    "bool as a number": ArgumentError,
}


@pytest.mark.parametrize("what", list(EXPECTED))
def test_the_same_misuse_raises_the_same_class_in_every_engine(what: str) -> None:
    raised = {}
    for kind in ENGINES:
        with pytest.raises(PointNavError) as info:
            misuse(kind, what)
        raised[kind] = info.type
    # The exact class, not only a subclass of it: one story whatever the engine.
    assert raised == dict.fromkeys(ENGINES, EXPECTED[what])
    assert issubclass(EXPECTED[what], ValueError if EXPECTED[what] is ArgumentError else RuntimeError)


def test_a_wrong_type_is_an_argument_type_error_caught_as_both_builtins() -> None:
    from pointnav_core.sensors.raycast import ScanGeometry

    for builtin in (TypeError, ValueError, ArgumentError):
        with pytest.raises(builtin, match="tmap must be a TraversableMap, got str"):
            ScanGeometry("not a map")
    with pytest.raises(ArgumentTypeError):
        ScanGeometry("not a map")
