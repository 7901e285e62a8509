"""Envs survive being copied: ``pickle``, ``copy.deepcopy``, ``cloudpickle`` and read-only
buffers (issue 11).

Vector-env libraries and Ray send envs to worker processes by pickling them; Ray's object
store hands numpy arrays back read-only. Each copy must then behave exactly like the
original: the same observations, rewards, flags and infos, step for step. The reference is
the original env itself, stepped with the same actions.
"""

from __future__ import annotations

import copy
import math
import pickle
from collections.abc import Callable
from typing import Any

import cloudpickle
import numpy as np
import pytest

from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.utils.frozen import FrozenMapping, thaw

STEPS = 300


def _readonly_copy(obj: Any) -> Any:
    """A copy whose arrays are rebuilt from read-only buffers, as Ray's serializer does."""
    buffers: list[pickle.PickleBuffer] = []
    data = pickle.dumps(obj, protocol=5, buffer_callback=buffers.append)
    assert buffers, "nothing went out of band, so nothing is read-only"
    return pickle.loads(data, buffers=[memoryview(b.raw()).toreadonly() for b in buffers])


COPIERS: dict[str, Callable[[Any], Any]] = {
    "pickle": lambda env: pickle.loads(pickle.dumps(env)),
    "deepcopy": copy.deepcopy,
    "cloudpickle": lambda env: cloudpickle.loads(cloudpickle.dumps(env)),
    "readonly": _readonly_copy,
}


def _same(a: Any, b: Any) -> bool:
    """Exact equality through dicts, sequences and arrays (NaN equals NaN)."""
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return (
            isinstance(b, np.ndarray)
            and a.dtype == b.dtype
            and np.array_equal(a, b, equal_nan=True)
        )
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return type(a) is type(b) and a == b


def _drive_single(env: PointNavEnv, seed: int, steps: int) -> list[Any]:
    """Mostly-forward random actions; every episode end is followed by a reset."""
    rng = np.random.default_rng(seed)
    out: list[Any] = []
    for i in range(steps):
        action = np.array([rng.uniform(0.3, 1.0), rng.uniform(-1.0, 1.0)], dtype=np.float32)
        result = env.step(action)
        out.append(result)
        if result[2] or result[3]:
            # The same seed again: the copy must reuse its cached goal field, the one
            # that came through the copy (read-only in the "readonly" case).
            out.append(env.reset(seed=seed if i % 2 else seed + i))
    return out


def _drive_multi(env: MultiPointNavEnv, seed: int, steps: int) -> list[Any]:
    rng = np.random.default_rng(seed)
    out: list[Any] = []
    for i in range(steps):
        if not env.agents:
            out.append(env.reset(seed=seed if i % 2 else seed + i))
            continue
        actions = {
            agent: np.array([rng.uniform(0.3, 1.0), rng.uniform(-1.0, 1.0)], dtype=np.float32)
            for agent in env.agents
        }
        out.append(env.step(actions))
    return out


def _collisions(results: list[Any]) -> int:
    """Steps on which the single robot touched something."""
    return sum(1 for r in results if len(r) == 5 and r[4]["reward_breakdown"]["collision"] != 0.0)


@pytest.mark.parametrize("copier", sorted(COPIERS))
@pytest.mark.parametrize("backend", ["kinematic", "pymunk"])
@pytest.mark.parametrize("when", ["before_reset", "after_reset"])
def test_a_copied_single_robot_env_steps_exactly_like_the_original(
    copier: str, backend: str, when: str
) -> None:
    env = PointNavEnv(backend=backend, task={"reward_type": "geodesic"})
    if when == "after_reset":
        env.reset(seed=4)
        _drive_single(env, 4, 40)
    twin = COPIERS[copier](env)
    assert twin is not env
    first = _same(env.reset(seed=4), twin.reset(seed=4)) if when == "before_reset" else True
    ours, theirs = _drive_single(env, 4, STEPS), _drive_single(twin, 4, STEPS)
    assert first and _same(ours, theirs)
    # The run touches walls, so a copy that lost its collision geometry could not pass.
    assert _collisions(ours) > 0


@pytest.mark.parametrize("copier", sorted(COPIERS))
@pytest.mark.parametrize("backend", ["kinematic", "pymunk"])
@pytest.mark.parametrize("when", ["before_reset", "after_reset"])
def test_a_copied_multi_robot_env_steps_exactly_like_the_original(
    copier: str, backend: str, when: str
) -> None:
    env = MultiPointNavEnv(n_robots=3, backend=backend, task={"reward_type": "geodesic"})
    if when == "after_reset":
        env.reset(seed=2)
        _drive_multi(env, 2, 40)
    twin = COPIERS[copier](env)
    first = _same(env.reset(seed=2), twin.reset(seed=2)) if when == "before_reset" else True
    assert first and _same(_drive_multi(env, 2, STEPS), _drive_multi(twin, 2, STEPS))


def test_the_kinematic_collision_cache_survives_cloudpickle_as_numbers() -> None:
    # The failure: a cached memoryview came back as bytes, whose items are small
    # integers, so every travel budget looked huge and no contact was ever checked.
    env = PointNavEnv()
    env.reset(seed=0)
    twin = cloudpickle.loads(cloudpickle.dumps(env))
    ours = env.backend._robots[0].fast
    theirs = twin.backend._robots[0].fast
    assert len(ours) == len(theirs) > 0
    assert all(type(v) is float for v in theirs[:10])
    assert list(ours) == list(theirs)


def test_frozen_mapping_is_read_only_and_picklable() -> None:
    frozen = FrozenMapping({"a": 1, "b": [2]})
    with pytest.raises(TypeError):
        frozen["a"] = 3  # type: ignore[index]
    for name in ("pickle", "deepcopy", "cloudpickle"):
        again = COPIERS[name](frozen)
        assert isinstance(again, FrozenMapping) and dict(again) == {"a": 1, "b": [2]}


def test_thaw_copies_only_read_only_arrays() -> None:
    locked = np.arange(3.0)
    locked.flags.writeable = False
    free = np.zeros(2)
    out = thaw({"x": [locked, (free, 1)], "y": "s"})
    assert out["x"][0].flags.writeable and np.array_equal(out["x"][0], locked)
    assert out["x"][1][0] is free and out["y"] == "s"
